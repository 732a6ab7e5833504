//! Spectrum to RGB conversion against Mitsuba 3, and the named IOR and conductor tables.

use mltbench::math::Rgb;
use mltbench::scene::spectra::{
    SpectrumUse, conductor_names, named_conductor, named_ior, spectrum_to_rgb,
    uniform_spectrum_to_rgb,
};

fn parse(spectrum: &str) -> Vec<(f32, f32)> {
    spectrum
        .split(',')
        .map(|pair| {
            let (w, v) = pair.trim().split_once(':').unwrap();
            (w.parse().unwrap(), v.parse().unwrap())
        })
        .collect()
}

fn assert_close(got: Rgb, want: [f32; 3], relative: f32, what: &str) {
    for (c, (g, w)) in got.0.into_iter().zip(want).enumerate() {
        let tolerance = relative * w.abs().max(1e-3);
        assert!(
            (g - w).abs() <= tolerance,
            "{what}: channel {c} is {g}, Mitsuba 3 gives {w} ({got:?})"
        );
    }
}

const CBOX_WHITE: &str = "400:0.343, 404:0.445, 408:0.551, 412:0.624, 416:0.665, 420:0.687, 424:0.708, 428:0.723, 432:0.715, 436:0.71, 440:0.745, 444:0.758, 448:0.739, 452:0.767, 456:0.777, 460:0.765, 464:0.751, 468:0.745, 472:0.748, 476:0.729, 480:0.745, 484:0.757, 488:0.753, 492:0.75, 496:0.746, 500:0.747, 504:0.735, 508:0.732, 512:0.739, 516:0.734, 520:0.725, 524:0.721, 528:0.733, 532:0.725, 536:0.732, 540:0.743, 544:0.744, 548:0.748, 552:0.728, 556:0.716, 560:0.733, 564:0.726, 568:0.713, 572:0.74, 576:0.754, 580:0.764, 584:0.752, 588:0.736, 592:0.734, 596:0.741, 600:0.74, 604:0.732, 608:0.745, 612:0.755, 616:0.751, 620:0.744, 624:0.731, 628:0.733, 632:0.744, 636:0.731, 640:0.712, 644:0.708, 648:0.729, 652:0.73, 656:0.727, 660:0.707, 664:0.703, 668:0.729, 672:0.75, 676:0.76, 680:0.751, 684:0.739, 688:0.724, 692:0.73, 696:0.74, 700:0.737";
const CBOX_RED: &str = "400:0.04, 404:0.046, 408:0.048, 412:0.053, 416:0.049, 420:0.05, 424:0.053, 428:0.055, 432:0.057, 436:0.056, 440:0.059, 444:0.057, 448:0.061, 452:0.061, 456:0.06, 460:0.062, 464:0.062, 468:0.062, 472:0.061, 476:0.062, 480:0.06, 484:0.059, 488:0.057, 492:0.058, 496:0.058, 500:0.058, 504:0.056, 508:0.055, 512:0.056, 516:0.059, 520:0.057, 524:0.055, 528:0.059, 532:0.059, 536:0.058, 540:0.059, 544:0.061, 548:0.061, 552:0.063, 556:0.063, 560:0.067, 564:0.068, 568:0.072, 572:0.08, 576:0.09, 580:0.099, 584:0.124, 588:0.154, 592:0.192, 596:0.255, 600:0.287, 604:0.349, 608:0.402, 612:0.443, 616:0.487, 620:0.513, 624:0.558, 628:0.584, 632:0.62, 636:0.606, 640:0.609, 644:0.651, 648:0.612, 652:0.61, 656:0.65, 660:0.638, 664:0.627, 668:0.62, 672:0.63, 676:0.628, 680:0.642, 684:0.639, 688:0.657, 692:0.639, 696:0.635, 700:0.642";
const CBOX_GREEN: &str = "400:0.092, 404:0.096, 408:0.098, 412:0.097, 416:0.098, 420:0.095, 424:0.095, 428:0.097, 432:0.095, 436:0.094, 440:0.097, 444:0.098, 448:0.096, 452:0.101, 456:0.103, 460:0.104, 464:0.107, 468:0.109, 472:0.112, 476:0.115, 480:0.125, 484:0.14, 488:0.16, 492:0.187, 496:0.229, 500:0.285, 504:0.343, 508:0.39, 512:0.435, 516:0.464, 520:0.472, 524:0.476, 528:0.481, 532:0.462, 536:0.447, 540:0.441, 544:0.426, 548:0.406, 552:0.373, 556:0.347, 560:0.337, 564:0.314, 568:0.285, 572:0.277, 576:0.266, 580:0.25, 584:0.23, 588:0.207, 592:0.186, 596:0.171, 600:0.16, 604:0.148, 608:0.141, 612:0.136, 616:0.13, 620:0.126, 624:0.123, 628:0.121, 632:0.122, 636:0.119, 640:0.114, 644:0.115, 648:0.117, 652:0.117, 656:0.118, 660:0.12, 664:0.122, 668:0.128, 672:0.132, 676:0.139, 680:0.144, 684:0.146, 688:0.15, 692:0.152, 696:0.157, 700:0.159";

