//! The report's table of photon maps: for every estimator whose runs wrote photon-mapping
//! diagnostics (`ppm`), the means over its runs of the light paths traced, the photons
//! stored (and per light path), the final mean gather radius and the memory per photon and
//! per hit point.

use std::fmt::Write as _;

use serde_json::Value;

/// The section, or None when no estimator wrote photon diagnostics; `collected` as
/// `chain_diagnostics::collect` gives it.
pub fn readme_section(collected: &[(String, Vec<Value>)]) -> Option<String> {
    let mut md = String::new();
    for (label, values) in collected {
        let field = |v: &Value, key: &str| v.get(key).and_then(Value::as_f64);
        let runs: Vec<[f64; 5]> = values
            .iter()
            .filter_map(|v| {
                Some([
                    field(v, "light_paths")?,
                    field(v, "photons_stored")?,
                    field(v, "mean_radius")?,
                    field(v, "bytes_per_photon")?,
                    field(v, "bytes_per_hit_point")?,
                ])
            })
            .collect();
        if runs.is_empty() {
            continue;
        }
        let mean = |i: usize| runs.iter().map(|r| r[i]).sum::<f64>() / runs.len() as f64;
        let _ = writeln!(
            md,
            "| {label} | {} | {:.3e} | {:.3e} | {:.2} | {:.3e} | {:.0} | {:.0} |",
            runs.len(),
            mean(0),
            mean(1),
            mean(1) / mean(0).max(1.0),
            mean(2),
            mean(3),
            mean(4),
        );
    }
    if md.is_empty() {
        return None;
    }
    Some(format!(
        "\n## Photon maps\n\nMeans over runs of each photon-mapping estimator's diagnostics \
         (`diagnostics.json`): light paths traced, photons stored (one per non-specular \
         vertex of a light path), photons per light path, the mean gather radius at the end \
         (scene units), and bytes per photon (the photon and its kd-tree entry) and per hit \
         point (the eye sample and the pixel's statistics).\n\n\
         | estimator | runs | light paths | photons | per path | mean radius | bytes/photon | bytes/hit point |\n\
         |---|---|---|---|---|---|---|---|\n{md}\n"
    ))
}
