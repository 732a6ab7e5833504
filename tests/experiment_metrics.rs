//! The experiment harness's pure computation: docs/DESIGN.md §5 metrics against values worked out
//! by hand, the bias/variance decomposition and its t-test on synthetic ensembles with known
//! bias and noise, the convergence-slope fit on synthetic power laws, and the reference noise
//! estimate from two independent halves.

use mltbench::experiment::metrics::{
    Region, metrics, metrics_in, reference_noise, relative_error_map,
};
use mltbench::experiment::statistics::{
    bias_variance, fit_later_half, fit_power_law, later_half, mean_interval,
    nonnegative_mean_interval,
};
use mltbench::image::Image;
use mltbench::math::Rgb;
use rand::{RngExt, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * b.abs().max(1e-300)
}

fn image(width: u32, height: u32, pixels: &[[f32; 3]]) -> Image {
    Image {
        width,
        height,
        pixels: pixels.iter().map(|&p| Rgb(p)).collect(),
    }
}

/// A standard normal draw (Box–Muller; 1 − u keeps the logarithm's argument in (0, 1]).
fn normal(rng: &mut Xoshiro256PlusPlus) -> f64 {
    let u1 = 1.0 - rng.random::<f64>();
    let u2 = rng.random::<f64>();
    (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
}

// ---------------------------------------------------------------------------------------------
// Metrics by hand

/// Reference y and image x, 2×1, with binary-exact values:
///   y: (1, 0, 0.5)     (2, 0.25, 0)
///   x: (1.5, 0.25, 0.5) (1, 0.25, 0.75)
///   d = x − y: 0.5, 0.25, 0, −1, 0, 0.75
fn hand_pair() -> (Image, Image) {
    let y = image(2, 1, &[[1.0, 0.0, 0.5], [2.0, 0.25, 0.0]]);
    let x = image(2, 1, &[[1.5, 0.25, 0.5], [1.0, 0.25, 0.75]]);
    (x, y)
}

#[test]
fn metrics_match_hand_computation() {
    let (x, y) = hand_pair();
    let m = metrics(&x, &y).unwrap();
    // d² = 0.25, 0.0625, 0, 1, 0, 0.5625; sum 1.875; mean 0.3125; RMSE = √0.3125 ≈ 0.559017.
    assert!(close(m.rmse, 0.3125f64.sqrt(), 1e-12), "{m:?}");
    // relMSE terms d²/(y² + 0.01): 0.25/1.01, 0.0625/0.01, 0, 1/4.01, 0/0.0725, 0.5625/0.01
    //   = 0.247525, 6.25, 0, 0.249377, 0, 56.25; mean ≈ 10.499484.
    let relmse = (0.25 / 1.01 + 0.0625 / 0.01 + 1.0 / 4.01 + 0.5625 / 0.01) / 6.0;
    assert!(close(m.relmse, relmse, 1e-12), "{m:?}");
    assert!(close(m.relmse, 10.499483551846456, 1e-12));
    // MAPE terms |d|/(y + 0.01): 0.5/1.01, 0.25/0.01, 0, 1/2.01, 0, 0.75/0.01
    //   = 0.495050, 25, 0, 0.497512, 0, 75; mean ≈ 16.832094.
    let mape = (0.5 / 1.01 + 0.25 / 0.01 + 1.0 / 2.01 + 0.75 / 0.01) / 6.0;
    assert!(close(m.mape, mape, 1e-12), "{m:?}");
    assert!(close(m.mape, 16.832093657126908, 1e-12));

    // An image against itself has no error.
    let zero = metrics(&y, &y).unwrap();
    assert_eq!((zero.relmse, zero.rmse, zero.mape), (0.0, 0.0, 0.0));
}

#[test]
fn metrics_in_a_crop_match_hand_computation() {
    let (x, y) = hand_pair();
    // Only pixel (1, 0): d = −1, 0, 0.75.
    let region = Region {
        x: 1,
        y: 0,
        width: 1,
        height: 1,
    };
    let m = metrics_in(&x, &y, region).unwrap();
    // RMSE = √((1 + 0.5625)/3) ≈ 0.721688
    assert!(close(m.rmse, (1.5625f64 / 3.0).sqrt(), 1e-12), "{m:?}");
    // relMSE = (1/4.01 + 0 + 0.5625/0.01)/3 ≈ 18.833126
    assert!(close(m.relmse, (1.0 / 4.01 + 0.5625 / 0.01) / 3.0, 1e-12));
    // MAPE = (1/2.01 + 0 + 0.75/0.01)/3 ≈ 25.165837
    assert!(close(m.mape, (1.0 / 2.01 + 0.75 / 0.01) / 3.0, 1e-12));

    // The full-image region equals `metrics`.
    let full = Region {
        x: 0,
        y: 0,
        width: 2,
        height: 1,
    };
    assert_eq!(metrics_in(&x, &y, full).unwrap(), metrics(&x, &y).unwrap());

    // Regions outside the image or empty are errors, also near u32::MAX (no overflow).
    for bad in [
        Region {
            x: 1,
            y: 0,
            width: 2,
            height: 1,
        },
        Region {
            x: 0,
            y: 1,
            width: 1,
            height: 1,
        },
        Region {
            x: 0,
            y: 0,
            width: 0,
            height: 1,
        },
        Region {
            x: u32::MAX,
            y: 0,
            width: 2,
            height: 1,
        },
    ] {
        let err = metrics_in(&x, &y, bad).unwrap_err().to_string();
        assert!(err.contains("2×1"), "{err}");
    }
}

#[test]
fn region_round_trips_through_toml() {
    let region: Region = toml::from_str("x = 10\ny = 20\nwidth = 30\nheight = 40\n").unwrap();
    assert_eq!(
        region,
        Region {
            x: 10,
            y: 20,
            width: 30,
            height: 40
        }
    );
    let text = toml::to_string(&region).unwrap();
    assert_eq!(toml::from_str::<Region>(&text).unwrap(), region);
}

#[test]
fn relative_error_map_matches_hand_computation() {
    let (x, y) = hand_pair();
    let map = relative_error_map(&x, &y).unwrap();
    // Pixel 0: (0.5/1.01 + 0.25/0.01 + 0)/3 ≈ 8.498350; pixel 1: (1/2.01 + 0 + 0.75/0.01)/3
    // ≈ 25.165837.
    assert_eq!(map.len(), 2);
    let expected = [
        (0.5 / 1.01 + 0.25 / 0.01) / 3.0,
        (1.0 / 2.01 + 0.75 / 0.01) / 3.0,
    ];
    for (got, want) in map.iter().zip(expected) {
        assert!(close(f64::from(*got), want, 1e-6), "{got} vs {want}");
    }
}

#[test]
fn bad_images_are_errors_not_panics() {
    let (x, y) = hand_pair();
    // Size mismatch names both sizes.
    let tall = image(1, 2, &[[0.0; 3], [0.0; 3]]);
    let err = metrics(&x, &tall).unwrap_err().to_string();
    assert!(err.contains("2×1") && err.contains("1×2"), "{err}");
    assert!(relative_error_map(&x, &tall).is_err());
    assert!(reference_noise(&x, &tall).is_err());

    // Empty images.
    let empty = image(0, 0, &[]);
    assert!(metrics(&empty, &empty).is_err());
    assert!(relative_error_map(&empty, &empty).is_err());
    assert!(reference_noise(&empty, &empty).is_err());
    assert!(bias_variance(&[empty.clone(), empty.clone()], &empty).is_err());

    // A pixel buffer that does not match the stated size.
    let short = Image {
        width: 2,
        height: 1,
        pixels: vec![Rgb([0.0; 3])],
    };
    assert!(metrics(&short, &y).is_err());

    // Non-finite values name the pixel.
    for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
        let mut nan = x.clone();
        nan.pixels[1].0[2] = bad;
        let err = metrics(&nan, &y).unwrap_err().to_string();
        assert!(err.contains("(1, 0)") && err.contains("blue"), "{err}");
        assert!(metrics(&y, &nan).is_err());
        assert!(relative_error_map(&nan, &y).is_err());
        assert!(reference_noise(&y, &nan).is_err());
        let err = bias_variance(&[x.clone(), nan.clone()], &y)
            .unwrap_err()
            .to_string();
        assert!(err.contains("run 1") && err.contains("(1, 0)"), "{err}");
    }

    // A reference whose MAPE denominator y + 0.01 is not positive.
    let mut negative = y.clone();
    negative.pixels[0].0[0] = -1.0;
    let err = metrics(&x, &negative).unwrap_err().to_string();
    assert!(err.contains("(0, 0)"), "{err}");

    // Bias needs at least two runs.
    assert!(bias_variance(&[], &y).is_err());
    assert!(bias_variance(std::slice::from_ref(&x), &y).is_err());
    assert!(bias_variance(&[x.clone(), tall], &y).is_err());
}

