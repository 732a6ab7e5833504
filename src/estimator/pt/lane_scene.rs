//! What the wavefront looks up per lane, as flat tables indexed by shape: whether the
//! lane code can scatter there (an untextured `diffuse` BSDF, or a `twosided` one of two
//! untextured `diffuse` sides) and with which reflectances, and the area light of the shape.

use crate::material::Bsdf;
use crate::scene::Scene;

/// Marks a shape without an area light in `LaneScene::light`.
pub(super) const NO_LIGHT: u32 = u32::MAX;

/// Per-shape tables for gathers by shape index.
pub(super) struct LaneScene {
    /// 1 where the shape's BSDF is an untextured `diffuse` or a `twosided` pair of them
    /// (scattered in lanes), 0 where the scalar code scatters.
    pub diffuse: Vec<u32>,
    /// 1 where the BSDF is `twosided`: from behind, the back reflectance with both
    /// directions mirrored through the surface (`TwoSided`).
    pub two_sided: Vec<u32>,
    /// Whether any shape is `two_sided` (else the lanes skip the back side's lookups).
    pub any_two_sided: bool,
    /// The front diffuse reflectance's channels (0 for other shapes).
    pub reflectance: [Vec<f32>; 3],
    /// The back's channels (the front's for a one-sided `diffuse`).
    pub back_reflectance: [Vec<f32>; 3],
    /// Index of the shape's area light, or `NO_LIGHT`.
    pub light: Vec<u32>,
}

impl LaneScene {
    pub fn new(scene: &Scene) -> LaneScene {
        let n = scene.description.shapes.len();
        let mut diffuse = vec![0u32; n.max(1)];
        let mut two_sided = vec![0u32; n.max(1)];
        let channels = || {
            [
                vec![0.0f32; n.max(1)],
                vec![0.0; n.max(1)],
                vec![0.0; n.max(1)],
            ]
        };
        let (mut reflectance, mut back_reflectance) = (channels(), channels());
        let mut light = vec![NO_LIGHT; n.max(1)];
        for shape in 0..n {
            let sides = match scene.untextured_bsdf(shape) {
                Some(Bsdf::Diffuse(d)) => Some((d.reflectance, d.reflectance, 0)),
                Some(Bsdf::TwoSided(t)) => match (&t.front, &t.back) {
                    (Bsdf::Diffuse(front), Bsdf::Diffuse(back)) => {
                        Some((front.reflectance, back.reflectance, 1))
                    }
                    _ => None,
                },
                _ => None,
            };
            if let Some((front, back, is_two_sided)) = sides {
                diffuse[shape] = 1;
                two_sided[shape] = is_two_sided;
                for c in 0..3 {
                    reflectance[c][shape] = front[c];
                    back_reflectance[c][shape] = back[c];
                }
            }
            if let Some(l) = scene.lights.light_of_shape(shape) {
                light[shape] = l as u32;
            }
        }
        LaneScene {
            diffuse,
            any_two_sided: two_sided.contains(&1),
            two_sided,
            reflectance,
            back_reflectance,
            light,
        }
    }
}