/// What Mitsuba 3.9.1 (scalar_rgb) makes of these spectra through its XML parser, printed by
/// experiments/tools/spectra_reference.py (same spectra, same usages): a diffuse reflectance
/// for Reflectance, a constant emitter's radiance for Emission, a conductor's eta for
/// Unbounded. Measured agreement: 4e-6 relative at worst; the test allows 1e-4 (Mitsuba
/// printed 7 significant digits).
const MITSUBA_REFERENCES: [(&str, SpectrumUse, &str, [f32; 3]); 13] = [
    (
        "cbox white",
        SpectrumUse::Reflectance,
        CBOX_WHITE,
        [0.735013, 0.7356246, 0.7362643],
    ),
    (
        "cbox red",
        SpectrumUse::Reflectance,
        CBOX_RED,
        [0.49132, 0.04922811, 0.0509219],
    ),
    (
        "cbox green",
        SpectrumUse::Reflectance,
        CBOX_GREEN,
        [0.06828254, 0.3977602, 0.08629087],
    ),
    (
        "constant",
        SpectrumUse::Reflectance,
        "360:0.5, 830:0.5",
        [0.4994926, 0.4994369, 0.4994008],
    ),
    (
        "band",
        SpectrumUse::Reflectance,
        "450:1, 650:1",
        [0.8412538, 1.0, 0.5002488],
    ),
    (
        "green peak",
        SpectrumUse::Reflectance,
        "500:0, 520:1, 540:0",
        [0.0, 0.2462953, 0.0],
    ),
    (
        "bright red",
        SpectrumUse::Reflectance,
        "580:0, 600:5, 640:5, 660:0",
        [1.0, 0.006118373, 0.0],
    ),
    (
        "cbox light",
        SpectrumUse::Emission,
        "400:0, 500:8, 600:15.6, 700:18.4",
        [20.71084, 10.85463, 2.771152],
    ),
    (
        "constant",
        SpectrumUse::Emission,
        "360:0.5, 830:0.5",
        [0.6024418, 0.4741141, 0.4546334],
    ),
    (
        "blue line",
        SpectrumUse::Emission,
        "440:0, 450:10, 460:0",
        [0.1330454, 0.0, 1.753532],
    ),
    (
        "constant",
        SpectrumUse::Unbounded,
        "360:0.5, 830:0.5",
        [0.4994926, 0.4994369, 0.4994008],
    ),
    (
        "rising eta",
        SpectrumUse::Unbounded,
        "400:0.2, 700:1.5",
        [1.244461, 0.8193434, 0.3758365],
    ),
    (
        "blue line",
        SpectrumUse::Unbounded,
        "440:0, 450:10, 460:0",
        [0.1537241, 0.0, 2.03877],
    ),
];

#[test]
fn agrees_with_mitsuba() {
    let mut worst = 0.0f32;
    for (name, usage, spectrum, mitsuba) in MITSUBA_REFERENCES {
        let rgb = spectrum_to_rgb(&parse(spectrum), usage);
        eprintln!(
            "{name:12} {usage:?}: mltbench {:?}, Mitsuba 3 {mitsuba:?}",
            rgb.0
        );
        for (g, w) in rgb.0.into_iter().zip(mitsuba) {
            worst = worst.max((g - w).abs() / w.abs().max(1e-3));
        }
        assert_close(rgb, mitsuba, 1e-4, &format!("{name} ({usage:?})"));
    }
    eprintln!("largest relative difference: {worst:e}");
}

