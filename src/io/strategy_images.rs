//! The files of `render --set strategies=true` (`bdpt`): beside `OUT.exr`, a folder
//! `OUT-strategies/` with, for every strategy (s, t), `sS-tT-weighted.exr` (its share of the
//! image: these sum to `OUT.exr`) and `sS-tT-unweighted.exr` (its own estimate of the light
//! of its path length), the pyramids `pyramid-weighted.png` and `pyramid-unweighted.png`
//! (rows: path length, columns: s), and `strategies.csv` (s, t, path length, the share of
//! the image's mean luminance each weighted image holds, and each image's mean RGB).

use std::path::{Path, PathBuf};

use crate::error::{Error, Result};
use crate::estimator::bdpt::StrategyImage;
use crate::experiment::plot::{PyramidCell, strategy_pyramid};
use crate::image::Image;
use crate::io::atomic::{check_writable, write_file_atomically};
use crate::io::exr::write_exr;

/// The folder for the strategy images of output `exr`: `OUT-strategies` beside `OUT.exr`.
pub fn folder_for(exr: &Path) -> PathBuf {
    let stem = exr
        .file_stem()
        .map(|s| s.to_os_string())
        .unwrap_or_default();
    let mut name = stem;
    name.push("-strategies");
    exr.with_file_name(name)
}

/// Creates `folder` (and its parents) and checks that files can be written in it: for
/// `render` to call before it renders.
pub fn prepare(folder: &Path) -> Result<()> {
    std::fs::create_dir_all(folder).map_err(|e| Error::io(folder, e))?;
    check_writable(&folder.join("pyramid-weighted.png"))
}

/// Writes the files of the strategy images into `folder` (see the module documentation),
/// the EXRs only with `exrs`; `whole` is the estimator's image.
pub fn write(folder: &Path, whole: &Image, images: &[StrategyImage], exrs: bool) -> Result<()> {
    let mean = |image: &Image| {
        let n = (image.pixels.len().max(1)) as f64;
        let mut sum = [0f64; 3];
        for p in &image.pixels {
            for (c, s) in sum.iter_mut().enumerate() {
                *s += p[c] as f64;
            }
        }
        sum.map(|s| s / n)
    };
    let luminance = |c: [f64; 3]| 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
    let total = luminance(mean(whole));
    let mut csv = String::from(
        "s,t,length,share,weighted_r,weighted_g,weighted_b,unweighted_r,unweighted_g,unweighted_b\n",
    );
    for im in images {
        if exrs {
            let name = format!("s{}-t{}", im.s, im.t);
            write_exr(&folder.join(format!("{name}-weighted.exr")), &im.weighted)?;
            let unweighted = folder.join(format!("{name}-unweighted.exr"));
            write_exr(&unweighted, &im.unweighted)?;
        }
        let (w, u) = (mean(&im.weighted), mean(&im.unweighted));
        let share = if total > 0.0 {
            luminance(w) / total
        } else {
            0.0
        };
        csv.push_str(&format!(
            "{},{},{},{share:.6e},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e}\n",
            im.s,
            im.t,
            im.s + im.t - 1,
            w[0],
            w[1],
            w[2],
            u[0],
            u[1],
            u[2]
        ));
    }
    write_file_atomically(&folder.join("strategies.csv"), csv.as_bytes())?;
    for (suffix, title, pick) in [
        (
            "weighted",
            "Weighted strategies: each one's share of the image",
            (|im: &StrategyImage| &im.weighted) as fn(&StrategyImage) -> &Image,
        ),
        (
            "unweighted",
            "Unweighted strategies: each one's own estimate of its path length",
            |im: &StrategyImage| &im.unweighted,
        ),
    ] {
        let cells: Vec<PyramidCell> = images
            .iter()
            .map(|im| PyramidCell {
                s: im.s,
                t: im.t,
                image: pick(im),
            })
            .collect();
        strategy_pyramid(
            &folder.join(format!("pyramid-{suffix}")),
            title,
            whole,
            &cells,
        )?;
    }
    Ok(())
}
