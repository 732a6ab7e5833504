//! Statistical and closed-form tests of `mltbench::light`.
//!
//! 1. χ² goodness of fit of `sample_li` directions against `pdf_li` (rectangles seen
//!    frontally and at grazing angles, a pyramid mesh of unequal triangles seen from above
//!    and from the side, spheres from near, far and inside, an elliptic disk), with the
//!    expected counts from numerical integration of `pdf_li` over the hits of an independent
//!    ray caster written here; per sample, the point lies where that caster says, and
//!    `pdf_li` of the sample equals its reported density.
//! 2. χ² of `sample_le` positions and directions against their exact distributions
//!    (uniform by area × cosine; uniform sphere or cone; uniform disk), and `pdf_le`.
//! 3. The 2D distribution and the environment map: χ² against a small known image, the
//!    density integrates to one, the lookup reproduces hand-computed texels.
//! 4. Closed forms: irradiance from a rectangle (Lambert's polygon formula) and from a
//!    sphere (π L (r/d)²) by Monte Carlo within 4σ; powers; selection by power.
//! 5. Bad input: zero-area emitters and invalid environment maps are errors naming them.
//!
//! Every χ² case draws `N` samples with a fixed seed and is tested at the Šidák-corrected
//! level for an overall significance of 10⁻³ over the `CHI2_CASES` cases of this file.

mod chi2_support;
mod scratch_support;
use scratch_support::ScratchDir;

use std::path::PathBuf;

use chi2_support::make_bins;

use glam::{DVec3, Mat4, Quat, Vec2, Vec3};
use mltbench::image::Image;
use mltbench::io::exr::write_exr;
use mltbench::light::*;
use mltbench::math::{Frame, Rgb, Transform};
use mltbench::sampler::{IndependentSampler, Sampler};
use mltbench::scene::*;
use rayon::prelude::*;
use statrs::distribution::{ChiSquared, ContinuousCDF};

const PI: f64 = std::f64::consts::PI;
/// Samples per χ² case.
const N: usize = 100_000;
/// Overall significance of all χ² tests in this file.
const ALPHA: f64 = 1e-3;
/// 9 `sample_li` cases + 7 `sample_le` cases + the 2D distribution + the envmap.
const CHI2_CASES: u32 = 18;

/// The level each case is tested at (Šidák: 1 − (1 − α)^(1/m)).
fn case_alpha() -> f64 {
    1.0 - (1.0 - ALPHA).powf(1.0 / CHI2_CASES as f64)
}

// ---------------------------------------------------------------------------------------
// Scenes
// ---------------------------------------------------------------------------------------

fn shape_desc(name: &str, geometry: ShapeGeometry, flip_normals: bool) -> ShapeDesc {
    ShapeDesc {
        name: name.to_string(),
        geometry,
        bsdf: 0,
        emitter: Some(0),
        flip_normals,
        interior_medium: None,
        exterior_medium: None,
    }
}

/// A sphere shape (Mitsuba's `sphere`: centre and radius, normals out unless flipped).
fn sphere_shape(name: &str, center: Vec3, radius: f32, flip_normals: bool) -> ShapeDesc {
    shape_desc(name, ShapeGeometry::Sphere { center, radius }, flip_normals)
}

fn mesh(positions: &[Vec3], indices: &[[u32; 3]]) -> TriangleMesh {
    TriangleMesh {
        positions: positions.to_vec(),
        normals: None,
        uvs: None,
        indices: indices.to_vec(),
    }
}

fn scene_of(shapes: Vec<ShapeDesc>, emitters: Vec<EmitterDesc>) -> SceneDescription {
    SceneDescription {
        source: PathBuf::from("lights-test.xml"),
        shapes,
        emitters,
        ..SceneDescription::default()
    }
}

/// The area light on a scene's only shape.
fn area_light(shape: ShapeDesc, radiance: Rgb) -> Light {
    let scene = scene_of(vec![shape], vec![EmitterDesc::Area { radiance, shape: 0 }]);
    let set = LightSet::build(&scene).expect("light builds");
    set.get(0).clone()
}

/// 1 × 2 rectangle in the z = 0 plane, normal +z (two triangles, counter-clockwise).
fn rectangle() -> Vec<[Vec3; 3]> {
    let v = [
        Vec3::new(-0.5, -1.0, 0.0),
        Vec3::new(0.5, -1.0, 0.0),
        Vec3::new(0.5, 1.0, 0.0),
        Vec3::new(-0.5, 1.0, 0.0),
    ];
    vec![[v[0], v[1], v[2]], [v[0], v[2], v[3]]]
}

/// A pyramid over an irregular pentagon with its apex off-centre: five triangles of unequal
/// areas, normals up and out. It is the graph of a concave function, so a ray from outside
/// meets it first on a face turned towards the ray's origin.
fn pyramid() -> Vec<[Vec3; 3]> {
    let apex = Vec3::new(0.1, -0.2, 0.6);
    let base = [
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(0.3, 0.9, 0.0),
        Vec3::new(-0.8, 0.5, 0.0),
        Vec3::new(-0.6, -0.7, 0.0),
        Vec3::new(0.5, -0.9, 0.0),
    ];
    (0..5).map(|i| [base[i], base[(i + 1) % 5], apex]).collect()
}

fn mesh_shape(triangles: &[[Vec3; 3]]) -> ShapeDesc {
    let positions: Vec<Vec3> = triangles.iter().flatten().copied().collect();
    let indices: Vec<[u32; 3]> = (0..triangles.len() as u32)
        .map(|t| [3 * t, 3 * t + 1, 3 * t + 2])
        .collect();
    shape_desc(
        "test-mesh",
        ShapeGeometry::Mesh(mesh(&positions, &indices)),
        false,
    )
}

/// An elliptic disk (semi-axes 1.5 and 0.6), tilted and moved.
fn disk_transform() -> Transform {
    let m = Mat4::from_translation(Vec3::new(0.3, -0.2, 0.5))
        * Mat4::from_quat(Quat::from_axis_angle(
            Vec3::new(1.0, 1.0, 0.0).normalize(),
            40f32.to_radians(),
        ))
        * Mat4::from_scale(Vec3::new(1.5, 0.6, 1.0));
    Transform::new(m).unwrap()
}

// ---------------------------------------------------------------------------------------
// An independent ray caster for the light shapes (f64)
// ---------------------------------------------------------------------------------------

#[derive(Clone, Debug)]
enum TestShape {
    Mesh(Vec<[Vec3; 3]>),
    Sphere { c: Vec3, r: f32, flip: bool },
    Disk { m: Mat4, inv: Mat4, n: Vec3 },
}

impl TestShape {
    fn disk(t: &Transform, flip: bool) -> TestShape {
        let inv = t.matrix.inverse();
        let n = inv.transpose().transform_vector3(Vec3::Z).normalize();
        TestShape::Disk {
            m: t.matrix,
            inv,
            n: if flip { -n } else { n },
        }
    }

    /// Closest hit of the ray o + t·w, t > 0, with the front normal.
    fn hit(&self, o: Vec3, w: Vec3) -> Option<LightPoint> {
        let (o64, w64) = (o.as_dvec3(), w.as_dvec3());
        match self {
            TestShape::Mesh(tris) => {
                let mut best: Option<(f64, LightPoint)> = None;
                for (i, t) in tris.iter().enumerate() {
                    let [a, b, c] = t.map(|v| v.as_dvec3());
                    // Möller & Trumbore (1997), with edges widened by 1e-7.
                    let (e1, e2) = (b - a, c - a);
                    let p = w64.cross(e2);
                    let det = e1.dot(p);
                    if det.abs() < 1e-300 {
                        continue;
                    }
                    let s = o64 - a;
                    let u = s.dot(p) / det;
                    let q = s.cross(e1);
                    let v = w64.dot(q) / det;
                    let tt = e2.dot(q) / det;
                    let tol = 1e-7;
                    if u < -tol || v < -tol || u + v > 1.0 + tol || tt <= 1e-9 {
                        continue;
                    }
                    if best.as_ref().is_none_or(|(bt, _)| tt < *bt) {
                        let n = e1.cross(e2).normalize().as_vec3();
                        let point = LightPoint {
                            p: (o64 + w64 * tt).as_vec3(),
                            n,
                            front: n,
                            primitive: i as u32,
                        };
                        best = Some((tt, point));
                    }
                }
                best.map(|(_, p)| p)
            }
            TestShape::Sphere { c, r, flip } => {
                // Unit direction in f64, and the discriminant from the distance between the
                // centre and the line (no cancellation of b² against c for far spheres).
                let w64 = w64.normalize();
                let f = o64 - c.as_dvec3();
                let b = f.dot(w64);
                let disc = (*r as f64).powi(2) - (f - w64 * b).length_squared();
                if disc < 0.0 {
                    return None;
                }
                let sq = disc.sqrt();
                let t = if -b - sq > 1e-9 { -b - sq } else { -b + sq };
                if t <= 1e-9 {
                    return None;
                }
                let p = o64 + w64 * t;
                let out = ((p - c.as_dvec3()) / *r as f64).as_vec3();
                Some(LightPoint {
                    p: p.as_vec3(),
                    n: if *flip { -out } else { out },
                    front: if *flip { -out } else { out },
                    primitive: 0,
                })
            }
            TestShape::Disk { inv, n, .. } => {
                let inv64 = inv.as_dmat4();
                let ol = inv64.transform_point3(o64);
                let wl = inv64.transform_vector3(w64);
                let t = -ol.z / wl.z;
                if t.is_nan() || t <= 1e-9 {
                    return None;
                }
                let (x, y) = (ol.x + t * wl.x, ol.y + t * wl.y);
                if x * x + y * y > 1.0 + 1e-7 {
                    return None;
                }
                Some(LightPoint {
                    p: (o64 + w64 * t).as_vec3(),
                    n: *n,
                    front: *n,
                    primitive: 0,
                })
            }
        }
    }

    /// Points whose gnomonic projection bounds the shape's (vertices; rim points).
    fn outline(&self) -> Vec<Vec3> {
        match self {
            TestShape::Mesh(tris) => tris.iter().flatten().copied().collect(),
            TestShape::Disk { m, .. } => (0..720)
                .map(|k| {
                    let a = k as f32 / 720.0 * std::f32::consts::TAU;
                    m.transform_point3(Vec3::new(a.cos(), a.sin(), 0.0))
                })
                .collect(),
            TestShape::Sphere { .. } => unreachable!("spheres use their cone"),
        }
    }
}

// ---------------------------------------------------------------------------------------
// Grids over directions, integration, bins, χ²
// ---------------------------------------------------------------------------------------

