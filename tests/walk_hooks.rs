//! The one walk (`path::random_walk`) with hooks: what photon mapping's passes need is a few
//! lines on top of it. An eye pass that stops at the first non-specular vertex goes through
//! mirrors and glass and ends on a diffuse surface; a photon tracer records a photon at
//! every non-specular vertex of a light walk, with a power that matches the light's.

mod render_support;

use glam::Vec3;
use mltbench::camera::raster_in_pixel;
use mltbench::material::TransportMode;
use mltbench::math::Rgb;
use mltbench::path::random_walk::{Step, Walk, WalkHook, random_walk};
use mltbench::path::subpath::start_light;
use mltbench::path::vertex::Vertex;
use mltbench::sampler::{IndependentSampler, Sampler};
use render_support::{furnace, shipped_scene};

/// Stops at the first vertex with a non-delta component; counts the delta ones before it.
#[derive(Default)]
struct EyePass {
    hit: Option<(Vec3, bool)>,
    specular: u32,
}

impl<'a> WalkHook<'a> for EyePass {
    fn arrive(&mut self, v: &Vertex<'a>, _: &Walk, _: &mut impl Sampler) -> Step {
        if v.is_connectible() {
            self.hit = Some((v.p, true));
            return Step::Stop;
        }
        self.specular += 1;
        Step::Continue
    }
}

/// Keeps (position, power) at every non-delta vertex of a light walk.
#[derive(Default)]
struct Photons(Vec<(Vec3, Rgb)>);

impl<'a> WalkHook<'a> for Photons {
    fn arrive(&mut self, v: &Vertex<'a>, walk: &Walk, _: &mut impl Sampler) -> Step {
        if v.is_connectible() {
            self.0.push((v.p, walk.beta));
        }
        Step::Continue
    }
}

#[test]
fn an_eye_pass_stops_on_the_first_diffuse_surface_through_mirrors_and_glass() {
    let scene = shipped_scene("cbox-spheres.xml", 32);
    let mut sampler = IndependentSampler::new(5);
    let (mut through_specular, mut samples) = (0, 0);
    for y in 0..32 {
        for x in 0..32 {
            sampler.start_pixel_sample((x, y), 0);
            let ray = scene
                .camera
                .generate_ray(raster_in_pixel(x, y, sampler.next_2d()));
            let mut eye = EyePass::default();
            random_walk(
                &scene,
                Walk::new(ray, Rgb::WHITE),
                TransportMode::Radiance,
                100,
                &mut sampler,
                &mut eye,
            );
            if let Some((p, diffuse)) = eye.hit {
                assert!(diffuse && p.is_finite());
                samples += 1;
                through_specular += (eye.specular > 0) as u32;
            }
        }
    }
    // The box is closed but for its front: every camera ray ends on a diffuse wall, and the
    // two spheres (about a tenth of the image) send some of them through mirror and glass.
    assert!(samples > 900, "{samples}");
    assert!(through_specular > 30, "{through_specular}");
}

#[test]
fn photons_carry_the_lights_power() {
    // A closed emitting sphere: every light walk lands on it again, and its first photon
    // carries the walk's starting throughput Le·|cos θ|/(p_light·p_pos·p_dir), whose mean is
    // the light's power Φ = π·A·Le (here the same for every walk: cosine-weighted emission).
    let scene = furnace("sphere", "0.5", "1", -1, "");
    let mut sampler = IndependentSampler::new(9);
    let n = 4000;
    let mut first = Rgb::BLACK;
    for k in 0..n {
        sampler.start_pixel_sample((k, 0), 0);
        let start = start_light(&scene, &mut sampler).expect("a light");
        let mut photons = Photons::default();
        random_walk(
            &scene,
            start.walk(),
            TransportMode::Importance,
            3,
            &mut sampler,
            &mut photons,
        );
        if let Some(&(_, power)) = photons.0.first() {
            first += power;
        }
    }
    let light = &scene.lights.lights()[0];
    let expected = light.power() as f64;
    let mean = first.mean() as f64 / n as f64;
    assert!(
        (mean - expected).abs() < 1e-4 * expected,
        "{mean} against {expected}"
    );
}