// ---------------------------------------------------------------------------------------------
// Confidence intervals

#[test]
fn mean_interval_uses_student_t_quantiles() {
    // [−1, 1]: mean 0, s = √2, s/√n = 1; t_{0.975, 1} = 12.7062047.
    let i = mean_interval(&[-1.0, 1.0], 0.95);
    assert_eq!(i.mean, 0.0);
    assert!(
        close(i.hi, 12.7062047, 1e-6) && close(i.lo, -12.7062047, 1e-6),
        "{i:?}"
    );
    // [1..5]: mean 3, s² = 2.5, s/√n = √0.5; t_{0.975, 4} = 2.7764451.
    let i = mean_interval(&[1.0, 2.0, 3.0, 4.0, 5.0], 0.95);
    assert!(close(i.hi - 3.0, 2.7764451 * 0.5f64.sqrt(), 1e-6), "{i:?}");
    // 99%: t_{0.995, 4} = 4.6040949.
    let i = mean_interval(&[1.0, 2.0, 3.0, 4.0, 5.0], 0.99);
    assert!(close(i.hi - 3.0, 4.6040949 * 0.5f64.sqrt(), 1e-6), "{i:?}");
    // Large samples (the per-pixel intervals): the quantile t_{0.975, n−1} read back from the
    // half-width, against exact values (1.9623391 at 1000 dof, 1.9602012 at 10⁴, → z_{0.975} =
    // 1.9599640 for millions of terms, where statrs alone is off in the third digit).
    for (n, t) in [
        (1001, 1.962339080826),
        (10_001, 1.960201239891),
        (3_000_001, 1.959964775),
    ] {
        let values: Vec<f64> = (0..n)
            .map(|k| if k % 2 == 0 { 1.0 } else { -1.0 })
            .collect();
        let i = mean_interval(&values, 0.95);
        let m = i.mean;
        let s2 = values.iter().map(|v| (v - m).powi(2)).sum::<f64>() / (n as f64 - 1.0);
        let quantile = (i.hi - m) / (s2 / n as f64).sqrt();
        assert!(close(quantile, t, 1e-9), "{n}: {quantile} vs {t}");
    }

    // Degenerate, documented cases: finite where there is a value, NaN only with none.
    let one = mean_interval(&[2.5], 0.95);
    assert_eq!((one.mean, one.lo, one.hi), (2.5, 2.5, 2.5));
    for bad in [0.0, 1.0, -0.5, 2.0, f64::NAN] {
        let i = mean_interval(&[1.0, 2.0], bad);
        assert_eq!((i.mean, i.lo, i.hi), (1.5, 1.5, 1.5));
    }
    let none = mean_interval(&[], 0.95);
    assert!(none.mean.is_nan() && none.lo.is_nan() && none.hi.is_nan());
}

