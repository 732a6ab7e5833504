//! Mitsuba 3's `checkerboard`: two colours alternating over unit cells of uv space.

use glam::Vec2;

use super::UvTransform;
use crate::math::Rgb;

/// `color0` where the fractional parts of u and v are both above one half or both not,
/// `color1` elsewhere (Mitsuba 3's rule; defaults 0.4 and 0.2).
#[derive(Clone, Debug, PartialEq)]
pub struct Checkerboard {
    pub color0: Rgb,
    pub color1: Rgb,
    pub to_uv: UvTransform,
}

impl Checkerboard {
    #[inline]
    pub fn eval(&self, uv: Vec2) -> Rgb {
        let p = self.to_uv.apply(uv);
        let upper = |x: f32| x - x.floor() > 0.5;
        if upper(p.x) == upper(p.y) {
            self.color0
        } else {
            self.color1
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cells_alternate_and_repeat() {
        let c = Checkerboard {
            color0: Rgb::splat(0.4),
            color1: Rgb::splat(0.2),
            to_uv: UvTransform::IDENTITY,
        };
        let at = |u: f32, v: f32| c.eval(Vec2::new(u, v)).0[0];
        assert_eq!(at(0.25, 0.25), 0.4);
        assert_eq!(at(0.75, 0.75), 0.4);
        assert_eq!(at(0.75, 0.25), 0.2);
        assert_eq!(at(0.25, 0.75), 0.2);
        // Period 1 in both directions, negative coordinates included.
        assert_eq!(at(-0.75, 0.25), 0.4);
        assert_eq!(at(3.25, -1.25), 0.2);
    }
}
