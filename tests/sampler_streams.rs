//! The sampler contract (`sampler::Sampler`): estimators draw every number through it, per
//! stream, so that a primary-sample-space sampler can replay and mutate them.
//!
//! * Recording every number a `bdpt` camera sample (and a `pt` one) draws, per stream, and
//!   replaying the recording gives the bit-identical contribution: the pixel value, every
//!   splat, both subpaths.
//! * Replacing only the light stream's numbers leaves the camera subpath's vertices
//!   bit-identical (and consumes exactly the camera numbers recorded), and replacing only the
//!   camera stream's leaves the light subpath's: a subpath's dimensions do not depend on the
//!   other subpath.

mod render_support;

use glam::Vec3;
use mltbench::estimator::camera_pass::camera_ray;
use mltbench::estimator::{Params, bdpt, pt};
use mltbench::film::SplatList;
use mltbench::sampler::{IndependentSampler, Sampler, Stream};
use mltbench::scene::Scene;
use render_support::shipped_scene;

fn slot(s: Stream) -> usize {
    match s {
        Stream::Camera => 0,
        Stream::Light => 1,
        Stream::Connect => 2,
    }
}

/// Passes `inner`'s numbers through and keeps them per stream.
struct Recorder<S> {
    inner: S,
    stream: Stream,
    draws: [Vec<f32>; 3],
}

impl<S: Sampler> Sampler for Recorder<S> {
    fn start_stream(&mut self, stream: Stream) {
        self.inner.start_stream(stream);
        self.stream = stream;
    }

    fn next_1d(&mut self) -> f32 {
        let u = self.inner.next_1d();
        self.draws[slot(self.stream)].push(u);
        u
    }
}

/// Hands out recorded numbers per stream; a stream marked `fresh` gets new numbers from
/// `rng` instead.
struct Replay {
    draws: [Vec<f32>; 3],
    used: [usize; 3],
    fresh: [bool; 3],
    rng: IndependentSampler,
    stream: Stream,
}

impl Replay {
    fn new(draws: [Vec<f32>; 3], fresh: [bool; 3], seed: u64) -> Replay {
        Replay {
            draws,
            used: [0; 3],
            fresh,
            rng: IndependentSampler::new(seed),
            stream: Stream::Camera,
        }
    }
}

impl Sampler for Replay {
    fn start_stream(&mut self, stream: Stream) {
        self.stream = stream;
    }

    fn next_1d(&mut self) -> f32 {
        let k = slot(self.stream);
        if self.fresh[k] {
            return self.rng.next_1d();
        }
        let u = self.draws[k][self.used[k]];
        self.used[k] += 1;
        u
    }
}

/// What one `bdpt` camera sample gave: the pixel value's bits, the splats' bits, the
/// positions of both subpaths.
#[derive(Debug, PartialEq)]
struct Outcome {
    value: [u32; 3],
    splats: Vec<[u32; 5]>,
    camera: Vec<[u32; 3]>,
    light: Vec<[u32; 3]>,
}

fn bits(v: Vec3) -> [u32; 3] {
    v.to_array().map(f32::to_bits)
}

fn bdpt_sample(
    scene: &Scene,
    e: &bdpt::Bdpt,
    pixel: (u32, u32),
    sampler: &mut impl Sampler,
) -> Outcome {
    let (_, ray) = camera_ray(&scene.camera, pixel, sampler);
    let mut scratch = bdpt::Scratch::default();
    let mut splats = SplatList::new();
    let value = e.sample_fn().trace(
        scene,
        ray,
        sampler,
        &mut scratch,
        &mut splats,
        &mut (0, 0),
        false,
        |_| {},
    );
    Outcome {
        value: value.0.map(f32::to_bits),
        splats: splats
            .entries()
            .iter()
            .map(|(r, v)| {
                let [a, b] = r.to_array().map(f32::to_bits);
                let [c, d, f] = v.0.map(f32::to_bits);
                [a, b, c, d, f]
            })
            .collect(),
        camera: scratch.camera_path().iter().map(|v| bits(v.p)).collect(),
        light: scratch.light_path().iter().map(|v| bits(v.p)).collect(),
    }
}

