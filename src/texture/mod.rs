//! Textures: colours that vary over a surface, looked up by the hit's (u, v).
//!
//! Mitsuba 3's `bitmap` and `checkerboard`, with their parameters' meanings and defaults.
//! A texture maps the surface's uv through its `to_uv` transform first. Where uvs come from:
//! meshes' own (OBJ's v flipped by `flip_tex_coords`, as Mitsuba does), barycentrics for
//! meshes without, the analytic sphere's (φ/2π, θ/π), the disk's (r, φ/2π), and the
//! rectangle's corners (0, 0) to (1, 1) (`geometry`).
//!
//! mltbench reads textures for `diffuse` reflectance (`BsdfDesc::TexturedDiffuse`); the
//! loader refuses them elsewhere with an error naming the line.

pub mod bitmap;
pub mod checkerboard;

use std::sync::Arc;

use glam::Vec2;

use crate::math::Rgb;

pub use bitmap::{Bitmap, TextureFilter, WrapMode};
pub use checkerboard::Checkerboard;

/// An affine map of the plane, (u, v) ↦ (a·u + b·v + c, d·u + e·v + f): Mitsuba's `to_uv`
/// (the 2D part of the 4×4 transform written in the scene).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UvTransform {
    pub rows: [[f32; 3]; 2],
}

impl UvTransform {
    pub const IDENTITY: UvTransform = UvTransform {
        rows: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
    };

    #[inline]
    pub fn apply(&self, uv: Vec2) -> Vec2 {
        let [r0, r1] = self.rows;
        Vec2::new(
            r0[0] * uv.x + r0[1] * uv.y + r0[2],
            r1[0] * uv.x + r1[1] * uv.y + r1[2],
        )
    }
}

/// A texture ready to look up.
#[derive(Clone, Debug, PartialEq)]
pub enum Texture {
    Bitmap(Arc<Bitmap>),
    Checkerboard(Checkerboard),
}

impl Texture {
    /// The colour at surface coordinates `uv` (before `to_uv`).
    #[inline]
    pub fn eval(&self, uv: Vec2) -> Rgb {
        match self {
            Texture::Bitmap(b) => b.eval(uv),
            Texture::Checkerboard(c) => c.eval(uv),
        }
    }

    /// The largest value of any channel anywhere (a reflectance above 1 creates energy).
    pub fn max_value(&self) -> f32 {
        match self {
            Texture::Bitmap(b) => b.max_value(),
            Texture::Checkerboard(c) => c.color0.max_component().max(c.color1.max_component()),
        }
    }

    /// The mean colour over the unit uv square (for previews and summaries).
    pub fn mean(&self) -> Rgb {
        match self {
            Texture::Bitmap(b) => b.mean(),
            Texture::Checkerboard(c) => (c.color0 + c.color1) * 0.5,
        }
    }
}
