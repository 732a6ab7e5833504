//! Small math vocabulary shared by every part of mltbench.

pub mod erf;
pub mod fast_trig;
pub mod frame;
pub mod lanes;
pub mod spectrum;
pub mod transform;
pub mod warp;

pub use frame::Frame;
pub use glam::{Vec2, Vec3, Vec3A};
pub use spectrum::Rgb;
pub use transform::Transform;

pub const PI: f32 = std::f32::consts::PI;
pub const INV_PI: f32 = std::f32::consts::FRAC_1_PI;
