//! Constant environment lights (Mitsuba 3's `constant`): the same radiance L arriving from
//! every direction at infinity.

use glam::{Vec2, Vec3};

use crate::light::{EmissionSample, LightSample, LightSampleLanes, SceneSphere};
use crate::math::lanes::{F32x16, Mask16, V3};
use crate::math::{PI, Rgb, warp};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ConstantLight {
    pub radiance: Rgb,
    pub sphere: SceneSphere,
}

impl ConstantLight {
    pub fn new(radiance: Rgb, sphere: SceneSphere) -> Self {
        ConstantLight { radiance, sphere }
    }

    /// Φ = π R² ∫ L dω = 4π² R² L̄: the flux entering the scene's bounding sphere.
    pub fn power(&self) -> f32 {
        4.0 * PI * PI * self.sphere.radius * self.sphere.radius * self.radiance.mean()
    }

    /// A uniform direction on the sphere (pdf 1/4π), as Mitsuba.
    pub fn sample_li(&self, u: Vec2) -> Option<LightSample> {
        let wi = warp::square_to_sphere(u);
        let pdf = warp::sphere_pdf();
        Some(LightSample::at_infinity(wi, self.radiance, pdf))
    }

    /// `sample_li` for the lanes of `m`, lane by lane the same bits.
    pub fn sample_li_lanes(&self, ux: F32x16, uy: F32x16, m: Mask16) -> LightSampleLanes {
        let wi = warp::sphere_direction(ux, uy);
        let pdf = warp::sphere_pdf();
        let c = F32x16::splat;
        let r = self.radiance;
        LightSampleLanes {
            ok: m,
            p: wi,
            n: -wi,
            p_error: V3::splat(0.0),
            wi,
            radiance: V3::new(c(r.r()), c(r.g()), c(r.b())),
            pdf_solid_angle: c(pdf),
            pdf_area: pdf,
            delta: false,
            at_infinity: true,
        }
    }

    pub fn pdf_li(&self) -> f32 {
        warp::sphere_pdf()
    }

    /// A uniform direction of travel (pdf 1/4π) and a uniform point of the disk of radius R
    /// perpendicular to it, R before the scene's centre.
    pub fn sample_le(&self, u1: Vec2, u2: Vec2) -> Option<EmissionSample> {
        let direction = warp::square_to_sphere(u2);
        let (origin, pdf_pos) = self.sphere.sample_disk(direction, u1);
        Some(EmissionSample {
            origin,
            direction,
            n: direction,
            front: direction,
            p_error: Vec3::ZERO,
            primitive: 0,
            radiance: self.radiance,
            pdf_pos,
            pdf_dir: warp::sphere_pdf(),
            delta_pos: false,
            delta_dir: false,
        })
    }

    pub fn pdf_le(&self, _dir: Vec3) -> (f32, f32) {
        (self.sphere.disk_pdf(), warp::sphere_pdf())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light::Light;

    /// Each lane of `Light::sample_li_lanes` holds the bits of `Light::sample_li`: direction,
    /// radiance and density, u at the square's edges included; masked lanes have none.
    #[test]
    fn samples_in_lanes_give_the_scalar_bits() {
        let sphere = SceneSphere {
            center: Vec3::new(1.0, -2.0, 0.5),
            radius: 3.0,
        };
        let light = Light::Constant(ConstantLight::new(Rgb([0.1, 0.15, 0.25]), sphere));
        for round in 0..200u32 {
            let u = |i: u32, salt: u32| match (round + i * salt) % 13 {
                0 => 0.0,
                1 => 1.0 - f32::EPSILON / 2.0,
                k => ((round * 7919 + i * 104_729 + k * salt) % 10_007) as f32 / 10_007.0,
            };
            let ux: [f32; 16] = std::array::from_fn(|i| u(i as u32, 3));
            let uy: [f32; 16] = std::array::from_fn(|i| u(i as u32, 5));
            let m = Mask16(0xffff ^ (1 << (round % 16)));
            let got = light
                .sample_li_lanes(
                    V3::splat(0.0),
                    F32x16::from_array(ux),
                    F32x16::from_array(uy),
                    m,
                )
                .expect("constant lights sample in lanes");
            assert!(got.at_infinity && !got.delta);
            for i in 0..16 {
                let want = m
                    .get(i)
                    .then(|| light.sample_li(Vec3::ZERO, Vec2::new(ux[i], uy[i])))
                    .flatten();
                assert_eq!(got.ok.get(i), want.is_some(), "lane {i}");
                let Some(want) = want else { continue };
                let lane = |v: V3<F32x16>| {
                    [v.x.to_array()[i], v.y.to_array()[i], v.z.to_array()[i]].map(f32::to_bits)
                };
                assert_eq!(
                    lane(got.wi),
                    [want.wi.x, want.wi.y, want.wi.z].map(f32::to_bits)
                );
                assert_eq!(
                    lane(got.p),
                    [want.p.x, want.p.y, want.p.z].map(f32::to_bits)
                );
                assert_eq!(lane(got.radiance), want.radiance.0.map(f32::to_bits));
                assert_eq!(
                    got.pdf_solid_angle.to_array()[i].to_bits(),
                    want.pdf_solid_angle.to_bits()
                );
            }
        }
    }
}