#[test]
fn constant_spectra() {
    // A constant reflectance seen under D65 is grey: about the constant (Mitsuba's D65
    // normalisation leaves it 0.11 % low), for any constant, and linear in it.
    for c in [0.1f32, 0.5, 1.0] {
        let rgb = spectrum_to_rgb(&[(360.0, c), (830.0, c)], SpectrumUse::Reflectance);
        for v in rgb.0 {
            assert!((v - c).abs() <= 2e-3 * c, "reflectance {c} -> {rgb:?}");
        }
        // Unbounded spectra are D65-weighted too, and may exceed 1.
        let big = spectrum_to_rgb(
            &[(360.0, 3.0 * c), (830.0, 3.0 * c)],
            SpectrumUse::Unbounded,
        );
        for (b, v) in big.0.iter().zip(rgb.0) {
            assert!((b - 3.0 * v).abs() <= 1e-5 * b, "unbounded {c} -> {big:?}");
        }
    }
    // A constant emission is the equal-energy white E: the CIE functions have equal areas, so
    // X = Y = Z = c, which the BT.709 matrix maps to c times its row sums.
    let row_sums = [1.204794f32, 0.948291, 0.908916];
    for c in [0.5f32, 2.0, 40.0] {
        let rgb = spectrum_to_rgb(&[(360.0, c), (830.0, c)], SpectrumUse::Emission);
        assert_close(rgb, row_sums.map(|s| s * c), 1e-3, "constant emission");
        // A single value inside an emitter is the same colour.
        assert_close(
            uniform_spectrum_to_rgb(c, SpectrumUse::Emission),
            row_sums.map(|s| s * c),
            1e-6,
            "uniform emission",
        );
    }
    assert_eq!(
        uniform_spectrum_to_rgb(0.3, SpectrumUse::Reflectance),
        Rgb::splat(0.3)
    );
    assert_eq!(
        uniform_spectrum_to_rgb(1.5, SpectrumUse::Unbounded),
        Rgb::splat(1.5)
    );
}

#[test]
fn clamping_rules() {
    // A bright red band: red far above 1 and blue below 0 before clamping.
    let red = parse("580:0, 600:5, 640:5, 660:0");
    let reflectance = spectrum_to_rgb(&red, SpectrumUse::Reflectance);
    assert_eq!((reflectance.r(), reflectance.b()), (1.0, 0.0));
    let unbounded = spectrum_to_rgb(&red, SpectrumUse::Unbounded);
    assert!(unbounded.r() > 4.0 && unbounded.b() == 0.0, "{unbounded:?}");
    let emission = spectrum_to_rgb(&red, SpectrumUse::Emission);
    assert!(emission.r() > 4.0 && emission.b() == 0.0, "{emission:?}");
    for usage in [
        SpectrumUse::Reflectance,
        SpectrumUse::Emission,
        SpectrumUse::Unbounded,
    ] {
        // Negative values clamp to 0, never below.
        let negative = spectrum_to_rgb(&[(360.0, -1.0), (830.0, -1.0)], usage);
        assert_eq!(negative, Rgb::BLACK);
    }
}

#[test]
fn zero_outside_the_given_wavelengths() {
    for usage in [
        SpectrumUse::Reflectance,
        SpectrumUse::Emission,
        SpectrumUse::Unbounded,
    ] {
        assert_eq!(
            spectrum_to_rgb(&[(900.0, 1.0), (1000.0, 1.0)], usage),
            Rgb::BLACK
        );
        assert_eq!(
            spectrum_to_rgb(&[(200.0, 1.0), (350.0, 1.0)], usage),
            Rgb::BLACK
        );
        assert_eq!(spectrum_to_rgb(&[], usage), Rgb::BLACK);
        assert_eq!(spectrum_to_rgb(&[(550.0, 1.0)], usage), Rgb::BLACK);
        // Extending a spectrum beyond 360–830 nm changes nothing.
        let inside = spectrum_to_rgb(&[(360.0, 0.2), (830.0, 0.2)], usage);
        let wider = spectrum_to_rgb(
            &[(300.0, 0.2), (360.0, 0.2), (830.0, 0.2), (900.0, 0.2)],
            usage,
        );
        assert_close(wider, inside.0, 1e-6, "wider");
        // Duplicate or unsorted wavelengths do not panic.
        let rgb = spectrum_to_rgb(
            &[(500.0, 1.0), (500.0, 2.0), (600.0, 1.0), (550.0, 3.0)],
            usage,
        );
        assert!(rgb.0.iter().all(|c| c.is_finite()));
    }
}

