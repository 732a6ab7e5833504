//! `eyelight`: a preview, not a light-transport estimate. Emitted radiance where the camera
//! sees an emitter, otherwise the surface's diffuse albedo × |cos θ| between the ray and the
//! shading normal (0.5 grey for non-diffuse BSDFs). Rays pass through `null` surfaces.
//! A miss shows the constant environment emitter, if the scene has one, else black. Under
//! the scene's `hide_emitters` neither shows: an emitter is shaded as the surface it is.

use super::camera_pass::{CameraEstimator, CameraSampleFn};
use crate::error::Result;
use crate::geometry::Ray;
use crate::math::Rgb;
use crate::sampler::pixel_samples::CameraSampler;
use crate::scene::{BsdfDesc, EmitterDesc, Scene};

/// How many `null` surfaces a preview ray may cross before giving up.
const MAX_NULL_CROSSINGS: u32 = 64;

/// The `eyelight` estimator.
pub type EyeLight = CameraEstimator<Shade>;

/// Makes `eyelight` for `scene`; an error when its film does not fit in memory.
pub fn new(scene: &Scene, seed: u64) -> Result<EyeLight> {
    let hide_emitters = scene.description.integrator.hide_emitters;
    let background = scene
        .description
        .emitters
        .iter()
        .map(|e| match e {
            EmitterDesc::Constant { radiance } => *radiance,
            _ => Rgb::BLACK,
        })
        .fold(Rgb::BLACK, |a, b| a + b);
    let background = if hide_emitters {
        Rgb::BLACK
    } else {
        background
    };
    CameraEstimator::new(
        "eyelight",
        scene,
        seed,
        Shade {
            background,
            hide_emitters,
        },
    )
}

/// The preview shading of one camera ray.
pub struct Shade {
    background: Rgb,
    hide_emitters: bool,
}

impl CameraSampleFn for Shade {
    type Scratch<'a> = ();
    type Extra = ();

    fn radiance(
        &self,
        scene: &Scene,
        ray: &Ray,
        _raster: glam::Vec2,
        _sampler: &mut CameraSampler,
        _scratch: &mut (),
        _extra: &mut (),
    ) -> (Rgb, u64) {
        let mut ray = *ray;
        for crossing in 0..=MAX_NULL_CROSSINGS {
            let Some(hit) = scene.geometry.intersect(&ray) else {
                return (self.background, crossing as u64 + 1);
            };
            let shape = &scene.description.shapes[hit.shape as usize];
            let bsdf = &scene.description.bsdfs[shape.bsdf];
            if matches!(bsdf, BsdfDesc::Null) && shape.emitter.is_none() {
                ray = hit.spawn_ray(ray.d);
                continue;
            }
            let toward_eye = -ray.d.normalize();
            if let Some(EmitterDesc::Area { radiance, .. }) =
                shape.emitter.map(|e| &scene.description.emitters[e])
                && hit.ng.dot(toward_eye) > 0.0
                && !self.hide_emitters
            {
                return (*radiance, crossing as u64 + 1);
            }
            let albedo = bsdf.diffuse_albedo_at(hit.uv).unwrap_or(Rgb::splat(0.5));
            return (albedo * hit.ns.dot(toward_eye).abs(), crossing as u64 + 1);
        }
        (Rgb::BLACK, MAX_NULL_CROSSINGS as u64 + 1)
    }
}
