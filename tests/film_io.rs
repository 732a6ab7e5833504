//! Film accumulation (filters, tiles, splats, determinism) and image files (EXR, PNG,
//! tone mapping, atomic writes).

mod dir_support;

use std::path::{Path, PathBuf};

use dir_support::listing;
use glam::Vec2;
use mltbench::Error;
use mltbench::film::{Film, FilmTile, PixelRect, SplatList};
use mltbench::image::Image;
use mltbench::io::atomic::{write_atomically, write_file_atomically};
use mltbench::io::exr::{read_exr, write_exr};
use mltbench::io::png::{srgb_encode, srgb_to_u8, write_png_preview};
use mltbench::io::tonemap::{INVALID_PIXEL, Reinhard, reinhard};
use mltbench::math::Rgb;
use mltbench::scene::FilterDesc;
use rand::{RngExt, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

const GAUSS: FilterDesc = FilterDesc::Gaussian { stddev: 0.5 };

/// A fresh, empty directory for one test.
fn test_dir(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("film_io")
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn bits(image: &Image) -> Vec<[u32; 3]> {
    image.pixels.iter().map(|c| c.0.map(f32::to_bits)).collect()
}

fn whole(film: &Film) -> PixelRect {
    PixelRect {
        x0: 0,
        y0: 0,
        x1: film.width(),
        y1: film.height(),
    }
}

// ---------------------------------------------------------------------------------------
// Film

#[test]
fn box_filter_adds_a_sample_to_its_own_pixel_only() {
    let mut film = Film::new(8, 5, FilterDesc::Box).unwrap();
    let mut tile = film.tile(whole(&film));
    tile.add_sample(Vec2::new(3.7, 2.2), Rgb::new(1.0, 2.0, 3.0));
    // On a pixel's top-left corner: that pixel (floor).
    tile.add_sample(Vec2::new(5.0, 4.0), Rgb::new(4.0, 4.0, 4.0));
    film.merge_tile(&tile);
    let image = film.image(1.0);
    for y in 0..5 {
        for x in 0..8 {
            let expected = match (x, y) {
                (3, 2) => Rgb::new(1.0, 2.0, 3.0),
                (5, 4) => Rgb::splat(4.0),
                _ => Rgb::BLACK,
            };
            assert_eq!(image.get(x, y), expected, "pixel ({x}, {y})");
            let (_, w) = film.pixel_sums(x, y);
            assert_eq!(w, if expected.is_black() { 0.0 } else { 1.0 });
        }
    }
    assert_eq!(film.sample_count(), 2);
}

/// Mitsuba 3's Gaussian filter, σ = 0.5, radius 4σ = 2: exp(−t²/(2σ²)) − exp(−r²/(2σ²))
/// = exp(−2t²) − exp(−8) for |t| < 2, else 0.
fn gauss_by_hand(t: f64) -> f64 {
    if t.abs() < 2.0 {
        (-2.0 * t * t).exp() - (-8.0f64).exp()
    } else {
        0.0
    }
}

#[test]
fn gaussian_weights_of_one_sample_are_the_separable_truncated_gaussian() {
    let mut film = Film::new(32, 32, GAUSS).unwrap();
    let mut tile = film.tile(PixelRect {
        x0: 8,
        y0: 16,
        x1: 16,
        y1: 24,
    });
    let value = Rgb::new(2.0, 4.0, 8.0);
    let raster = Vec2::new(10.3, 20.7);
    tile.add_sample(raster, value);
    // The position as the film sees it (10.3 and 20.7 rounded to f32).
    let (sx, sy) = (raster.x as f64, raster.y as f64);
    film.merge_tile(&tile);
    // Pixel centres are at i + 0.5. Along x, |i + 0.5 − 10.3| < 2 for i = 8..=11
    // (offsets 1.8, 0.8, −0.2, −1.2); along y, |j + 0.5 − 20.7| < 2 for j = 19..=22
    // (offsets 1.2, 0.2, −0.8, −1.8). E.g. the weight of pixel (10, 20) is
    // (e^(−2·0.04) − e^(−8))² = (0.923116 − 0.000335)² = 0.922781² = 0.851524.
    let mut total = 0.0;
    for y in 0..32u32 {
        for x in 0..32u32 {
            let wx = gauss_by_hand(x as f64 + 0.5 - sx);
            let wy = gauss_by_hand(y as f64 + 0.5 - sy);
            let expected = wx * wy;
            let (sum, w) = film.pixel_sums(x, y);
            let covered = (8..=11).contains(&x) && (19..=22).contains(&y);
            assert_eq!(w > 0.0, covered, "pixel ({x}, {y})");
            assert!(
                (w - expected).abs() <= 1e-12 * expected.max(1e-300),
                "({x},{y}): {w} vs {expected}"
            );
            for k in 0..3 {
                assert!(
                    (sum[k] - expected * value[k] as f64).abs() <= 1e-12 * sum[k].abs().max(1e-300)
                );
            }
            total += w;
        }
    }
    let w1020 = film.pixel_sums(10, 20).1;
    assert!((w1020 - 0.851524).abs() < 1e-6, "{w1020}");
    assert!(total > 0.0);
}

#[test]
fn constant_radiance_develops_to_that_constant_everywhere() {
    for filter in [FilterDesc::Box, GAUSS, FilterDesc::Gaussian { stddev: 1.3 }] {
        let (w, h) = (13, 7);
        let mut film = Film::new(w, h, filter).unwrap();
        let c = Rgb::new(0.3, 1.7, 5.0);
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(11);
        for rect in film.tiles(4) {
            let mut tile = film.tile(rect);
            for y in rect.y0..rect.y1 {
                for x in rect.x0..rect.x1 {
                    for _ in 0..4 {
                        let u = Vec2::new(rng.random::<f32>(), rng.random::<f32>());
                        tile.add_sample(mltbench::camera::raster_in_pixel(x, y, u), c);
                    }
                }
            }
            film.merge_tile(&tile);
        }
        let image = film.image(1.0);
        for y in 0..h {
            for x in 0..w {
                let p = image.get(x, y);
                for k in 0..3 {
                    // Σ w c / Σ w = c up to rounding of the sums.
                    assert!(
                        (p[k] / c[k] - 1.0).abs() < 1e-6,
                        "{filter:?} ({x}, {y}): {p:?}"
                    );
                }
            }
        }
        assert_eq!(film.sample_count(), (w * h * 4) as u64);
    }
}

/// The radiance of a made-up scene, with edges so filtering matters.
fn scene_radiance(p: Vec2) -> Rgb {
    let stripe = if (p.x * 0.7 + p.y * 0.3).sin() > 0.2 {
        5.0
    } else {
        0.1
    };
    Rgb::new(stripe, p.x * 0.01, 1.0 / (1.0 + p.y))
}

/// Renders one tile: each pixel's samples come from a generator seeded by the pixel, so
/// the sample set does not depend on the tiling.
fn render_tile(film: &Film, rect: PixelRect, spp: u32) -> FilmTile {
    let mut tile = film.tile(rect);
    for y in rect.y0..rect.y1 {
        for x in rect.x0..rect.x1 {
            let mut rng = Xoshiro256PlusPlus::seed_from_u64(((y as u64) << 32) | x as u64);
            for _ in 0..spp {
                let u = Vec2::new(rng.random::<f32>(), rng.random::<f32>());
                let raster = mltbench::camera::raster_in_pixel(x, y, u);
                tile.add_sample(raster, scene_radiance(raster));
            }
        }
    }
    tile
}

#[test]
fn tiles_merged_in_tile_order_are_bit_identical_for_any_thread_count() {
    for filter in [FilterDesc::Box, GAUSS] {
        let (w, h, spp) = (37, 23, 3);
        let reference = {
            let mut film = Film::new(w, h, filter).unwrap();
            for rect in film.tiles(8) {
                let tile = render_tile(&film, rect, spp);
                film.merge_tile(&tile);
            }
            film.image(1.0)
        };
        for threads in [2usize, 3, 5] {
            let mut film = Film::new(w, h, filter).unwrap();
            let rects = film.tiles(8);
            // Each thread takes every `threads`-th tile, in reverse: tiles finish in an
            // order unrelated to the tile order.
            let mut done: Vec<(usize, FilmTile)> = std::thread::scope(|s| {
                let handles: Vec<_> = (0..threads)
                    .map(|t| {
                        let (film, rects) = (&film, &rects);
                        s.spawn(move || {
                            (0..rects.len())
                                .rev()
                                .filter(|i| i % threads == t)
                                .map(|i| (i, render_tile(film, rects[i], spp)))
                                .collect::<Vec<_>>()
                        })
                    })
                    .collect();
                handles
                    .into_iter()
                    .flat_map(|h| h.join().unwrap())
                    .collect()
            });
            done.sort_by_key(|(i, _)| *i);
            let mut merged_by_rows = film.clone();
            for (_, tile) in &done {
                film.merge_tile(tile);
            }
            assert_eq!(
                bits(&film.image(1.0)),
                bits(&reference),
                "{filter:?}, {threads} threads"
            );
            // The rows merged in parallel, each pixel's tiles still in tile order.
            merged_by_rows.merge_tiles(done.iter().map(|(_, tile)| tile));
            assert_eq!(
                bits(&merged_by_rows.image(1.0)),
                bits(&reference),
                "{filter:?}, {threads} threads, merge_tiles"
            );
        }
        // A different tiling adds the same samples in another grouping: equal up to
        // rounding, which checks the tiles' filter margins lose nothing.
        let mut film = Film::new(w, h, filter).unwrap();
        for rect in film.tiles(5) {
            let tile = render_tile(&film, rect, spp);
            film.merge_tile(&tile);
        }
        for (a, b) in film.image(1.0).pixels.iter().zip(&reference.pixels) {
            for k in 0..3 {
                assert!(
                    (a[k] - b[k]).abs() <= 1e-6 * b[k].abs().max(1e-3),
                    "{a:?} vs {b:?}"
                );
            }
        }
    }
}

#[test]
fn merging_in_a_different_order_is_allowed_to_differ_only_by_rounding() {
    // Sanity check of the test above: the merge order is what fixes the bits, the sums
    // themselves are the same.
    let mut a = Film::new(16, 16, GAUSS).unwrap();
    let mut b = Film::new(16, 16, GAUSS).unwrap();
    let rects = a.tiles(4);
    let tiles: Vec<_> = rects.iter().map(|&r| render_tile(&a, r, 5)).collect();
    for t in &tiles {
        a.merge_tile(t);
    }
    for t in tiles.iter().rev() {
        b.merge_tile(t);
    }
    for (p, q) in a.image(1.0).pixels.iter().zip(&b.image(1.0).pixels) {
        for k in 0..3 {
            assert!((p[k] - q[k]).abs() <= 1e-6 * q[k].abs().max(1e-3));
        }
    }
}

#[test]
fn splats_add_with_the_scale() {
    let mut film = Film::new(6, 4, FilterDesc::Box).unwrap();
    let mut tile = film.tile(whole(&film));
    tile.add_sample(Vec2::new(2.5, 1.5), Rgb::new(1.0, 1.0, 1.0));
    tile.add_sample(Vec2::new(2.25, 1.75), Rgb::new(3.0, 3.0, 3.0));
    film.merge_tile(&tile);
    film.splat(Vec2::new(2.9, 1.1), Rgb::new(0.5, 1.0, 2.0));
    film.splat(Vec2::new(2.1, 1.9), Rgb::new(0.5, 1.0, 2.0));
    film.splat(Vec2::new(0.5, 3.5), Rgb::new(8.0, 0.0, 0.0));
    film.splat(Vec2::new(-0.5, 3.5), Rgb::new(8.0, 0.0, 0.0)); // outside: dropped
    // On a pixel's top-left corner: that pixel; on the image's right edge: dropped.
    film.splat(Vec2::new(4.0, 2.0), Rgb::new(4.0, 4.0, 4.0));
    film.splat(Vec2::new(6.0, 2.5), Rgb::new(4.0, 4.0, 4.0));
    let image = film.image(0.25);
    assert_eq!(image.get(4, 2), Rgb::splat(1.0));
    assert_eq!(image.get(3, 1), Rgb::BLACK);
    assert_eq!(image.get(5, 2), Rgb::BLACK);
    // Pixel (2, 1): mean of the samples (2) + 0.25 · (1, 2, 4).
    assert_eq!(image.get(2, 1), Rgb::new(2.25, 2.5, 3.0));
    assert_eq!(image.get(0, 3), Rgb::new(2.0, 0.0, 0.0));
    assert_eq!(image.get(1, 3), Rgb::BLACK);
    let image = film.image(0.0);
    assert_eq!(image.get(2, 1), Rgb::splat(2.0));
}

#[test]
fn a_uniform_splat_density_develops_to_a_constant_with_either_filter() {
    // n × n splats per pixel of value 1/n² on a regular grid approximate a density of 1:
    // every pixel, the border ones included, must come out 1 (the Gaussian is normalised by
    // its mass over the image), as camera samples of constant radiance do. The midpoint
    // rule's error is about h²/24 · |w'| ≈ 5·10⁻⁵ per axis with h = 1/32 at the image edge;
    // without the border normalisation the corner pixel would be off by 10 %.
    for (filter, tol) in [
        (FilterDesc::Box, 1e-6),
        (GAUSS, 2e-4),
        (FilterDesc::Gaussian { stddev: 0.8 }, 2e-4),
    ] {
        let (w, h, n) = (9u32, 6u32, 32u32);
        let mut film = Film::new(w, h, filter).unwrap();
        let mut list = SplatList::new();
        let v = 1.0 / (n * n) as f32;
        for j in 0..h * n {
            for i in 0..w * n {
                let p = Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                list.push(p, Rgb::splat(v));
            }
        }
        film.merge_splats(&list);
        let image = film.image(1.0);
        for y in 0..h {
            for x in 0..w {
                let p = image.get(x, y);
                assert!((p.r() - 1.0).abs() < tol, "{filter:?} ({x}, {y}): {p:?}");
            }
        }
    }
}

#[test]
fn splat_lists_merge_like_direct_splats_and_clear_resets() {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(3);
    let mut direct = Film::new(20, 10, GAUSS).unwrap();
    let mut merged = Film::new(20, 10, GAUSS).unwrap();
    let mut lists = vec![SplatList::new(), SplatList::new()];
    for k in 0..500 {
        let p = Vec2::new(rng.random::<f32>() * 20.0, rng.random::<f32>() * 10.0);
        let v = Rgb::new(rng.random(), rng.random(), rng.random());
        direct.splat(p, v);
        lists[k * 2 / 500].push(p, v);
    }
    for l in &lists {
        merged.merge_splats(l);
    }
    assert_eq!(bits(&direct.image(0.3)), bits(&merged.image(0.3)));
    assert_eq!(lists[0].len(), 250);
    merged.clear();
    assert!(merged.image(1.0).pixels.iter().all(|p| p.is_black()));
    assert_eq!(merged.sample_count(), 0);
}

#[test]
fn non_finite_samples_are_dropped_and_counted() {
    let mut film = Film::new(4, 4, GAUSS).unwrap();
    let mut tile = film.tile(whole(&film));
    tile.add_sample(Vec2::new(1.5, 1.5), Rgb::new(1.0, 1.0, 1.0));
    tile.add_sample(Vec2::new(1.5, 1.5), Rgb::new(f32::NAN, 1.0, 1.0));
    tile.add_sample(Vec2::new(1.5, 1.5), Rgb::new(1.0, f32::INFINITY, 1.0));
    tile.add_sample(Vec2::new(f32::NAN, 1.5), Rgb::new(1.0, 1.0, 1.0));
    film.merge_tile(&tile);
    film.splat(Vec2::new(1.5, 1.5), Rgb::new(f32::NAN, 0.0, 0.0));
    assert_eq!(film.invalid_samples(), 4);
    assert_eq!(film.sample_count(), 1);
    assert!(
        film.image(1.0)
            .pixels
            .iter()
            .all(|p| p.0.iter().all(|c| c.is_finite()))
    );
    assert_eq!(film.image(1.0).get(1, 1), Rgb::WHITE);
}

// ---------------------------------------------------------------------------------------
// EXR

fn random_image(w: u32, h: u32, seed: u64) -> Image {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let special = [
        0.0,
        -0.0,
        1e-40, // subnormal
        f32::MIN_POSITIVE,
        f32::MAX,
        3.0e38,
        -1.5,
        1.0,
        f32::INFINITY,
        f32::EPSILON,
    ];
    let mut image = Image::new(w, h);
    for (i, p) in image.pixels.iter_mut().enumerate() {
        for c in p.0.iter_mut() {
            *c = if i < 4 {
                special[(i * 3 + rng.random_range(0..3usize)) % special.len()]
            } else {
                // Any finite float: random bits, NaN and infinity excluded.
                loop {
                    let f = f32::from_bits(rng.random());
                    if f.is_finite() {
                        break f;
                    }
                }
            };
        }
    }
    if let Some(p) = image.pixels.get_mut(5) {
        *p = Rgb::new(0.0, 1e-40, f32::MAX);
    }
    image
}

#[test]
fn exr_round_trip_is_bit_exact() {
    let dir = test_dir("exr_round_trip");
    for (w, h) in [(37, 23), (1, 1), (300, 2)] {
        let image = random_image(w, h, w as u64 * 1000 + h as u64);
        let path = dir.join(format!("image_{w}x{h}.exr"));
        write_exr(&path, &image).unwrap();
        let back = read_exr(&path).unwrap();
        assert_eq!((back.width, back.height), (w, h));
        assert_eq!(bits(&back), bits(&image));
    }
    // Only the images, no temporary files.
    assert_eq!(
        listing(&dir),
        vec!["image_1x1.exr", "image_300x2.exr", "image_37x23.exr"]
    );
}

#[test]
fn exr_reads_half_float_rgba_files_written_by_others() {
    use exr::prelude::f16;
    let dir = test_dir("exr_rgba_f16");
    let path = dir.join("rgba.exr");
    let value = |x: usize, y: usize| (x as f32 * 0.5, y as f32 * 0.25, 3.0 - x as f32, 0.5);
    // The exr crate stores channels sorted by name (A, B, G, R) and as f16 here.
    exr::prelude::write_rgba_file(&path, 5, 3, |x, y| {
        let (r, g, b, a) = value(x, y);
        (
            f16::from_f32(r),
            f16::from_f32(g),
            f16::from_f32(b),
            f16::from_f32(a),
        )
    })
    .unwrap();
    let image = read_exr(&path).unwrap();
    assert_eq!((image.width, image.height), (5, 3));
    for y in 0..3 {
        for x in 0..5 {
            let (r, g, b, _) = value(x, y);
            assert_eq!(
                image.get(x as u32, y as u32),
                Rgb::new(r, g, b),
                "({x}, {y})"
            );
        }
    }
}

fn assert_error_names(result: Result<Image, Error>, path: &Path) {
    let message = match result {
        Ok(_) => panic!("{} was read", path.display()),
        Err(e) => e.to_string(),
    };
    let name = path.file_name().unwrap().to_string_lossy();
    assert!(
        message.contains(&*name),
        "message {message:?} does not name {name}"
    );
}

#[test]
fn bad_exr_files_give_errors_naming_the_file() {
    let dir = test_dir("exr_bad");
    let garbage = dir.join("garbage.exr");
    std::fs::write(&garbage, b"this is not an OpenEXR file at all").unwrap();
    assert_error_names(read_exr(&garbage), &garbage);

    let empty = dir.join("empty.exr");
    std::fs::write(&empty, b"").unwrap();
    assert_error_names(read_exr(&empty), &empty);

    let missing = dir.join("missing.exr");
    assert_error_names(read_exr(&missing), &missing);

    // Truncated copies of a valid file, cut anywhere.
    let good = dir.join("good.exr");
    write_exr(&good, &random_image(40, 30, 5)).unwrap();
    let bytes = std::fs::read(&good).unwrap();
    let truncated = dir.join("truncated.exr");
    for len in [
        4,
        20,
        100,
        300,
        bytes.len() / 2,
        bytes.len() - 16,
        bytes.len() - 1,
    ] {
        std::fs::write(&truncated, &bytes[..len]).unwrap();
        assert_error_names(read_exr(&truncated), &truncated);
    }

    // A file without RGB channels.
    let luma = dir.join("luma.exr");
    let layer = exr::prelude::Layer::new(
        (4, 4),
        exr::prelude::LayerAttributes::default(),
        exr::prelude::Encoding::UNCOMPRESSED,
        exr::prelude::AnyChannels::sort(exr::prelude::SmallVec::from_vec(vec![
            exr::prelude::AnyChannel::new("Y", exr::prelude::FlatSamples::F32(vec![0.5; 16])),
        ])),
    );
    use exr::prelude::WritableImage;
    exr::prelude::Image::from_layer(layer)
        .write()
        .to_file(&luma)
        .unwrap();
    assert_error_names(read_exr(&luma), &luma);
}

// ---------------------------------------------------------------------------------------
// Tone mapping and PNG

#[test]
fn reinhard_matches_the_hand_computation_on_two_pixels() {
    // Grey pixels Lw = 1 and Lw = 0.25 (luminance weights sum to 1).
    let image = Image {
        width: 2,
        height: 1,
        pixels: vec![Rgb::splat(1.0), Rgb::splat(0.25)],
    };
    let tm = Reinhard::default();
    assert_eq!((tm.key, tm.white), (0.18, None));
    let d = tm.delta;
    // eq. 1: L̄w = exp((ln(δ + 1) + ln(δ + 0.25)) / 2) ≈ √0.25 = 0.5
    let lbar = (((d + 1.0f64).ln() + (d + 0.25f64).ln()) / 2.0).exp();
    assert!((tm.log_average_luminance(&image) - lbar).abs() < 1e-12);
    assert!((lbar - 0.5).abs() < 2e-4);
    // eq. 2: L = 0.18 / L̄w · Lw ≈ 0.36 and 0.09; L_white = max L ≈ 0.36
    let (l1, l2) = (0.18 / lbar, 0.18 / lbar * 0.25);
    // eq. 4: Ld = L (1 + L / L_white²) / (1 + L): 1 for the brightest pixel, and for the
    // other ≈ 0.09 · (1 + 0.09/0.1296) / 1.09 = 0.139908
    let ld2 = l2 * (1.0 + l2 / (l1 * l1)) / (1.0 + l2);
    assert!((ld2 - 0.139908).abs() < 2e-4);
    let out = reinhard(&image);
    for k in 0..3 {
        assert!((out.pixels[0][k] as f64 - 1.0).abs() < 1e-6);
        assert!((out.pixels[1][k] as f64 - ld2).abs() < 1e-6);
    }
    // A fixed L_white = 2L: the brightest pixel gets L (1 + L/(4L²)) / (1 + L)
    // = (0.36 + 0.25) / 1.36 ≈ 0.4485.
    let fixed = Reinhard {
        white: Some(2.0 * l1),
        ..tm
    }
    .apply(&image);
    let expected = l1 * (1.0 + 0.25 / l1) / (1.0 + l1);
    assert!((fixed.pixels[0].r() as f64 - expected).abs() < 1e-6);
    assert!((expected - 0.4485).abs() < 1e-3);
}

#[test]
fn reinhard_keeps_chromaticity_isolates_bad_pixels_and_keeps_black_black() {
    let colours = vec![
        Rgb::new(2.0, 1.0, 0.5),
        Rgb::new(0.1, 0.3, 0.05),
        Rgb::BLACK,
    ];
    let clean = Image {
        width: 3,
        height: 1,
        pixels: colours.clone(),
    };
    let mut with_bad = colours.clone();
    with_bad.push(Rgb::new(f32::NAN, 1.0, 1.0));
    with_bad.push(Rgb::new(1.0, f32::INFINITY, 1.0));
    let dirty = Image {
        width: 5,
        height: 1,
        pixels: with_bad,
    };
    let a = reinhard(&clean);
    let b = reinhard(&dirty);
    assert_eq!(&b.pixels[..3], &a.pixels[..]);
    assert_eq!(b.pixels[3], INVALID_PIXEL);
    assert_eq!(b.pixels[4], INVALID_PIXEL);
    // Chromaticity: channel ratios survive.
    let p = a.pixels[0];
    assert!((p.r() / p.g() - 2.0).abs() < 1e-5 && (p.g() / p.b() - 2.0).abs() < 1e-5);
    assert_eq!(a.pixels[2], Rgb::BLACK);
    let black = Image::new(4, 3);
    assert_eq!(reinhard(&black), black);
}

#[test]
fn srgb_encoding_hits_known_points() {
    assert_eq!(srgb_to_u8(0.0), 0);
    assert_eq!(srgb_to_u8(1.0), 255);
    assert_eq!(srgb_to_u8(7.5), 255);
    assert_eq!(srgb_to_u8(-1.0), 0);
    assert_eq!(srgb_to_u8(f32::NAN), 0);
    // 0.5 → 1.055 · 0.5^(1/2.4) − 0.055 = 0.735357 → 187.5 → 188.
    assert_eq!(srgb_to_u8(0.5), 188);
    // 18% grey → 0.461356 → 117.6 → 118.
    assert_eq!(srgb_to_u8(0.18), 118);
    // At the break point 0.0031308 both branches give 0.04045 (the curve is continuous).
    let c = 0.0031308f32;
    assert!((srgb_encode(c) - 0.04045).abs() < 1e-6);
    assert!((srgb_encode(c.next_up()) - 0.04045).abs() < 1e-5);
    assert!((srgb_encode(0.001) - 0.01292).abs() < 1e-8);
    assert_eq!(srgb_to_u8(c), 10);
}

#[test]
fn png_preview_decodes_to_the_right_size_and_orientation() {
    let dir = test_dir("png");
    let (w, h) = (17u32, 9u32);
    let mut image = Image::new(w, h);
    for (i, p) in image.pixels.iter_mut().enumerate() {
        *p = Rgb::splat(0.01 + 0.001 * i as f32);
    }
    // The brightest pixel (grey) is the top-left one: tone mapped to exactly 1 → 255.
    image.set(0, 0, Rgb::splat(50.0));
    let path = dir.join("preview.png");
    write_png_preview(&path, &image).unwrap();
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&path).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!((info.width, info.height), (w, h));
    assert_eq!(info.color_type, png::ColorType::Rgb);
    assert_eq!(info.bit_depth, png::BitDepth::Eight);
    assert_eq!(&buf[0..3], &[255, 255, 255]);
    // The next pixel is much darker, and the bottom-right one brighter than its neighbour.
    assert!(buf[3] < 100);
    let last = (w * h * 3) as usize;
    assert!(buf[last - 3] >= buf[last - 6]);
    assert_eq!(listing(&dir), vec!["preview.png"]);
}

// ---------------------------------------------------------------------------------------
// Atomic writes

#[test]
fn atomic_writes_replace_content_and_leave_no_temporary_files() {
    let dir = test_dir("atomic");
    let path = dir.join("result.csv");
    write_file_atomically(&path, b"old").unwrap();
    write_file_atomically(&path, b"new content").unwrap();
    assert_eq!(std::fs::read(&path).unwrap(), b"new content");
    assert_eq!(listing(&dir), vec!["result.csv"]);

    // A failing writer leaves the old file and no temporary file.
    let failed = write_atomically(&path, |w| {
        use std::io::Write;
        w.write_all(b"half of it").unwrap();
        Err(Error::usage("stopped half-way"))
    });
    assert!(failed.is_err());
    assert_eq!(std::fs::read(&path).unwrap(), b"new content");
    assert_eq!(listing(&dir), vec!["result.csv"]);

    // A missing directory is an error naming the file.
    let nowhere = dir.join("no_such_dir").join("x.exr");
    let message = write_file_atomically(&nowhere, b"x")
        .unwrap_err()
        .to_string();
    assert!(message.contains("x.exr"), "{message}");
}