#[derive(Clone, Copy, Debug)]
enum Param {
    /// (z, φ) over the whole sphere of the frame: dω = dz dφ.
    Sphere,
    /// Gnomonic coordinates (x/z, y/z) in a box, for z > 0: dω = dx dy / (1 + x² + y²)^{3/2}.
    Gnomonic { x0: f64, x1: f64, y0: f64, y1: f64 },
}

#[derive(Clone, Copy, Debug)]
struct Grid {
    frame: Frame,
    param: Param,
    na: usize,
    nb: usize,
}

impl Grid {
    fn cells(&self) -> usize {
        self.na * self.nb
    }

    /// World direction at grid coordinates (a, b) ∈ [0, 1)², and dω/(da db).
    fn direction(&self, a: f64, b: f64) -> (Vec3, f64) {
        match self.param {
            Param::Sphere => {
                let z = -1.0 + 2.0 * a;
                let phi = 2.0 * PI * b;
                let s = (1.0 - z * z).max(0.0).sqrt();
                let local = DVec3::new(s * phi.cos(), s * phi.sin(), z).as_vec3();
                (self.frame.to_world(local), 4.0 * PI)
            }
            Param::Gnomonic { x0, x1, y0, y1 } => {
                let x = x0 + (x1 - x0) * a;
                let y = y0 + (y1 - y0) * b;
                let r2 = 1.0 + x * x + y * y;
                let local = DVec3::new(x, y, 1.0).normalize().as_vec3();
                (
                    self.frame.to_world(local),
                    (x1 - x0) * (y1 - y0) / (r2 * r2.sqrt()),
                )
            }
        }
    }

    /// The cell holding world direction `w`, None outside the grid.
    fn cell_of(&self, w: Vec3) -> Option<usize> {
        let l = self.frame.to_local(w).as_dvec3().normalize();
        let (a, b) = match self.param {
            Param::Sphere => {
                let mut phi = l.y.atan2(l.x) / (2.0 * PI);
                if phi < 0.0 {
                    phi += 1.0;
                }
                ((l.z + 1.0) / 2.0, phi)
            }
            Param::Gnomonic { x0, x1, y0, y1 } => {
                if l.z <= 0.0 {
                    return None;
                }
                ((l.x / l.z - x0) / (x1 - x0), (l.y / l.z - y0) / (y1 - y0))
            }
        };
        if !((0.0..1.0).contains(&a) && (0.0..=1.0).contains(&b)) {
            return None;
        }
        let i = ((a * self.na as f64) as usize).min(self.na - 1);
        let j = ((b * self.nb as f64) as usize).min(self.nb - 1);
        Some(i * self.nb + j)
    }

    /// ∫ pdf dω over each cell by the k × k midpoint rule.
    fn integrate(&self, pdf: &(dyn Fn(Vec3) -> f64 + Sync), k: usize) -> Vec<f64> {
        (0..self.cells())
            .into_par_iter()
            .map(|c| {
                let (i, j) = (c / self.nb, c % self.nb);
                let (da, db) = (1.0 / self.na as f64, 1.0 / self.nb as f64);
                let mut sum = 0.0;
                for si in 0..k {
                    for sj in 0..k {
                        let a = (i as f64 + (si as f64 + 0.5) / k as f64) * da;
                        let b = (j as f64 + (sj as f64 + 0.5) / k as f64) * db;
                        let (w, jac) = self.direction(a, b);
                        sum += pdf(w) * jac;
                    }
                }
                sum * da * db / (k * k) as f64
            })
            .collect()
    }
}

/// p-value of Pearson's χ² after pooling bins expected to hold fewer than 5 (Cochran's
/// rule); 0 when draws fall where nothing at all was expected.
fn chi2_p_value(expected: &[f64], observed: &[f64]) -> f64 {
    let (mut pe, mut po) = (0.0, 0.0);
    let mut kept: Vec<(f64, f64)> = Vec::new();
    for (&e, &o) in expected.iter().zip(observed) {
        if e < 5.0 {
            pe += e;
            po += o;
        } else {
            kept.push((e, o));
        }
    }
    if pe > 0.0 || po > 0.0 {
        if pe >= 5.0 || kept.is_empty() {
            kept.push((pe, po));
        } else {
            let smallest = kept
                .iter_mut()
                .min_by(|a, b| a.0.partial_cmp(&b.0).unwrap())
                .unwrap();
            smallest.0 += pe;
            smallest.1 += po;
        }
    }
    if kept.iter().any(|&(e, o)| e <= 0.0 && o > 0.0) || kept.len() < 2 {
        return 0.0;
    }
    let stat: f64 = kept.iter().map(|&(e, o)| (o - e) * (o - e) / e).sum();
    1.0 - ChiSquared::new((kept.len() - 1) as f64).unwrap().cdf(stat)
}

// ---------------------------------------------------------------------------------------
// 1. sample_li against pdf_li
// ---------------------------------------------------------------------------------------

struct LiCase {
    name: &'static str,
    light: Light,
    shape: TestShape,
    r: Vec3,
    grid: Grid,
    radiance: Rgb,
    /// Whether some points of the light face away from `r` (so `sample_li` may return
    /// None). When not, a None is an error rather than an observation of the last bin:
    /// the quadrature's small error would otherwise dominate that bin's expected count.
    may_miss: bool,
}

/// A frame around `axis` turned by 0.1 rad from `Frame::from_normal`, so that edges of the
/// test shapes (often axis-aligned) do not line up with the rows of the quadrature grid,
/// which would make the midpoint rule's error systematic instead of cancelling.
fn turned_frame(axis: Vec3) -> Frame {
    let f = Frame::from_normal(axis);
    let (c, s) = (0.1f32.cos(), 0.1f32.sin());
    Frame {
        s: f.s * c + f.t * s,
        t: f.t * c - f.s * s,
        n: f.n,
    }
}

/// A gnomonic grid around the direction from `r` to `target`, bounding the projections of
/// `outline` with a 3% margin.
fn gnomonic_around(r: Vec3, target: Vec3, outline: &[Vec3], n: usize) -> Grid {
    let frame = turned_frame((target - r).normalize());
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for &p in outline {
        let l = frame.to_local(p - r).as_dvec3();
        assert!(l.z > 0.0, "outline point behind the reference point");
        let (x, y) = (l.x / l.z, l.y / l.z);
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y);
        y1 = y1.max(y);
    }
    let (mx, my) = (0.03 * (x1 - x0) + 1e-6, 0.03 * (y1 - y0) + 1e-6);
    Grid {
        frame,
        param: Param::Gnomonic {
            x0: x0 - mx,
            x1: x1 + mx,
            y0: y0 - my,
            y1: y1 + my,
        },
        na: n,
        nb: n,
    }
}

/// A gnomonic grid over the cone a sphere subtends from `r` (outside it).
fn cone_grid(r: Vec3, c: Vec3, radius: f32, n: usize) -> Grid {
    let d = (c - r).length() as f64;
    let t = radius as f64 / (d * d - (radius as f64).powi(2)).sqrt() * 1.03;
    Grid {
        frame: Frame::from_normal((c - r).normalize()),
        param: Param::Gnomonic {
            x0: -t,
            x1: t,
            y0: -t,
            y1: t,
        },
        na: n,
        nb: n,
    }
}

fn li_cases() -> Vec<LiCase> {
    let white = Rgb::new(1.0, 2.0, 0.5);
    let mut cases = Vec::new();
    let rect = rectangle();
    let rect_light = area_light(mesh_shape(&rect), white);
    let rect_shape = TestShape::Mesh(rect.clone());
    for (name, r) in [
        ("rectangle, above", Vec3::new(0.2, -0.3, 1.0)),
        ("rectangle, grazing 6°", Vec3::new(3.0, 0.5, 0.3)),
        ("rectangle, grazing 0.7° along", Vec3::new(0.0, 4.0, 0.05)),
    ] {
        cases.push(LiCase {
            name,
            light: rect_light.clone(),
            grid: gnomonic_around(r, Vec3::ZERO, &rect_shape.outline(), 64),
            shape: rect_shape.clone(),
            r,
            radiance: white,
            may_miss: false,
        });
    }
    let pyr = pyramid();
    let pyr_light = area_light(mesh_shape(&pyr), white);
    let pyr_shape = TestShape::Mesh(pyr.clone());
    for (name, r, may_miss) in [
        ("pyramid, above", Vec3::new(0.3, 0.2, 2.0), false),
        ("pyramid, from the side", Vec3::new(2.5, 0.3, 0.25), true),
    ] {
        cases.push(LiCase {
            name,
            light: pyr_light.clone(),
            grid: gnomonic_around(r, Vec3::new(0.0, 0.0, 0.25), &pyr_shape.outline(), 64),
            shape: pyr_shape.clone(),
            r,
            radiance: white,
            may_miss,
        });
    }
    let c = Vec3::new(0.5, -0.25, 1.0);
    let sphere = |flip| area_light(sphere_shape("sphere", c, 1.0, flip), white);
    let outside = sphere(false);
    for (name, r) in [
        (
            "sphere, from 1.5 r",
            c + Vec3::new(0.6, 0.8, 1.2).normalize() * 1.5,
        ),
        (
            "sphere, from 40 r",
            c + Vec3::new(-0.3, 0.5, -0.4).normalize() * 40.0,
        ),
    ] {
        cases.push(LiCase {
            name,
            light: outside.clone(),
            grid: cone_grid(r, c, 1.0, 64),
            shape: TestShape::Sphere {
                c,
                r: 1.0,
                flip: false,
            },
            r,
            radiance: white,
            may_miss: false,
        });
    }
    cases.push(LiCase {
        name: "flipped sphere, from inside",
        light: sphere(true),
        grid: Grid {
            frame: Frame::from_normal(Vec3::Z),
            param: Param::Sphere,
            na: 48,
            nb: 48,
        },
        shape: TestShape::Sphere {
            c,
            r: 1.0,
            flip: true,
        },
        r: c + Vec3::new(0.3, 0.2, -0.5),
        radiance: white,
        may_miss: false,
    });
    let t = disk_transform();
    let disk = TestShape::disk(&t, false);
    let TestShape::Disk { n, .. } = disk else {
        unreachable!()
    };
    let centre = t.point(Vec3::ZERO);
    let r = centre + n * 1.2 + Vec3::new(0.4, -0.3, 0.2);
    cases.push(LiCase {
        name: "elliptic disk",
        light: area_light(
            shape_desc("disk", ShapeGeometry::Disk { to_world: t }, false),
            white,
        ),
        grid: gnomonic_around(r, centre, &disk.outline(), 64),
        shape: disk,
        r,
        radiance: white,
        may_miss: false,
    });
    cases
}

