//! `ppm`'s parameters (docs/DESIGN.md §3): the radius schedule's α, photons per pass, the
//! initial radius, fixed or stochastic hit points, and the path settings every estimator
//! reads.

use crate::error::{Error, Result};
use crate::estimator::Params;
use crate::path::settings::PathSettings;
use crate::scene::Scene;

/// How the gather radius starts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum InitialRadius {
    /// `radius=auto`: `AUTO_FOOTPRINTS` pixel footprints at the hit point (the camera's
    /// angle per pixel times the eye path's length), set where a pixel first has one.
    Auto,
    /// The same radius for every hit point, in scene units.
    Fixed(f32),
}

/// Pixel footprints in an automatic initial radius.
pub const AUTO_FOOTPRINTS: f32 = 2.0;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PpmSettings {
    pub path: PathSettings,
    /// The share of new photons a hit point keeps (Hachisuka et al. 2008, eq. 7), in (0, 1).
    pub alpha: f64,
    /// Light paths traced per pass.
    pub photons: u64,
    pub radius: InitialRadius,
    /// SPPM (Hachisuka and Jensen 2009): new eye paths every pass.
    pub stochastic: bool,
}

impl PpmSettings {
    pub fn from_params(params: &Params, scene: &Scene) -> Result<PpmSettings> {
        let path = PathSettings::from_params(params, scene)?;
        let alpha: f64 = params.get("alpha", 2.0 / 3.0)?;
        if !(alpha > 0.0 && alpha < 1.0) {
            return Err(Error::usage(format!(
                "--set alpha={alpha}: must lie strictly between 0 and 1"
            )));
        }
        let photons: u64 = params.get("photons", 100_000)?;
        if photons == 0 {
            return Err(Error::usage("--set photons=0: must be at least 1"));
        }
        let radius = match params.raw("radius") {
            None | Some("auto") => InitialRadius::Auto,
            Some(text) => match text.parse::<f32>() {
                Ok(r) if r > 0.0 && r.is_finite() => InitialRadius::Fixed(r),
                _ => {
                    return Err(Error::usage(format!(
                        "--set radius={text}: expected auto or a positive, finite number"
                    )));
                }
            },
        };
        let stochastic: bool = params.get("stochastic", false)?;
        Ok(PpmSettings {
            path,
            alpha,
            photons,
            radius,
            stochastic,
        })
    }
}
