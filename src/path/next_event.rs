//! Next-event estimation: a point on a light, chosen for a surface point of a camera path
//! (`pt`'s light samples, `bdpt`'s s = 1 strategies).

use glam::Vec3;

use crate::geometry::{Ray, SurfaceInteraction};
use crate::light::LightSample;
use crate::sampler::Sampler;
use crate::scene::Scene;

/// A light point chosen for next-event estimation.
#[derive(Clone, Copy, Debug)]
pub struct LightChoice {
    /// The light (index in the scene's `LightSet`) and the probability it was chosen with.
    pub light: usize,
    pub pmf: f32,
    pub sample: LightSample,
}

/// Draws next-event estimation's three numbers (the light's choice, then the point on it)
/// whatever happens, and samples a light by power and a point on it as seen from `p`. None
/// when the scene has no light or the light gives no sample.
#[inline]
pub fn sample_light(scene: &Scene, p: Vec3, sampler: &mut impl Sampler) -> Option<LightChoice> {
    let u_light = sampler.next_1d();
    let u = sampler.next_2d();
    let (light, pmf, _) = scene.lights.sample(u_light)?;
    let sample = scene.lights.get(light).sample_li(p, u)?;
    Some(LightChoice { light, pmf, sample })
}

/// The shadow ray from `si` to the light point `ls`: to a point at a finite distance (both
/// ends offset off their surfaces; point and spot lights have no error box and no normal,
/// so no offset at their end), or towards a light at infinity.
#[inline]
pub fn shadow_ray(si: &SurfaceInteraction, ls: &LightSample) -> Ray {
    if ls.dist.is_finite() {
        si.spawn_ray_to_surface(ls.p, ls.p_error, ls.n)
    } else {
        si.spawn_ray(ls.wi)
    }
}