struct LiOutcome {
    p_value: f64,
    mass: f64,
    none_fraction: f64,
    /// Samples whose point is not where the ray caster finds it, whose `pdf_li` differs from
    /// the reported density, or whose radiance is wrong.
    inconsistent: usize,
}

/// The density `pdf_li` gives direction `w` (via the test's ray caster).
fn pdf_of(case: &LiCase, w: Vec3) -> f64 {
    case.shape
        .hit(case.r, w)
        .map_or(0.0, |h| case.light.pdf_li(case.r, &h) as f64)
}

/// The χ² test of one case: expected counts from `pdf` (normally `pdf_of`).
fn run_li_case(case: &LiCase, seed: u64, pdf: &(dyn Fn(Vec3) -> f64 + Sync)) -> LiOutcome {
    let n = N as f64;
    let cells: Vec<f64> = case
        .grid
        .integrate(pdf, 16)
        .into_iter()
        .map(|p| p * n)
        .collect();
    let mass = cells.iter().sum::<f64>() / n;
    let (bin_of_cell, n_bins) = make_bins(case.grid.na, case.grid.nb, &cells, n);
    // Bins: the grid's, then "outside the grid" (nothing expected), then "no sample".
    let mut expected = vec![0.0; n_bins + 2];
    for (c, e) in cells.iter().enumerate() {
        expected[bin_of_cell[c]] += e;
    }
    if case.may_miss {
        expected[n_bins + 1] = (n - cells.iter().sum::<f64>()).max(0.0);
    }
    let mut observed = vec![0.0; n_bins + 2];
    let mut sampler = IndependentSampler::new(seed);
    let mut inconsistent = 0;
    for _ in 0..N {
        let u = sampler.next_2d();
        let Some(s) = case.light.sample_li(case.r, u) else {
            observed[n_bins + 1] += 1.0;
            if !case.may_miss {
                inconsistent += 1;
            }
            continue;
        };
        match case.grid.cell_of(s.wi) {
            Some(c) => observed[bin_of_cell[c]] += 1.0,
            None => observed[n_bins] += 1.0,
        }
        // The ray towards the sample meets the light first at the sample. A direction
        // rounded by δ ≈ 10⁻⁷ moves the hit by about δ·dist/cos at incidence cos from the
        // normal, hence the tolerance.
        let cos = s.n.dot(-s.wi).abs();
        let hit = case.shape.hit(case.r, s.wi);
        let tol = 1e-4 * (1.0 + s.dist) + 1e-6 * s.dist / cos;
        let same_point = hit.is_some_and(|h| (h.p - s.p).length() <= tol);
        let pdf_back = case.light.pdf_li(case.r, &s.point());
        let same_pdf = (pdf_back - s.pdf_solid_angle).abs() <= 1e-4 * s.pdf_solid_angle;
        let area_ok = {
            let expect = s.pdf_solid_angle * cos / (s.dist * s.dist);
            (s.pdf_area - expect).abs() <= 1e-3 * expect
        };
        if !(same_point && same_pdf && area_ok && s.radiance == case.radiance && !s.delta) {
            inconsistent += 1;
        }
    }
    LiOutcome {
        p_value: chi2_p_value(&expected, &observed),
        mass,
        none_fraction: observed[n_bins + 1] / n,
        inconsistent,
    }
}

#[test]
fn sample_li_matches_pdf_li() {
    let cases = li_cases();
    assert_eq!(cases.len(), 9);
    let outcomes: Vec<LiOutcome> = cases
        .par_iter()
        .enumerate()
        .map(|(k, c)| run_li_case(c, 1000 + k as u64, &|w| pdf_of(c, w)))
        .collect();
    let level = case_alpha();
    let mut failures = Vec::new();
    for (c, o) in cases.iter().zip(&outcomes) {
        println!(
            "{:32} p = {:.4}  ∫pdf = {:.5}  none = {:.5}  inconsistent = {}",
            c.name, o.p_value, o.mass, o.none_fraction, o.inconsistent
        );
        // The fraction of samples returned must match ∫ pdf dω within 5σ (binomial) plus
        // the quadrature's error.
        let sd = (o.mass.clamp(0.0, 1.0) * (1.0 - o.mass.clamp(0.0, 1.0)) / N as f64).sqrt();
        let mass_ok = (1.0 - o.none_fraction - o.mass).abs() <= 5.0 * sd + 2e-4;
        if o.p_value < level || o.inconsistent > 0 || !mass_ok {
            failures.push(c.name);
        }
    }
    assert!(failures.is_empty(), "failed: {failures:?}");
}

/// The harness can fail: a density that forgets the cosine in the area-to-solid-angle
/// conversion (pdf_A·d² instead of pdf_A·d²/cos, renormalised) is rejected even for a
/// rectangle seen from above, where cos varies only between 0.6 and 1.
#[test]
fn chi2_harness_rejects_a_wrong_pdf() {
    let case = li_cases().into_iter().next().unwrap();
    assert_eq!(case.name, "rectangle, above");
    let wrong = |w: Vec3| {
        case.shape.hit(case.r, w).map_or(0.0, |h| {
            let d = h.p - case.r;
            (d.length_squared() / 2.0) as f64 // pdf_A = 1/A, A = 2
        })
    };
    let mass: f64 = case.grid.integrate(&wrong, 8).iter().sum();
    let o = run_li_case(&case, 77, &|w| wrong(w) / mass);
    assert!(o.p_value < 1e-6, "p = {}", o.p_value);
    let right = run_li_case(&case, 77, &|w| pdf_of(&case, w));
    assert!(right.p_value > case_alpha(), "p = {}", right.p_value);
}

/// Where no point faces the reference point, nothing is sampled and every density is 0.
#[test]
fn lights_seen_from_behind_give_nothing() {
    let white = Rgb::splat(1.0);
    let c = Vec3::new(0.0, 0.0, 0.0);
    let cases = [
        (
            area_light(mesh_shape(&rectangle()), white),
            TestShape::Mesh(rectangle()),
            Vec3::new(0.1, 0.2, -1.0),
        ),
        (
            area_light(sphere_shape("s", c, 1.0, false), white),
            TestShape::Sphere {
                c,
                r: 1.0,
                flip: false,
            },
            Vec3::new(0.2, 0.1, 0.3),
        ),
        (
            area_light(sphere_shape("s", c, 1.0, true), white),
            TestShape::Sphere {
                c,
                r: 1.0,
                flip: true,
            },
            Vec3::new(0.2, 3.0, 0.3),
        ),
    ];
    let mut sampler = IndependentSampler::new(5);
    for (light, shape, r) in &cases {
        for _ in 0..10_000 {
            assert!(light.sample_li(*r, sampler.next_2d()).is_none());
            let w = mltbench::math::warp::square_to_sphere(sampler.next_2d());
            if let Some(h) = shape.hit(*r, w) {
                assert_eq!(light.pdf_li(*r, &h), 0.0);
                assert!(light.le(&h, -w).is_black());
            }
        }
    }
}

/// The sampled points are where the renderer's own ray caster finds the light, with the
/// same normal: the conventions (winding, `flip_normals`, disk normals) agree.
#[test]
fn samples_agree_with_the_ray_caster() {
    use mltbench::geometry::{Geometry, Ray};
    let c = Vec3::new(0.5, -0.25, 1.0);
    let shapes = vec![
        (mesh_shape(&pyramid()), Vec3::new(0.3, 0.2, 2.0)),
        (
            sphere_shape("s", c, 1.0, false),
            c + Vec3::new(0.0, 2.0, 0.5),
        ),
        (
            sphere_shape("s", c, 1.0, true),
            c + Vec3::new(0.1, 0.2, 0.3),
        ),
        (
            shape_desc(
                "d",
                ShapeGeometry::Disk {
                    to_world: disk_transform(),
                },
                false,
            ),
            disk_transform().point(Vec3::ZERO) + Vec3::new(0.1, -0.2, 1.5),
        ),
        (
            shape_desc(
                "d",
                ShapeGeometry::Disk {
                    to_world: disk_transform(),
                },
                true,
            ),
            disk_transform().point(Vec3::ZERO) - Vec3::new(0.1, -0.2, 1.5),
        ),
    ];
    let mut sampler = IndependentSampler::new(11);
    for (shape, r) in shapes {
        let light = area_light(shape.clone(), Rgb::splat(1.0));
        let geometry = Geometry::build(std::slice::from_ref(&shape));
        let mut found = 0;
        for _ in 0..2000 {
            let Some(s) = light.sample_li(r, sampler.next_2d()) else {
                continue;
            };
            found += 1;
            let hit = geometry
                .intersect(&Ray::new(r, s.wi))
                .unwrap_or_else(|| panic!("{}: no hit towards a sample", shape.name));
            let p = LightPoint::from(&hit);
            assert!(
                (p.p - s.p).length() < 1e-4,
                "{}: {:?} vs {:?}",
                shape.name,
                p,
                s
            );
            assert!(p.n.dot(s.n) > 0.9999, "{}: {:?} vs {:?}", shape.name, p, s);
            let pdf = light.pdf_li(r, &p);
            assert!(
                (pdf - s.pdf_solid_angle).abs() <= 1e-3 * pdf,
                "{}",
                shape.name
            );
            assert_eq!(light.le(&p, -s.wi), Rgb::splat(1.0));
        }
        assert!(found > 1000, "{}: only {found} samples", shape.name);
    }
}

// ---------------------------------------------------------------------------------------
// 2. sample_le against exact distributions
// ---------------------------------------------------------------------------------------

/// Runs `N` emission samples, bins each with `bin` (None = a sample that should not exist)
/// and compares with `expected` probabilities; `check` validates each sample.
fn run_le_case(
    light: &Light,
    seed: u64,
    expected_prob: &[f64],
    bin: &dyn Fn(&EmissionSample) -> Option<usize>,
    check: &dyn Fn(&EmissionSample) -> bool,
) -> (f64, usize) {
    let mut observed = vec![0.0; expected_prob.len() + 1];
    let mut sampler = IndependentSampler::new(seed);
    let mut bad = 0;
    for _ in 0..N {
        let (u1, u2) = (sampler.next_2d(), sampler.next_2d());
        match light.sample_le(u1, u2) {
            Some(s) => {
                match bin(&s) {
                    Some(b) => observed[b] += 1.0,
                    None => observed[expected_prob.len()] += 1.0,
                }
                let (pp, pd) = light.pdf_le(s.origin, s.n, s.direction);
                let same = (pp - s.pdf_pos).abs() <= 1e-5 * s.pdf_pos
                    && (pd - s.pdf_dir).abs() <= 1e-4 * s.pdf_dir;
                if !(same && check(&s)) {
                    bad += 1;
                }
            }
            None => observed[expected_prob.len()] += 1.0,
        }
    }
    let mut expected: Vec<f64> = expected_prob.iter().map(|p| p * N as f64).collect();
    expected.push(0.0);
    (chi2_p_value(&expected, &observed), bad)
}

