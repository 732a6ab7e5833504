//! The Metropolis estimators `pssmlt` (over `pt` and over `bdpt`) and `mmlt` against `bdpt`
//! (fixed seeds; Metropolis errors are correlated across pixels, so every tolerance comes
//! from the spread of 8 or more independent runs):
//!
//! * every shipped scene (the door-ajar rooms and `sds.xml` in a test of their own): the
//!   image mean within 4 σ (Welch's t, at the two-sided tail of 4 σ of a normal) and every
//!   16 × 16 block and channel (Welch's t, Šidák over all of them at 10⁻³);
//! * the normalisation b agrees with a long `bdpt` image's mean luminance within 4 of their
//!   combined standard errors;
//! * `large_step=1` (every proposal independent) agrees with the base estimator;
//! * `mmlt` with chains that change path length (`lengths=mutable`) as well as with the
//!   default, chains that keep one;
//! * `importance=relative` (the target divided by a pilot of each pixel) agrees with `bdpt`
//!   where the image's contrast is highest: the door ajar, a small light behind glass;
//! * bit-identical images for 1 and 2 threads;
//! * bad parameters, a scene without a light, a scene whose light reaches no pixel.

mod render_support;

use mltbench::estimator::{self, Params};
use mltbench::image::Image;
use mltbench::render::{Budget, render};
use mltbench::scene::Scene;
use render_support::*;
use statrs::distribution::{ContinuousCDF, Normal, StudentsT};

/// The Metropolis estimators as (estimator, its parameters).
const METROPOLIS: [(&str, &str); 3] = [
    ("pssmlt", "base=pt"),
    ("pssmlt", "base=bdpt"),
    ("mmlt", "large_step=0.3"),
];

/// Chain settings for short test runs: fewer chains and bootstrap samples than the
/// defaults, so that each chain takes several hundred steps.
const SHORT: [&str; 2] = ["chains=32", "bootstrap=20000"];

fn runs(
    name: &str,
    scene: &Scene,
    params: &[&str],
    count: u64,
    passes: u32,
    seed: u64,
) -> Vec<Image> {
    (0..count)
        .map(|k| render_with(name, scene, params, passes, seed + k))
        .collect()
}

/// Asserts that the image means of runs `a` and `b` agree: Welch's t against the tail of
/// 4 σ.
fn assert_means_agree(what: &str, a: &[Image], b: &[Image]) {
    for c in 0..3 {
        let ((ma, sa), (mb, sb)) = (image_mean_over_runs(a, c), image_mean_over_runs(b, c));
        let (va, vb) = (sa * sa, sb * sb);
        let t = (ma - mb) / (va + vb).sqrt().max(1e-30);
        let (na, nb) = (a.len() as f64 - 1.0, b.len() as f64 - 1.0);
        let dof = ((va + vb).powi(2) / (va * va / na + vb * vb / nb)).max(1.0);
        let p = 2.0 * StudentsT::new(0.0, 1.0, dof).unwrap().cdf(-t.abs());
        let p_4sigma = 2.0 * Normal::new(0.0, 1.0).unwrap().cdf(-SIGMAS);
        eprintln!("{what} channel {c}: {ma:.5} ± {sa:.1e} against {mb:.5} ± {sb:.1e}, p {p:.1e}");
        assert!(
            p > p_4sigma,
            "{what} channel {c}: mean {ma} ± {sa} against {mb} ± {sb} (t = {t:.2}, p = {p:.1e})"
        );
    }
}