#[test]
fn named_iors() {
    // The names scenes use most, with the values of Mitsuba 3's IOR table (its plugin
    // documentation), in increasing order as physics has them: gases, liquids, glasses,
    // diamond.
    let spot_checks = [
        ("vacuum", 1.0),
        ("air", 1.000277),
        ("water", 1.3330),
        ("fused quartz", 1.458),
        ("bk7", 1.5046),
        ("diamond", 2.419),
    ];
    for (name, ior) in spot_checks {
        assert_eq!(named_ior(name), Some(ior), "{name}");
    }
    assert!(spot_checks.windows(2).all(|w| w[0].1 < w[1].1));
    // Matched without regard to case; unknown names are not guessed.
    assert_eq!(named_ior("BK7"), Some(1.5046));
    assert_eq!(named_ior("Water Ice"), Some(1.31));
    assert_eq!(named_ior("glass"), None);
    assert_eq!(named_ior(""), None);
}

#[test]
fn named_conductors_are_physical() {
    for name in ["Au", "Ag", "Cu", "Al", "Cr", "W", "Cu2O"] {
        assert!(named_conductor(name).is_some(), "{name}");
    }
    for name in conductor_names() {
        let (eta, k) = named_conductor(name).unwrap();
        assert!(
            eta.0.iter().chain(&k.0).all(|c| c.is_finite() && *c >= 0.0),
            "{name}"
        );
    }
    // (Some data sets stop short of the visible range, e.g. AlSb's at 590 nm: their red η and
    // k are 0 in Mitsuba too. The common metals cover it.)
    for name in ["Au", "Ag", "Cu", "Al", "Cr", "W"] {
        let (eta, k) = named_conductor(name).unwrap();
        assert!(eta.0.iter().chain(&k.0).all(|&c| c > 0.0), "{name}");
    }
    // Gold and copper reflect red best: η is smallest in red, k largest in red.
    for name in ["Au", "Cu"] {
        let (eta, k) = named_conductor(name).unwrap();
        assert!(eta.r() < eta.b() && k.r() > k.b(), "{name}: {eta:?} {k:?}");
    }
    // Silver and aluminium are metals with a large extinction coefficient everywhere.
    for name in ["Ag", "Al"] {
        let (_, k) = named_conductor(name).unwrap();
        assert!(k.0.iter().all(|&c| c > 2.0), "{name}: {k:?}");
    }
    assert_eq!(named_conductor("none"), None);
    assert_eq!(named_conductor("au"), None);
    assert_eq!(named_conductor("unobtainium"), None);
}

/// Recomputes the named-conductor table from Mitsuba's own spectral files with
/// `spectrum_to_rgb` (Emission: no D65, negatives clamped), to show the table is what this
/// code makes of the data. Needs a Mitsuba 3.9 wheel:
/// `MITSUBA_IOR_DIR=/work/venv-mitsuba/lib/python3.11/site-packages/mitsuba/data/ior
///  cargo test --release --test spectra -- --ignored`
#[test]
#[ignore = "needs MITSUBA_IOR_DIR pointing at a Mitsuba 3 wheel's data/ior"]
fn named_conductors_from_mitsuba_spectral_data() {
    let dir = std::path::PathBuf::from(std::env::var("MITSUBA_IOR_DIR").expect("MITSUBA_IOR_DIR"));
    let read = |file: String| -> Vec<(f32, f32)> {
        let text =
            std::fs::read_to_string(dir.join(&file)).unwrap_or_else(|e| panic!("{file}: {e}"));
        text.lines()
            .map(|l| l.split('#').next().unwrap().trim())
            .filter(|l| !l.is_empty())
            .map(|l| {
                let mut words = l.split_whitespace().map(|w| w.parse::<f32>().unwrap());
                (words.next().unwrap(), words.next().unwrap())
            })
            .collect()
    };
    let mut worst = 0.0f32;
    for name in conductor_names() {
        let (eta, k) = named_conductor(name).unwrap();
        for (table, file) in [
            (eta, format!("{name}.eta.spd")),
            (k, format!("{name}.k.spd")),
        ] {
            let rgb = spectrum_to_rgb(&read(file.clone()), SpectrumUse::Emission);
            for (got, want) in rgb.0.into_iter().zip(table.0) {
                let error = (got - want).abs() / want.abs().max(1e-3);
                worst = worst.max(error);
                assert!(error < 1e-4, "{file}: {rgb:?}, table {table:?}");
            }
        }
    }
    eprintln!("largest relative difference: {worst:e}");
}