/// Index of an equal-area bin of the unit disk: `nr` rings in r², `nphi` sectors.
fn disk_bin(x: f64, y: f64, nr: usize, nphi: usize) -> Option<usize> {
    let r2 = x * x + y * y;
    if r2 >= 1.0 + 1e-9 {
        return None;
    }
    let i = ((r2 * nr as f64) as usize).min(nr - 1);
    let mut phi = y.atan2(x) / (2.0 * PI);
    if phi < 0.0 {
        phi += 1.0;
    }
    Some(i * nphi + ((phi * nphi as f64) as usize).min(nphi - 1))
}

/// Index of an equal-probability bin of a cosine-distributed direction about `n`:
/// `nz` bands of cos²θ (uniform under cos θ/π), `nphi` sectors.
fn cosine_bin(n: Vec3, d: Vec3, nz: usize, nphi: usize) -> Option<usize> {
    let f = Frame::from_normal(n);
    let l = f.to_local(d).as_dvec3();
    if l.z <= 0.0 {
        return None;
    }
    disk_bin(l.x, l.y, nz, nphi) // the projection onto the disk is uniform (Malley)
}

/// Equal-area bin of a direction on the sphere: `nz` bands of z, `nphi` sectors.
fn sphere_bin(d: Vec3, nz: usize, nphi: usize) -> usize {
    let d = d.as_dvec3().normalize();
    let i = (((d.z + 1.0) / 2.0 * nz as f64) as usize).min(nz - 1);
    let mut phi = d.y.atan2(d.x) / (2.0 * PI);
    if phi < 0.0 {
        phi += 1.0;
    }
    i * nphi + ((phi * nphi as f64) as usize).min(nphi - 1)
}

/// Which quarter of a triangle (b0 > ½, b1 > ½, b2 > ½, or the middle) holds p.
fn triangle_quarter(t: &[Vec3; 3], p: Vec3) -> Option<usize> {
    let [a, b, c] = t.map(|v| v.as_dvec3());
    let p = p.as_dvec3();
    let n = (b - a).cross(c - a);
    let n2 = n.length_squared();
    let b1 = (p - a).cross(c - a).dot(n) / n2;
    let b2 = (b - a).cross(p - a).dot(n) / n2;
    let b0 = 1.0 - b1 - b2;
    let plane = (p - a).dot(n) / n2.sqrt();
    let tol = 1e-5;
    if b0 < -tol || b1 < -tol || b2 < -tol || plane.abs() > 1e-5 {
        return None;
    }
    Some(if b0 > 0.5 {
        0
    } else if b1 > 0.5 {
        1
    } else if b2 > 0.5 {
        2
    } else {
        3
    })
}

fn tri_area(t: &[Vec3; 3]) -> f64 {
    let [a, b, c] = t.map(|v| v.as_dvec3());
    0.5 * (b - a).cross(c - a).length()
}

fn tri_normal(t: &[Vec3; 3]) -> Vec3 {
    (t[1] - t[0]).cross(t[2] - t[0]).normalize()
}

#[test]
fn sample_le_matches_its_distributions() {
    let level = case_alpha();
    let radiance = Rgb::new(2.0, 1.0, 0.5);
    let mut results: Vec<(&str, f64, usize)> = Vec::new();

    // Pyramid: triangle by area × quarter × cosine direction (4 × 4 bins).
    let pyr = pyramid();
    let light = area_light(mesh_shape(&pyr), radiance);
    let total: f64 = pyr.iter().map(tri_area).sum();
    let mut expect = Vec::new();
    for t in &pyr {
        expect.extend(std::iter::repeat_n(tri_area(t) / total / 64.0, 64));
    }
    let bin = |s: &EmissionSample| {
        let t = s.primitive as usize;
        let q = triangle_quarter(&pyr[t], s.origin)?;
        let d = cosine_bin(tri_normal(&pyr[t]), s.direction, 4, 4)?;
        Some(t * 64 + q * 16 + d)
    };
    let check = |s: &EmissionSample| {
        let n = tri_normal(&pyr[s.primitive as usize]);
        let cos = n.dot(s.direction) as f64;
        s.n.dot(n) > 0.99999
            && s.radiance == radiance
            && (s.pdf_pos as f64 - 1.0 / total).abs() < 1e-5 / total
            && (s.pdf_dir as f64 - cos / PI).abs() < 1e-4 * cos / PI
            && !s.delta_pos
            && !s.delta_dir
    };
    let (p, bad) = run_le_case(&light, 2001, &expect, &bin, &check);
    results.push(("pyramid", p, bad));

    // Sphere: uniform over its surface (8 × 8) × cosine about the outward normal (4 × 4).
    let c = Vec3::new(0.5, -0.25, 1.0);
    let light = area_light(sphere_shape("s", c, 0.7, false), radiance);
    let expect = vec![1.0 / 1024.0; 1024];
    let bin = |s: &EmissionSample| {
        let out = (s.origin - c).normalize();
        if ((s.origin - c).length() - 0.7).abs() > 1e-5 {
            return None;
        }
        Some(sphere_bin(out, 8, 8) * 16 + cosine_bin(out, s.direction, 4, 4)?)
    };
    let area = 4.0 * PI * 0.49;
    let check = |s: &EmissionSample| {
        (s.pdf_pos as f64 - 1.0 / area).abs() < 1e-5 / area && s.radiance == radiance
    };
    let (p, bad) = run_le_case(&light, 2002, &expect, &bin, &check);
    results.push(("sphere", p, bad));

    // Elliptic disk: uniform in local coordinates (rings × sectors) × cosine.
    let t = disk_transform();
    let light = area_light(
        shape_desc("d", ShapeGeometry::Disk { to_world: t }, false),
        radiance,
    );
    let TestShape::Disk { inv, n, .. } = TestShape::disk(&t, false) else {
        unreachable!()
    };
    let expect = vec![1.0 / 512.0; 512];
    let bin = |s: &EmissionSample| {
        let l = inv.as_dmat4().transform_point3(s.origin.as_dvec3());
        if l.z.abs() > 1e-5 {
            return None;
        }
        Some(disk_bin(l.x, l.y, 4, 8)? * 16 + cosine_bin(n, s.direction, 4, 4)?)
    };
    let area = PI * 1.5 * 0.6;
    let check = |s: &EmissionSample| {
        (s.pdf_pos as f64 - 1.0 / area).abs() < 1e-5 / area && s.n.dot(n) > 0.99999
    };
    let (p, bad) = run_le_case(&light, 2003, &expect, &bin, &check);
    results.push(("disk", p, bad));

    // Point: uniform directions from the position.
    let pos = Vec3::new(1.0, 2.0, 3.0);
    let intensity = Rgb::new(5.0, 4.0, 3.0);
    let point = Light::Point(PointLight::new(pos, intensity));
    let expect = vec![1.0 / 256.0; 256];
    let bin = |s: &EmissionSample| Some(sphere_bin(s.direction, 16, 16));
    let check = |s: &EmissionSample| {
        s.origin == pos
            && s.radiance == intensity
            && s.delta_pos
            && s.pdf_pos == 1.0
            && (s.pdf_dir as f64 - 0.25 / PI).abs() < 1e-6
    };
    let (p, bad) = run_le_case(&point, 2004, &expect, &bin, &check);
    results.push(("point", p, bad));

    // Spot: uniform in the cutoff cone, carrying I·f(θ).
    let to_world = Transform::new(
        Mat4::from_translation(pos)
            * Mat4::from_quat(Quat::from_axis_angle(
                Vec3::new(0.2, 1.0, -0.3).normalize(),
                1.1,
            )),
    )
    .unwrap();
    let axis = to_world.vector(Vec3::Z).normalize();
    let spot = Light::Spot(SpotLight::new(&to_world, intensity, 30.0, 20.0).unwrap());
    let cos_c = 30f64.to_radians().cos();
    let expect = vec![1.0 / 256.0; 256];
    let frame = Frame::from_normal(axis);
    let bin = |s: &EmissionSample| {
        let l = frame.to_local(s.direction).as_dvec3();
        if l.z < cos_c - 1e-6 {
            return None;
        }
        let i = (((1.0 - l.z) / (1.0 - cos_c) * 16.0) as usize).min(15);
        let mut phi = l.y.atan2(l.x) / (2.0 * PI);
        if phi < 0.0 {
            phi += 1.0;
        }
        Some(i * 16 + ((phi * 16.0) as usize).min(15))
    };
    let check = |s: &EmissionSample| {
        let theta = (s.direction.dot(axis) as f64)
            .clamp(-1.0, 1.0)
            .acos()
            .to_degrees();
        let f = if theta <= 20.0 {
            1.0
        } else {
            ((30.0 - theta) / 10.0).max(0.0)
        };
        let ok = (0..3).all(|k| (s.radiance[k] as f64 - intensity[k] as f64 * f).abs() < 2e-3);
        ok && s.origin == pos
            && s.delta_pos
            && (s.pdf_dir as f64 - 1.0 / (2.0 * PI * (1.0 - cos_c))).abs() < 1e-3
    };
    let (p, bad) = run_le_case(&spot, 2005, &expect, &bin, &check);
    results.push(("spot", p, bad));

    // Directional: uniform on the disk of radius R, R before the centre.
    let sphere = SceneSphere {
        center: Vec3::new(1.0, -2.0, 0.5),
        radius: 3.0,
    };
    let dir = Vec3::new(0.3, -1.0, 0.2).normalize();
    let irr = Rgb::new(1.0, 2.0, 3.0);
    let directional = Light::Directional(DirectionalLight::new(dir, irr, sphere).unwrap());
    let f = Frame::from_normal(dir);
    let disk_of = move |o: Vec3| -> Option<(f64, f64)> {
        let q = (o - sphere.center).as_dvec3() / sphere.radius as f64;
        let along = q.dot(dir.as_dvec3());
        if (along + 1.0).abs() > 1e-5 {
            return None;
        }
        Some((q.dot(f.s.as_dvec3()), q.dot(f.t.as_dvec3())))
    };
    let expect = vec![1.0 / 128.0; 128];
    let bin = |s: &EmissionSample| {
        let (x, y) = disk_of(s.origin)?;
        disk_bin(x, y, 8, 16)
    };
    let disk_pdf = 1.0 / (PI * 9.0);
    let check = |s: &EmissionSample| {
        s.direction == dir
            && s.radiance == irr
            && s.delta_dir
            && (s.pdf_pos as f64 - disk_pdf).abs() < 1e-6 * disk_pdf
    };
    let (p, bad) = run_le_case(&directional, 2006, &expect, &bin, &check);
    results.push(("directional", p, bad));

    // Constant: uniform directions × uniform disk perpendicular to each.
    let l = Rgb::new(0.5, 0.25, 1.0);
    let constant = Light::Constant(ConstantLight::new(l, sphere));
    let expect = vec![1.0 / 1024.0; 1024];
    let bin = |s: &EmissionSample| {
        let f = Frame::from_normal(s.direction);
        let q = (s.origin - sphere.center).as_dvec3() / sphere.radius as f64;
        if (q.dot(s.direction.as_dvec3()) + 1.0).abs() > 1e-5 {
            return None;
        }
        let pos = disk_bin(q.dot(f.s.as_dvec3()), q.dot(f.t.as_dvec3()), 4, 4)?;
        Some(sphere_bin(s.direction, 8, 8) * 16 + pos)
    };
    let check = |s: &EmissionSample| {
        s.radiance == l
            && (s.pdf_dir as f64 - 0.25 / PI).abs() < 1e-6
            && (s.pdf_pos as f64 - disk_pdf).abs() < 1e-6 * disk_pdf
    };
    let (p, bad) = run_le_case(&constant, 2007, &expect, &bin, &check);
    results.push(("constant", p, bad));

    let mut failures = Vec::new();
    for (name, p, bad) in &results {
        println!("{name:12} p = {p:.4}  inconsistent = {bad}");
        if *p < level || *bad > 0 {
            failures.push(*name);
        }
    }
    assert_eq!(results.len(), 7);
    assert!(failures.is_empty(), "failed: {failures:?}");
}

