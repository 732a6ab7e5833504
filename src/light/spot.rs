//! Spot lights as Mitsuba 3's `spot`: a point light at the origin of `to_world` shining
//! along its local +z axis with intensity I·f(θ), where θ is the angle to the axis and the
//! falloff f is 1 within `beam_width`, falls linearly in θ to 0 at `cutoff_angle`, and is 0
//! beyond:  f(θ) = (θ_c − θ)/(θ_c − θ_b) for θ_b < θ < θ_c.
//!
//! The loader only admits a `to_world` that rotates, translates and scales uniformly, so
//! angles measured in the local frame equal world angles to the transformed axis.

use glam::{Vec2, Vec3};

use crate::light::{EmissionSample, LightSample, towards_point};
use crate::math::{Frame, PI, Rgb, Transform, warp};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpotLight {
    pub position: Vec3,
    /// Unit axis of the cone (the local +z in world space).
    pub axis: Vec3,
    frame: Frame,
    /// Radiant intensity at the centre (W/sr).
    pub intensity: Rgb,
    /// Cutoff and beam angles in radians.
    pub cutoff: f32,
    pub beam: f32,
    cos_cutoff: f32,
    cos_beam: f32,
}

impl SpotLight {
    /// Angles in degrees, as in the scene file (0 ≤ beam ≤ cutoff ≤ 180, checked by the
    /// loader; a beam wider than the cutoff is narrowed to it here).
    pub fn new(
        to_world: &Transform,
        intensity: Rgb,
        cutoff_degrees: f32,
        beam_degrees: f32,
    ) -> Option<SpotLight> {
        let position = to_world.point(Vec3::ZERO);
        let axis = to_world.vector(Vec3::Z).normalize();
        if !(position.is_finite() && axis.is_finite()) {
            return None;
        }
        let cutoff = cutoff_degrees.to_radians().clamp(0.0, PI);
        let beam = beam_degrees.to_radians().clamp(0.0, cutoff);
        Some(SpotLight {
            position,
            axis,
            frame: Frame::from_normal(axis),
            intensity,
            cutoff,
            beam,
            cos_cutoff: cutoff.cos(),
            cos_beam: beam.cos(),
        })
    }

    /// f(θ) for the unit direction `w` leaving the light.
    pub fn falloff(&self, w: Vec3) -> f32 {
        let cos = w.dot(self.axis);
        if cos >= self.cos_beam {
            1.0
        } else if cos > self.cos_cutoff {
            ((self.cutoff - cos.clamp(-1.0, 1.0).acos()) / (self.cutoff - self.beam))
                .clamp(0.0, 1.0)
        } else {
            0.0
        }
    }

    /// Φ = Ī ∫ f dω = 2π Ī ∫₀^θc f(θ) sin θ dθ, exactly: integrating the linear ramp by
    /// parts gives 2π Ī [1 − (sin θc − sin θb)/(θc − θb)], written as
    /// 1 − cos((θc+θb)/2)·sinc((θc−θb)/2) so that it stays exact as θb → θc (→ 1 − cos θc).
    pub fn power(&self) -> f32 {
        let (c, b) = (self.cutoff as f64, self.beam as f64);
        let half = 0.5 * (c - b);
        let sinc = if half > 1e-8 { half.sin() / half } else { 1.0 };
        let fraction = 1.0 - (0.5 * (c + b)).cos() * sinc;
        (2.0 * std::f64::consts::PI * fraction) as f32 * self.intensity.mean()
    }

    /// Towards the light, carrying I f(θ)/d² (a delta sample, pdf 1); None outside the cone.
    pub fn sample_li(&self, r: Vec3) -> Option<LightSample> {
        let (wi, dist, dist2) = towards_point(self.position, r)?;
        let f = self.falloff(-wi);
        if f.is_nan() || f <= 0.0 {
            return None;
        }
        let radiance = self.intensity * (f / dist2);
        Some(LightSample::from_point_light(
            self.position,
            wi,
            dist,
            radiance,
        ))
    }

    /// A direction uniform in the cutoff cone (as Mitsuba), weighted by the falloff.
    pub fn sample_le(&self, u2: Vec2) -> Option<EmissionSample> {
        let local = warp::square_to_uniform_cone(u2, self.cos_cutoff);
        let pdf_dir = warp::uniform_cone_pdf(local, self.cos_cutoff);
        let direction = self.frame.to_world(local).normalize();
        let f = self.falloff(direction);
        if !(pdf_dir > 0.0 && f > 0.0) {
            return None;
        }
        Some(EmissionSample {
            origin: self.position,
            direction,
            n: Vec3::ZERO,
            front: Vec3::ZERO,
            p_error: Vec3::ZERO,
            primitive: 0,
            radiance: self.intensity * f,
            pdf_pos: 1.0,
            pdf_dir,
            delta_pos: true,
            delta_dir: false,
        })
    }

    /// (1, uniform-cone density of `dir`).
    pub fn pdf_le(&self, dir: Vec3) -> (f32, f32) {
        let local = self.frame.to_local(dir.normalize_or_zero());
        (1.0, warp::uniform_cone_pdf(local, self.cos_cutoff))
    }
}