#[test]
fn intervals_of_nonnegative_quantities_stay_at_or_above_zero() {
    // Two runs' relMSE: the t interval reaches below 0; the upper end and mean are kept.
    let values = [1e-3, 1e-2];
    let t = mean_interval(&values, 0.95);
    assert!(t.lo < 0.0, "{t:?}");
    let i = nonnegative_mean_interval(&values, 0.95);
    assert_eq!((i.mean, i.lo, i.hi), (t.mean, 0.0, t.hi));
    // Already positive: unchanged; no values: still NaN.
    let values = [1.0, 1.1, 0.9, 1.05];
    assert_eq!(
        nonnegative_mean_interval(&values, 0.95),
        mean_interval(&values, 0.95)
    );
    assert!(nonnegative_mean_interval(&[], 0.95).lo.is_nan());
}

// ---------------------------------------------------------------------------------------------
// Bias and variance

/// A synthetic ensemble: reference y(p, c) uniform in [0.2, 2.2) (or 1 everywhere if `flat`), runs x_k = y + b_c + σ(y)·N(0, 1)
/// with a per-channel bias b_c and a noise level σ(y) = `noise`·√y (photon-like), each pixel
/// independent. Returns the reference, the runs, and the true bias², variance, relative bias²
/// and relative variance (means over pixel-channels of b_c², σ², b_c²/(y² + 0.01),
/// σ²/(y² + 0.01)).
fn ensemble(
    seed: u64,
    size: u32,
    runs: usize,
    bias: [f64; 3],
    noise: f64,
    flat: bool,
) -> (Image, Vec<Image>, [f64; 4]) {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let mut reference = Image::new(size, size);
    for p in &mut reference.pixels {
        for c in 0..3 {
            let u = rng.random::<f64>();
            p.0[c] = if flat { 1.0 } else { (0.2 + 2.0 * u) as f32 };
        }
    }
    let mut truth = [0.0; 4];
    for p in &reference.pixels {
        for (&v, b) in p.0.iter().zip(bias) {
            let y = f64::from(v);
            let (b2, s2) = (b * b, noise * noise * y);
            let d = y * y + 0.01;
            truth[0] += b2;
            truth[1] += s2;
            truth[2] += b2 / d;
            truth[3] += s2 / d;
        }
    }
    let terms = (reference.pixels.len() * 3) as f64;
    truth.iter_mut().for_each(|t| *t /= terms);
    let images = (0..runs)
        .map(|_| {
            let mut x = reference.clone();
            for p in &mut x.pixels {
                for (v, b) in p.0.iter_mut().zip(bias) {
                    let y = f64::from(*v);
                    *v = (y + b + noise * y.sqrt() * normal(&mut rng)) as f32;
                }
            }
            x
        })
        .collect();
    (reference, images, truth)
}

