//! The environment map for sixteen directions at once: what rays that escaped the scene
//! read from it (`le`), the density with which next-event estimation would have drawn
//! their directions (`pdf_direction`), and next-event estimation's own draws
//! (`sample_li`). Every step is the scalar code's step in
//! lanes (`Real` formulas, gathers for the texels, the row bands and the cell densities),
//! so each lane holds the bits the scalar functions give.

use glam::Mat3;

use super::EnvmapLight;
use crate::light::LightSampleLanes;
use crate::math::PI;
use crate::math::lanes::{F32x16, Mask16, U32x16, V3};
use crate::math::warp;

impl EnvmapLight {
    /// For world directions `wi` (towards the environment) in the lanes of `m`: the
    /// radiance arriving from each (`le`), and in the lanes of `with_pdf` (within `m`) the
    /// density of drawing it as `Light::pdf_li` returns it (`pdf_direction`, 0 where not
    /// positive and finite). Other lanes: 0.
    pub fn le_and_pdf_lanes(
        &self,
        wi: V3<F32x16>,
        m: Mask16,
        with_pdf: Mask16,
    ) -> (V3<F32x16>, F32x16) {
        let zero = F32x16::splat(0.0);
        // `(to_local · wi).normalize_or_zero()`, and `lookup`'s test for the zero vector.
        let local = mul_mat3(&self.to_local, wi);
        let rcp = F32x16::splat(1.0) / local.length();
        let normalizable = rcp.is_finite() & rcp.gt(zero);
        let d = local * rcp;
        let is_zero = d.x.eq(zero) & d.y.eq(zero) & d.z.eq(zero);
        let valid = m & normalizable & !is_zero;
        let d = V3::select(valid, d, V3::splat(0.0));

        let x = self.column_of(d.x, d.z);
        let le = self.bilinear_lanes(x, self.row_coordinate(d.y), valid);
        let le = V3::select(valid, le, V3::splat(0.0));

        let wanted = valid & with_pdf;
        if self.cells.is_none() || wanted.none() {
            return (le, zero);
        }
        let width = self.width as u32;
        let iu = x.to_u32().min(U32x16::splat(width - 1));
        let iv = self.row_band_lanes(clamp(d.y, -1.0, 1.0), wanted);
        let pdf = F32x16::gather(&self.cell_density, iv * U32x16::splat(width) + iu, wanted);
        // `Light::pdf_li`'s cleaning.
        let clean = pdf.is_finite() & pdf.gt(zero) & wanted;
        (le, F32x16::select(clean, pdf, zero))
    }

    /// `sample_li` (through `Light::sample_li`'s checks, which `Light::sample_li_lanes`
    /// applies) for the lanes of `m`: a cell by the map's distribution, a direction uniform
    /// in solid angle within it, its density and the radiance at its texel coordinates.
    /// None for a black map (the scalar code draws nothing there either).
    pub fn sample_li_lanes(&self, ux: F32x16, uy: F32x16, m: Mask16) -> Option<LightSampleLanes> {
        let cells = self.cells.as_ref()?;
        let zero = F32x16::splat(0.0);
        // `sample_texel_direction`.
        let (u, v, iu, iv) = cells.sample_lanes(ux, uy, m);
        let (w, h) = (self.width as f32, self.height as f32);
        let fx = clamp(u * F32x16::splat(w) - iu.to_f32(), 0.0, 1.0);
        let fy = clamp(v * F32x16::splat(h - 1.0) - iv.to_f32(), 0.0, 1.0);
        let x = iu.to_f32() + fx;
        let phi = F32x16::splat(2.0 * PI) * (x + F32x16::splat(0.5)) / F32x16::splat(w);
        let cos_top = F32x16::gather(&self.cos_rows, iv, m);
        let cos_bottom = F32x16::gather(&self.cos_rows, iv + U32x16::splat(1), m);
        let cos = cos_top + (cos_bottom - cos_top) * fy;
        let sin = (F32x16::splat(1.0) - cos * cos).max_gt(zero).sqrt();
        let (sin_phi, cos_phi) = warp::sin_cos_turns(phi);
        let local = V3::new(sin_phi * sin, cos, -cos_phi * sin);
        let wi = mul_mat3(&self.to_world, local).normalize();
        let cell = iv * U32x16::splat(self.width as u32) + iu;
        let pdf = F32x16::gather(&self.cell_density, cell, m);
        let ok = m & pdf.gt(zero) & pdf.is_finite() & wi.is_finite();
        // `sample_with_radiance`, then `LightSample::at_infinity`.
        let radiance = self.bilinear_lanes(x, self.row_coordinate(cos), ok);
        let zero3 = V3::splat(0.0);
        Some(LightSampleLanes {
            ok,
            p: wi,
            n: -wi,
            p_error: zero3,
            wi,
            radiance,
            pdf_solid_angle: pdf,
            // Per lane the scalar sample's area density is its solid-angle density, whose
            // checks cover it; the one value here only has to be finite.
            pdf_area: 1.0,
            delta: false,
            at_infinity: true,
        })
    }