#[test]
fn agrees_with_bdpt_on_every_shipped_scene() {
    // The small light behind glass gives the path-traced chains rare, bright caustic paths:
    // there a coarser film and more mutations per pixel, so that each run finds them.
    for (file, res, passes, seed) in [
        ("cbox.xml", 32, 32, 100),
        ("cbox-dof.xml", 32, 32, 200),
        ("cbox-point.xml", 32, 32, 300),
        ("cbox-spheres.xml", 32, 32, 400),
        ("cbox-smalllight.xml", 32, 32, 500),
        ("cbox-spheres-smalllight.xml", 16, 256, 550),
        ("cbox-mm.xml", 32, 32, 600),
        ("envmap-spheres.xml", 32, 32, 700),
        ("sun-room.xml", 32, 32, 800),
        ("textures.xml", 32, 32, 900),
        ("textures-plastic.xml", 32, 32, 950),
    ] {
        let scene = shipped_scene(file, res);
        // mmlt needs a finite max_depth: the one scene with −1 gets 8 for every estimator.
        let depth: &[&str] = if file == "textures-plastic.xml" {
            &["max_depth=8"]
        } else {
            &[]
        };
        assert_metropolis_agrees_with_bdpt(file, &scene, depth, &[], passes, seed);
    }
}

/// Every Metropolis estimator (with `extra` parameters, which `bdpt` gets too, and
/// `chain_extra`, which it does not) against `bdpt` on `scene`, 8 runs each: image means
/// and 16 × 16 blocks.
fn assert_metropolis_agrees_with_bdpt(
    file: &str,
    scene: &Scene,
    extra: &[&str],
    chain_extra: &[&str],
    passes: u32,
    seed: u64,
) {
    let bdpt = runs("bdpt", scene, extra, 8, passes, seed);
    for (k, (name, param)) in METROPOLIS.iter().enumerate() {
        let mut params = vec![*param];
        params.extend(extra);
        params.extend(chain_extra);
        let what = format!("{file}: {name} {param} {}", chain_extra.join(" "));
        let seed = seed + 10 * (k as u64 + 1);
        assert_short_runs_agree(&what, scene, name, &params, passes, seed, &bdpt);
    }
}

/// 8 short runs of Metropolis estimator `name` (with `params` and `SHORT`) against the runs
/// `against`: image means and 16 × 16 blocks.
fn assert_short_runs_agree(
    what: &str,
    scene: &Scene,
    name: &str,
    params: &[&str],
    passes: u32,
    seed: u64,
    against: &[Image],
) {
    let mut params = params.to_vec();
    params.extend(SHORT);
    let mlt = runs(name, scene, &params, 8, passes, seed);
    assert_means_agree(what, &mlt, against);
    assert_blocks_agree_of(what, &mlt, against, 16);
}

/// The rest of the shipped scenes, where light takes one narrow way: through a door ajar
/// (seen at the gap, and seen only after a bounce) and through glass from a point light
/// (`sds.xml`, whose SDS caustic no estimator here samples, so all see the same rest).
/// Paths through the gap are rare at this film size, so more passes per run.
#[test]
fn agrees_with_bdpt_where_light_comes_through_a_gap() {
    for (file, res, passes, seed) in [
        ("door-ajar.xml", 16, 128, 1100),
        ("door-ajar-indirect.xml", 16, 128, 1200),
        ("sds.xml", 32, 32, 1300),
    ] {
        let scene = shipped_scene(file, res);
        assert_metropolis_agrees_with_bdpt(file, &scene, &[], &[], passes, seed);
    }
}

/// `mmlt` with `lengths=mutable` (chains that change path length; the default keeps each
/// chain at one length) against `bdpt`: on the spheres' caustics and behind the door.
#[test]
fn mutable_lengths_agree_with_bdpt() {
    for (file, res, passes, seed) in [
        ("cbox-spheres.xml", 32, 32, 1400),
        ("door-ajar-indirect.xml", 16, 128, 1500),
    ] {
        let scene = shipped_scene(file, res);
        let bdpt = runs("bdpt", &scene, &[], 8, passes, seed);
        let what = format!("{file}: mmlt lengths=mutable");
        let params = ["lengths=mutable"];
        assert_short_runs_agree(&what, &scene, "mmlt", &params, passes, seed + 10, &bdpt);
    }
}