#[test]
fn a_recorded_bdpt_sample_replays_bit_for_bit_and_its_subpaths_keep_their_streams() {
    // Mirror and glass (delta vertices), a thin lens (lens numbers on both sides).
    for file in ["cbox-spheres.xml", "cbox-dof.xml", "envmap-spheres.xml"] {
        let scene = shipped_scene(file, 12);
        let params = Params::parse(&["max_depth=-1", "rr_depth=2"]).unwrap();
        let e = bdpt::new(
            &scene,
            1,
            bdpt::BdptSettings::from_params(&params, &scene).unwrap(),
        )
        .unwrap();
        let (mut camera_changed, mut light_changed) = (0, 0);
        for index in 0..8u64 {
            for y in 0..scene.height() {
                for x in 0..scene.width() {
                    let mut inner = IndependentSampler::new(7);
                    inner.start_pixel_sample((x, y), index);
                    let mut rec = Recorder {
                        inner,
                        stream: Stream::Camera,
                        draws: Default::default(),
                    };
                    let original = bdpt_sample(&scene, &e, (x, y), &mut rec);
                    let seed = 1000 + index;
                    // Replayed: the same bits.
                    let mut replay = Replay::new(rec.draws.clone(), [false; 3], seed);
                    assert_eq!(bdpt_sample(&scene, &e, (x, y), &mut replay), original);
                    assert_eq!(replay.used, rec.draws.each_ref().map(Vec::len));
                    // New light numbers: the camera subpath stays, its numbers all used.
                    let mut replay = Replay::new(rec.draws.clone(), [false, true, true], seed);
                    let other = bdpt_sample(&scene, &e, (x, y), &mut replay);
                    assert_eq!(other.camera, original.camera, "{file}: camera subpath");
                    assert_eq!(replay.used[0], rec.draws[0].len(), "{file}: camera numbers");
                    light_changed += (other.light != original.light) as u32;
                    // New camera numbers: the light subpath stays.
                    let mut replay = Replay::new(rec.draws.clone(), [true, false, true], seed);
                    let other = bdpt_sample(&scene, &e, (x, y), &mut replay);
                    assert_eq!(other.light, original.light, "{file}: light subpath");
                    assert_eq!(replay.used[1], rec.draws[1].len(), "{file}: light numbers");
                    camera_changed += (other.camera != original.camera) as u32;
                }
            }
        }
        // The replaced streams did change their subpaths: the test tests something.
        let samples = 8 * scene.width() * scene.height();
        assert!(
            light_changed > samples / 2 && camera_changed > samples / 2,
            "{file}: {light_changed} light and {camera_changed} camera subpaths changed of {samples}"
        );
    }
}

#[test]
fn a_recorded_pt_sample_replays_bit_for_bit() {
    let scene = shipped_scene("cbox-spheres.xml", 12);
    let params = Params::parse(&["max_depth=-1", "rr_depth=2"]).unwrap();
    let e = pt::new(
        &scene,
        1,
        pt::PtSettings::from_params(&params, &scene).unwrap(),
    )
    .unwrap();
    let mut draws_per_sample = Vec::new();
    for index in 0..8u64 {
        for y in 0..scene.height() {
            for x in 0..scene.width() {
                let mut inner = IndependentSampler::new(3);
                inner.start_pixel_sample((x, y), index);
                let mut rec = Recorder {
                    inner,
                    stream: Stream::Camera,
                    draws: Default::default(),
                };
                let (_, ray) = camera_ray(&scene.camera, (x, y), &mut rec);
                let original = e.sample_fn().trace(&scene, &ray, &mut rec);
                assert!(
                    rec.draws[1].is_empty() && rec.draws[2].is_empty(),
                    "one stream"
                );
                let mut replay = Replay::new(rec.draws.clone(), [false; 3], 0);
                let (_, ray) = camera_ray(&scene.camera, (x, y), &mut replay);
                let again = e.sample_fn().trace(&scene, &ray, &mut replay);
                assert_eq!(again.0.0.map(f32::to_bits), original.0.0.map(f32::to_bits));
                assert_eq!(again.1, original.1);
                assert_eq!(replay.used[0], rec.draws[0].len());
                draws_per_sample.push(rec.draws[0].len());
            }
        }
    }
    // 2 for the raster position, then 7 per vertex that scatters (next-event 3, walk 4).
    assert!(
        draws_per_sample.iter().all(|&n| n >= 2 && (n - 2) % 7 == 0),
        "draw counts {:?}",
        &draws_per_sample[..16]
    );
}
