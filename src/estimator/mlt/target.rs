//! The path functions a Metropolis chain explores: a point of primary sample space (the
//! sampler's numbers) in, the contributions it makes to the image out. `pt`'s and `bdpt`'s
//! own sample code runs unchanged on the chain's sampler (the sampler contract,
//! docs/DESIGN.md §2), so "PSSMLT over PT" and "over BDPT" differ only here.

use glam::Vec2;

use crate::estimator::bdpt::{BdptSample, Scratch as BdptScratch};
use crate::estimator::camera_pass::camera_ray_in_image;
use crate::estimator::pt::PathSample;
use crate::film::SplatList;
use crate::math::Rgb;
use crate::sampler::Sampler;
use crate::scene::Scene;

/// What one point of primary sample space adds to the image: values at raster positions,
/// and the scalar the chain's target density is proportional to.
#[derive(Clone, Debug, Default)]
pub struct Contributions {
    /// (raster position, radiance), each already divided by its sample's density.
    pub entries: Vec<(Vec2, Rgb)>,
    /// The luminance of their sum (Kelemen et al. 2002's importance I).
    pub luminance: f64,
}

impl Contributions {
    pub fn clear(&mut self) {
        self.entries.clear();
        self.luminance = 0.0;
    }

    /// Adds a value at `raster`; values that are NaN, infinite or negative are dropped and
    /// counted in `invalid`, black ones skipped.
    pub fn push(&mut self, raster: Vec2, value: Rgb, invalid: &mut u64) {
        if !value.is_valid_radiance() {
            *invalid += 1;
        } else if !value.is_black() {
            self.entries.push((raster, value));
        }
    }

    /// Sets `luminance` from the entries.
    pub fn finish(&mut self) {
        let sum = self.entries.iter().fold(Rgb::BLACK, |a, &(_, v)| a + v);
        self.luminance = sum.luminance() as f64;
    }
}

/// What a path function computed for one point, beyond its contributions.
#[derive(Clone, Copy, Debug, Default)]
pub struct Evaluation {
    pub rays: u64,
    /// Contributions dropped as NaN, infinite or negative.
    pub invalid: u64,
}

/// A path function over primary sample space.
pub trait PathTarget: Sync + Send {
    /// Buffers reused by every evaluation of one task.
    type Scratch<'a>: Default;

    /// Bootstrap strata (1; `mmlt`: one per path length), each bootstrapped separately.
    fn strata(&self) -> usize {
        1
    }

    /// Evaluates the point the sampler's numbers make, into `out` (cleared first). With
    /// `stratum`, the point is confined to that stratum (`mmlt`: that path length): a
    /// bootstrap sample, or the state of a chain that keeps its stratum; without, the
    /// state of a chain that ranges over every stratum.
    fn evaluate<'a>(
        &self,
        scene: &'a Scene,
        sampler: &mut impl Sampler,
        stratum: Option<usize>,
        scratch: &mut Self::Scratch<'a>,
        out: &mut Contributions,
    ) -> Evaluation;

    /// Learns the strata's mean importances from the bootstrap (`mmlt`: how often a large
    /// step picks each path length).
    fn set_stratum_means(&mut self, _means: &[f64]) {}

    /// Rewrites a bootstrap sample of `stratum` (the numbers `evaluate` read with
    /// `Some(stratum)`) as a chain state, the same path (`mmlt`'s first number).
    fn to_chain_state(
        &self,
        _sampler: &mut crate::sampler::primary_sample::PrimarySampleSampler,
        _stratum: usize,
    ) {
    }
}

/// The film size camera samples spread over.
fn film_size(scene: &Scene) -> (u32, u32) {
    let window = scene.description.sensor.film.window();
    (window.width, window.height)
}

/// `pssmlt base=pt`: one camera path from a camera sample anywhere on the film.
pub struct PtTarget {
    pub sample: PathSample,
}

impl PathTarget for PtTarget {
    type Scratch<'a> = ();

    fn evaluate(
        &self,
        scene: &Scene,
        sampler: &mut impl Sampler,
        _stratum: Option<usize>,
        _scratch: &mut (),
        out: &mut Contributions,
    ) -> Evaluation {
        out.clear();
        let (raster, ray) = camera_ray_in_image(&scene.camera, film_size(scene), sampler);
        let (value, rays) = self.sample.trace(scene, &ray, sampler);
        let mut invalid = 0;
        out.push(raster, value, &mut invalid);
        out.finish();
        Evaluation { rays, invalid }
    }
}

/// `pssmlt base=bdpt`: one camera sample of `bdpt` anywhere on the film, every strategy;
/// light tracing's contributions land where they hit the film.
pub struct BdptTarget {
    pub sample: BdptSample,
}

/// `BdptTarget`'s buffers.
#[derive(Default)]
pub struct BdptTargetScratch<'a> {
    subpaths: BdptScratch<'a>,
    splats: SplatList,
}

impl PathTarget for BdptTarget {
    type Scratch<'a> = BdptTargetScratch<'a>;

    fn evaluate<'a>(
        &self,
        scene: &'a Scene,
        sampler: &mut impl Sampler,
        _stratum: Option<usize>,
        scratch: &mut BdptTargetScratch<'a>,
        out: &mut Contributions,
    ) -> Evaluation {
        out.clear();
        let (raster, ray) = camera_ray_in_image(&scene.camera, film_size(scene), sampler);
        scratch.splats.clear();
        let mut counts = (0u64, 0u64);
        let value = self.sample.trace(
            scene,
            ray,
            sampler,
            &mut scratch.subpaths,
            &mut scratch.splats,
            &mut counts,
            false,
            |_| {},
        );
        let (rays, mut invalid) = counts;
        out.push(raster, value, &mut invalid);
        for &(at, v) in scratch.splats.entries() {
            out.push(at, v, &mut invalid);
        }
        out.finish();
        Evaluation { rays, invalid }
    }
}
