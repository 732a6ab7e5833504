//! What the wavefront looks up per lane, as flat tables indexed by shape: whether the
//! lane code can scatter there (a `diffuse` BSDF, or a `twosided` one of two `diffuse`
//! sides) and with which reflectances (or whether they come from textures), and the area
//! light of the shape.

use super::hit_lanes::HitLanes;
use super::path_lanes::put3;
use crate::material::Bsdf;
use crate::math::Rgb;
use crate::math::lanes::{F32x16, Mask16, U32x16, V3};
use crate::scene::Scene;
use glam::Vec3;

/// Marks a shape without an area light in `LaneScene::light`.
pub(super) const NO_LIGHT: u32 = u32::MAX;

/// Per-shape tables for gathers by shape index.
pub(super) struct LaneScene {
    /// 1 where the shape's BSDF is a `diffuse` or a `twosided` pair of them (scattered in
    /// lanes), 0 where the scalar code scatters.
    pub diffuse: Vec<u32>,
    /// 1 where such a BSDF has a texture: its reflectances are looked up per hit
    /// (`Reflectances::of`).
    pub textured: Vec<u32>,
    /// Whether any shape is `textured`.
    pub any_textured: bool,
    /// 1 where the BSDF is `twosided`: from behind, the back reflectance with both
    /// directions mirrored through the surface (`TwoSided`).
    pub two_sided: Vec<u32>,
    /// Whether any shape is `two_sided` (else the lanes skip the back side's lookups).
    pub any_two_sided: bool,
    /// The front diffuse reflectance's channels (0 for other shapes and textured ones).
    pub reflectance: [Vec<f32>; 3],
    /// The back's channels (the front's for a one-sided `diffuse`).
    pub back_reflectance: [Vec<f32>; 3],
    /// Index of the shape's area light, or `NO_LIGHT`.
    pub light: Vec<u32>,
    /// The smooth specular BSDFs the lanes sample (`specular_lanes.rs`), by shape.
    pub specular: SpecularTables,
    /// 1 where the BSDF is not `null`: the lanes scatter there with the scalar BSDF calls
    /// (`general_lanes.rs`) when neither the diffuse nor the specular lanes do.
    pub general: Vec<u32>,
}

/// Which shapes have a smooth specular BSDF the lanes sample, and its parameters.
pub(super) struct SpecularTables {
    /// `MIRROR`, `GLASS`, or 0 for the other shapes.
    pub kind: Vec<u32>,
    /// Whether any shape has one.
    pub any: bool,
    /// η = η_inside/η_outside of a `dielectric` (1 elsewhere).
    pub eta: Vec<f32>,
    /// Specular reflectance's channels (a mirror's, or a dielectric's).
    pub reflectance: [Vec<f32>; 3],
    /// A dielectric's specular transmittance's channels.
    pub transmittance: [Vec<f32>; 3],
}

/// An untextured `conductor` without a complex IOR: reflectance independent of the angle.
pub(super) const MIRROR: u32 = 1;
/// An untextured smooth `dielectric`.
pub(super) const GLASS: u32 = 2;

