//! The index-matched boundary (Mitsuba `null`): light passes straight through unchanged.
//! It marks medium boundaries and invisible emitters' supports.

use glam::{Vec2, Vec3};

use crate::material::{BsdfFlags, BsdfModel, BsdfSample, TransportMode};
use crate::math::Rgb;

#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Null;

impl BsdfModel for Null {
    fn eval(&self, _wo: Vec3, _wi: Vec3, _mode: TransportMode) -> Rgb {
        Rgb::BLACK
    }

    fn pdf(&self, _wo: Vec3, _wi: Vec3) -> f32 {
        0.0
    }

    fn sample(&self, wo: Vec3, _u_lobe: f32, _u: Vec2, _mode: TransportMode) -> Option<BsdfSample> {
        if !wo.is_finite() {
            return None;
        }
        Some(BsdfSample {
            wi: -wo,
            weight: Rgb::WHITE,
            pdf: 1.0,
            delta: true,
            eta: 1.0,
        })
    }

    fn flags(&self) -> BsdfFlags {
        BsdfFlags {
            delta: true,
            transmission: true,
            null: true,
            ..Default::default()
        }
    }
}
