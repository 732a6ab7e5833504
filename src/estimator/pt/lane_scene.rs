//! What the wavefront looks up per lane, as flat tables indexed by shape: whether the
//! lane code can scatter there (an untextured `diffuse` BSDF) and with which reflectance,
//! and the area light of the shape.

use crate::material::Bsdf;
use crate::scene::Scene;

/// Marks a shape without an area light in `LaneScene::light`.
pub(super) const NO_LIGHT: u32 = u32::MAX;

/// Per-shape tables for gathers by shape index.
pub(super) struct LaneScene {
    /// 1 where the shape's BSDF is an untextured `diffuse` (scattered in lanes), 0 where
    /// the scalar code scatters.
    pub diffuse: Vec<u32>,
    /// The diffuse reflectance's channels (0 for other shapes).
    pub reflectance: [Vec<f32>; 3],
    /// Index of the shape's area light, or `NO_LIGHT`.
    pub light: Vec<u32>,
}

impl LaneScene {
    pub fn new(scene: &Scene) -> LaneScene {
        let n = scene.description.shapes.len();
        let mut diffuse = vec![0u32; n.max(1)];
        let mut reflectance = [
            vec![0.0f32; n.max(1)],
            vec![0.0; n.max(1)],
            vec![0.0; n.max(1)],
        ];
        let mut light = vec![NO_LIGHT; n.max(1)];
        for shape in 0..n {
            if let Some(Bsdf::Diffuse(d)) = scene.untextured_bsdf(shape) {
                diffuse[shape] = 1;
                for (c, channel) in reflectance.iter_mut().enumerate() {
                    channel[shape] = d.reflectance[c];
                }
            }
            if let Some(l) = scene.lights.light_of_shape(shape) {
                light[shape] = l as u32;
            }
        }
        LaneScene {
            diffuse,
            reflectance,
            light,
        }
    }
}