// ---------------------------------------------------------------------------------------
// 3. The 2D distribution and the environment map
// ---------------------------------------------------------------------------------------

#[test]
fn distribution_2d_matches_its_image() {
    // A 4 × 3 image of weights with a zero cell and a zero row.
    let (nu, nv) = (4, 3);
    let w = [
        1.0, 2.0, 0.0, 4.0, //
        0.0, 0.0, 0.0, 0.0, //
        3.0, 0.5, 7.0, 1.5, //
    ];
    let sum: f64 = w.iter().map(|&x| x as f64).sum();
    let d = Distribution2D::new(&w, nu, nv).unwrap();
    // Bins: each cell cut into 2 × 2, expected N · w/Σw / 4.
    let expected: Vec<f64> = (0..nu * nv * 4)
        .map(|b| w[b / 4] as f64 / sum / 4.0 * N as f64)
        .collect();
    let mut observed = vec![0.0; expected.len()];
    let mut sampler = IndependentSampler::new(3001);
    let mut bad = 0;
    for _ in 0..N {
        let (p, pdf, [iu, iv]) = d.sample(sampler.next_2d());
        let (x, y) = (p.x as f64 * nu as f64, p.y as f64 * nv as f64);
        let (cu, cv) = (x as usize, y as usize);
        let sub = (((x - cu as f64) * 2.0) as usize) + 2 * (((y - cv as f64) * 2.0) as usize);
        observed[(cv * nu + cu) * 4 + sub] += 1.0;
        // The density of a cell is nu·nv·w/Σw, and pdf() agrees with sample().
        let expect = (nu * nv) as f64 * w[cv * nu + cu] as f64 / sum;
        if (cu, cv) != (iu, iv)
            || (pdf as f64 - expect).abs() > 1e-5 * expect
            || (d.pdf(p) as f64 - expect).abs() > 1e-5 * expect
        {
            bad += 1;
        }
    }
    let p = chi2_p_value(&expected, &observed);
    println!("2D distribution: p = {p:.4}, inconsistent = {bad}");
    assert!(p >= case_alpha(), "p = {p}");
    assert_eq!(bad, 0);
}

/// The 8 × 5 test map: varied colours, black texels around the nadir, one bright texel.
fn test_texels() -> (usize, usize, Vec<Rgb>) {
    let (w, h) = (8, 5);
    let mut t = Vec::new();
    for j in 0..h {
        for i in 0..w {
            let v = if j == 4 && i < 5 {
                Rgb::BLACK
            } else if (i, j) == (5, 2) {
                Rgb::new(40.0, 30.0, 20.0)
            } else {
                Rgb::new(1.0 + i as f32, 0.5 + j as f32, ((i * j) % 3) as f32)
            };
            t.push(v);
        }
    }
    (w, h, t)
}

fn lum(c: Rgb) -> f64 {
    0.2126 * c[0] as f64 + 0.7152 * c[1] as f64 + 0.0722 * c[2] as f64
}

fn rotation() -> Transform {
    Transform::new(Mat4::from_quat(Quat::from_axis_angle(
        Vec3::new(0.3, 1.0, 0.5).normalize(),
        0.8,
    )))
    .unwrap()
}

fn test_envmap(to_world: &Transform, scale: f32) -> EnvmapLight {
    let (w, h, t) = test_texels();
    EnvmapLight::from_texels(
        &PathBuf::from("test.exr"),
        w,
        h,
        &t,
        scale,
        to_world,
        SceneSphere {
            center: Vec3::ZERO,
            radius: 2.0,
        },
    )
    .unwrap()
}

/// cos θ_j of texel row j of a lat-long map of `h` rows: θ_j = π j/(h − 1).
fn envmap_cos_row(j: usize, h: usize) -> f64 {
    (PI * j as f64 / (h - 1) as f64).cos()
}

/// The unnormalised sampling weight of envmap cell (i, j) of `t` (`w` × `h` texels): the cell
/// spans texel columns i..i+1 (wrapping) and rows j..j+1, and its probability is ∝ mean
/// corner luminance × (cos θ_j − cos θ_{j+1}).
fn envmap_cell_weight(t: &[Rgb], w: usize, h: usize, i: usize, j: usize) -> f64 {
    let i1 = (i + 1) % w;
    let corners = [
        t[j * w + i],
        t[j * w + i1],
        t[(j + 1) * w + i],
        t[(j + 1) * w + i1],
    ];
    corners.iter().map(|&c| lum(c)).sum::<f64>() / 4.0
        * (envmap_cos_row(j, h) - envmap_cos_row(j + 1, h))
}

/// The radiance a sample carries and `le` of its direction agree to 10⁻³ of the larger:
/// the sample reads the map at its own texel coordinates, `le` recovers them from the
/// direction (a rotation there and back, then atan2 and acos, whose rounding grows as
/// 1/sin θ near the poles: 2·10⁻⁴ seen on this map's steep texels). A sample read from the
/// wrong texel or with the wrong weights inside its cell is off by a share of the
/// neighbouring texels' difference, far more.
fn close_rgb(a: Rgb, b: Rgb) -> bool {
    let scale = a.max_component().max(b.max_component());
    a.0.iter()
        .zip(b.0)
        .all(|(x, y)| (x - y).abs() <= 1e-3 * scale)
}

#[test]
fn envmap_sampling_matches_luminance_times_solid_angle() {
    let (w, h, t) = test_texels();
    let rot = rotation();
    let env = Light::Envmap(Box::new(test_envmap(&rot, 1.5)));
    let rows = h - 1;
    let cos_row = |j: usize| envmap_cos_row(j, h);
    let mut weight = vec![0.0; w * rows];
    for j in 0..rows {
        for i in 0..w {
            weight[j * w + i] = envmap_cell_weight(&t, w, h, i, j);
        }
    }
    let total: f64 = weight.iter().sum();
    // Bins: each cell split into 2 × 2 (halves in φ and in cos θ: equal solid angle).
    let expected: Vec<f64> = (0..w * rows * 4)
        .map(|b| weight[b / 4] / total / 4.0 * N as f64)
        .collect();
    let bin = |wi: Vec3| {
        let d = rot.inverse().vector(wi).as_dvec3().normalize();
        let u = d.x.atan2(-d.z) / (2.0 * PI);
        let x = (u * w as f64 - 0.5).rem_euclid(w as f64);
        let i = (x as usize).min(w - 1);
        let theta_v = d.y.clamp(-1.0, 1.0).acos() / PI * rows as f64;
        let j = (theta_v as usize).min(rows - 1);
        let half_cos = 0.5 * (cos_row(j) + cos_row(j + 1));
        let sub = usize::from(x - i as f64 >= 0.5) + 2 * usize::from(d.y < half_cos);
        (j * w + i) * 4 + sub
    };
    let mut observed = vec![0.0; expected.len()];
    let mut sampler = IndependentSampler::new(3002);
    let mut bad = 0;
    for _ in 0..N {
        let Some(s) = env.sample_li(Vec3::new(0.1, 0.2, 0.3), sampler.next_2d()) else {
            bad += 1;
            continue;
        };
        let b = bin(s.wi);
        observed[b] += 1.0;
        // Density = P(cell) / Ω(cell), Ω = (2π/W)(cos θ_j − cos θ_{j+1}).
        let (cell, j) = (b / 4, b / 4 / w);
        let expect = weight[cell] / total / (2.0 * PI / w as f64 * (cos_row(j) - cos_row(j + 1)));
        let back = env.pdf_li(Vec3::ZERO, &LightPoint::direction(s.wi)) as f64;
        if (s.pdf_solid_angle as f64 - expect).abs() > 1e-3 * expect
            || (back - expect).abs() > 1e-3 * expect
            || s.dist != f32::INFINITY
            || !close_rgb(s.radiance, env.le(&LightPoint::direction(s.wi), Vec3::ZERO))
        {
            bad += 1;
        }
        // Emission uses the same directions, travelling the other way.
        let e = env.sample_le(sampler.next_2d(), sampler.next_2d()).unwrap();
        let (pp, pd) = env.pdf_le(e.origin, e.n, e.direction);
        if (pd - e.pdf_dir).abs() > 1e-4 * pd
            || (pp - 1.0 / (4.0 * std::f32::consts::PI)).abs() > 1e-6
        {
            bad += 1;
        }
    }
    let p = chi2_p_value(&expected, &observed);
    println!("envmap: p = {p:.4}, inconsistent = {bad}");
    assert!(p >= case_alpha(), "p = {p}");
    assert_eq!(bad, 0);
}

#[test]
fn envmap_pdf_integrates_to_one() {
    let env = Light::Envmap(Box::new(test_envmap(&rotation(), 1.0)));
    let grid = Grid {
        frame: Frame::from_normal(Vec3::Z),
        param: Param::Sphere,
        na: 400,
        nb: 400,
    };
    let cells = grid.integrate(
        &|w| env.pdf_li(Vec3::ZERO, &LightPoint::direction(w)) as f64,
        2,
    );
    let total: f64 = cells.iter().sum();
    assert!((total - 1.0).abs() < 2e-3, "∫ pdf dω = {total}");
}