    /// `bilinear` for texel coordinates (x, y) in the lanes of `m`.
    #[inline(always)]
    fn bilinear_lanes(&self, x: F32x16, y: F32x16, m: Mask16) -> V3<F32x16> {
        let (w, h) = (self.width as u32, self.height as u32);
        let i0 = x.to_u32().min(U32x16::splat(w - 1));
        let j0 = y.to_u32().min(U32x16::splat(h - 2));
        let fx = clamp(x - i0.to_f32(), 0.0, 1.0);
        let fy = clamp(y - j0.to_f32(), 0.0, 1.0);
        let next = i0 + U32x16::splat(1);
        let i1 = U32x16::select(next.eq(U32x16::splat(w)), U32x16::splat(0), next);
        let top = j0 * U32x16::splat(w);
        let bottom = top + U32x16::splat(w);
        let texel = |k: U32x16| {
            let base = k * U32x16::splat(3);
            V3::new(
                F32x16::gather(&self.channels, base, m),
                F32x16::gather(&self.channels, base + U32x16::splat(1), m),
                F32x16::gather(&self.channels, base + U32x16::splat(2), m),
            )
        };
        let one = F32x16::splat(1.0);
        let lerp = |a: V3<F32x16>, b: V3<F32x16>, f: F32x16| a * (one - f) + b * f;
        let upper = lerp(texel(top + i0), texel(top + i1), fx);
        let lower = lerp(texel(bottom + i0), texel(bottom + i1), fx);
        lerp(upper, lower, fy)
    }

    /// `row_band` in the lanes of `m` (others: row 0): from the row coordinate's estimate,
    /// each lane steps up or down until its band holds its cosine.
    #[inline(always)]
    fn row_band_lanes(&self, cos: F32x16, m: Mask16) -> U32x16 {
        let rows = self.height as u32 - 1;
        let one = U32x16::splat(1);
        let mut j = self
            .row_coordinate(cos)
            .to_u32()
            .min(U32x16::splat(rows - 1));
        j = U32x16::select(m, j, U32x16::splat(0));
        loop {
            let up = m & !j.eq(U32x16::splat(0)) & F32x16::gather(&self.cos_rows, j, m).le(cos);
            if up.none() {
                break;
            }
            j = U32x16::select(up, j - one, j);
        }
        loop {
            let below = j + one;
            let down = m
                & below.lt(U32x16::splat(rows))
                & F32x16::gather(&self.cos_rows, below, m).gt(cos);
            if down.none() {
                break;
            }
            j = U32x16::select(down, below, j);
        }
        j
    }
}

/// `m · v` per lane, in glam's order: ((x_axis·v.x) + y_axis·v.y) + z_axis·v.z.
#[inline(always)]
fn mul_mat3(m: &Mat3, v: V3<F32x16>) -> V3<F32x16> {
    let column =
        |c: glam::Vec3| V3::new(F32x16::splat(c.x), F32x16::splat(c.y), F32x16::splat(c.z));
    column(m.x_axis) * v.x + column(m.y_axis) * v.y + column(m.z_axis) * v.z
}

