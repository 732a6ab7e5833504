//! The multiple-importance weights of `bdpt`, path by path (fixed seeds).
//!
//! * **Specular chains, by hand.** For paths light → glass → glass → floor → camera (a glass
//!   sphere under a ceiling light) and light-inside-glass → glass face → floor → camera (the
//!   chain starts inside glass), exactly two strategies can make the path: light tracing
//!   (t = 1) and the camera path hitting the light (s = 0). Their densities are derived here
//!   from the definition: each strategy samples one direction that the specular chain maps
//!   to the far endpoint, so its density there is the direction's density over the chain's
//!   Jacobian |dA/dω|, which the test measures by finite differences through its own
//!   intersection and Snell code. The weights `bdpt` gives must be the balance and power
//!   heuristics of those densities (within 1% of the smaller weight). Mapping a delta
//!   vertex's density 0 to 1 (the convention this replaced) gives light tracing a median
//!   weight of 0.16 on the first path, where these densities give 0.975; leaving the
//!   indices of refraction out of the delta densities gives light tracing 0.989 on a second
//!   path where they give 0.975, the light hit's weight less than half what it should be
//!   (both checked by mutation: the tests fail).
//! * **Every strategy, every path.** For thousands of paths `bdpt` makes in scenes with
//!   mirrors, glass, rough metal and glass, an area light, an environment map and a
//!   directional light, the test recomputes every vertex's densities from the geometry
//!   (its own code: BSDF densities, cosines, distances, the delta convention with its own
//!   Fresnel), and checks that the weight `bdpt` gave equals the balance heuristic of the
//!   densities so recomputed (a naive product per strategy, in f64), and that the weights of
//!   all strategies that can make the path sum to one.

use glam::{DVec3, Vec3};
use mltbench::estimator::Params;
use mltbench::estimator::bdpt::{self, BdptSettings, StrategyEvent};
use mltbench::material::Bsdf;
use mltbench::path::mis::{Heuristic, PathDensity, StrategyRules, strategy_weight};
use mltbench::path::vertex::{Vertex, VertexKind};
use mltbench::scene::Scene;

mod render_support;
use render_support::{scene, shipped_scene};

/// The complete path of a strategy event, light to camera.
fn full_path<'a>(e: &StrategyEvent<'_, 'a>) -> Vec<Vertex<'a>> {
    let mut light: Vec<Vertex<'a>> = e.light_path.to_vec();
    let mut camera: Vec<Vertex<'a>> = e.camera_path.to_vec();
    if let Some(sampled) = e.sampled {
        if sampled.light_side {
            light[0] = sampled.vertex.clone();
        } else {
            camera[0] = sampled.vertex.clone();
        }
    }
    camera.reverse();
    light.extend(camera);
    light
}

fn d(v: Vec3) -> DVec3 {
    v.as_dvec3()
}

/// Unpolarised Fresnel reflectance at an interface, `cos_i` > 0 on the incident side,
/// `eta` = η_t/η_i (Born & Wolf §1.5.2).
fn fresnel(cos_i: f64, eta: f64) -> f64 {
    let sin_t2 = (1.0 - cos_i * cos_i) / (eta * eta);
    if sin_t2 >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin_t2).sqrt();
    let rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    let rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    0.5 * (rs * rs + rp * rp)
}

/// Snell refraction of unit `w` (travelling towards the surface) at normal `n` (either
/// side), from index `n1` into `n2`; None under total internal reflection.
fn refract(w: DVec3, n: DVec3, n1: f64, n2: f64) -> Option<DVec3> {
    let n = if w.dot(n) > 0.0 { -n } else { n };
    let cos_i = -w.dot(n);
    let eta = n1 / n2;
    let k = 1.0 - eta * eta * (1.0 - cos_i * cos_i);
    (k >= 0.0).then(|| eta * w + (eta * cos_i - k.sqrt()) * n)
}

/// The unit vector from `a` to `b` (both may be at infinity: a direction).
fn dir(a: &Vertex, b: &Vertex) -> DVec3 {
    if b.is_infinite() {
        d(b.p)
    } else if a.is_infinite() {
        -d(a.p)
    } else {
        (d(b.p) - d(a.p)).normalize()
    }
}