/// Known bias² and σ² lie inside their 95% intervals. The seed is fixed, so the test is
/// deterministic; it is not a lucky draw: the per-pixel-channel terms are independent here
/// (the intervals' assumption), 12 288 of them, so the Student-t interval of their mean covers
/// the true mean 95% of the time, which `intervals_cover_at_the_stated_rate` measures over
/// hundreds of seeds. The widths are also checked, so a uselessly wide interval would fail.
#[test]
fn bias_and_variance_recovered_within_their_intervals() {
    let bias = [0.05, 0.0, -0.03];
    let (reference, runs, truth) = ensemble(1, 64, 16, bias, 0.2, false);
    let bv = bias_variance(&runs, &reference).unwrap();
    println!("truth (bias², σ², rel bias², rel σ²) = {truth:?}\n{bv:#?}");
    assert_eq!(bv.runs, 16);
    let named = [
        ("bias2", bv.bias2, truth[0]),
        ("variance", bv.variance, truth[1]),
        ("relative_bias2", bv.relative_bias2, truth[2]),
        ("relative_variance", bv.relative_variance, truth[3]),
    ];
    for (name, interval, true_value) in named {
        assert!(
            interval.contains(true_value),
            "{name}: {true_value} outside {interval:?}"
        );
        let half_width = 0.5 * (interval.hi - interval.lo);
        assert!(
            half_width < 0.15 * true_value,
            "{name}: interval {interval:?} too wide for {true_value}"
        );
    }
    // The mean signed error over runs estimates mean(b_c) = 0.02/3.
    let mean_bias = bias.iter().sum::<f64>() / 3.0;
    assert!(bv.mean_signed_error.contains(mean_bias), "{bv:?}");

    // Exact identities: bias² + variance = the mean over runs of each run's MSE, and likewise
    // relative bias² + relative variance = the mean over runs of relMSE.
    let k = runs.len() as f64;
    let mse = runs
        .iter()
        .map(|x| metrics(x, &reference).unwrap().rmse.powi(2))
        .sum::<f64>()
        / k;
    let relmse = runs
        .iter()
        .map(|x| metrics(x, &reference).unwrap().relmse)
        .sum::<f64>()
        / k;
    assert!(close(bv.bias2.mean + bv.variance.mean, mse, 1e-9));
    assert!(close(
        bv.relative_bias2.mean + bv.relative_variance.mean,
        relmse,
        1e-9
    ));
}

