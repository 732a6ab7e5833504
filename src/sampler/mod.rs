//! Where estimators draw their random numbers from.
//!
//! Every random number an estimator uses comes through a `Sampler`, so that a different
//! sample pattern (or PSSMLT's mutating primary-sample sampler) can be swapped in without
//! touching the estimator.

pub mod ccvt;
pub mod independent;
pub mod lane_streams;
pub mod pattern;
pub mod permutation;
pub mod pixel_samples;
pub mod poisson;
pub mod regular;
pub mod sobol;
pub mod stratified;

pub use independent::IndependentSampler;

use glam::Vec2;

pub trait Sampler {
    /// Starts the sample with index `sample_index` of pixel `pixel`; what follows depends
    /// only on (seed, pixel, sample_index), never on the thread that runs it.
    fn start_pixel_sample(&mut self, pixel: (u32, u32), sample_index: u64);

    /// A uniform number in [0, 1).
    fn next_1d(&mut self) -> f32;

    /// A uniform point in [0, 1)².
    fn next_2d(&mut self) -> Vec2 {
        let x = self.next_1d();
        let y = self.next_1d();
        Vec2::new(x, y)
    }
}
