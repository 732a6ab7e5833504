//! The settings every path-building estimator reads: how long paths may be, when Russian
//! roulette starts, and whether emitters seen directly count.

use crate::error::{Error, Result};
use crate::estimator::Params;
use crate::scene::Scene;

/// `max_depth`, `rr_depth`, `hide_emitters`, each defaulting to the scene's `<integrator>`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PathSettings {
    /// Longest path in segments, Mitsuba's count (1: emitters seen directly, 2: direct
    /// lighting); None for unbounded (Mitsuba's −1).
    pub max_depth: Option<u32>,
    /// Russian roulette once a walk has scattered this many times.
    pub rr_depth: u32,
    /// Emitters the camera sees are left out, as Mitsuba 3.9's `hide_emitters` does it:
    /// the emission of the surface a camera ray hits first, and the environment for paths
    /// that escape having crossed nothing but `null` surfaces. Emitting surfaces seen
    /// through a `null` surface, anything seen in a mirror, and all light reflected stay.
    pub hide_emitters: bool,
}

impl PathSettings {
    /// Reads `max_depth`, `rr_depth` and `hide_emitters` from `params`, defaulting to the
    /// scene's integrator element (and its bounds, Mitsuba's).
    pub fn from_params(params: &Params, scene: &Scene) -> Result<PathSettings> {
        let integrator = &scene.description.integrator;
        let max_depth: i64 = params.get("max_depth", integrator.max_depth as i64)?;
        let rr_depth: u32 = params.get("rr_depth", integrator.rr_depth)?;
        let hide_emitters: bool = params.get("hide_emitters", integrator.hide_emitters)?;
        if max_depth < -1 {
            return Err(Error::usage(format!(
                "--set max_depth={max_depth}: must be -1 (unbounded) or at least 0"
            )));
        }
        if rr_depth == 0 {
            return Err(Error::usage("--set rr_depth=0: must be at least 1"));
        }
        Ok(PathSettings {
            max_depth: (max_depth >= 0).then(|| max_depth.min(u32::MAX as i64) as u32),
            rr_depth,
            hide_emitters,
        })
    }

    /// The longest path in segments, `u32::MAX` standing for unbounded.
    pub fn max_segments(&self) -> u32 {
        self.max_depth.unwrap_or(u32::MAX)
    }
}