/// The 95% intervals cover the truth at the stated rate, and the t-test's false rejection
/// rate at level 0.05 is about 5%, over 400 seeded ensembles (deterministic).
///
/// With a flat reference every pixel-channel term has the same distribution, the intervals'
/// model exactly, and coverage is 95%. With a varying reference (σ² ∝ y, bias per channel)
/// the terms' expectations differ from pixel to pixel; the spread of the terms then includes
/// that spread, which does not vary between runs, so the intervals are conservative (cover
/// more often than 95%) — the right direction for a bench that flags bias.
#[test]
fn intervals_cover_at_the_stated_rate() {
    let trials = 400u64;
    let rate = |n: usize| n as f64 / trials as f64;
    for flat in [true, false] {
        let mut cover = [0usize; 4];
        let mut rejections = 0;
        for seed in 0..trials {
            let (reference, runs, truth) =
                ensemble(1000 + seed, 16, 8, [0.1, 0.05, -0.08], 0.2, flat);
            let bv = bias_variance(&runs, &reference).unwrap();
            let intervals = [
                bv.bias2,
                bv.variance,
                bv.relative_bias2,
                bv.relative_variance,
            ];
            for j in 0..4 {
                cover[j] += usize::from(intervals[j].contains(truth[j]));
            }
            let (reference, runs, _) = ensemble(5000 + seed, 16, 8, [0.0; 3], 0.2, flat);
            let bv = bias_variance(&runs, &reference).unwrap();
            rejections += usize::from(bv.p_value < 0.05);
        }
        let rates = cover.map(rate);
        println!(
            "flat {flat}: coverage over {trials} of bias², variance, relative bias², relative \
             variance {rates:?}; t-test rejections at 0.05: {}",
            rate(rejections)
        );
        // Binomial(400, 0.95) has standard deviation 0.011: these bounds are > 3.5σ away.
        let upper = if flat { 0.99 } else { 1.0 };
        for r in rates {
            assert!((0.91..=upper).contains(&r), "flat {flat}: {rates:?}");
        }
        assert!(
            (0.01..=0.09).contains(&rate(rejections)),
            "{}",
            rate(rejections)
        );
    }
}