#[test]
fn envmap_lookup_follows_mitsuba_mapping() {
    let (w, _, t) = test_texels();
    let texel = |i: usize, j: usize| t[j * w + i];
    let mix = |a: Rgb, b: Rgb| (a + b) * 0.5;
    let close = |a: Rgb, b: Rgb| (0..3).all(|k| (a[k] - b[k]).abs() <= 1e-5 * (1.0 + b[k].abs()));
    for (to_world, name) in [(Transform::IDENTITY, "identity"), (rotation(), "rotated")] {
        let env = test_envmap(&to_world, 2.0);
        let look = |d: Vec3| env.le(to_world.vector(d));
        // Texel (i, j) sits at φ = 2π(i + ½)/W, θ = π j/(H − 1), with d = (sin φ sin θ,
        // cos θ, −cos φ sin θ): its value exactly (× scale 2). At the poles φ is undefined
        // (so is the column Mitsuba reads): rows 0 and H − 1 are checked 0.01 rad away, where
        // the next row weighs 0.01 · 4/π (to 10⁻³: f32 cos θ limits the precision there).
        let at = |i: usize, theta: f64| {
            let phi = 2.0 * PI * (i as f64 + 0.5) / 8.0;
            DVec3::new(
                phi.sin() * theta.sin(),
                theta.cos(),
                -phi.cos() * theta.sin(),
            )
            .as_vec3()
        };
        for i in 0..8 {
            for j in 1..4 {
                let got = look(at(i, PI * j as f64 / 4.0));
                assert!(
                    close(got, texel(i, j) * 2.0),
                    "{name} texel ({i}, {j}): {got:?}"
                );
            }
            let eps = 1e-2;
            let w = eps * 4.0 / PI;
            let near = |a: Rgb, b: Rgb| (0..3).all(|k| (a[k] - b[k]).abs() <= 1e-3 * (1.0 + b[k]));
            let top = (texel(i, 0) * (1.0 - w as f32) + texel(i, 1) * w as f32) * 2.0;
            assert!(near(look(at(i, eps)), top), "{name} zenith, column {i}");
            let bottom = (texel(i, 4) * (1.0 - w as f32) + texel(i, 3) * w as f32) * 2.0;
            assert!(
                near(look(at(i, PI - eps)), bottom),
                "{name} nadir, column {i}"
            );
        }
        // −z: u = atan2(0, 1)/2π = 0, so x = −½ → halfway between the last and the first
        // column; v = ½ → row 2 exactly.
        assert!(
            close(look(-Vec3::Z), mix(texel(7, 2), texel(0, 2)) * 2.0),
            "{name} −z"
        );
        // +x: u = ¼, x = 8/4 − ½ = 1.5 → columns 1 and 2 of row 2.
        assert!(
            close(look(Vec3::X), mix(texel(1, 2), texel(2, 2)) * 2.0),
            "{name} +x"
        );
        // +z: u = ½, x = 3.5 → columns 3 and 4.
        assert!(
            close(look(Vec3::Z), mix(texel(3, 2), texel(4, 2)) * 2.0),
            "{name} +z"
        );
        // −x: u = −¼ ≡ ¾, x = 5.5 → columns 5 and 6 (5 is the bright texel).
        assert!(
            close(look(-Vec3::X), mix(texel(5, 2), texel(6, 2)) * 2.0),
            "{name} −x"
        );
        // Halfway between rows 1 and 2 (θ = 3π/8) at column 0's centre: the mean.
        let got = look(at(0, 3.0 * PI / 8.0));
        assert!(close(got, mix(texel(0, 1), texel(0, 2)) * 2.0), "{name}");
    }
}

/// Radiance of the test map (scale 1.5) in ten directions, identity and `rotation()`
/// orientation, as evaluated by Mitsuba 3.9.1 itself (scalar_rgb; `envmap` from the same
/// texels via `mi.Bitmap`, `to_world` the rotation by 0.8 rad about the unit axis along
/// (0.3, 1, 0.5), `eval` with si.wi = −d). Mitsuba's Python `rotate` does not normalise
/// its axis, hence the explicit division:
///
/// ```text
/// import mitsuba as mi, math; mi.set_variant('scalar_rgb')
/// e = mi.load_dict({'type': 'envmap', 'bitmap': mi.Bitmap(texels), 'scale': 1.5,
///     'to_world': mi.ScalarTransform4f().rotate(
///         mi.ScalarVector3f(0.3, 1, 0.5) / math.sqrt(1.34), math.degrees(0.8))})
/// si = mi.SurfaceInteraction3f(); si.wi = -d; e.eval(si)
/// ```
const MITSUBA_ENVMAP: [(bool, [f32; 3], [f32; 3]); 20] = [
    (false, [0.3, 0.4, -0.5], [1.7821258, 2.6016698, 0.34826922]),
    (false, [-0.7, 0.1, 0.2], [45.217003, 32.60574, 21.621067]),
    (false, [0.05, -0.9, 0.3], [2.669885, 2.1783667, 0.0]),
    (false, [0.6, 0.6, 0.6], [5.2499986, 2.5745203, 1.3377424]),
    (
        false,
        [-0.2, 0.95, -0.1],
        [10.635502, 1.1914983, 0.03988249],
    ),
    (false, [0.0, 0.0, -1.0], [6.75, 3.75, 1.5]),
    (false, [1.0, 0.0, 0.0], [3.75, 3.75, 2.25]),
    (false, [0.1, -0.2, 0.97], [6.5538006, 4.1363516, 0.8223183]),
    (
        false,
        [-0.5, -0.5, -0.1],
        [10.285316, 5.359326, 0.093128026],
    ),
    (false, [0.9, -0.1, -0.4], [2.951251, 3.943255, 2.5285542]),
    (true, [0.3, 0.4, -0.5], [3.1618388, 3.349785, 2.5243068]),
    (true, [-0.7, 0.1, 0.2], [10.696281, 2.8852148, 0.2794027]),
    (true, [0.05, -0.9, 0.3], [8.297258, 5.2118154, 0.36898366]),
    (true, [0.6, 0.6, 0.6], [6.0538373, 2.6011624, 0.06644106]),
    (true, [-0.2, 0.95, -0.1], [2.2460375, 1.5315661, 0.38871837]),
    (true, [0.0, 0.0, -1.0], [2.0122733, 4.330077, 0.6283357]),
    (true, [1.0, 0.0, 0.0], [5.1616926, 4.21672, 0.5774709]),
    (true, [0.1, -0.2, 0.97], [20.82814, 14.031294, 9.719732]),
    (true, [-0.5, -0.5, -0.1], [10.976881, 4.791597, 0.29147166]),
    (true, [0.9, -0.1, -0.4], [4.392155, 4.6075015, 0.68869156]),
];

#[test]
fn envmap_matches_mitsuba_reference_values() {
    let plain = test_envmap(&Transform::IDENTITY, 1.5);
    let rotated = test_envmap(&rotation(), 1.5);
    for (rot, d, expect) in MITSUBA_ENVMAP {
        let env = if rot { &rotated } else { &plain };
        let got = env.le(Vec3::from_array(d).normalize());
        for k in 0..3 {
            // f32 angles: agreement to ~1e-5 relative where the map is smooth.
            assert!(
                (got[k] - expect[k]).abs() <= 2e-4 * (1.0 + expect[k]),
                "{d:?} (rotated {rot}): {got:?} vs Mitsuba {expect:?}"
            );
        }
    }
}

fn scratch(test: &str) -> ScratchDir {
    ScratchDir::new(&format!("lights-{test}"))
}

fn envmap_scene(path: PathBuf) -> SceneDescription {
    scene_of(
        vec![sphere_shape("ball", Vec3::ZERO, 1.0, false)],
        vec![EmitterDesc::Envmap {
            filename: path,
            scale: 1.0,
            to_world: Transform::IDENTITY,
        }],
    )
}

#[test]
fn envmap_files_are_read_and_checked() {
    let dir = scratch("envmap_files");
    let (w, h, t) = test_texels();
    let good = dir.join("good.exr");
    write_exr(
        &good,
        &Image {
            width: w as u32,
            height: h as u32,
            pixels: t.clone(),
        },
    )
    .unwrap();
    let mut scene = envmap_scene(good.clone());
    scene.shapes[0].emitter = None;
    let set = LightSet::build(&scene).unwrap();
    assert_eq!(set.environment(), &[0]);
    let from_file = set.get(0);
    let in_memory = test_envmap(&Transform::IDENTITY, 1.0);
    for d in [Vec3::X, Vec3::new(0.3, 0.4, -0.5), -Vec3::Y] {
        let a = from_file.le(&LightPoint::direction(d.normalize()), Vec3::ZERO);
        assert_eq!(a, in_memory.le(d.normalize()));
    }

    for (name, bad, what) in [
        ("nan.exr", Rgb::new(f32::NAN, 0.0, 0.0), "texel (3, 1)"),
        ("negative.exr", Rgb::new(0.0, -1.0, 0.0), "texel (3, 1)"),
        ("inf.exr", Rgb::new(0.0, 0.0, f32::INFINITY), "texel (3, 1)"),
    ] {
        let mut pixels = t.clone();
        pixels[w + 3] = bad;
        let path = dir.join(name);
        write_exr(
            &path,
            &Image {
                width: w as u32,
                height: h as u32,
                pixels,
            },
        )
        .unwrap();
        let err = LightSet::build(&envmap_scene(path.clone()))
            .unwrap_err()
            .to_string();
        assert!(err.contains(&path.display().to_string()), "{err}");
        assert!(err.contains(what), "{err}");
    }
    let small = dir.join("small.exr");
    write_exr(&small, &Image::new(2, 2)).unwrap();
    let err = LightSet::build(&envmap_scene(small.clone()))
        .unwrap_err()
        .to_string();
    assert!(
        err.contains(&small.display().to_string()) && err.contains("2×3"),
        "{err}"
    );
    let missing = dir.join("missing.exr");
    let err = LightSet::build(&envmap_scene(missing.clone()))
        .unwrap_err()
        .to_string();
    assert!(err.contains(&missing.display().to_string()), "{err}");
}

