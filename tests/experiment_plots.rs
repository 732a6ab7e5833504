//! The experiment plots: files written (and nothing else), PNGs that decode with text and
//! colour in them, SVGs that parse and name their series, and errors rather than panics on
//! empty, NaN or inconsistent data.
//!
//! Set `MLTBENCH_PLOT_DIR=/some/dir` to keep the figures for a look.

mod dir_support;

use std::collections::HashSet;
use std::path::{Path, PathBuf};

use dir_support::listing;
use mltbench::experiment::plot::{
    Band, Crop, Series, SheetEntry, bias_variance_plot, check_crops, contact_sheet,
    convergence_plot, viridis,
};
use mltbench::image::Image;
use mltbench::math::Rgb;

/// A fresh directory for one test.
fn out_dir(test: &str) -> PathBuf {
    let dir = match std::env::var_os("MLTBENCH_PLOT_DIR") {
        Some(base) => PathBuf::from(base).join(test),
        None => std::env::temp_dir().join(format!("mltbench-plots-{}-{test}", std::process::id())),
    };
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn done(dir: &Path) {
    if std::env::var_os("MLTBENCH_PLOT_DIR").is_none() {
        let _ = std::fs::remove_dir_all(dir);
    }
}

struct Png {
    width: u32,
    height: u32,
    pixels: Vec<[u8; 3]>,
}

impl Png {
    fn read(path: &Path) -> Png {
        let file = std::fs::File::open(path).unwrap();
        let decoder = png::Decoder::new(std::io::BufReader::new(file));
        let mut reader = decoder.read_info().unwrap();
        let mut buf = vec![0; reader.output_buffer_size().unwrap()];
        let info = reader.next_frame(&mut buf).unwrap();
        assert_eq!(info.color_type, png::ColorType::Rgb);
        assert_eq!(info.bit_depth, png::BitDepth::Eight);
        let pixels = buf[..info.buffer_size()]
            .chunks_exact(3)
            .map(|c| [c[0], c[1], c[2]])
            .collect();
        Png {
            width: info.width,
            height: info.height,
            pixels,
        }
    }

    fn distinct_colors(&self) -> usize {
        self.pixels.iter().collect::<HashSet<_>>().len()
    }

    fn count(&self, rows: std::ops::Range<u32>, pred: impl Fn([u8; 3]) -> bool) -> usize {
        rows.flat_map(|y| (0..self.width).map(move |x| (x, y)))
            .filter(|&(x, y)| pred(self.pixels[(y * self.width + x) as usize]))
            .count()
    }

    fn has(&self, color: [u8; 3]) -> bool {
        self.pixels.contains(&color)
    }
}

fn dark(p: [u8; 3]) -> bool {
    p.iter().all(|&c| c < 80)
}

/// The SVG parsed as XML, and the text of all its `<text>` elements.
fn svg_texts(path: &Path) -> Vec<String> {
    let source = std::fs::read_to_string(path).unwrap();
    let doc = roxmltree::Document::parse(&source).expect("the SVG is well-formed XML");
    assert_eq!(doc.root_element().tag_name().name(), "svg");
    doc.descendants()
        .filter(|n| n.has_tag_name("text"))
        .map(|n| n.text().unwrap_or("").trim().to_string())
        .collect()
}

/// A power law a·x^slope with a ×/÷ spread band, at 10 log-spaced x from 0.5.
fn power_law(label: &str, a: f64, slope: f64, spread: f64) -> Series {
    let x: Vec<f64> = (0..10).map(|i| 0.5 * 2f64.powi(i)).collect();
    let mean: Vec<f64> = x.iter().map(|&x| a * x.powf(slope)).collect();
    Series {
        label: label.to_string(),
        band: Band {
            lo: mean.iter().map(|m| m / spread).collect(),
            hi: mean.iter().map(|m| m * spread).collect(),
            x,
            mean,
        },
    }
}

const GUIDES: [(f64, &str); 2] = [(-1.0, "slope −1"), (-2.0 / 3.0, "slope −2/3")];

/// Checks a plot's PNG and SVG; returns the SVG's texts.
fn check_plot(dir: &Path, stem: &str) -> (Png, Vec<String>) {
    assert_eq!(listing(dir), [format!("{stem}.png"), format!("{stem}.svg")]);
    let png = Png::read(&dir.join(format!("{stem}.png")));
    assert_eq!((png.width, png.height), (960, 640));
    // Text: the title in the top rows, tick and axis labels under the plot.
    assert!(png.count(0..50, dark) > 100, "no title text");
    assert!(png.count(570..640, dark) > 40, "no axis text");
    let texts = svg_texts(&dir.join(format!("{stem}.svg")));
    (png, texts)
}

#[test]
fn convergence_plot_draws_lines_bands_guides_and_legend() {
    let dir = out_dir("convergence");
    let series = [
        power_law("pt", 0.3, -1.0, 1.3),
        power_law("eyelight (biased)", 0.05, -0.4, 1.15),
        power_law("sppm α=2/3", 1.0, -2.0 / 3.0, 1.5),
    ];
    convergence_plot(
        &dir.join("convergence"),
        "cbox: relMSE against time",
        "time (s)",
        "relMSE",
        &series,
        &GUIDES,
    )
    .unwrap();
    let (png, texts) = check_plot(&dir, "convergence");
    assert!(
        png.distinct_colors() > 50,
        "{} colours",
        png.distinct_colors()
    );
    // The first two series' colours (Okabe–Ito blue and vermillion) are drawn as lines.
    assert!(png.has([0, 114, 178]) && png.has([213, 94, 0]));
    for want in [
        "cbox: relMSE against time",
        "time (s)",
        "relMSE",
        "pt",
        "eyelight (biased)",
        "sppm α=2/3",
        "slope −1",
        "slope −2/3",
        // Powers of ten on both axes.
        "10⁻²",
        "10⁰",
        "10²",
    ] {
        assert!(texts.iter().any(|t| t == want), "no {want:?} in {texts:?}");
    }
    // The legend (in the free lower-left corner here) has text on white.
    let legend_text = png.count(440..560, dark);
    assert!(
        legend_text > 100,
        "{legend_text} dark pixels in the legend rows"
    );
    done(&dir);
}

#[test]
fn bias_variance_plot_pairs_colours_and_styles() {
    let dir = out_dir("bias");
    let var = [
        power_law("pt", 0.3, -1.0, 1.2),
        power_law("eyelight", 0.01, -1.0, 1.2),
    ];
    // eyelight's bias² levels off; pt's is noise around zero, some of it negative.
    let mut pt_bias = power_law("pt", 1e-4, -1.0, 2.0);
    pt_bias.band.mean[3] = -1e-6;
    pt_bias.band.mean[7] = -2e-7;
    let bias = [pt_bias, power_law("eyelight", 0.02, 0.0, 1.1)];
    bias_variance_plot(
        &dir.join("bias"),
        "cbox: bias² and variance",
        "time (s)",
        &bias,
        &var,
    )
    .unwrap();
    let (png, texts) = check_plot(&dir, "bias");
    assert!(png.has([0, 114, 178]) && png.has([213, 94, 0]));
    for want in [
        "pt",
        "eyelight",
        "variance",
        "bias²",
        "2 points not finite or ≤ 0 left out",
    ] {
        assert!(texts.iter().any(|t| t == want), "no {want:?} in {texts:?}");
    }
    // Each estimator is named once in the legend.
    assert_eq!(texts.iter().filter(|t| *t == "pt").count(), 1);
    done(&dir);
}

#[test]
fn empty_and_nan_data_give_valid_plots() {
    let dir = out_dir("empty");
    convergence_plot(
        &dir.join("none"),
        "nothing yet",
        "passes",
        "relMSE",
        &[],
        &GUIDES,
    )
    .unwrap();
    let (_, texts) = check_plot(&dir, "none");
    assert!(texts.iter().any(|t| t == "no data to plot"), "{texts:?}");
    done(&dir);

    let dir = out_dir("nan");
    let bad = Series {
        label: "broken".into(),
        band: Band {
            x: vec![1.0, 2.0, f64::NAN, 4.0, 8.0, -1.0, 16.0],
            mean: vec![f64::NAN, 0.5, 0.4, f64::INFINITY, 0.1, 0.1, 0.0],
            lo: vec![0.1],         // shorter than x: the band collapses
            hi: vec![f64::NAN; 9], // longer than x: ignored
        },
    };
    let all_nan = Series {
        label: "all NaN".into(),
        band: Band {
            x: vec![f64::NAN; 3],
            mean: vec![f64::NAN; 3],
            lo: vec![f64::NAN; 3],
            hi: vec![f64::NAN; 3],
        },
    };
    let single = Series {
        label: "one point".into(),
        band: Band {
            x: vec![3.0],
            mean: vec![0.2],
            lo: vec![-0.1], // a band reaching below zero goes to the axis
            hi: vec![0.3],
        },
    };
    let guides = [(f64::NAN, "nan slope"), (0.0, "flat"), (2.0, "rising")];
    convergence_plot(
        &dir.join("nan"),
        "bad data",
        "s",
        "e",
        &[bad, all_nan, single],
        &guides,
    )
    .unwrap();
    let (_, texts) = check_plot(&dir, "nan");
    // Short axes: ticks at 1, 2, 5 × 10ⁿ, labelled as plain numbers.
    for want in [
        "broken",
        "all NaN (no data)",
        "one point",
        "0.1",
        "0.2",
        "0.5",
        "2",
        "5",
    ] {
        assert!(texts.iter().any(|t| t == want), "no {want:?} in {texts:?}");
    }
    assert!(
        texts
            .iter()
            .any(|t| t == "8 points not finite or ≤ 0 left out"),
        "{texts:?}"
    );
    bias_variance_plot(&dir.join("bv"), "empty", "s", &[], &[]).unwrap();
    svg_texts(&dir.join("bv.svg"));
    done(&dir);
}

/// A deterministic hash in [0, 1) for synthetic noise.
fn hash01(i: u64) -> f32 {
    let mut z = i.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    ((z ^ (z >> 31)) >> 40) as f32 / (1u64 << 24) as f32
}

/// A small synthetic scene: a lit gradient with a bright blob (a "caustic").
fn reference_image(w: u32, h: u32) -> Image {
    let mut image = Image::new(w, h);
    for y in 0..h {
        for x in 0..w {
            let (u, v) = (x as f32 / w as f32, y as f32 / h as f32);
            let blob = 8.0 * (-((u - 0.7).powi(2) + (v - 0.65).powi(2)) / 0.004).exp();
            let c = Rgb::new(
                0.6 * u + 0.1 + blob,
                0.3 + 0.2 * v + blob,
                0.2 + 0.5 * (1.0 - u) + 0.6 * blob,
            );
            image.set(x, y, c);
        }
    }
    image
}

/// The reference with multiplicative noise of relative size about `noise`, and its
/// per-pixel relative error |x − y| / (y + 0.01), averaged over the channels.
fn noisy(reference: &Image, noise: f32, seed: u64) -> (Image, Vec<f32>) {
    let mut image = reference.clone();
    for (i, p) in image.pixels.iter_mut().enumerate() {
        let k = 1.0 + noise * 1.7 * (2.0 * hash01(seed * 1_000_003 + i as u64) - 1.0);
        *p = Rgb::new(p.r() * k, p.g() * k, p.b() * k);
    }
    let map = image
        .pixels
        .iter()
        .zip(&reference.pixels)
        .map(|(x, y)| {
            (0..3)
                .map(|c| (x.0[c] - y.0[c]).abs() / (y.0[c] + 0.01))
                .sum::<f32>()
                / 3.0
        })
        .collect();
    (image, map)
}

fn crop(label: &str, x: u32, y: u32, width: u32, height: u32) -> Crop {
    Crop {
        label: label.into(),
        x,
        y,
        width,
        height,
    }
}

#[test]
fn contact_sheet_shows_images_error_maps_and_crops() {
    let dir = out_dir("sheet");
    let reference = reference_image(96, 64);
    let (pt, pt_map) = noisy(&reference, 0.3, 1);
    let (mut bdpt, mut bdpt_map) = noisy(&reference, 0.05, 2);
    // A broken pixel must show, not poison the sheet.
    bdpt.set(5, 40, Rgb::new(f32::NAN, 0.0, 0.0));
    bdpt_map[40 * 96 + 5] = f32::NAN;
    let entries = [
        SheetEntry {
            label: "pt".into(),
            image: pt,
            error_map: pt_map,
        },
        SheetEntry {
            label: "bdpt (max depth 8)".into(),
            image: bdpt,
            error_map: bdpt_map,
        },
    ];
    let crops = [
        crop("caustic", 60, 34, 16, 12),
        crop("corner", 0, 0, 10, 10),
    ];
    contact_sheet(&dir.join("sheet"), &reference, &entries, &crops).unwrap();
    assert_eq!(listing(&dir), ["sheet.png"]);
    let png = Png::read(&dir.join("sheet.png"));
    // Three rows: 288×192 tiles (96×64 enlarged 3×) for the image and the error map, the
    // crops enlarged 16× (256×192) and 19× (190×190).
    let min_width = 2 * 288 + 256 + 190;
    assert!(
        png.width >= min_width && png.height >= 3 * 192,
        "{}×{}",
        png.width,
        png.height
    );
    assert!(
        png.distinct_colors() > 1000,
        "{} colours",
        png.distinct_colors()
    );
    // Column titles in the top rows; crop outlines in their colours; the NaN pixel magenta.
    assert!(png.count(0..40, dark) > 100);
    assert!(png.has([230, 159, 0]) && png.has([86, 180, 233]));
    assert!(png.has([255, 0, 255]));
    // The colour bar's ends.
    assert!(png.has(viridis(0.0)) && png.has(viridis(1.0)));
    done(&dir);
}

#[test]
fn contact_sheet_of_the_reference_alone() {
    let dir = out_dir("sheet-alone");
    let reference = reference_image(40, 30);
    contact_sheet(&dir.join("sheet"), &reference, &[], &[]).unwrap();
    let png = Png::read(&dir.join("sheet.png"));
    assert!(png.count(0..40, dark) > 50);
    // A tiny image is enlarged by a whole factor; a big one shrunk to the same tile size.
    let big = reference_image(1000, 700);
    contact_sheet(
        &dir.join("big"),
        &big,
        &[],
        &[crop("middle", 400, 300, 200, 100)],
    )
    .unwrap();
    Png::read(&dir.join("big.png"));
    done(&dir);
}

#[test]
fn contact_sheet_rejects_inconsistent_input() {
    let dir = out_dir("sheet-bad");
    let reference = reference_image(20, 10);
    let stem = dir.join("sheet");
    let entry = |w: u32, h: u32, n: usize| SheetEntry {
        label: "x".into(),
        image: reference_image(w, h),
        error_map: vec![0.1; n],
    };
    assert!(contact_sheet(&stem, &reference, &[entry(20, 10, 199)], &[]).is_err());
    assert!(contact_sheet(&stem, &reference, &[entry(10, 20, 200)], &[]).is_err());
    assert!(contact_sheet(&stem, &Image::new(0, 0), &[], &[]).is_err());
    let outside = [crop("off", 15, 5, 10, 2)];
    assert!(contact_sheet(&stem, &reference, &[], &outside).is_err());
    assert!(check_crops(&outside, 20, 10).is_err());
    assert!(check_crops(&[crop("empty", 0, 0, 0, 3)], 20, 10).is_err());
    assert!(check_crops(&[crop("edge", 10, 5, 10, 5)], 20, 10).is_ok());
    assert!(listing(&dir).is_empty(), "nothing written on error");
    done(&dir);
}

#[test]
fn viridis_runs_from_dark_purple_to_yellow() {
    assert_eq!(viridis(0.0), [68, 1, 84]);
    assert_eq!(viridis(1.0), [253, 231, 37]);
    // matplotlib's entries 127 and 128: (33, 144, 141) and (33, 145, 140).
    let mid = viridis(0.5);
    for (got, want) in mid.iter().zip([33u8, 144, 140]) {
        assert!(got.abs_diff(want) <= 1, "{mid:?}");
    }
    assert_eq!(viridis(f32::NAN), viridis(0.0));
    assert_eq!(viridis(7.0), viridis(1.0));
}