/// `f32::clamp(lo, hi)` per lane (NaN stays NaN).
#[inline(always)]
fn clamp(v: F32x16, lo: f32, hi: f32) -> F32x16 {
    let v = F32x16::select(v.lt(F32x16::splat(lo)), F32x16::splat(lo), v);
    F32x16::select(v.gt(F32x16::splat(hi)), F32x16::splat(hi), v)
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use glam::Vec3;

    use super::*;
    use crate::light::{Light, LightPoint, SceneSphere};
    use crate::math::{Rgb, Transform};

    /// A map of `w` × `h` texels of varying colour, some rows black (cells of density 0).
    fn map(w: usize, h: usize, to_world: Transform) -> EnvmapLight {
        let texels: Vec<Rgb> = (0..w * h)
            .map(|k| {
                let (i, j) = (k % w, k / w);
                if j == 1 {
                    Rgb::BLACK
                } else {
                    Rgb([
                        (i as f32 * 0.37).sin().abs(),
                        j as f32 * 0.1,
                        1.0 + (k % 5) as f32,
                    ])
                }
            })
            .collect();
        let sphere = SceneSphere {
            center: Vec3::ZERO,
            radius: 2.0,
        };
        EnvmapLight::from_texels(Path::new("test"), w, h, &texels, 1.5, &to_world, sphere).unwrap()
    }

    /// Directions all around the sphere, the poles, the seam (u = 0) and degenerate ones
    /// (zero, NaN, infinite, unnormalised).
    fn directions() -> Vec<Vec3> {
        let mut out = vec![
            Vec3::Y,
            -Vec3::Y,
            Vec3::Z,
            -Vec3::Z,
            Vec3::new(0.0, 0.0, -1e-30),
            Vec3::ZERO,
            Vec3::new(f32::NAN, 0.0, 1.0),
            Vec3::new(f32::INFINITY, 0.0, 0.0),
            Vec3::new(3.0, -2.0, 0.5),
            Vec3::new(-0.0, 0.3, -1.0),
            Vec3::new(1e-8, 1.0, -1e-8),
        ];
        let mut s = 0x2545_f491_4f6c_dd1du64;
        while out.len() < 16 * 40 {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            let u = (s >> 40) as f32 / (1u64 << 24) as f32;
            let v = ((s >> 16) & 0xff_ffff) as f32 / (1u64 << 24) as f32;
            let z = 1.0 - 2.0 * u;
            let r = (1.0 - z * z).max(0.0).sqrt();
            let phi = 2.0 * std::f32::consts::PI * v;
            out.push(Vec3::new(r * phi.cos(), z, r * phi.sin()));
        }
        out
    }

    /// Each lane of `Light::sample_li_lanes` on an environment map holds the bits of
    /// `Light::sample_li` (direction, radiance, density, whether there is a sample), on maps
    /// of several sizes with black rows, u at the square's edges; lanes masked out have none.
    #[test]
    fn samples_in_lanes_give_the_scalar_bits() {
        let axis = Vec3::new(-0.5, 1.0, 0.25).normalize();
        let rotated = Transform::new(glam::Mat4::from_axis_angle(axis, 2.1)).unwrap();
        let mut s = 0x853c_49e6_748f_ea9bu64;
        let mut next = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 40) as f32 / (1u64 << 24) as f32
        };
        for (w, h, t) in [
            (2, 3, Transform::IDENTITY),
            (16, 9, rotated),
            (40, 33, Transform::IDENTITY),
        ] {
            let light = Light::Envmap(Box::new(map(w, h, t)));
            for round in 0..300 {
                let edge = |k: usize, v: f32| match k % 11 {
                    0 => 0.0,
                    1 => 1.0 - f32::EPSILON / 2.0,
                    _ => v,
                };
                let ux: [f32; 16] = std::array::from_fn(|i| edge(round + i, next()));
                let uy: [f32; 16] = std::array::from_fn(|i| edge(round + 3 * i + 1, next()));
                let m = Mask16(0xffff ^ (1 << (round % 16)));
                let r = V3::splat(0.5);
                let got = light
                    .sample_li_lanes(r, F32x16::from_array(ux), F32x16::from_array(uy), m)
                    .expect("environment maps sample in lanes");
                assert!(got.at_infinity && !got.delta);
                let bits = |v: V3<F32x16>, i: usize| {
                    [v.x.to_array()[i], v.y.to_array()[i], v.z.to_array()[i]].map(f32::to_bits)
                };
                for i in 0..16 {
                    let want = if m.get(i) {
                        light.sample_li(Vec3::splat(0.5), glam::Vec2::new(ux[i], uy[i]))
                    } else {
                        None
                    };
                    assert_eq!(got.ok.get(i), want.is_some(), "{w}x{h} lane {i}");
                    let Some(want) = want else { continue };
                    let where_ = format!("{w}x{h} u ({}, {}) lane {i}", ux[i], uy[i]);
                    assert_eq!(
                        bits(got.wi, i),
                        [want.wi.x, want.wi.y, want.wi.z].map(f32::to_bits),
                        "wi {where_}"
                    );
                    assert_eq!(
                        bits(got.p, i),
                        [want.p.x, want.p.y, want.p.z].map(f32::to_bits),
                        "p {where_}"
                    );
                    assert_eq!(
                        bits(got.radiance, i),
                        want.radiance.0.map(f32::to_bits),
                        "radiance {where_}"
                    );
                    assert_eq!(
                        got.pdf_solid_angle.to_array()[i].to_bits(),
                        want.pdf_solid_angle.to_bits(),
                        "pdf {where_}"
                    );
                    assert!(want.dist.is_infinite());
                }
            }
        }
    }

    /// Each lane of `le_and_pdf_lanes` holds the bits of `Light::le` and `Light::pdf_li`,
    /// on maps of several sizes (two columns, odd rows, a rotated map), lanes masked out
    /// reading 0.
    #[test]
    fn lanes_give_the_scalar_bits() {
        let axis = Vec3::new(0.3, 1.0, -0.2).normalize();
        let rotated = Transform::new(glam::Mat4::from_axis_angle(axis, 0.82)).unwrap();
        for (w, h, t) in [
            (2, 3, Transform::IDENTITY),
            (16, 9, Transform::IDENTITY),
            (33, 17, rotated),
        ] {
            let env = map(w, h, t);
            let light = Light::Envmap(Box::new(env.clone()));
            for (k, chunk) in directions().chunks(16).enumerate() {
                let lane = |i: usize| chunk[i];
                let wi = V3::new(
                    F32x16::from_array(std::array::from_fn(|i| lane(i).x)),
                    F32x16::from_array(std::array::from_fn(|i| lane(i).y)),
                    F32x16::from_array(std::array::from_fn(|i| lane(i).z)),
                );
                let m = Mask16(if k % 3 == 0 { 0xffff } else { 0xbeef });
                let with_pdf = Mask16(0x7ff7);
                let (le, pdf) = env.le_and_pdf_lanes(wi, m, with_pdf);
                let (lr, lg, lb) = (le.x.to_array(), le.y.to_array(), le.z.to_array());
                let pdf = pdf.to_array();
                for i in 0..16 {
                    let d = lane(i);
                    let point = LightPoint::direction(d);
                    let (want, want_pdf) = if m.get(i) {
                        let pdf = if with_pdf.get(i) {
                            light.pdf_li(Vec3::ZERO, &point)
                        } else {
                            0.0
                        };
                        (light.le(&point, -d).0, pdf)
                    } else {
                        ([0.0; 3], 0.0)
                    };
                    let got = [lr[i], lg[i], lb[i]];
                    for c in 0..3 {
                        assert_eq!(
                            got[c].to_bits(),
                            want[c].to_bits(),
                            "{w}x{h} le {d} lane {i}"
                        );
                    }
                    assert_eq!(
                        pdf[i].to_bits(),
                        want_pdf.to_bits(),
                        "{w}x{h} pdf {d} lane {i}"
                    );
                }
            }
        }
    }
}
