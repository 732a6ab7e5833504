//! Mitsuba 3's `bitmap`: an image stretched over uv space [0, 1]², (0, 0) at the first
//! pixel of the first row (the top of the image), looked up with Mitsuba's filters and wrap
//! modes.

use glam::Vec2;

use super::UvTransform;
use crate::math::Rgb;

/// How a lookup between texel centres is answered (`filter_type`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TextureFilter {
    /// The texel containing the point.
    Nearest,
    /// Bilinear interpolation between the four nearest texel centres (Mitsuba's default).
    Bilinear,
}

/// What lies outside [0, 1]² (`wrap_mode`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WrapMode {
    /// The image tiles the plane (the default).
    Repeat,
    /// Every other tile is mirrored, so tiles meet without a seam.
    Mirror,
    /// The border texels extend outwards.
    Clamp,
}

impl WrapMode {
    /// Texel index `i` brought into 0..n.
    #[inline]
    fn wrap(self, i: i64, n: i64) -> usize {
        let inside = match self {
            WrapMode::Repeat => i.rem_euclid(n),
            WrapMode::Clamp => i.clamp(0, n - 1),
            WrapMode::Mirror => {
                let m = i.rem_euclid(2 * n);
                if m < n { m } else { 2 * n - 1 - m }
            }
        };
        inside as usize
    }

    /// `wrap` of texel indices `i` and `i + 1`, with one division where the mode allows
    /// (a bilinear lookup wraps two neighbours per axis).
    #[inline]
    fn wrap_pair(self, i: i64, n: i64) -> (usize, usize) {
        match self {
            WrapMode::Repeat => {
                let a = i.rem_euclid(n);
                (a as usize, if a + 1 == n { 0 } else { a as usize + 1 })
            }
            _ => (self.wrap(i, n), self.wrap(i + 1, n)),
        }
    }
}

/// Linear RGB texels, row 0 at the top, with the lookup's settings.
#[derive(Clone, Debug, PartialEq)]
pub struct Bitmap {
    pub width: u32,
    pub height: u32,
    /// `width × height` texels, row by row.
    pub texels: Vec<Rgb>,
    pub filter: TextureFilter,
    pub wrap: WrapMode,
    pub to_uv: UvTransform,
}

impl Bitmap {
    #[inline]
    fn texel(&self, x: i64, y: i64) -> Rgb {
        let x = self.wrap.wrap(x, self.width as i64);
        let y = self.wrap.wrap(y, self.height as i64);
        self.texels[y * self.width as usize + x]
    }

    /// The colour at surface coordinates `uv`: texel (i, j) covers
    /// [i/w, (i+1)/w) × [j/h, (j+1)/h) with its centre at ((i + ½)/w, (j + ½)/h).
    pub fn eval(&self, uv: Vec2) -> Rgb {
        let p = self.to_uv.apply(uv);
        if !p.is_finite() {
            return Rgb::BLACK;
        }
        // In f64: texel indices of large uvs stay exact.
        let x = p.x as f64 * self.width as f64;
        let y = p.y as f64 * self.height as f64;
        match self.filter {
            TextureFilter::Nearest => self.texel(x.floor() as i64, y.floor() as i64),
            TextureFilter::Bilinear => {
                let (x, y) = (x - 0.5, y - 0.5);
                let (x0, y0) = (x.floor(), y.floor());
                let (fx, fy) = ((x - x0) as f32, (y - y0) as f32);
                let (x0, x1) = self.wrap.wrap_pair(x0 as i64, self.width as i64);
                let (y0, y1) = self.wrap.wrap_pair(y0 as i64, self.height as i64);
                let at = |x: usize, y: usize| self.texels[y * self.width as usize + x];
                let top = at(x0, y0) * (1.0 - fx) + at(x1, y0) * fx;
                let bottom = at(x0, y1) * (1.0 - fx) + at(x1, y1) * fx;
                top * (1.0 - fy) + bottom * fy
            }
        }
    }

    /// The largest channel value of any texel.
    pub fn max_value(&self) -> f32 {
        self.texels
            .iter()
            .map(|t| t.max_component())
            .fold(0.0, f32::max)
    }