/// The factor turning a density of the ray from `a` towards `b` into `b`'s measure: solid
/// angle at infinity, else area (× |cos θ_b| / d², or × |cos θ_b| for parallel rays from
/// infinity).
fn to_measure(a: &Vertex, b: &Vertex) -> f64 {
    if b.is_infinite() {
        return 1.0;
    }
    let w = dir(a, b);
    let cos_b = if b.ng == Vec3::ZERO {
        1.0
    } else {
        d(b.ng).dot(w).abs()
    };
    if a.is_infinite() {
        return cos_b;
    }
    cos_b / (d(b.p) - d(a.p)).length_squared()
}

/// The solid-angle density with which surface vertex `v`, reached from `from`, sends the
/// path towards `to`: its BSDF's, or, where the path crosses `v` through a delta component,
/// the delta convention: P · (η_to/η_from) · |cos θ_to| (shading frame), with P and η
/// from this test's own Fresnel.
fn scatter_density(v: &Vertex, from: &Vertex, to: &Vertex, delta: bool) -> f64 {
    let VertexKind::Surface { si, bsdf, frame } = &v.kind else {
        panic!("interior vertices are surfaces");
    };
    let (wf, wt) = (dir(v, from), dir(v, to));
    if !delta {
        let pdf = bsdf.pdf(frame.to_local(wf.as_vec3()), frame.to_local(wt.as_vec3()));
        return pdf as f64;
    }
    let ns = d(si.ns);
    let (cf, ct) = (ns.dot(wf), ns.dot(wt));
    let reflects = cf * ct > 0.0;
    let (p, eta_ratio) = match bsdf.as_ref() {
        Bsdf::Conductor(_) | Bsdf::Null(_) => (1.0, 1.0),
        Bsdf::Dielectric(g) => {
            // The normal points outside: η on wf's side and on wt's.
            let eta = g.eta as f64;
            let (eta_f, eta_t) = if cf > 0.0 { (1.0, eta) } else { (eta, 1.0) };
            let f = fresnel(cf.abs(), eta_t / eta_f);
            if reflects {
                (f, 1.0)
            } else {
                (1.0 - f, eta_t / eta_f)
            }
        }
        other => panic!("no delta convention in this test for {other:?}"),
    };
    p * eta_ratio * ct.abs()
}

/// A path's densities from either side (f64) and where connections may end.
struct Densities {
    from_light: Vec<f64>,
    from_camera: Vec<f64>,
    connectible: Vec<bool>,
}

impl Densities {
    /// As the weight code takes them.
    fn path_densities(&self) -> Vec<PathDensity> {
        (0..self.from_light.len())
            .map(|i| PathDensity {
                from_light: self.from_light[i] as f32,
                from_camera: self.from_camera[i] as f32,
                connectible: self.connectible[i],
            })
            .collect()
    }
}