/// Texels near f32's limit: a texel whose product with `scale` overflows is an error
/// naming it; a finite texel of 3·10³⁸ is sampled by its true share (its cells' four-corner
/// sums overflow f32), every other cell stays drawable, and the power stays finite.
#[test]
fn envmap_texels_near_the_f32_limit() {
    let (w, h, mut t) = test_texels();
    let sphere = SceneSphere {
        center: Vec3::ZERO,
        radius: 2.0,
    };
    let build = |t: &[Rgb], scale: f32| {
        EnvmapLight::from_texels(
            &PathBuf::from("hot.exr"),
            w,
            h,
            t,
            scale,
            &Transform::IDENTITY,
            sphere,
        )
    };
    t[2 * w + 5] = Rgb::splat(1e30);
    let err = build(&t, 1e10).unwrap_err().to_string();
    assert!(
        err.contains("hot.exr") && err.contains("texel (5, 2)") && err.contains("scale"),
        "{err}"
    );
    assert!(build(&t, 1e8).is_ok());

    t[2 * w + 5] = Rgb::splat(3e38);
    let env = build(&t, 1.0).unwrap();
    assert!(env.power().is_finite() && env.power() > 0.0);
    let rows = h - 1;
    let cos_row = |j: usize| envmap_cos_row(j, h);
    let weight = |i: usize, j: usize| envmap_cell_weight(&t, w, h, i, j);
    let total: f64 = (0..rows)
        .flat_map(|j| (0..w).map(move |i| (i, j)))
        .map(|(i, j)| weight(i, j))
        .sum();
    for j in 0..rows {
        for i in 0..w {
            // The centre of cell (i, j), in the map's frame (identity here).
            let phi = 2.0 * PI * (i as f64 + 1.0) / w as f64;
            let cos = 0.5 * (cos_row(j) + cos_row(j + 1));
            let sin = (1.0 - cos * cos).sqrt();
            let d = Vec3::new(
                (phi.sin() * sin) as f32,
                cos as f32,
                (-phi.cos() * sin) as f32,
            );
            let solid_angle = 2.0 * PI / w as f64 * (cos_row(j) - cos_row(j + 1));
            let expect = weight(i, j) / total / solid_angle;
            let pdf = env.pdf_direction(d) as f64;
            if weight(i, j) > 0.0 {
                assert!(pdf > 0.0, "cell ({i}, {j}) cannot be drawn");
            }
            if expect > 1e-30 {
                assert!(
                    (pdf - expect).abs() <= 1e-4 * expect,
                    "cell ({i}, {j}): pdf {pdf}, expected {expect}"
                );
            }
        }
    }
    let s = env.sample_li(Vec2::new(0.5, 0.5)).expect("a sample");
    assert!(s.pdf_solid_angle.is_finite() && s.radiance.is_valid_radiance());
}

/// A black map is no light: nothing sampled, zero density and power.
#[test]
fn black_envmap_is_harmless() {
    let env = test_envmap(&Transform::IDENTITY, 0.0);
    assert_eq!(env.power(), 0.0);
    assert!(env.sample_li(Vec2::new(0.3, 0.7)).is_none());
    assert!(env.sample_le(Vec2::splat(0.5), Vec2::splat(0.5)).is_none());
    assert_eq!(env.pdf_direction(Vec3::Y), 0.0);
}

// ---------------------------------------------------------------------------------------
// 4. Closed forms
// ---------------------------------------------------------------------------------------

/// Mean and standard error of the Monte Carlo irradiance estimate E ≈ Σ L·cos⁺/pdf at x.
fn irradiance_estimate(light: &Light, x: Vec3, normal: Vec3, seed: u64, n: usize) -> (f64, f64) {
    let mut sampler = IndependentSampler::new(seed);
    let (mut sum, mut sum2) = (0.0f64, 0.0f64);
    for _ in 0..n {
        let v = match light.sample_li(x, sampler.next_2d()) {
            Some(s) => {
                s.radiance[0] as f64 * (normal.dot(s.wi).max(0.0) as f64) / s.pdf_solid_angle as f64
            }
            None => 0.0,
        };
        sum += v;
        sum2 += v * v;
    }
    let mean = sum / n as f64;
    let var = (sum2 / n as f64 - mean * mean).max(0.0);
    (mean, (var / n as f64).sqrt())
}

/// Irradiance at x (normal n) from a uniform Lambertian polygon of radiance L, by Lambert's
/// formula: E = (L/2) |Σ_i Θ_i (n · Γ_i)|, Θ_i the angle the edge (v_i, v_{i+1}) subtends
/// at x and Γ_i the unit normal of the plane through x and that edge (Lambert 1760; Arvo,
/// "Applications of Irradiance Tensors…", SIGGRAPH 1995, eq. 3). The polygon must lie wholly
/// above x's tangent plane.
fn polygon_irradiance(l: f64, poly: &[Vec3], x: Vec3, n: Vec3) -> f64 {
    let x = x.as_dvec3();
    let n = n.as_dvec3();
    let mut sum = 0.0;
    for i in 0..poly.len() {
        let a = (poly[i].as_dvec3() - x).normalize();
        let b = (poly[(i + 1) % poly.len()].as_dvec3() - x).normalize();
        let theta = a.dot(b).clamp(-1.0, 1.0).acos();
        sum += theta * n.dot(a.cross(b).normalize());
    }
    0.5 * l * sum.abs()
}

#[test]
fn rectangle_irradiance_matches_lambert() {
    // The rectangle at height 1, facing down (normal −z): the corners in clockwise order
    // seen from above make the triangles' normals point down.
    let corners = [
        Vec3::new(-0.5, -1.0, 1.0),
        Vec3::new(-0.5, 1.0, 1.0),
        Vec3::new(0.5, 1.0, 1.0),
        Vec3::new(0.5, -1.0, 1.0),
    ];
    let tris = vec![
        [corners[0], corners[1], corners[2]],
        [corners[0], corners[2], corners[3]],
    ];
    assert!(tri_normal(&tris[0]).z < -0.999);
    let l = 3.0;
    let light = area_light(mesh_shape(&tris), Rgb::splat(l as f32));
    for (k, (x, n)) in [
        (Vec3::ZERO, Vec3::Z),
        (Vec3::new(1.5, 0.5, 0.0), Vec3::Z),
        (
            Vec3::new(0.3, -0.2, 0.4),
            Vec3::new(1.0, 0.5, 2.0).normalize(),
        ),
        (
            Vec3::new(-2.0, 3.0, -0.5),
            Vec3::new(0.5, -0.6, 1.0).normalize(),
        ),
    ]
    .into_iter()
    .enumerate()
    {
        assert!(corners.iter().all(|c| (*c - x).dot(n) > 0.0));
        let exact = polygon_irradiance(l, &corners, x, n);
        let (mean, se) = irradiance_estimate(&light, x, n, 4000 + k as u64, 200_000);
        println!("rectangle at {x}: E = {exact:.6}, estimate {mean:.6} ± {se:.6}");
        assert!(
            (mean - exact).abs() < 4.0 * se + 1e-9,
            "{mean} vs {exact} (σ {se})"
        );
    }
}

#[test]
fn sphere_irradiance_matches_closed_form() {
    let c = Vec3::new(0.2, 0.3, -0.1);
    let (radius, l) = (0.5f32, 2.0f64);
    let light = area_light(sphere_shape("s", c, radius, false), Rgb::splat(l as f32));
    for (k, (d, axis)) in [
        (2.0f32, Vec3::new(0.0, 0.0, 1.0)),
        (0.6, Vec3::new(1.0, -1.0, 0.3).normalize()),
        (25.0, Vec3::new(-0.2, 0.1, -1.0).normalize()),
    ]
    .into_iter()
    .enumerate()
    {
        let x = c + axis * d;
        // A receiver facing the centre sees the whole sphere above its horizon:
        // E = π L (r/d)² (e.g. Pharr et al., PBR 3rd ed., §12.5).
        let exact = PI * l * (radius as f64 / d as f64).powi(2);
        let (mean, se) = irradiance_estimate(&light, x, -axis, 5000 + k as u64, 200_000);
        println!("sphere at d = {d}: E = {exact:.6}, estimate {mean:.6} ± {se:.6}");
        assert!(
            (mean - exact).abs() < 4.0 * se + 1e-6 * exact,
            "{mean} vs {exact}"
        );
    }
}

#[test]
fn delta_lights_give_intensity_over_distance_squared() {
    let pos = Vec3::new(1.0, 2.0, 3.0);
    let i = Rgb::new(4.0, 8.0, 12.0);
    let point = Light::Point(PointLight::new(pos, i));
    let x = Vec3::new(1.0, 2.0, 1.0);
    let s = point.sample_li(x, Vec2::new(0.3, 0.9)).unwrap();
    assert!(s.delta && s.pdf_solid_angle == 1.0);
    assert_eq!(s.wi, Vec3::Z);
    assert_eq!(s.dist, 2.0);
    assert_eq!(s.radiance, i / 4.0);
    assert_eq!(point.pdf_li(x, &s.point()), 0.0);

    // Spot along −z from the origin, cutoff 30°, beam 20°: f = 1 within 20°, (30 − θ)/10
    // between, 0 beyond. (Mitsuba 3.9.1's `spot`, placed the same way, returns the same
    // I·f/d² at these points: (1, 2, 3) × 1, 1, 0.5, 0.2, 0.)
    let to_world =
        Transform::new(Mat4::from_quat(Quat::from_rotation_x(std::f32::consts::PI))).unwrap();
    let spot = Light::Spot(SpotLight::new(&to_world, i, 30.0, 20.0).unwrap());
    for (theta, f) in [(0.0f32, 1.0f32), (15.0, 1.0), (25.0, 0.5), (28.0, 0.2)] {
        let t = theta.to_radians();
        let x = Vec3::new(t.sin(), 0.0, -t.cos()) * 2.0;
        let s = spot.sample_li(x, Vec2::ZERO).unwrap();
        for k in 0..3 {
            assert!(
                (s.radiance[k] - i[k] * f / 4.0).abs() < 1e-4 * i[k],
                "θ = {theta}"
            );
        }
    }
    let t = 31f32.to_radians();
    assert!(
        spot.sample_li(Vec3::new(t.sin(), 0.0, -t.cos()), Vec2::ZERO)
            .is_none()
    );
    assert!(
        spot.sample_li(Vec3::new(0.0, 0.0, 1.0), Vec2::ZERO)
            .is_none()
    );

    let dir = Vec3::new(1.0, -1.0, 0.0).normalize();
    let sun = Light::Directional(
        DirectionalLight::new(
            dir,
            Rgb::splat(7.0),
            SceneSphere {
                center: Vec3::ZERO,
                radius: 1.0,
            },
        )
        .unwrap(),
    );
    let s = sun.sample_li(Vec3::new(5.0, 5.0, 5.0), Vec2::ZERO).unwrap();
    assert!((s.wi + dir).length() < 1e-6);
    assert!(s.dist.is_infinite() && s.delta);
    assert_eq!(s.radiance, Rgb::splat(7.0));
}

