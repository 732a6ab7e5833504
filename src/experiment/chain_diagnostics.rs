//! The report's table of Markov chain diagnostics: for every estimator whose cells wrote
//! diagnostics (`pssmlt`, `mmlt`; `runner::run_cell`), the means over its runs of
//! acceptance (overall, small and large steps), the normalisation b with its standard
//! error, chains that never moved, the integrated autocorrelation time, the effective
//! sample size and mutations per second.

use std::fmt::Write as _;

use serde_json::Value;

use super::Experiment;
use super::runner::ResultsDir;
use crate::error::{Error, Result};
use crate::io::atomic::write_file_atomically;

/// The numbers the table shows, read from one run's JSON.
struct RunDiagnostics {
    acceptance: f64,
    small: f64,
    large: f64,
    b: f64,
    b_se: f64,
    never_moved: f64,
    chains: f64,
    tau: Option<f64>,
    tau_converged: bool,
    ess: Option<f64>,
    per_second: f64,
}

fn read(value: &Value) -> Option<RunDiagnostics> {
    let f = |path: &[&str]| -> Option<f64> {
        let mut v = value;
        for key in path {
            v = v.get(key)?;
        }
        v.as_f64()
    };
    Some(RunDiagnostics {
        acceptance: f(&["acceptance", "rate"])?,
        small: f(&["small_steps", "rate"])?,
        large: f(&["large_steps", "rate"])?,
        b: f(&["bootstrap", "b"])?,
        b_se: f(&["bootstrap", "b_standard_error"])?,
        never_moved: f(&["chains_never_moved"])?,
        chains: f(&["chains"])?,
        tau: f(&["autocorrelation_time"]),
        tau_converged: value
            .get("autocorrelation_converged")
            .and_then(Value::as_bool)
            .unwrap_or(false),
        ess: f(&["effective_sample_size"]),
        per_second: f(&["mutations_per_second"])?,
    })
}

fn mean(values: impl Iterator<Item = f64>) -> Option<f64> {
    let v: Vec<f64> = values.collect();
    (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64)
}

/// Every estimator's per-run diagnostics (chains, photon maps) as its cells wrote them, in the
/// spec's order; estimators without diagnostics are left out.
pub fn collect(experiment: &Experiment, results: &ResultsDir) -> Vec<(String, Vec<Value>)> {
    experiment
        .estimators
        .iter()
        .map(|entry| {
            let runs: Vec<Value> = (0..experiment.runs)
                .filter_map(|r| {
                    let path = results.cell_diagnostics(&entry.label, r);
                    serde_json::from_str(&std::fs::read_to_string(path).ok()?).ok()
                })
                .collect();
            (entry.label.clone(), runs)
        })
        .filter(|(_, runs)| !runs.is_empty())
        .collect()
}

/// `diagnostics.json`: the collected diagnostics, kept with the report (the cells are working
/// files and not committed).
pub fn write_json(path: &std::path::Path, collected: &[(String, Vec<Value>)]) -> Result<()> {
    let map: serde_json::Map<String, Value> = collected
        .iter()
        .map(|(label, runs)| (label.clone(), Value::Array(runs.clone())))
        .collect();
    let text = serde_json::to_string_pretty(&Value::Object(map))
        .map_err(|e| Error::io(path, std::io::Error::other(e)))?;
    write_file_atomically(path, (text + "\n").as_bytes())
}

/// The section, or None when no estimator wrote diagnostics.
pub fn readme_section(collected: &[(String, Vec<Value>)]) -> Option<String> {
    let mut md = String::new();
    for (label, values) in collected {
        let runs: Vec<RunDiagnostics> = values.iter().filter_map(read).collect();
        if runs.is_empty() {
            continue;
        }
        let m = |g: fn(&RunDiagnostics) -> f64| mean(runs.iter().map(g)).unwrap_or(0.0);
        let tau = mean(runs.iter().filter_map(|r| r.tau));
        let lower_bound = runs.iter().any(|r| r.tau.is_some() && !r.tau_converged);
        let ess = mean(runs.iter().filter_map(|r| r.ess));
        let _ = writeln!(
            md,
            "| {} | {} | {:.3} | {:.3} | {:.3} | {:.4e} ± {:.1e} | {:.1} / {:.0} | {} | {} | {:.3e} |",
            label,
            runs.len(),
            m(|r| r.acceptance),
            m(|r| r.small),
            m(|r| r.large),
            m(|r| r.b),
            m(|r| r.b_se),
            m(|r| r.never_moved),
            m(|r| r.chains),
            match tau {
                Some(t) => format!("{}{t:.1}", if lower_bound { "≥ " } else { "" }),
                None => "–".into(),
            },
            ess.map_or("–".into(), |e| format!("{e:.3e}")),
            m(|r| r.per_second),
        );
    }
    if md.is_empty() {
        return None;
    }
    Some(format!(
        "\n## Markov chains\n\nMeans over runs of each Metropolis estimator's chain diagnostics \
         (`diagnostics.json`): acceptance overall and of small and large steps, the \
         normalisation b (mean luminance of the bootstrap) with its standard error, chains \
         that never moved out of all chains, the integrated autocorrelation time τ of the \
         chains' importance in mutations (Sokal's automatic window over each chain's first \
         steps; ≥ where the window never closed), the effective sample size (mutations / τ) \
         and mutations per second.\n\n\
         | estimator | runs | accept | small | large | b ± s.e. | never moved | τ | ESS | mutations/s |\n\
         |---|---|---|---|---|---|---|---|---|---|\n{md}\nPer run: `diagnostics.json`.\n\n"
    ))
}