/// Every vertex's densities from either side, recomputed from the path's geometry.
fn densities(scene: &Scene, path: &[Vertex], delta: &[bool]) -> Densities {
    let n = path.len();
    let lights = &scene.lights;
    let mut out = Densities {
        from_light: vec![0.0; n],
        from_camera: vec![0.0; n],
        connectible: vec![true; n],
    };
    // From the light side.
    for i in 0..n - 1 {
        out.from_light[i] = if i == 0 {
            let x0 = &path[0];
            match x0.kind {
                VertexKind::Infinite { light, delta: true } => lights.pmf(light.unwrap()) as f64,
                VertexKind::Infinite { .. } => {
                    let travel = -x0.p;
                    lights
                        .environment()
                        .iter()
                        .map(|&j| {
                            lights.pmf(j) as f64
                                * lights.get(j).pdf_le(Vec3::ZERO, travel, travel).1 as f64
                        })
                        .sum()
                }
                _ => {
                    let l = x0.light_index(scene).expect("x0 on a light");
                    let w = dir(x0, &path[1]).as_vec3();
                    (lights.pmf(l) * lights.get(l).pdf_le(x0.p, x0.ng, w).0) as f64
                }
            }
        } else if i == 1 {
            let (x0, x1) = (&path[0], &path[1]);
            let emitted = if x0.is_infinite() {
                lights.sphere().disk_pdf() as f64
            } else if x0.is_delta_light() {
                let l = x0.light_index(scene).unwrap();
                lights.get(l).pdf_le(x0.p, x0.ng, dir(x0, x1).as_vec3()).1 as f64
            } else {
                // Area lights emit cosine-weighted.
                d(x0.ng).dot(dir(x0, x1)).abs() / std::f64::consts::PI
            };
            emitted * to_measure(x0, x1)
        } else {
            scatter_density(&path[i - 1], &path[i - 2], &path[i], delta[i - 1])
                * to_measure(&path[i - 1], &path[i])
        };
    }
    // From the camera side.
    for i in (0..n - 1).rev() {
        out.from_camera[i] = if i == n - 2 {
            let cam = &path[n - 1];
            scene.camera.pdf_direction(dir(cam, &path[i]).as_vec3()) as f64
                * to_measure(cam, &path[i])
        } else {
            scatter_density(&path[i + 1], &path[i + 2], &path[i], delta[i + 1])
                * to_measure(&path[i + 1], &path[i])
        };
    }
    for i in 1..n - 1 {
        out.connectible[i] = match &path[i].kind {
            VertexKind::Surface { bsdf, .. } => !delta[i] && bsdf.has_non_delta(),
            _ => true,
        };
    }
    out
}

fn rules(path: &[Vertex], heuristic: Heuristic) -> StrategyRules {
    let x0 = &path[0];
    StrategyRules {
        heuristic,
        hide_emitters: false,
        light_hittable: !x0.is_delta_light(),
        light_seen_by_camera: matches!(
            x0.kind,
            VertexKind::Surface { .. } | VertexKind::Light { delta: false, .. }
        ),
    }
}

/// The balance or power heuristic of strategy s from naive products of the densities (the
/// camera point's own density is common to every strategy with t ≥ 1 and left out).
fn naive_weight(dens: &Densities, s: usize, rules: &StrategyRules) -> f64 {
    let n = dens.from_light.len();
    let p = |j: usize| -> f64 {
        let light: f64 = dens.from_light[..j].iter().product();
        let camera: f64 = dens.from_camera[j..n - 1].iter().product();
        light * camera
    };
    let h = |x: f64| match rules.heuristic {
        Heuristic::Balance => x,
        Heuristic::Power => x * x,
    };
    let valid = |j: usize| {
        let c = &dens.connectible;
        match j {
            0 => rules.light_hittable,
            _ => c[j - 1] && c[j] && !(n == 2 && j == 1 && !rules.light_seen_by_camera),
        }
    };
    if !valid(s) {
        return 0.0;
    }
    let sum: f64 = (0..n).filter(|&j| valid(j)).map(|j| h(p(j))).sum();
    h(p(s)) / sum
}

fn make_bdpt(scene: &Scene, params: &[&str], seed: u64) -> bdpt::Bdpt {
    let params = Params::parse(params).unwrap();
    bdpt::new(
        scene,
        seed,
        BdptSettings::from_params(&params, scene).unwrap(),
    )
    .unwrap()
}