/// Spot power against a numerical integral of the falloff (Simpson's rule over θ).
#[test]
fn spot_power_matches_quadrature() {
    for (cutoff, beam) in [
        (20.0f64, 15.0f64),
        (30.0, 20.0),
        (45.0, 45.0),
        (120.0, 10.0),
        (5.0, 0.0),
    ] {
        let spot = SpotLight::new(
            &Transform::IDENTITY,
            Rgb::splat(2.0),
            cutoff as f32,
            beam as f32,
        )
        .unwrap();
        let (tc, tb) = (cutoff.to_radians(), beam.to_radians());
        let f = |t: f64| {
            if t <= tb {
                1.0
            } else if t < tc {
                (tc - t) / (tc - tb)
            } else {
                0.0
            }
        };
        let m = 20_000;
        let h = tc / m as f64;
        let mut s = 0.0;
        for k in 0..=m {
            let t = k as f64 * h;
            let wgt = if k == 0 || k == m {
                1.0
            } else if k % 2 == 1 {
                4.0
            } else {
                2.0
            };
            s += wgt * f(t) * t.sin();
        }
        let exact = 2.0 * PI * 2.0 * s * h / 3.0;
        let got = spot.power() as f64;
        assert!(
            (got - exact).abs() < 1e-4 * exact,
            "cutoff {cutoff}: {got} vs {exact}"
        );
    }
}

#[test]
fn selection_is_proportional_to_power() {
    let quad = rectangle();
    let c = Vec3::new(3.0, 0.0, 0.0);
    let disk = disk_transform();
    let mut shapes = vec![
        mesh_shape(&quad),
        sphere_shape("ball", c, 0.5, false),
        shape_desc("disk", ShapeGeometry::Disk { to_world: disk }, false),
        sphere_shape("not emitting", -c, 1.0, false),
    ];
    shapes[0].emitter = Some(0);
    shapes[1].emitter = Some(1);
    shapes[2].emitter = Some(2);
    shapes[3].emitter = None;
    let spot_world = Transform::new(Mat4::from_translation(Vec3::Y)).unwrap();
    let emitters = vec![
        EmitterDesc::Area {
            radiance: Rgb::new(1.0, 2.0, 3.0),
            shape: 0,
        },
        EmitterDesc::Area {
            radiance: Rgb::splat(4.0),
            shape: 1,
        },
        EmitterDesc::Area {
            radiance: Rgb::splat(0.5),
            shape: 2,
        },
        EmitterDesc::Point {
            intensity: Rgb::splat(3.0),
            position: Vec3::Z,
        },
        EmitterDesc::Spot {
            intensity: Rgb::splat(6.0),
            to_world: spot_world,
            cutoff_angle: 40.0,
            beam_width: 40.0,
        },
        EmitterDesc::Directional {
            irradiance: Rgb::splat(0.25),
            direction: -Vec3::Z,
        },
        EmitterDesc::Constant {
            radiance: Rgb::new(0.1, 0.2, 0.3),
        },
    ];
    let scene = scene_of(shapes, emitters);
    let set = LightSet::build(&scene).unwrap();
    assert_eq!(set.len(), 7);
    assert_eq!(set.light_of_shape(0), Some(0));
    assert_eq!(set.light_of_shape(2), Some(2));
    assert_eq!(set.light_of_shape(3), None);
    assert_eq!(set.environment(), &[6]);
    // The scene's bounding sphere: the box of the rectangle, both spheres and the square
    // around the disk.
    let mut lo = Vec3::new(-4.0, -1.0, -1.0);
    let mut hi = Vec3::new(3.5, 1.0, 1.0);
    for (x, y) in [(-1.0, -1.0), (-1.0, 1.0), (1.0, -1.0), (1.0, 1.0)] {
        let p = disk.point(Vec3::new(x, y, 0.0));
        lo = lo.min(p);
        hi = hi.max(p);
    }
    let r = ((hi - lo).length() / 2.0) as f64;
    let sphere = set.sphere();
    assert!((sphere.radius as f64 - r).abs() < 1e-4 * r);
    assert!((sphere.center - (lo + hi) / 2.0).length() < 1e-5);
    let powers = [
        PI * 2.0 * 2.0,                                    // π · A · mean L, A = 2
        PI * (4.0 * PI * 0.25) * 4.0,                      // sphere of radius 0.5
        PI * (PI * 1.5 * 0.6) * 0.5,                       // ellipse 1.5 × 0.6
        4.0 * PI * 3.0,                                    // point: 4π I
        2.0 * PI * (1.0 - 40f64.to_radians().cos()) * 6.0, // spot, no transition
        PI * r * r * 0.25,                                 // directional: π R² E
        4.0 * PI * PI * r * r * 0.2,                       // constant: 4π² R² L
    ];
    let total: f64 = powers.iter().sum();
    for (k, p) in powers.iter().enumerate() {
        let got = set.get(k).power() as f64;
        assert!((got - p).abs() < 2e-4 * p, "light {k}: power {got} vs {p}");
        let pmf = set.pmf(k) as f64;
        assert!(
            (pmf - p / total).abs() < 2e-4 * p / total,
            "light {k}: pmf {pmf}"
        );
    }
    // Stratified draws land on each light in proportion to its probability (±1 draw).
    let m = 100_000;
    let mut counts = [0usize; 7];
    for k in 0..m {
        let (i, pmf, u) = set.sample((k as f32 + 0.5) / m as f32).unwrap();
        assert_eq!(pmf, set.pmf(i));
        assert!((0.0..1.0).contains(&u));
        counts[i] += 1;
    }
    for (k, &c) in counts.iter().enumerate() {
        let expect = set.pmf(k) as f64 * m as f64;
        assert!(
            (c as f64 - expect).abs() <= 2.0,
            "light {k}: {c} draws, expected {expect}"
        );
    }
}

// ---------------------------------------------------------------------------------------
// 5. Emitters without area
// ---------------------------------------------------------------------------------------

#[test]
fn emitters_without_area_are_errors_naming_the_shape() {
    let flat = mesh(
        &[
            Vec3::ZERO,
            Vec3::X,
            Vec3::X * 2.0,
            Vec3::new(1.0, f32::NAN, 0.0),
        ],
        &[[0, 1, 2], [0, 1, 3]],
    );
    for (geometry, name) in [
        (ShapeGeometry::Mesh(flat), "flat mesh"),
        (
            ShapeGeometry::Sphere {
                center: Vec3::ZERO,
                radius: 0.0,
            },
            "point sphere",
        ),
        (
            ShapeGeometry::Disk {
                to_world: Transform {
                    matrix: Mat4::from_scale(Vec3::new(1.0, 0.0, 1.0)),
                    inverse: Mat4::IDENTITY,
                },
            },
            "line disk",
        ),
    ] {
        let scene = scene_of(
            vec![shape_desc(name, geometry, false)],
            vec![EmitterDesc::Area {
                radiance: Rgb::splat(1.0),
                shape: 0,
            }],
        );
        let err = LightSet::build(&scene).unwrap_err().to_string();
        assert!(
            err.contains(name) && err.contains("lights-test.xml"),
            "{err}"
        );
    }
}

/// Degenerate reference points and directions (on the light, at a sphere's centre, far
/// away, not finite) never produce a NaN or infinite density or radiance.
#[test]
fn degenerate_queries_stay_finite() {
    let sphere = SceneSphere {
        center: Vec3::ZERO,
        radius: 2.0,
    };
    let spot_world = Transform::new(Mat4::from_translation(Vec3::Y)).unwrap();
    let c = Vec3::new(0.5, -0.25, 1.0);
    let lights = vec![
        area_light(mesh_shape(&rectangle()), Rgb::splat(1.0)),
        area_light(mesh_shape(&pyramid()), Rgb::splat(1.0)),
        area_light(sphere_shape("s", c, 1.0, false), Rgb::splat(1.0)),
        area_light(sphere_shape("s", c, 1.0, true), Rgb::splat(1.0)),
        area_light(
            shape_desc(
                "d",
                ShapeGeometry::Disk {
                    to_world: disk_transform(),
                },
                false,
            ),
            Rgb::splat(1.0),
        ),
        Light::Point(PointLight::new(Vec3::Z, Rgb::splat(1.0))),
        Light::Spot(SpotLight::new(&spot_world, Rgb::splat(1.0), 30.0, 30.0).unwrap()),
        Light::Directional(DirectionalLight::new(-Vec3::Z, Rgb::splat(1.0), sphere).unwrap()),
        Light::Constant(ConstantLight::new(Rgb::splat(1.0), sphere)),
        Light::Envmap(Box::new(test_envmap(&rotation(), 1.0))),
    ];
    let refs = [
        Vec3::ZERO,
        Vec3::Z,
        Vec3::Y,
        c,
        c + Vec3::X,
        Vec3::new(0.2, 0.3, 0.0),
        disk_transform().point(Vec3::ZERO),
        Vec3::splat(1e30),
        Vec3::splat(f32::NAN),
        Vec3::new(f32::INFINITY, 0.0, 0.0),
    ];
    let dirs = [Vec3::Z, -Vec3::Y, Vec3::ZERO, Vec3::splat(f32::NAN)];
    let mut sampler = IndependentSampler::new(9);
    for light in &lights {
        for &r in &refs {
            for _ in 0..200 {
                let u = sampler.next_2d();
                if let Some(s) = light.sample_li(r, u) {
                    assert!(s.radiance.is_valid_radiance(), "{light:?} {r} {s:?}");
                    assert!(s.pdf_solid_angle.is_finite() && s.pdf_solid_angle > 0.0);
                    assert!(s.pdf_area.is_finite() && s.wi.is_finite() && !s.dist.is_nan());
                    let back = light.pdf_li(r, &s.point());
                    assert!(back.is_finite() && back >= 0.0);
                }
                for &d in &dirs {
                    let hit = LightPoint {
                        p: r,
                        n: d,
                        front: d,
                        primitive: 0,
                    };
                    for q in [r, Vec3::ZERO] {
                        let pdf = light.pdf_li(q, &hit);
                        assert!(
                            pdf.is_finite() && pdf >= 0.0,
                            "{light:?} {q} {hit:?}: {pdf}"
                        );
                    }
                    assert!(light.le(&hit, d).is_valid_radiance());
                    let (pp, pd) = light.pdf_le(r, d, d);
                    assert!(pp.is_finite() && pd.is_finite() && pp >= 0.0 && pd >= 0.0);
                }
                if let Some(e) = light.sample_le(u, sampler.next_2d()) {
                    assert!(e.radiance.is_valid_radiance() && e.origin.is_finite());
                }
            }
        }
    }
}
