//! Environment maps (Mitsuba 3's `envmap`): radiance at infinity from a latitude-longitude
//! OpenEXR image, times `scale`, oriented by `to_world` (a rotation).
//!
//! Mapping (Mitsuba 3, MITSUBA-NOTES.md): in the map's local frame +y is up; a direction d
//! has u = atan2(d.x, −d.z)/2π and v = acos(d.y)/π. The lookup is bilinear with texel
//! values placed at grid points: horizontally texel i sits at u = (i + ½)/W and the map
//! wraps around (column W is column 0); vertically row j sits at v = j/(H − 1), so row 0 is
//! exactly the zenith and row H − 1 the nadir. The image needs W ≥ 2 and H ≥ 3 (Mitsuba's
//! minimum).
//!
//! Sampling: the bilinear patches between neighbouring texels are the W × (H − 1) cells
//! of a `Distribution2D`, each weighted by the mean luminance of its four corners times its
//! solid angle (2π/W)(cos θ_j − cos θ_{j+1}) — "luminance × sin θ", integrated exactly over
//! the cell's band of latitudes. Within a cell the direction is uniform in solid angle
//! (φ uniform, cos θ uniform), so the density is the cell's probability over its solid
//! angle: bounded, with no 1/sin θ growth at the poles. A cell is drawable exactly when the
//! bilinear radiance in it can be non-zero, so the estimator stays unbiased.

use std::path::{Path, PathBuf};

use glam::{Mat3, Vec2, Vec3};

use crate::error::{Error, Location, Result};
use crate::io::exr::read_exr;
use crate::light::distribution::Distribution2D;
use crate::light::{EmissionSample, LightSample, SceneSphere};
use crate::math::lanes::Real;
use crate::math::{PI, Rgb, Transform, fast_trig, warp};

mod lanes;

#[derive(Clone, Debug, PartialEq)]
pub struct EnvmapLight {
    pub filename: PathBuf,
    width: usize,
    height: usize,
    /// Radiance (texel × scale), row-major, row 0 at the zenith, three channels per texel
    /// (flat, so that lanes can gather them).
    channels: Vec<f32>,
    to_world: Mat3,
    to_local: Mat3,
    /// cos θ of each texel row: cos(π j / (H − 1)).
    cos_rows: Vec<f32>,
    /// None when the map is black everywhere.
    cells: Option<Distribution2D>,
    /// Per cell (row-major, W × (H − 1)): its probability over its solid angle, the
    /// density of a direction drawn in it (empty when `cells` is None).
    cell_density: Vec<f32>,
    sphere: SceneSphere,
    power: f32,
}

impl EnvmapLight {
    /// Reads the image. Errors name the file: unreadable, smaller than 2 × 3, or a texel that
    /// is negative or not finite, or that overflows f32 times `scale`.
    pub fn load(
        filename: &Path,
        scale: f32,
        to_world: &Transform,
        sphere: SceneSphere,
    ) -> Result<EnvmapLight> {
        let image = read_exr(filename)?;
        EnvmapLight::from_texels(
            filename,
            image.width as usize,
            image.height as usize,
            &image.pixels,
            scale,
            to_world,
            sphere,
        )
    }

