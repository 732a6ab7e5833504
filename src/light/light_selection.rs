//! Choosing one light for next-event estimation or for starting a light path: with
//! probability proportional to its power (`Light::power`), so bright lights get the samples.
//!
//! A light of zero power is never chosen. Every light that emits anything has positive
//! power (given a scene with positive extent), so choosing by power keeps the estimators
//! unbiased; estimators that combine strategies with MIS must use `pmf` for the chance of
//! having chosen the light an emitter hit belongs to.

use crate::light::distribution::Distribution1D;
use crate::math::lanes::{F32x16, Mask16, U32x16};

#[derive(Clone, Debug, PartialEq)]
pub struct LightSelection {
    /// None when no light has positive power.
    by_power: Option<Distribution1D>,
}

impl LightSelection {
    /// From the lights' powers (negative or NaN powers count as 0; a power that overflowed
    /// f32 counts as f32::MAX, so that light is still chosen).
    pub fn new(powers: &[f32]) -> LightSelection {
        let weights: Vec<f32> = powers
            .iter()
            .map(|&p| if p > 0.0 { p.min(f32::MAX) } else { 0.0 })
            .collect();
        LightSelection {
            by_power: Distribution1D::new(&weights),
        }
    }

    /// (light index, its probability, `u` rescaled to [0, 1) for reuse); None when there
    /// is no light to choose.
    pub fn sample(&self, u: f32) -> Option<(usize, f32, f32)> {
        self.by_power.as_ref().map(|d| d.sample_discrete(u))
    }

    /// The light and its probability of `sample`, for the lanes of `m`
    /// (`Distribution1D::pick_lanes`).
    #[inline]
    pub fn choose_lanes(&self, u: F32x16, m: Mask16) -> Option<(U32x16, F32x16)> {
        self.by_power.as_ref().map(|d| d.pick_lanes(u, m))
    }

    /// Probability of choosing light `i`.
    pub fn pmf(&self, i: usize) -> f32 {
        self.by_power.as_ref().map_or(0.0, |d| d.pmf(i))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_power_that_overflowed_is_still_chosen() {
        let selection = LightSelection::new(&[f32::INFINITY, 1.0, f32::NAN, -1.0]);
        assert!(selection.pmf(0) > 0.99);
        assert!(selection.pmf(1) > 0.0);
        assert_eq!((selection.pmf(2), selection.pmf(3)), (0.0, 0.0));
    }
}