impl LaneScene {
    pub fn new(scene: &Scene) -> LaneScene {
        let n = scene.description.shapes.len();
        let mut diffuse = vec![0u32; n.max(1)];
        let mut textured = vec![0u32; n.max(1)];
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
        let mut general = vec![0u32; n.max(1)];
        let mut specular = SpecularTables {
            kind: vec![0; n.max(1)],
            any: false,
            eta: vec![1.0; n.max(1)],
            reflectance: channels(),
            transmittance: channels(),
        };
        for shape in 0..n {
            let (kind, mirror_or_glass, transmittance, eta) = match scene.untextured_bsdf(shape) {
                Some(Bsdf::Conductor(c)) if c.eta_k.is_none() => {
                    (MIRROR, c.specular_reflectance, Rgb::BLACK, 1.0)
                }
                Some(Bsdf::Dielectric(d)) => (
                    GLASS,
                    d.specular_reflectance,
                    d.specular_transmittance,
                    d.eta,
                ),
                _ => (0, Rgb::BLACK, Rgb::BLACK, 1.0),
            };
            specular.kind[shape] = kind;
            specular.any |= kind != 0;
            specular.eta[shape] = eta;
            for c in 0..3 {
                specular.reflectance[c][shape] = mirror_or_glass[c];
                specular.transmittance[c][shape] = transmittance[c];
            }
            // A textured BSDF keeps its kind (`Bsdf::at_point`): a textured `diffuse` is a
            // `diffuse` at every point.
            let has_texture = scene.untextured_bsdf(shape).is_none();
            if let Some((front, back, is_two_sided)) =
                diffuse_sides(scene.bsdf_of_shape(shape as u32))
            {
                diffuse[shape] = 1;
                two_sided[shape] = is_two_sided as u32;
                textured[shape] = has_texture as u32;
                for c in 0..3 {
                    reflectance[c][shape] = if has_texture { 0.0 } else { front[c] };
                    back_reflectance[c][shape] = if has_texture { 0.0 } else { back[c] };
                }
            }
            if let Some(l) = scene.lights.light_of_shape(shape) {
                light[shape] = l as u32;
            }
            general[shape] = !scene.bsdf_of_shape(shape as u32).is_null() as u32;
        }
        LaneScene {
            diffuse,
            any_textured: textured.contains(&1),
            textured,
            any_two_sided: two_sided.contains(&1),
            two_sided,
            reflectance,
            back_reflectance,
            light,
            specular,
            general,
        }
    }
}

/// A `diffuse` BSDF's reflectance as (front, back, false), a `twosided` pair of them as
/// (front, back, true); None for other BSDFs.
fn diffuse_sides(bsdf: &Bsdf) -> Option<(Rgb, Rgb, bool)> {
    match bsdf {
        Bsdf::Diffuse(d) => Some((d.reflectance, d.reflectance, false)),
        Bsdf::TwoSided(t) => match (&t.front, &t.back) {
            (Bsdf::Diffuse(front), Bsdf::Diffuse(back)) => {
                Some((front.reflectance, back.reflectance, true))
            }
            _ => None,
        },
        _ => None,
    }
}

/// The diffuse reflectances at sixteen hits: the front and back sides' channels, and the
/// lanes whose BSDF is `twosided`.
pub(super) struct Reflectances {
    pub front: V3<F32x16>,
    pub back: V3<F32x16>,
    pub two_sided: Mask16,
}

impl LaneScene {
    /// The reflectances at the hits of the lanes of `m` (every one at a shape of
    /// `diffuse`): gathered from the tables, and for textured shapes taken from the BSDF at
    /// the hit (`Scene::bsdf_at`, the scalar code's lookup), lane by lane.
    pub fn reflectances(&self, scene: &Scene, hits: &HitLanes, m: Mask16) -> Reflectances {
        let channels = |table: &[Vec<f32>; 3]| {
            let c = |k: usize| F32x16::gather(&table[k], hits.shape, m);
            V3::new(c(0), c(1), c(2))
        };
        let one = U32x16::splat(1);
        let front = channels(&self.reflectance);
        let mut r = if self.any_two_sided {
            Reflectances {
                front,
                back: channels(&self.back_reflectance),
                two_sided: m & U32x16::gather(&self.two_sided, hits.shape, m).eq(one),
            }
        } else {
            Reflectances {
                front,
                back: front,
                two_sided: Mask16::NONE,
            }
        };
        if !self.any_textured {
            return r;
        }
        let textured = m & U32x16::gather(&self.textured, hits.shape, m).eq(one);
        let rgb = |c: Rgb| Vec3::new(c.r(), c.g(), c.b());
        let shapes = hits.shape.to_array();
        for i in textured.lanes() {
            let uv = hits
                .uv(scene, i)
                .expect("a lane at a diffuse shape has a hit");
            let (front, back, _) = diffuse_sides(&scene.bsdf_at_uv(shapes[i], uv))
                .expect("a textured diffuse BSDF is diffuse at every point (Bsdf::at_point)");
            put3(&mut r.front, i, rgb(front));
            put3(&mut r.back, i, rgb(back));
        }
        r
    }
}