/// Checks every strategy event of `samples` camera samples per pixel of `scene`: the weight
/// `bdpt` gave is the heuristic of the recomputed densities (within 2·10⁻³: f32 densities
/// of nearly grazing vertices), and the weights of all strategies that can make the path
/// sum to one (within 10⁻⁴). Returns the paths checked and the largest weight difference.
fn check_every_event(scene: &Scene, heuristic: &str, samples: u32, seed: u64) -> (usize, f64) {
    let h = if heuristic == "mis=power" {
        Heuristic::Power
    } else {
        Heuristic::Balance
    };
    let bdpt = make_bdpt(scene, &[heuristic], seed);
    let (w, hgt) = (scene.width(), scene.height());
    let mut checked = 0usize;
    let mut worst = 0f64;
    let mut failures = Vec::new();
    for index in 0..samples {
        for y in 0..hgt {
            for x in 0..w {
                bdpt.observe_sample(scene, (x, y), index, |e| {
                    let path = full_path(e);
                    let n = path.len();
                    // The endpoints of the connection left their vertices through it.
                    let delta: Vec<bool> = (0..n)
                        .map(|i| i != e.s && i + 1 != e.s && path[i].delta)
                        .collect();
                    let dens = densities(scene, &path, &delta);
                    let r = rules(&path, h);
                    let naive = naive_weight(&dens, e.s, &r);
                    let path_densities = dens.path_densities();
                    let total: f64 = (0..n)
                        .map(|s| strategy_weight(&path_densities, s, &r) as f64)
                        .sum();
                    let diff = (e.weight as f64 - naive).abs();
                    worst = worst.max(diff);
                    checked += 1;
                    if diff > 2e-3 || (total - 1.0).abs() > 1e-4 {
                        failures.push(format!(
                            "(s, t) = ({}, {}), {} vertices: bdpt's weight {} against {naive} \
                             recomputed; weights of all strategies sum to {total}",
                            e.s, e.t, n, e.weight
                        ));
                    }
                });
            }
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {checked} paths fail, e.g.:\n{}",
        failures.len(),
        failures[..failures.len().min(8)].join("\n")
    );
    (checked, worst)
}

#[test]
fn every_weight_is_the_heuristic_of_the_recomputed_densities_and_they_sum_to_one() {
    let rough = r#"<scene version="3.0.0">
        <integrator type="path"><integer name="max_depth" value="7"/></integrator>
        <sensor type="perspective"><float name="fov" value="50"/>
            <transform name="to_world"><lookat origin="0, 1.5, 4" target="0, 0, 0" up="0, 1, 0"/></transform>
            <film type="hdrfilm"><integer name="width" value="12"/><integer name="height" value="12"/></film></sensor>
        <emitter type="constant"><rgb name="radiance" value="0.5"/></emitter>
        <shape type="rectangle"><transform name="to_world"><scale value="0.3"/><rotate x="1" angle="90"/><translate y="2"/></transform>
            <emitter type="area"><rgb name="radiance" value="20"/></emitter></shape>
        <shape type="rectangle"><transform name="to_world"><scale value="3"/><rotate x="1" angle="-90"/></transform>
            <bsdf type="diffuse"/></shape>
        <shape type="sphere"><point name="center" x="-0.8" y="0.5" z="0"/><float name="radius" value="0.5"/>
            <bsdf type="roughconductor"><float name="alpha" value="0.2"/></bsdf></shape>
        <shape type="sphere"><point name="center" x="0.8" y="0.5" z="0"/><float name="radius" value="0.5"/>
            <bsdf type="roughdielectric"><float name="alpha" value="0.3"/></bsdf></shape>
        <shape type="sphere"><point name="center" x="0" y="0.4" z="1"/><float name="radius" value="0.4"/>
            <bsdf type="dielectric"/></shape>
    </scene>"#;
    for (name, scene, heuristic, samples) in [
        (
            "cbox-spheres.xml",
            shipped_scene("cbox-spheres.xml", 16),
            "mis=balance",
            8,
        ),
        (
            "envmap-spheres.xml",
            shipped_scene("envmap-spheres.xml", 16),
            "mis=power",
            8,
        ),
        (
            "sun-room.xml",
            shipped_scene("sun-room.xml", 16),
            "mis=balance",
            32,
        ),
        ("rough surfaces", scene(rough), "mis=power", 16),
    ] {
        let (checked, worst) = check_every_event(&scene, heuristic, samples, 5);
        eprintln!("{name}: {checked} paths, largest weight difference {worst:.2e}");
        assert!(checked > 2000, "{name}: only {checked} paths");
    }
}

/// A plane or a sphere of the hand-derivation scenes, for the test's own ray tracing.
#[derive(Clone, Copy)]
enum Surface {
    /// Points p with p·n = offset.
    Plane {
        n: DVec3,
        offset: f64,
    },
    Sphere {
        center: DVec3,
        radius: f64,
    },
}

impl Surface {
    /// The nearest hit of the ray o + t w, t > 10⁻⁹: (point, unit normal).
    fn hit(&self, o: DVec3, w: DVec3) -> Option<(DVec3, DVec3)> {
        match *self {
            Surface::Plane { n, offset } => {
                let t = (offset - o.dot(n)) / w.dot(n);
                (t > 1e-9).then(|| (o + t * w, n))
            }
            Surface::Sphere { center, radius } => {
                let oc = o - center;
                let b = oc.dot(w);
                let disc = b * b - (oc.length_squared() - radius * radius);
                if disc < 0.0 {
                    return None;
                }
                let t = [-b - disc.sqrt(), -b + disc.sqrt()]
                    .into_iter()
                    .find(|&t| t > 1e-9)?;
                let p = o + t * w;
                Some((p, (p - center) / radius))
            }
        }
    }
}

/// Follows the ray from `o` in direction `w` through refractions at `interfaces` (each with
/// the indices on its normal's side and the other), then to `end`: the point reached and
/// the direction it arrives in.
fn trace_chain(
    o: DVec3,
    mut w: DVec3,
    interfaces: &[(Surface, f64, f64)],
    end: Surface,
) -> Option<(DVec3, DVec3)> {
    let mut o = o;
    for &(surface, n_outside, n_inside) in interfaces {
        let (p, n) = surface.hit(o, w)?;
        let (n1, n2) = if w.dot(n) < 0.0 {
            (n_outside, n_inside)
        } else {
            (n_inside, n_outside)
        };
        w = refract(w, n, n1, n2)?;
        o = p;
    }
    end.hit(o, w).map(|(p, _)| (p, w))
}

/// |dA/dω| of the map from the direction leaving `o` (around unit `w`) to the point the
/// chain reaches: the area the points sweep per unit solid angle, by central differences.
fn chain_jacobian(o: DVec3, w: DVec3, interfaces: &[(Surface, f64, f64)], end: Surface) -> f64 {
    let (u, v) = w.any_orthonormal_pair();
    let h = 1e-5;
    let at = |a: f64, b: f64| {
        trace_chain(o, (w + a * u + b * v).normalize(), interfaces, end)
            .expect("chain")
            .0
    };
    let da = (at(h, 0.0) - at(-h, 0.0)) / (2.0 * h);
    let db = (at(0.0, h) - at(0.0, -h)) / (2.0 * h);
    da.cross(db).length()
}

/// The two strategies of a path x0 (area light, cosine emission) → specular chain →
/// x(k−1) (diffuse plane) → xk (pinhole), by hand: light tracing
/// p_LT = (1/A) (cos θ0/π) Π P / |dA_(k−1)/dω_0| and the camera path hitting the light
/// p_PT = p_cam(x(k−1)) (cos θ/π) Π P / |dA_0/dω_(k−1)|, the component probabilities Π P
/// the same both ways (Fresnel transmittances `transmittance`). The path's f32 vertices lie
/// only near the chain's exact paths, and near a caustic's focus the Jacobians change fast:
/// the path is retraced in f64 from x0 along its first segment, and both Jacobians taken
/// on that exact path. Returns light tracing's weight under the balance and the power
/// heuristic (None when the retraced chain misses).
#[allow(clippy::too_many_arguments)]
fn hand_weights(
    scene: &Scene,
    path: &[Vertex],
    light_area: f64,
    light_plane: Surface,
    diffuse_plane: Surface,
    chain: &[(Surface, f64, f64)],
    transmittance: f64,
) -> Option<(f64, f64)> {
    let cam = d(path[path.len() - 1].p);
    let x0 = d(path[0].p);
    let (n0, nd) = (d(path[0].ng), d(path[path.len() - 2].ng));
    let w0 = (d(path[1].p) - x0).normalize();
    let (xd, arriving) = trace_chain(x0, w0, chain, diffuse_plane)?;
    let wd = -arriving;
    let reversed: Vec<_> = chain.iter().rev().copied().collect();
    let j_light = chain_jacobian(x0, w0, chain, diffuse_plane);
    let j_camera = chain_jacobian(xd, wd, &reversed, light_plane);
    let p_lt =
        (1.0 / light_area) * n0.dot(w0).abs() / std::f64::consts::PI * transmittance / j_light;
    let to_diffuse = (xd - cam).normalize();
    let p_cam = scene.camera.pdf_direction(to_diffuse.as_vec3()) as f64 * nd.dot(to_diffuse).abs()
        / (xd - cam).length_squared();
    let p_pt = p_cam * nd.dot(wd).abs() / std::f64::consts::PI * transmittance / j_camera;
    // A retraced path that leaves the image (a sample at its very edge) has no camera
    // strategy to compare with.
    if !(p_lt > 0.0 && p_lt.is_finite() && p_pt > 0.0 && p_pt.is_finite()) {
        return None;
    }
    Some((
        p_lt / (p_lt + p_pt),
        p_lt * p_lt / (p_lt * p_lt + p_pt * p_pt),
    ))
}

/// Runs `bdpt` (both heuristics) over `scene` and compares light tracing's and the light
/// hit's weights on every path that `is_chain` accepts with `hand` (which gives light
/// tracing's balance and power weights). Returns the median balance weight of light tracing.
fn assert_hand_weights(
    what: &str,
    scene: &Scene,
    samples: u32,
    is_chain: impl Fn(&[Vertex]) -> bool,
    hand: impl Fn(&[Vertex]) -> Option<(f64, f64)>,
) -> f64 {
    let mut balance_lt = Vec::new();
    for (heuristic, power) in [("mis=balance", false), ("mis=power", true)] {
        let bdpt = make_bdpt(scene, &[heuristic], 11);
        let mut checked = [0usize; 2];
        for index in 0..samples {
            for y in 0..scene.height() {
                for x in 0..scene.width() {
                    bdpt.observe_sample(scene, (x, y), index, |e| {
                        let path = full_path(e);
                        let k = path.len() - 1;
                        let lt = e.s == k;
                        if !(is_chain(&path) && (lt || e.s == 0)) {
                            return;
                        }
                        let Some((b, p)) = hand(&path) else {
                            return;
                        };
                        let expected_lt = if power { p } else { b };
                        let expected = if lt { expected_lt } else { 1.0 - expected_lt };
                        assert!(
                            (e.weight as f64 - expected).abs() <= 0.01 * expected.max(0.01),
                            "{what} ({heuristic}): {} weight {} where the densities give \
                             {expected}",
                            if lt {
                                "light tracing's"
                            } else {
                                "the light hit's"
                            },
                            e.weight
                        );
                        checked[lt as usize] += 1;
                        if lt && !power {
                            balance_lt.push(expected_lt);
                        }
                    });
                }
            }
        }
        eprintln!(
            "{what} ({heuristic}): {} light tracing paths, {} light hits checked",
            checked[1], checked[0]
        );
        assert!(
            checked[0] >= 20 && checked[1] >= 200,
            "{what}: too few paths ({checked:?})"
        );
    }
    balance_lt.sort_by(f64::total_cmp);
    balance_lt[balance_lt.len() / 2]
}

/// The shape of a surface vertex, if it is one.
fn shape_of(v: &Vertex) -> Option<u32> {
    v.si().map(|si| si.shape)
}

#[test]
fn weights_through_a_glass_sphere_are_those_of_the_strategies_densities() {
    // Shapes: 0 light, 1 floor, 2 glass sphere.
    let scene = scene(
        r#"<scene version="3.0.0">
        <integrator type="path"><integer name="max_depth" value="6"/></integrator>
        <sensor type="perspective"><float name="fov" value="30"/>
            <transform name="to_world"><lookat origin="0, 0.6, 3" target="0, -0.85, 0.2" up="0, 1, 0"/></transform>
            <film type="hdrfilm"><integer name="width" value="24"/><integer name="height" value="24"/></film></sensor>
        <shape type="rectangle"><transform name="to_world"><scale x="0.23" y="0.19"/><rotate x="1" angle="90"/><translate y="0.99"/></transform>
            <emitter type="area"><rgb name="radiance" value="15"/></emitter></shape>
        <shape type="rectangle"><transform name="to_world"><scale value="2"/><rotate x="1" angle="-90"/><translate y="-1"/></transform>
            <bsdf type="diffuse"/></shape>
        <shape type="sphere"><point name="center" x="0" y="-0.55" z="0"/><float name="radius" value="0.4"/>
            <bsdf type="dielectric"><float name="int_ior" value="1.5"/></bsdf></shape>
    </scene>"#,
    );
    let sphere = Surface::Sphere {
        center: DVec3::new(0.0, -0.55, 0.0),
        radius: 0.4,
    };
    let light_plane = Surface::Plane {
        n: DVec3::Y,
        offset: 0.99,
    };
    let floor = Surface::Plane {
        n: DVec3::Y,
        offset: -1.0,
    };
    let chain = [(sphere, 1.0, 1.5), (sphere, 1.0, 1.5)];
    // light → sphere → sphere → floor → camera, refracted at both sphere vertices.
    let is_chain = |p: &[Vertex]| {
        let shapes: Vec<Option<u32>> = p.iter().map(shape_of).collect();
        p.len() == 5
            && (p[0].light_index(&scene).is_some())
            && shapes[1..4] == [Some(2), Some(2), Some(1)]
            && (d(p[1].p) - d(p[2].p)).length() > 1e-3
    };
    let median = assert_hand_weights("glass sphere", &scene, 128, is_chain, |p| {
        let cos_in = |i: usize| {
            let n = (d(p[i].p) - DVec3::new(0.0, -0.55, 0.0)).normalize();
            n.dot((d(p[i - 1].p) - d(p[i].p)).normalize()).abs()
        };
        // Entering (η 1 → 1.5) at x1, leaving (1.5 → 1) at x2.
        let t = (1.0 - fresnel(cos_in(1), 1.5)) * (1.0 - fresnel(cos_in(2), 1.0 / 1.5));
        hand_weights(&scene, p, 0.46 * 0.38, light_plane, floor, &chain, t)
    });
    eprintln!("glass sphere: median balance weight of light tracing {median:.3}");
    assert!(median > 0.9, "median {median}");
}

#[test]
fn weights_of_a_chain_starting_inside_glass_keep_the_indices_of_refraction() {
    // A light inside a glass block over a floor: light → block's bottom face → floor →
    // camera. Shapes: 0 light, 1 floor, 2 glass block (y from −0.2 to 0.6).
    let scene = scene(
        r#"<scene version="3.0.0">
        <integrator type="path"><integer name="max_depth" value="5"/></integrator>
        <sensor type="perspective"><float name="fov" value="30"/>
            <transform name="to_world"><lookat origin="0, 0.3, 3.5" target="0, -1, 0.3" up="0, 1, 0"/></transform>
            <film type="hdrfilm"><integer name="width" value="24"/><integer name="height" value="24"/></film></sensor>
        <shape type="rectangle"><transform name="to_world"><scale value="0.1"/><rotate x="1" angle="90"/><translate y="0.3"/></transform>
            <emitter type="area"><rgb name="radiance" value="40"/></emitter></shape>
        <shape type="rectangle"><transform name="to_world"><scale value="2"/><rotate x="1" angle="-90"/><translate y="-1"/></transform>
            <bsdf type="diffuse"/></shape>
        <shape type="cube"><transform name="to_world"><scale x="0.5" y="0.4" z="0.5"/><translate y="0.2"/></transform>
            <bsdf type="dielectric"><float name="int_ior" value="1.5"/></bsdf></shape>
    </scene>"#,
    );
    let bottom = Surface::Plane {
        n: -DVec3::Y,
        offset: 0.2,
    };
    let light_plane = Surface::Plane {
        n: DVec3::Y,
        offset: 0.3,
    };
    let floor = Surface::Plane {
        n: DVec3::Y,
        offset: -1.0,
    };
    // The bottom face's normal points down, out of the glass.
    let chain = [(bottom, 1.0, 1.5)];
    let is_chain = |p: &[Vertex]| {
        p.len() == 4
            && p[0].light_index(&scene).is_some()
            && shape_of(&p[1]) == Some(2)
            && (p[1].p.y + 0.2).abs() < 1e-4
            && shape_of(&p[2]) == Some(1)
    };
    assert_hand_weights("light inside glass", &scene, 48, is_chain, |p| {
        let cos_glass = (d(p[0].p) - d(p[1].p)).normalize().y.abs();
        let t = 1.0 - fresnel(cos_glass, 1.0 / 1.5);
        hand_weights(&scene, p, 0.2 * 0.2, light_plane, floor, &chain, t)
    });
}