#[test]
fn t_test_rejects_bias_only_when_there_is_some() {
    // Unbiased: p well above 1e-3.
    let (reference, runs, _) = ensemble(7, 64, 16, [0.0; 3], 0.2, false);
    let unbiased = bias_variance(&runs, &reference).unwrap();
    println!(
        "unbiased: t = {}, p = {}",
        unbiased.t_statistic, unbiased.p_value
    );
    assert!(unbiased.p_value > 1e-3, "{unbiased:?}");
    assert!(unbiased.bias2.contains(0.0), "{unbiased:?}");

    // A bias of 0.005 per channel against noise 0.2·√y: each run's mean signed error has a
    // standard deviation ≈ 0.2·1.05/√12288 ≈ 0.0019, so over 16 runs t ≈ 0.005/(0.0019/4) ≈ 10.
    let (reference, runs, _) = ensemble(7, 64, 16, [0.005; 3], 0.2, false);
    let biased = bias_variance(&runs, &reference).unwrap();
    println!("biased: t = {}, p = {}", biased.t_statistic, biased.p_value);
    assert!(biased.p_value < 1e-3, "{biased:?}");
    assert!(biased.t_statistic > 0.0);

    // A deterministic biased "estimator": every run identical, t is finite, p = 0.
    let (reference, runs, _) = ensemble(7, 8, 1, [0.01; 3], 0.0, false);
    let same = vec![runs[0].clone(), runs[0].clone(), runs[0].clone()];
    let bv = bias_variance(&same, &reference).unwrap();
    assert!(bv.t_statistic.is_finite() && bv.t_statistic > 0.0 && bv.p_value == 0.0);
    // And runs equal to the reference: no error at all, p = 1.
    let exact = vec![reference.clone(), reference.clone()];
    let bv = bias_variance(&exact, &reference).unwrap();
    assert_eq!((bv.t_statistic, bv.p_value), (0.0, 1.0));
    assert_eq!(bv.bias2.mean, 0.0);
}

// ---------------------------------------------------------------------------------------------
// Convergence slope

/// `n` log-spaced checkpoints from 1 to 1000.
fn log_spaced(n: usize) -> Vec<f64> {
    (0..n)
        .map(|k| 10f64.powf(3.0 * k as f64 / (n - 1) as f64))
        .collect()
}

#[test]
fn slope_fit_recovers_an_exact_power_law() {
    let x = log_spaced(12);
    let y: Vec<f64> = x.iter().map(|t| 3.0 / t).collect();
    let fit = fit_power_law(&x, &y).unwrap();
    println!("exact: {fit:?}");
    assert!((fit.slope + 1.0).abs() < 1e-12, "{fit:?}");
    assert!((fit.intercept - 3f64.ln()).abs() < 1e-12, "{fit:?}");
    assert!(fit.slope_se < 1e-12 && fit.points == 12);

    let y: Vec<f64> = x.iter().map(|t| 0.5 * t.powf(-2.0 / 3.0)).collect();
    let fit = fit_power_law(&x, &y).unwrap();
    assert!((fit.slope + 2.0 / 3.0).abs() < 1e-12, "{fit:?}");
}

#[test]
fn slope_fit_recovers_a_noisy_power_law() {
    // y = 2·x^−1·exp(0.2·N(0, 1)): log-normal noise is additive in log space, so ordinary
    // least squares is the right fit and its slope error is 0.2/√Σ(ln x − mean)².
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(42);
    let x = log_spaced(30);
    let y: Vec<f64> = x
        .iter()
        .map(|t| 2.0 / t * (0.2 * normal(&mut rng)).exp())
        .collect();
    let fit = fit_power_law(&x, &y).unwrap();
    let mean_u = x.iter().map(|t| t.ln()).sum::<f64>() / 30.0;
    let suu: f64 = x.iter().map(|t| (t.ln() - mean_u).powi(2)).sum();
    println!("noisy: {fit:?}, theoretical se {}", 0.2 / suu.sqrt());
    assert!((fit.slope + 1.0).abs() < 3.0 * fit.slope_se, "{fit:?}");
    assert!(close(fit.slope_se, 0.2 / suu.sqrt(), 0.5), "{fit:?}");
}

