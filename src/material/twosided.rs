//! Two-sided adapter (Mitsuba `twosided`): the front BSDF seen from above; from below, the
//! back BSDF with both directions mirrored through the surface (z → −z), so a one-sided
//! material looks the same from both sides.

use glam::{Vec2, Vec3};

use crate::material::{Bsdf, BsdfFlags, BsdfModel, BsdfSample, TransportMode};
use crate::math::Rgb;

#[derive(Clone, Debug, PartialEq)]
pub struct TwoSided {
    pub front: Bsdf,
    pub back: Bsdf,
}

#[inline]
fn flip(w: Vec3) -> Vec3 {
    Vec3::new(w.x, w.y, -w.z)
}

impl TwoSided {
    pub fn new(front: Bsdf, back: Bsdf) -> Self {
        TwoSided { front, back }
    }
}

impl BsdfModel for TwoSided {
    fn eval(&self, wo: Vec3, wi: Vec3, mode: TransportMode) -> Rgb {
        if wo.z > 0.0 {
            self.front.eval(wo, wi, mode)
        } else if wo.z < 0.0 {
            self.back.eval(flip(wo), flip(wi), mode)
        } else {
            Rgb::BLACK
        }
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z > 0.0 {
            self.front.pdf(wo, wi)
        } else if wo.z < 0.0 {
            self.back.pdf(flip(wo), flip(wi))
        } else {
            0.0
        }
    }

    fn sample(&self, wo: Vec3, u_lobe: f32, u: Vec2, mode: TransportMode) -> Option<BsdfSample> {
        if wo.z > 0.0 {
            self.front.sample(wo, u_lobe, u, mode)
        } else if wo.z < 0.0 {
            let mut s = self.back.sample(flip(wo), u_lobe, u, mode)?;
            s.wi = flip(s.wi);
            Some(s)
        } else {
            None
        }
    }

    fn flags(&self) -> BsdfFlags {
        self.front.flags().union(self.back.flags())
    }
}
