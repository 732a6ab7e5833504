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
pub mod primary_sample;
pub mod regular;
pub mod sobol;
pub mod stratified;

pub use independent::IndependentSampler;

use glam::Vec2;

/// The streams of a sample: what a sampler may keep apart, so that the numbers of one do not
/// shift when another draws more or fewer (a light subpath's length must not move the camera
/// subpath's dimensions in a Metropolis sampler's primary sample space).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stream {
    /// The camera sample (its first 2D draw is the raster position within the sample's
    /// area, then the lens point for a thin lens) and the camera subpath.
    Camera,
    /// The light subpath: the light's choice, its emission, the walk.
    Light,
    /// What joins the two subpaths: light points of next-event estimation from the camera
    /// subpath, lens points of light-tracing connections.
    Connect,
}

/// The sampler contract: estimators only draw numbers and say which stream they draw from.
/// Where a sample starts (the pixel, the pass, the seed) is the concrete sampler's business
/// (`IndependentSampler::start_pixel_sample`, `CameraSampler::start_pixel_sample`): an
/// estimator written against this trait runs unchanged on a Metropolis sampler.
///
/// Every estimator draws a fixed number of dimensions per vertex whatever happens there (a
/// specular vertex still consumes its next-event numbers, Russian roulette its number before
/// `rr_depth`), so that dimension k means the same thing from one sample to the next.
pub trait Sampler {
    /// Starts drawing from `stream`. The independent samplers draw every stream from one
    /// random sequence: for them this does nothing.
    fn start_stream(&mut self, _stream: Stream) {}

    /// A uniform number in [0, 1).
    fn next_1d(&mut self) -> f32;

    /// A uniform point in [0, 1)².
    fn next_2d(&mut self) -> Vec2 {
        let x = self.next_1d();
        let y = self.next_1d();
        Vec2::new(x, y)
    }
}