    /// The same from texels in memory (row-major, row 0 at the zenith); `filename` names
    /// them in messages.
    pub fn from_texels(
        filename: &Path,
        width: usize,
        height: usize,
        texels: &[Rgb],
        scale: f32,
        to_world: &Transform,
        sphere: SceneSphere,
    ) -> Result<EnvmapLight> {
        let fail = |message: String| Error::input(Location::file(filename), message);
        if width < 2 || height < 3 || texels.len() != width * height {
            return Err(fail(format!(
                "an environment map needs at least 2×3 texels, got {width}×{height}"
            )));
        }
        if !(scale.is_finite() && scale >= 0.0) {
            return Err(fail(format!(
                "the environment map's scale must be finite and not negative, got {scale}"
            )));
        }
        if let Some(k) = texels.iter().position(|t| !t.is_valid_radiance()) {
            return Err(fail(format!(
                "texel ({}, {}) of the environment map is {:?}: radiance must be finite and \
                 not negative",
                k % width,
                k / width,
                texels[k].0
            )));
        }
        let linear = Mat3::from_mat4(to_world.matrix);
        let to_local = linear.inverse();
        if !(linear.is_finite() && to_local.is_finite()) {
            return Err(fail(
                "the environment map's to_world is singular".to_string(),
            ));
        }
        let scaled: Vec<Rgb> = texels.iter().map(|&t| t * scale).collect();
        if let Some(k) = scaled.iter().position(|t| !t.is_valid_radiance()) {
            return Err(fail(format!(
                "texel ({}, {}) of the environment map is {:?}: times the scale {scale} it \
                 overflows f32",
                k % width,
                k / width,
                texels[k].0
            )));
        }
        let texels = scaled;
        let rows = height - 1;
        let cos_rows: Vec<f32> = (0..height)
            .map(|j| {
                if j == rows {
                    -1.0
                } else {
                    (std::f64::consts::PI * j as f64 / rows as f64).cos() as f32
                }
            })
            .collect();
        // Weights and flux in f64: four corners of 3e38 overflow an f32 sum.
        let mut weights = Vec::with_capacity(width * rows);
        let mut flux = 0.0f64; // ∫ L̄ dω by the cell rule
        for j in 0..rows {
            let band = (cos_rows[j] - cos_rows[j + 1]) as f64;
            for i in 0..width {
                let i1 = (i + 1) % width;
                let corners = [
                    texels[j * width + i],
                    texels[j * width + i1],
                    texels[(j + 1) * width + i],
                    texels[(j + 1) * width + i1],
                ];
                let lum: f64 = corners.iter().map(luminance_f64).sum::<f64>() * 0.25;
                let mean: f64 = corners
                    .iter()
                    .map(|c| c.0.iter().map(|&v| v as f64).sum::<f64>() / 3.0)
                    .sum::<f64>()
                    * 0.25;
                weights.push(lum * band);
                flux += mean * band * 2.0 * std::f64::consts::PI / width as f64;
            }
        }
        let cells = Distribution2D::new(&f32_weights(&weights), width, rows);
        let cell_solid_angle = |j: usize| 2.0 * PI / width as f32 * (cos_rows[j] - cos_rows[j + 1]);
        let cell_density = cells.as_ref().map_or_else(Vec::new, |c| {
            (0..rows)
                .flat_map(|j| (0..width).map(move |i| (i, j)))
                .map(|(i, j)| c.cell_probability(i, j) / cell_solid_angle(j))
                .collect()
        });
        let r = sphere.radius as f64;
        // Only compared with other lights' powers: saturate rather than become infinite.
        let power = (std::f64::consts::PI * r * r * flux).min(f32::MAX as f64) as f32;
        Ok(EnvmapLight {
            filename: filename.to_path_buf(),
            width,
            height,
            channels: texels.iter().flat_map(|t| t.0).collect(),
            to_world: linear,
            to_local,
            cos_rows,
            cells,
            cell_density,
            sphere,
            power,
        })
    }

    pub fn size(&self) -> (usize, usize) {
        (self.width, self.height)
    }

    /// Φ = π R² ∫ L̄ dω: the flux entering the scene's bounding sphere. The integral is
    /// taken cell by cell with the mean of the four corners (exact for the bilinear lookup
    /// along φ, a close approximation along θ).
    pub fn power(&self) -> f32 {
        self.power
    }

    /// Radiance arriving from world direction `wi` (pointing towards the environment).
    pub fn le(&self, wi: Vec3) -> Rgb {
        self.lookup(self.to_local * wi)
    }

    /// Bilinear lookup of local direction `d` (not necessarily unit).
    pub fn lookup(&self, d: Vec3) -> Rgb {
        let d = d.normalize_or_zero();
        if d == Vec3::ZERO {
            return Rgb::BLACK;
        }
        self.bilinear(self.column_coordinate(d), self.row_coordinate(d.y))
    }

    /// The texel column coordinate x = u·W − ½ in [0, W) of unit local direction `d`
    /// (u = atan2(d.x, −d.z)/2π, wrapped around).
    fn column_coordinate(&self, d: Vec3) -> f32 {
        self.column_of(d.x, d.z)
    }

    /// `column_coordinate` from the direction's x and z, over `Real` (one direction, or
    /// sixteen in lanes).
    #[inline(always)]
    fn column_of<T: Real>(&self, x: T, z: T) -> T {
        let u = fast_trig::atan2(x, -z) * T::splat(0.5 / PI);
        let w = T::splat(self.width as f32);
        let x = u * w - T::splat(0.5);
        // u is in [−½, ½], so x is in (−W, W), where `x.rem_euclid(W)` is this one add,
        // bit for bit (the remainder of |x| < W is x itself).
        T::select(x.lt(T::splat(0.0)), x + w, x)
    }