#[test]
fn slope_fit_over_the_later_half() {
    assert_eq!(later_half(&[1, 2, 3, 4, 5, 6, 7, 8]), &[5, 6, 7, 8]);
    assert_eq!(later_half(&[1, 2, 3, 4, 5]), &[3, 4, 5]);
    assert!(later_half::<u8>(&[]).is_empty());

    // A plateau at first (start-up), then y = x^−1 from the middle on: the later half sees
    // only the power law.
    let x = log_spaced(10);
    let y: Vec<f64> = x.iter().map(|&t| 1.0 / t.max(x[5])).collect();
    let fit = fit_later_half(&x, &y).unwrap();
    assert!(
        (fit.slope + 1.0).abs() < 1e-12 && fit.points == 5,
        "{fit:?}"
    );
}

#[test]
fn slope_fit_refuses_or_skips_bad_points() {
    assert!(fit_power_law(&[1.0, 2.0], &[1.0, 0.5]).is_none());
    assert!(fit_power_law(&[1.0, 2.0, 3.0], &[1.0, 0.5]).is_none());
    assert!(fit_power_law(&[2.0, 2.0, 2.0], &[1.0, 0.5, 0.3]).is_none());
    assert!(fit_power_law(&[], &[]).is_none());
    // Zero, negative and non-finite values are skipped; what remains is fitted.
    let x = [0.0, 1.0, 2.0, f64::NAN, 4.0, 8.0, -1.0];
    let y = [1.0, 1.0, 0.5, 1.0, 0.25, 0.125, 1.0];
    let fit = fit_power_law(&x, &y).unwrap();
    assert!(
        (fit.slope + 1.0).abs() < 1e-12 && fit.points == 4,
        "{fit:?}"
    );
    let y0 = [1.0, 1.0, 0.0, 1.0, 0.25, f64::INFINITY, 1.0];
    assert!(fit_power_law(&x, &y0).is_none()); // only (1, 1) and (4, 0.25) remain
    assert!(fit_later_half(&[1.0, 2.0], &[1.0]).is_none());
}

// ---------------------------------------------------------------------------------------------
// Reference noise

#[test]
fn reference_noise_from_two_halves() {
    // Two halves a, b = μ + N(0, σ²) per pixel-channel, μ in [0.5, 2.5), σ = 0.05. The
    // reference (a + b)/2 has variance σ²/2, so its relMSE is mean(σ²/2 / (μ² + 0.01)).
    // Statistical precision: 49 152 terms, each ∝ χ²₁ (relative sd √2): ≈ 0.6%; using y for μ
    // in the denominator adds a bias of order σ²/μ² < 1%.
    let (size, sigma) = (128u32, 0.05);
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(3);
    let (mut a, mut b) = (Image::new(size, size), Image::new(size, size));
    let mut truth = 0.0;
    for i in 0..a.pixels.len() {
        for c in 0..3 {
            let mu = 0.5 + 2.0 * rng.random::<f64>();
            truth += 0.5 * sigma * sigma / (mu * mu + 0.01);
            a.pixels[i].0[c] = (mu + sigma * normal(&mut rng)) as f32;
            b.pixels[i].0[c] = (mu + sigma * normal(&mut rng)) as f32;
        }
    }
    truth /= (a.pixels.len() * 3) as f64;
    let estimate = reference_noise(&a, &b).unwrap();
    // The tempting "relMSE between the halves" is four times too large.
    let between = metrics(&a, &b).unwrap().relmse;
    println!(
        "reference noise: estimate {estimate:.6e}, truth {truth:.6e}, relMSE(a, b) / truth {}",
        between / truth
    );
    assert!(close(estimate, truth, 0.03), "{estimate} vs {truth}");
    assert!(close(between / truth, 4.0, 0.05));
    // Identical halves: no noise.
    assert_eq!(reference_noise(&a, &a).unwrap(), 0.0);
}