    /// The mean texel.
    pub fn mean(&self) -> Rgb {
        let sum = self
            .texels
            .iter()
            .fold([0.0f64; 3], |s, t| [0, 1, 2].map(|c| s[c] + t.0[c] as f64));
        let n = self.texels.len().max(1) as f64;
        Rgb(sum.map(|s| (s / n) as f32))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 2×2 image with texels 1, 2 (top row) and 3, 4 (bottom row).
    fn two_by_two(filter: TextureFilter, wrap: WrapMode) -> Bitmap {
        Bitmap {
            width: 2,
            height: 2,
            texels: [1.0, 2.0, 3.0, 4.0].map(Rgb::splat).to_vec(),
            filter,
            wrap,
            to_uv: UvTransform::IDENTITY,
        }
    }

    fn at(b: &Bitmap, u: f32, v: f32) -> f32 {
        b.eval(Vec2::new(u, v)).0[0]
    }

    #[test]
    fn nearest_picks_the_texel_under_the_point_with_v_down_the_rows() {
        let b = two_by_two(TextureFilter::Nearest, WrapMode::Repeat);
        assert_eq!(at(&b, 0.1, 0.1), 1.0);
        assert_eq!(at(&b, 0.9, 0.1), 2.0);
        assert_eq!(at(&b, 0.1, 0.9), 3.0);
        assert_eq!(at(&b, 0.9, 0.9), 4.0);
        assert_eq!(at(&b, 1.1, -0.9), 1.0);
    }

    #[test]
    fn bilinear_is_exact_at_texel_centres_and_linear_between() {
        for wrap in [WrapMode::Repeat, WrapMode::Mirror, WrapMode::Clamp] {
            let b = two_by_two(TextureFilter::Bilinear, wrap);
            assert_eq!(at(&b, 0.25, 0.25), 1.0);
            assert_eq!(at(&b, 0.75, 0.75), 4.0);
            // Midway between the four centres: their mean.
            assert!((at(&b, 0.5, 0.5) - 2.5).abs() < 1e-6);
            // A quarter of the way from texel 1's centre to texel 2's.
            assert!((at(&b, 0.375, 0.25) - 1.25).abs() < 1e-6);
        }
    }

    /// The pair a bilinear lookup wraps is each index wrapped on its own.
    #[test]
    fn wrapped_pairs_are_wrapped_indices() {
        for mode in [WrapMode::Repeat, WrapMode::Mirror, WrapMode::Clamp] {
            for n in [1i64, 2, 3, 7, 64] {
                for i in -4 * n..4 * n {
                    let pair = mode.wrap_pair(i, n);
                    assert_eq!(
                        pair,
                        (mode.wrap(i, n), mode.wrap(i + 1, n)),
                        "{mode:?} {i} {n}"
                    );
                }
            }
        }
    }

    #[test]
    fn wrap_modes_decide_what_lies_beyond_the_border() {
        // At the left border, halfway between texel 1's centre and the texel beyond.
        let u = 0.0;
        let v = 0.25;
        let repeat = two_by_two(TextureFilter::Bilinear, WrapMode::Repeat);
        let mirror = two_by_two(TextureFilter::Bilinear, WrapMode::Mirror);
        let clamp = two_by_two(TextureFilter::Bilinear, WrapMode::Clamp);
        // Repeat: the neighbour is the row's last texel, 2.
        assert!((at(&repeat, u, v) - 1.5).abs() < 1e-6);
        // Mirror and clamp: the neighbour is texel 1 itself.
        assert!((at(&mirror, u, v) - 1.0).abs() < 1e-6);
        assert!((at(&clamp, u, v) - 1.0).abs() < 1e-6);
        // Far outside: clamp keeps the border, mirror reflects every other tile.
        let nearest = |wrap| two_by_two(TextureFilter::Nearest, wrap);
        assert_eq!(at(&nearest(WrapMode::Clamp), 7.9, 0.1), 2.0);
        assert_eq!(at(&nearest(WrapMode::Mirror), 1.1, 0.1), 2.0);
        assert_eq!(at(&nearest(WrapMode::Mirror), 1.9, 0.1), 1.0);
        assert_eq!(at(&nearest(WrapMode::Repeat), 1.1, 0.1), 1.0);
    }

    #[test]
    fn to_uv_maps_before_the_lookup() {
        let mut b = two_by_two(TextureFilter::Nearest, WrapMode::Repeat);
        // Scale u by 2: u = 0.3 looks up 0.6, the right column.
        b.to_uv = UvTransform {
            rows: [[2.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        };
        assert_eq!(at(&b, 0.3, 0.1), 2.0);
        assert_eq!(b.eval(Vec2::new(f32::NAN, 0.0)), Rgb::BLACK);
    }
}