    /// The texel row coordinate y = v·(H − 1) of a direction with cos θ = `cos`
    /// (v = acos(cos θ)/π), over `Real`.
    #[inline(always)]
    fn row_coordinate<T: Real>(&self, cos: T) -> T {
        fast_trig::acos(cos) / T::splat(PI) * T::splat((self.height - 1) as f32)
    }

    /// Texel `k` (row-major index).
    #[inline(always)]
    fn texel(&self, k: usize) -> Rgb {
        Rgb([
            self.channels[3 * k],
            self.channels[3 * k + 1],
            self.channels[3 * k + 2],
        ])
    }

    /// The bilinear interpolation at texel coordinates (x, y): x in [0, W] from texel
    /// column 0 (wrapping around: W is column 0 again), y in [0, H − 1] from row 0.
    fn bilinear(&self, x: f32, y: f32) -> Rgb {
        let (w, h) = (self.width, self.height);
        let i0 = (x as usize).min(w - 1);
        let j0 = (y as usize).min(h - 2);
        let fx = (x - i0 as f32).clamp(0.0, 1.0);
        let fy = (y - j0 as f32).clamp(0.0, 1.0);
        let i1 = if i0 + 1 == w { 0 } else { i0 + 1 };
        let t = |i: usize, j: usize| self.texel(j * w + i);
        let top = t(i0, j0) * (1.0 - fx) + t(i1, j0) * fx;
        let bottom = t(i0, j0 + 1) * (1.0 - fx) + t(i1, j0 + 1) * fx;
        top * (1.0 - fy) + bottom * fy
    }

    /// A world direction towards the environment, its solid-angle density and the radiance
    /// from it, read at the sample's own texel coordinates (`lookup` of the direction would
    /// first recover them).
    fn sample_with_radiance(&self, u: Vec2) -> Option<(Vec3, f32, Rgb)> {
        let s = self.sample_texel_direction(u)?;
        let radiance = self.bilinear(s.x, self.row_coordinate(s.cos));
        Some((s.wi, s.pdf, radiance))
    }

    /// A cell by the map's distribution, a direction uniform in solid angle within it.
    fn sample_texel_direction(&self, u: Vec2) -> Option<TexelDirection> {
        let cells = self.cells.as_ref()?;
        let (uv, _, [iu, iv]) = cells.sample(u);
        let fx = (uv.x * self.width as f32 - iu as f32).clamp(0.0, 1.0);
        let fy = (uv.y * (self.height - 1) as f32 - iv as f32).clamp(0.0, 1.0);
        // Texel column coordinate x = u·W − ½ (`lookup`'s), so φ = 2π(x + ½)/W.
        let x = iu as f32 + fx;
        let phi = 2.0 * PI * (x + 0.5) / self.width as f32;
        let cos = self.cos_rows[iv] + (self.cos_rows[iv + 1] - self.cos_rows[iv]) * fy;
        let sin = (1.0 - cos * cos).max(0.0).sqrt();
        // Our own sine and cosine, which lanes reproduce (`lanes.rs`).
        let (sin_phi, cos_phi) = warp::sin_cos_turns(phi);
        let local = Vec3::new(sin_phi * sin, cos, -cos_phi * sin);
        let wi = (self.to_world * local).normalize();
        let pdf = self.cell_density[iv * self.width + iu];
        (pdf > 0.0 && pdf.is_finite() && wi.is_finite()).then_some(TexelDirection {
            wi,
            pdf,
            x,
            cos,
        })
    }

    /// Solid-angle density of `sample_with_radiance` producing world direction `wi`.
    pub fn pdf_direction(&self, wi: Vec3) -> f32 {
        if self.cells.is_none() {
            return 0.0;
        }
        let d = (self.to_local * wi).normalize_or_zero();
        if d == Vec3::ZERO {
            return 0.0;
        }
        let iu = (self.column_coordinate(d) as usize).min(self.width - 1);
        let iv = self.row_band(d.y.clamp(-1.0, 1.0));
        self.cell_density[iv * self.width + iu]
    }

