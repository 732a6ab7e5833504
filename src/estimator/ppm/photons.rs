//! The photon pass: light paths traced by the shared light walk (`path::random_walk` in
//! importance transport), a photon kept at every vertex with a non-delta component.
//!
//! A photon's power is the walk's throughput on arrival (Le·|cos θ|/(p_light·p_pos·p_dir)
//! times the scatterings' weights), so that summed over the photons that land in a region
//! and divided by the light paths traced, it estimates the flux arriving there (Jensen
//! 2001, §5; Hachisuka et al. 2008, §3). Paths are cut into fixed blocks, each seeded from
//! (seed, pass, path), and the blocks' photons are concatenated in block order: the photon
//! list does not depend on the thread count.

use glam::Vec3;
use rayon::prelude::*;

use crate::material::TransportMode;
use crate::math::Rgb;
use crate::path::random_walk::{Step, Walk, WalkHook, random_walk};
use crate::path::subpath::start_light;
use crate::path::vertex::Vertex;
use crate::sampler::{IndependentSampler, Sampler, Stream};
use crate::scene::Scene;

/// Light paths per block: the unit of parallel work and of the photons' order.
const PATHS_PER_BLOCK: u64 = 4096;

/// Tags the photon streams apart from every other estimator's streams of the same seed.
const STREAM_TAG: u32 = 0x5050_0000;

/// One stored photon.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Photon {
    pub p: Vec3,
    /// Unit direction towards where the photon came from.
    pub wi: Vec3,
    pub power: Rgb,
    /// Segments of the light path up to this photon (1: straight from the light).
    pub segments: u32,
}

/// What a photon pass made.
#[derive(Debug, Default)]
pub struct PhotonPass {
    pub photons: Vec<Photon>,
    pub rays: u64,
}

/// Traces `paths` light paths of pass `pass` and keeps their photons; `max_segments` bounds
/// a photon's light path (the eye side adds at least one more segment).
pub fn trace_photons(
    scene: &Scene,
    seed: u64,
    pass: u64,
    paths: u64,
    max_segments: u32,
    rr_depth: u32,
) -> PhotonPass {
    let blocks = paths.div_ceil(PATHS_PER_BLOCK);
    let traced: Vec<PhotonPass> = (0..blocks)
        .into_par_iter()
        .map(|b| {
            let mut out = PhotonPass::default();
            let mut sampler = IndependentSampler::new(seed);
            let first = b * PATHS_PER_BLOCK;
            for path in first..(first + PATHS_PER_BLOCK).min(paths) {
                sampler.start_light_path(path, STREAM_TAG, pass);
                sampler.start_stream(Stream::Light);
                let Some(start) = start_light(scene, &mut sampler) else {
                    continue;
                };
                let mut hook = Deposit {
                    photons: &mut out.photons,
                    max_segments,
                };
                out.rays += random_walk(
                    scene,
                    start.walk(),
                    TransportMode::Importance,
                    rr_depth,
                    &mut sampler,
                    &mut hook,
                );
            }
            out
        })
        .collect();
    let mut all = PhotonPass {
        photons: Vec::with_capacity(traced.iter().map(|t| t.photons.len()).sum()),
        rays: 0,
    };
    for block in traced {
        all.photons.extend_from_slice(&block.photons);
        all.rays += block.rays;
    }
    all
}

/// Keeps a photon at every non-delta vertex of a light walk.
struct Deposit<'o> {
    photons: &'o mut Vec<Photon>,
    max_segments: u32,
}

impl<'a> WalkHook<'a> for Deposit<'_> {
    fn arrive(&mut self, v: &Vertex<'a>, walk: &Walk, _: &mut impl Sampler) -> Step {
        let segments = walk.depth + 1;
        // An eye path adds at least one segment: a longer light path cannot count.
        if segments >= self.max_segments {
            return Step::Stop;
        }
        if v.is_connectible() && walk.beta.max_component() > 0.0 {
            self.photons.push(Photon {
                p: v.p,
                wi: v.wo,
                power: walk.beta,
                segments,
            });
        }
        Step::Continue
    }
}