/// `mmlt`'s default chains keep one path length each: the diagnostics say how many each
/// length got (every length the bootstrap found lit at least one, the rest none, all
/// chains used); chains that change length report none.
#[test]
fn fixed_lengths_share_the_chains_out_over_lengths() {
    let scene = shipped_scene("cbox.xml", 16);
    for (lengths, fixed) in [("lengths=fixed", true), ("lengths=mutable", false)] {
        let params = Params::parse(&[lengths, "chains=64", "bootstrap=4000"]).unwrap();
        let mut e = estimator::create("mmlt", &params, &scene, 3).unwrap();
        render(&scene, e.as_mut(), Budget::Passes(1), |_, _| {});
        let d = e.diagnostics().unwrap();
        if !fixed {
            assert!(d["chains_per_stratum"].is_null(), "{d}");
            continue;
        }
        let per: Vec<u64> = d["chains_per_stratum"]
            .as_array()
            .expect("chains per length")
            .iter()
            .map(|v| v.as_u64().unwrap())
            .collect();
        let means: Vec<f64> = d["bootstrap"]["stratum_means"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        assert_eq!(per.len(), 8, "cbox.xml's max_depth");
        assert_eq!(per.iter().sum::<u64>(), 64);
        for (k, (&n, &m)) in per.iter().zip(&means).enumerate() {
            assert_eq!(n > 0, m > 0.0, "length {}: {n} chains, b_d {m}", k + 1);
        }
    }
}

/// `importance=relative` changes only where the chains spend their mutations: the images
/// agree with `bdpt` where contrast is highest, the lit far room seen through a door ajar
/// beside the dim near room (at 32², where a pilot made from the bootstrap's own points
/// left b too small and every block a third too dark: t = −14.9), and a small light's
/// caustic under glass.
#[test]
fn relative_importance_agrees_with_bdpt() {
    for (file, res, passes, seed) in [
        ("door-ajar.xml", 32, 256, 1400),
        ("cbox-spheres-smalllight.xml", 16, 256, 1500),
    ] {
        let scene = shipped_scene(file, res);
        assert_metropolis_agrees_with_bdpt(
            file,
            &scene,
            &[],
            &["importance=relative"],
            passes,
            seed,
        );
    }
}

/// An image's mean luminance.
fn mean_luminance(im: &Image) -> f64 {
    im.pixels.iter().map(|p| p.luminance() as f64).sum::<f64>() / im.pixels.len() as f64
}

/// The mean luminance of 8 `bdpt` runs of 64 passes, and its standard error.
fn bdpt_mean_luminance(scene: &Scene) -> (f64, f64) {
    let bdpt = runs("bdpt", scene, &[], 8, 64, 3000);
    mean_and_standard_error(&bdpt.iter().map(mean_luminance).collect::<Vec<_>>())
}

/// The bootstrap's normalisation b is the mean luminance of the image.
#[test]
fn normalisation_is_the_image_mean_luminance() {
    let scene = shipped_scene("cbox-spheres.xml", 32);
    let (mean, se) = bdpt_mean_luminance(&scene);
    for (name, param) in METROPOLIS {
        let params = Params::parse(&[param, "bootstrap=100000"]).unwrap();
        let mut e = estimator::create(name, &params, &scene, 7).unwrap();
        render(&scene, e.as_mut(), Budget::Passes(1), |_, _| {});
        let d = e.diagnostics().expect("diagnostics");
        let b = d["bootstrap"]["b"].as_f64().unwrap();
        let b_se = d["bootstrap"]["b_standard_error"].as_f64().unwrap();
        let sigma = (se * se + b_se * b_se).sqrt();
        eprintln!("{name} {param}: b {b:.5} ± {b_se:.1e}, bdpt {mean:.5} ± {se:.1e}");
        assert!(
            (b - mean).abs() < SIGMAS * sigma,
            "{name} {param}: b = {b} ± {b_se} against the image's {mean} ± {se}"
        );
    }
}

/// `normalisation=large_steps` pools the bootstrap with every large step's proposal: from
/// a bootstrap of only 1000 points, the pooled b lands on the long `bdpt` image's mean
/// luminance within 4 σ of the two (the pooled b's σ from the bootstrap's spread over all
/// the points pooled), and the image's mean luminance is that b (each step splats b in
/// luminance).
#[test]
fn pooled_normalisation_converges_to_the_image_mean() {
    let scene = shipped_scene("cbox-spheres.xml", 32);
    let (mean, se) = bdpt_mean_luminance(&scene);
    for (name, param) in METROPOLIS {
        // mmlt's chains that keep their path length weigh by the bootstrap's b per length,
        // so pooling is for chains that change length.
        let mut params = vec![
            param,
            "bootstrap=1000",
            "chains=16",
            "normalisation=large_steps",
        ];
        if name == "mmlt" {
            params.push("lengths=mutable");
        }
        let params = Params::parse(&params).unwrap();
        let mut e = estimator::create(name, &params, &scene, 8).unwrap();
        render(&scene, e.as_mut(), Budget::Passes(64), |_, _| {});
        let d = e.diagnostics().expect("diagnostics");
        let b = d["b_pooled"]
            .as_f64()
            .expect("b_pooled with normalisation=large_steps");
        let n_boot = d["bootstrap"]["samples"].as_f64().unwrap();
        let spread = d["bootstrap"]["b_standard_error"].as_f64().unwrap() * n_boot.sqrt();
        let n_large = d["large_steps"]["proposed"].as_f64().unwrap();
        let b_se = spread / (n_boot + n_large).sqrt();
        let sigma = (se * se + b_se * b_se).sqrt();
        eprintln!(
            "{name} {param}: pooled b {b:.5} ± {b_se:.1e} over {n_large} large steps, bdpt {mean:.5} ± {se:.1e}"
        );
        assert!(
            (b - mean).abs() < SIGMAS * sigma,
            "{name} {param}: pooled b = {b} ± {b_se} against the image's {mean} ± {se}"
        );
        let image_mean = mean_luminance(&e.image());
        assert!(
            (image_mean / b - 1.0).abs() < 1e-3,
            "{name} {param}: image mean {image_mean} against b {b}"
        );
    }
}

/// With large_step=1 every proposal is an independent sample: the chain is then an
/// independence sampler and agrees with its base estimator.
#[test]
fn large_steps_only_agree_with_the_base_estimator() {
    let scene = shipped_scene("cbox-spheres.xml", 32);
    for (base, seed) in [("pt", 4000), ("bdpt", 4100)] {
        let own = runs(base, &scene, &[], 8, 32, seed);
        let param = format!("base={base}");
        let params = [param.as_str(), "large_step=1"];
        let what = format!("pssmlt base={base} large_step=1");
        assert_short_runs_agree(&what, &scene, "pssmlt", &params, 32, seed + 50, &own);
    }
}

#[test]
fn thread_count_does_not_matter() {
    let scene = shipped_scene("cbox-spheres.xml", 40);
    let variants = [
        ("pssmlt", "importance=relative"),
        ("mmlt", "importance=relative"),
        ("mmlt", "lengths=mutable normalisation=large_steps"),
        ("mmlt", "lengths=mutable"),
    ];
    for (name, param) in METROPOLIS.into_iter().chain(variants) {
        let bits = |threads: usize, seed: u64| -> Vec<u32> {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let mut params: Vec<&str> = param.split(' ').collect();
            params.extend(["chains=48", "bootstrap=5000"]);
            let params = Params::parse(&params).unwrap();
            let mut e = estimator::create(name, &params, &scene, seed).unwrap();
            let image = pool
                .install(|| render(&scene, e.as_mut(), Budget::Passes(6), |_, _| {}))
                .image;
            assert!(image.pixels.iter().any(|p| !p.is_black()));
            image
                .pixels
                .iter()
                .flat_map(|p| p.0.map(f32::to_bits))
                .collect()
        };
        let one = bits(1, 5);
        assert_eq!(one, bits(2, 5), "{name} {param}: 1 and 2 threads");
        assert_ne!(
            one,
            bits(2, 6),
            "{name} {param}: another seed, another image"
        );
    }
}

#[test]
fn bad_parameters_are_refused_naming_them() {
    let scene = shipped_scene("cbox.xml", 8);
    for name in ["pssmlt", "mmlt"] {
        for (param, expected) in [
            ("large_step=1.5", "large_step"),
            ("large_step=-1", "large_step"),
            ("chains=0", "chains"),
            ("s1=0.1", "s2"),
            ("bootstrap=0", "bootstrap"),
            ("importance=radiance", "importance"),
            ("normalisation=mean", "normalisation"),
            ("wavefront=false", "wavefront"),
            ("strategies=true", "strategies"),
        ] {
            let err = estimator::create(name, &Params::parse(&[param]).unwrap(), &scene, 1)
                .err()
                .unwrap_or_else(|| panic!("{name} {param} accepted"))
                .to_string();
            assert!(err.contains(expected), "{name} {param}: {err}");
        }
    }
    // Kelemen's weights use b while splatting: b cannot be pooled afterwards.
    let both = Params::parse(&["kelemen_weights=true", "normalisation=large_steps"]).unwrap();
    let err = estimator::create("pssmlt", &both, &scene, 1)
        .err()
        .unwrap()
        .to_string();
    assert!(err.contains("normalisation"), "{err}");
    let err = estimator::create("pssmlt", &Params::parse(&["base=lt"]).unwrap(), &scene, 1)
        .err()
        .unwrap()
        .to_string();
    assert!(err.contains("base"), "{err}");
    let err = estimator::create(
        "mmlt",
        &Params::parse(&["max_depth=-1"]).unwrap(),
        &scene,
        1,
    )
    .err()
    .unwrap()
    .to_string();
    assert!(err.contains("max_depth"), "{err}");
    // Chains that keep their path length: one per length at least, weighed by the
    // bootstrap's b (an 8 × 8 film has 64 pixels, so at most 64 chains move each pass).
    for (params, expected) in [
        (&["chains=4", "max_depth=8"][..], "chains = 4"),
        (&["chains=256", "max_depth=100"][..], "64 chains"),
        (&["normalisation=large_steps"][..], "normalisation"),
        (&["lengths=some"][..], "lengths"),
    ] {
        let err = estimator::create("mmlt", &Params::parse(params).unwrap(), &scene, 1)
            .err()
            .unwrap_or_else(|| panic!("mmlt {params:?} accepted"))
            .to_string();
        assert!(err.contains(expected), "{params:?}: {err}");
    }
    let mutable = Params::parse(&["chains=4", "max_depth=8", "lengths=mutable"]).unwrap();
    assert!(estimator::create("mmlt", &mutable, &scene, 1).is_ok());
}

#[test]
fn a_scene_without_light_is_an_error_naming_it() {
    let xml = format!(
        r#"<scene version="3.0.0">{}<shape type="sphere"><float name="radius" value="1"/></shape></scene>"#,
        camera()
    );
    let scene = render_support::scene(&xml);
    for name in ["pssmlt", "mmlt"] {
        let err = estimator::create(name, &Params::default(), &scene, 1)
            .err()
            .unwrap_or_else(|| panic!("{name} accepted a scene without light"))
            .to_string();
        assert!(
            err.contains("test-scene.xml") && err.contains("no light"),
            "{err}"
        );
    }
}

/// A light that reaches no pixel (inside a closed box the camera looks at from outside):
/// every bootstrap sample is zero, the image is black, nothing fails.
#[test]
fn a_light_that_reaches_no_pixel_renders_black() {
    let xml = format!(
        r#"<scene version="3.0.0">{}
        <shape type="cube"><transform name="to_world"><scale value="0.5"/></transform>
            <bsdf type="diffuse"/></shape>
        <shape type="sphere"><float name="radius" value="0.1"/>
            <emitter type="area"><rgb name="radiance" value="5"/></emitter></shape>
        </scene>"#,
        camera()
    );
    let scene = render_support::scene(&xml);
    for (name, param) in METROPOLIS {
        let params = Params::parse(&[param, "bootstrap=2000", "chains=8", "max_depth=6"]).unwrap();
        let mut e = estimator::create(name, &params, &scene, 1).unwrap();
        let out = render(&scene, e.as_mut(), Budget::Passes(2), |_, _| {});
        assert!(out.image.pixels.iter().all(|p| p.is_black()), "{name}");
        let d = e.diagnostics().unwrap();
        assert_eq!(d["bootstrap"]["nonzero"].as_u64(), Some(0));
    }
}