    /// The row band j whose cells hold cos θ = `cos`, cos θ in [cos_rows[j+1], cos_rows[j]]
    /// (decreasing in j): the number of cos_rows[1..H−1] above `cos`. Found by stepping from
    /// the row coordinate's estimate, a step or two, instead of a binary search.
    fn row_band(&self, cos: f32) -> usize {
        let rows = self.height - 1;
        let mut j = (self.row_coordinate(cos) as usize).min(rows - 1);
        // (A NaN cosine starts and stays at row 0, as the search puts it.)
        while j > 0 && self.cos_rows[j] <= cos {
            j -= 1;
        }
        while j + 1 < rows && self.cos_rows[j + 1] > cos {
            j += 1;
        }
        j
    }

    pub fn sample_li(&self, u: Vec2) -> Option<LightSample> {
        let (wi, pdf, radiance) = self.sample_with_radiance(u)?;
        Some(LightSample::at_infinity(wi, radiance, pdf))
    }

    /// A direction by the map's distribution, a uniform point of the disk of radius R
    /// perpendicular to it, R before the scene's centre.
    pub fn sample_le(&self, u1: Vec2, u2: Vec2) -> Option<EmissionSample> {
        let (wi, pdf_dir, radiance) = self.sample_with_radiance(u2)?;
        let direction = -wi;
        let (origin, pdf_pos) = self.sphere.sample_disk(direction, u1);
        Some(EmissionSample {
            origin,
            direction,
            n: direction,
            front: direction,
            p_error: Vec3::ZERO,
            primitive: 0,
            radiance,
            pdf_pos,
            pdf_dir,
            delta_pos: false,
            delta_dir: false,
        })
    }

    /// (1/(πR²), density of the direction −`dir` towards the environment).
    pub fn pdf_le(&self, dir: Vec3) -> (f32, f32) {
        (self.sphere.disk_pdf(), self.pdf_direction(-dir))
    }
}

/// A direction `sample_texel_direction` drew: world direction, solid-angle density, and
/// where it lies on the map (texel column coordinate x in [0, W], cos θ in the map's
/// frame).
struct TexelDirection {
    wi: Vec3,
    pdf: f32,
    x: f32,
    cos: f32,
}

fn luminance_f64(c: &Rgb) -> f64 {
    0.2126 * c.0[0] as f64 + 0.7152 * c.0[1] as f64 + 0.0722 * c.0[2] as f64
}

/// The cells' weights as f32 for `Distribution2D`: scaled by a power of two (exact) when
/// their sum would come near f32's range, and every positive weight kept positive, so each
/// cell whose radiance is not zero stays drawable.
fn f32_weights(weights: &[f64]) -> Vec<f32> {
    const MAX_SUM: f64 = 1e30;
    let sum: f64 = weights.iter().sum();
    let factor = if sum > MAX_SUM {
        2f64.powi(-((sum / MAX_SUM).log2().ceil() as i32))
    } else {
        1.0
    };
    weights
        .iter()
        .map(|&w| {
            if w > 0.0 {
                ((w * factor) as f32).max(f32::MIN_POSITIVE)
            } else {
                0.0
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `row_band` counts the rows above a cosine exactly as a binary search over them does,
    /// for maps of a few and of many rows, at every row's own cosine, its neighbouring
    /// floats, and a fine sweep of [−1, 1].
    #[test]
    fn row_band_agrees_with_a_binary_search() {
        for height in [3usize, 4, 7, 64, 1001, 4097] {
            let texels = vec![Rgb::WHITE; 2 * height];
            let sphere = SceneSphere {
                center: Vec3::ZERO,
                radius: 1.0,
            };
            let map = EnvmapLight::from_texels(
                Path::new("test"),
                2,
                height,
                &texels,
                1.0,
                &Transform::IDENTITY,
                sphere,
            )
            .unwrap();
            let rows = height - 1;
            let search = |cos: f32| {
                map.cos_rows[1..rows]
                    .partition_point(|&c| c > cos)
                    .min(rows - 1)
            };
            let mut cosines: Vec<f32> = (0..=20_000).map(|k| -1.0 + k as f32 / 10_000.0).collect();
            for &c in &map.cos_rows {
                cosines.extend([c, c.next_up(), c.next_down()]);
            }
            for cos in cosines {
                let cos = cos.clamp(-1.0, 1.0);
                assert_eq!(map.row_band(cos), search(cos), "H = {height}, cos = {cos}");
            }
        }
    }
}
