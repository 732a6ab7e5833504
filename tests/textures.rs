//! Textures (Mitsuba 3's `bitmap` and `checkerboard` as a diffuse reflectance): how the loader
//! reads them and refuses bad ones, and what `pt` renders with them.
//!
//! The uv conventions asserted here (the image's first row at v = 0, the rectangle's uvs
//! running from (0, 0) at its (−1, −1) corner) are Mitsuba 3's, found by rendering a probe
//! scene with both renderers (`experiments/scenes/textures.xml`; README, "Scene subset").

mod loader_support;

use std::path::Path;
use std::sync::Arc;

use glam::{Vec2, Vec3};
use loader_support::*;
use mltbench::camera::raster_in_pixel;
use mltbench::estimator::{self, Params};
use mltbench::image::Image;
use mltbench::io::exr::write_exr;
use mltbench::math::Rgb;
use mltbench::render::{Budget, render};
use mltbench::scene::{BsdfDesc, Scene};
use mltbench::texture::Texture;

/// Writes an 8-bit RGB PNG of `width` × `rows.len()` pixels, row 0 first.
fn write_png(path: &Path, width: u32, rows: &[Vec<[u8; 3]>]) {
    let file = std::fs::File::create(path).unwrap();
    let mut encoder = png::Encoder::new(file, width, rows.len() as u32);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    let mut writer = encoder.write_header().unwrap();
    let bytes: Vec<u8> = rows.iter().flatten().flatten().copied().collect();
    writer.write_image_data(&bytes).unwrap();
}

/// An 8-bit sRGB code as linear radiance (IEC 61966-2-1), in f64.
fn srgb_code_to_linear(code: u8) -> f64 {
    let c = code as f64 / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// The 4 × 3 test image: every texel a different colour.
fn test_codes() -> Vec<Vec<[u8; 3]>> {
    (0..3)
        .map(|j| {
            (0..4)
                .map(|i| [40 + 60 * i as u8, 30 + 100 * j as u8, 200 - 40 * i as u8])
                .collect()
        })
        .collect()
}

/// The texture of shape `shape`'s BSDF (inside a `twosided` too).
fn diffuse_texture(desc: &mltbench::scene::SceneDescription, shape: usize) -> Texture {
    fn of(bsdf: &BsdfDesc) -> Texture {
        match bsdf {
            BsdfDesc::Textured { diffuse, .. } => diffuse.clone(),
            BsdfDesc::TwoSided { front, .. } => of(front),
            other => panic!("expected a textured BSDF, got {other:?}"),
        }
    }
    of(&desc.bsdfs[desc.shapes[shape].bsdf])
}

#[test]
fn textures_are_read_nested_or_referenced_and_shared() {
    let dir = scratch("textures_read");
    write_png(&dir.join("grid.png"), 4, &test_codes());
    let text = scene(
        r#"<texture type="bitmap" id="grid"><string name="filename" value="grid.png"/></texture>
        <shape type="sphere"><bsdf type="diffuse"><ref name="reflectance" id="grid"/></bsdf></shape>
        <shape type="sphere"><bsdf type="twosided"><bsdf type="diffuse">
            <ref name="reflectance" id="grid"/></bsdf></bsdf></shape>
        <shape type="sphere"><bsdf type="diffuse">
            <texture type="checkerboard" name="reflectance">
                <rgb name="color0" value="0.1, 0.2, 0.3"/>
                <transform name="to_uv"><scale x="2" y="3"/><translate x="0.5"/></transform>
            </texture></bsdf></shape>
        <shape type="sphere"><bsdf type="diffuse">
            <texture type="bitmap" name="reflectance"><string name="filename" value="grid.png"/>
                <string name="filter_type" value="nearest"/><string name="wrap_mode" value="clamp"/>
                <boolean name="raw" value="true"/></texture></bsdf></shape>"#,
    );
    let desc = load_written(&dir, &text).unwrap();
    let (Texture::Bitmap(a), Texture::Bitmap(b)) =
        (diffuse_texture(&desc, 0), diffuse_texture(&desc, 1))
    else {
        panic!("bitmaps expected");
    };
    assert!(Arc::ptr_eq(&a, &b), "a referenced texture is read once");
    assert_eq!((a.width, a.height), (4, 3));
    // Texel (1, 2): sRGB decoded by default, kept as code / 255 with raw.
    let codes = test_codes();
    let [r, g, _] = codes[2][1];
    assert!((a.texels[2 * 4 + 1].0[0] as f64 - srgb_code_to_linear(r)).abs() < 1e-6);
    let Texture::Bitmap(raw) = diffuse_texture(&desc, 3) else {
        panic!("bitmap expected");
    };
    assert!((raw.texels[2 * 4 + 1].0[1] - g as f32 / 255.0).abs() < 1e-6);
    let Texture::Checkerboard(c) = diffuse_texture(&desc, 2) else {
        panic!("checkerboard expected");
    };
    assert_eq!(c.color0, Rgb::new(0.1, 0.2, 0.3));
    // Mitsuba's default color1, and to_uv's 2D part (scale, then translate).
    assert_eq!(c.color1, Rgb::splat(0.2));
    assert_eq!(c.to_uv.apply(Vec2::new(1.0, 1.0)), Vec2::new(2.5, 3.0));
    // Away from a hit (eyelight's fallback) a texture stands for its mean.
    assert!(
        desc.bsdfs[desc.shapes[2].bsdf]
            .diffuse_albedo()
            .is_some_and(|m| (m.0[0] - 0.15).abs() < 1e-6)
    );
}

#[test]
fn bad_textures_are_errors_naming_file_and_line() {
    let dir = scratch("bad_textures");
    write_png(&dir.join("grid.png"), 4, &test_codes());
    let mut nan = Image::new(4, 3);
    nan.set(2, 1, Rgb::new(0.5, f32::NAN, 0.5));
    write_exr(&dir.join("nan.exr"), &nan).unwrap();
    std::fs::write(dir.join("fake.png"), b"hello, not an image").unwrap();
    let good = std::fs::read(dir.join("grid.png")).unwrap();
    std::fs::write(dir.join("cut.png"), &good[..good.len() / 2]).unwrap();
    let bitmap = |extra: &str| {
        format!(
            "<shape type=\"sphere\"><bsdf type=\"diffuse\">\n<texture type=\"bitmap\" \
             name=\"reflectance\">\n{extra}\n</texture></bsdf></shape>"
        )
    };
    let file = |name: &str| format!("<string name=\"filename\" value=\"{name}\"/>");
    // (scene body, text on the line the error must name, words the message must contain)
    let cases = [
        (
            "<shape type=\"sphere\"><bsdf type=\"conductor\">\n<texture type=\"checkerboard\" \
             name=\"specular_reflectance\"/></bsdf></shape>"
                .to_string(),
            "<texture",
            "only as a diffuse",
        ),
        (
            "<shape type=\"sphere\"><bsdf type=\"diffuse\"/>\n<emitter type=\"area\">\n\
             <texture type=\"checkerboard\" name=\"radiance\"/></emitter></shape>"
                .to_string(),
            "<texture",
            "only as a diffuse",
        ),
        (bitmap(&file("missing.png")), "missing.png", "not found"),
        (bitmap(""), "<texture", "needs a \"filename\""),
        (
            bitmap(&format!(
                "{}\n<string name=\"filter_type\" value=\"cubic\"/>",
                file("grid.png")
            )),
            "cubic",
            "filter_type",
        ),
        (
            bitmap(&format!(
                "{}\n<string name=\"wrap_mode\" value=\"tile\"/>",
                file("grid.png")
            )),
            "tile",
            "wrap_mode",
        ),
        (
            bitmap(&format!(
                "{}\n<float name=\"gamma\" value=\"2.2\"/>",
                file("grid.png")
            )),
            "gamma",
            "unknown parameter",
        ),
        (bitmap(&file("nan.exr")), "<texture", "texel (2, 1)"),
        (
            bitmap(&file("fake.png")),
            "<texture",
            "not a PNG, JPEG or OpenEXR",
        ),
        (bitmap(&file("cut.png")), "<texture", "PNG"),
        (
            "<shape type=\"sphere\"><bsdf type=\"diffuse\">\n<texture type=\"wireframe\" \
             name=\"reflectance\"/></bsdf></shape>"
                .to_string(),
            "wireframe",
            "not supported",
        ),
        (
            "<shape type=\"sphere\"><bsdf type=\"diffuse\">\n<rgb name=\"reflectance\" \
             value=\"0.5\"/>\n<texture type=\"checkerboard\" name=\"reflectance\"/>\n\
             </bsdf></shape>"
                .to_string(),
            "<texture",
            "given twice",
        ),
        (
            "<shape type=\"sphere\"><bsdf type=\"diffuse\">\n<texture type=\"checkerboard\" \
             name=\"reflectance\">\n<float name=\"color0\" value=\"1.5\"/>\n</texture>\n\
             </bsdf></shape>"
                .to_string(),
            "color0",
            "[0, 1]",
        ),
        // Not used by any shape: still read, so that a broken file does not go unnoticed.
        (
            format!(
                "<shape type=\"sphere\"/>\n<texture type=\"bitmap\" id=\"t\">\n{}</texture>",
                file("missing.png")
            ),
            "missing.png",
            "not found",
        ),
    ];
    for (body, at, words) in cases {
        let text = scene(&body);
        let message = match load_written(&dir, &text) {
            Ok(_) => panic!("should not load:\n{text}"),
            Err(e) => e.to_string(),
        };
        assert_names(&message, &dir.join("scene.xml"), line_of(&text, at));
        assert!(message.contains(words), "{words:?} not in: {message}");
    }
    // Texture files named in messages: the bad texel's file.
    let text = scene(&bitmap(&file("nan.exr")));
    let message = load_written(&dir, &text).unwrap_err().to_string();
    assert!(message.contains("nan.exr"), "{message}");
}

#[test]
fn a_texture_brighter_than_one_is_used_with_a_warning() {
    let dir = scratch("bright_texture");
    let mut bright = Image::new(2, 2);
    for (i, v) in [0.5, 1.0, 1.5, 0.25].into_iter().enumerate() {
        bright.set(i as u32 % 2, i as u32 / 2, Rgb::splat(v));
    }
    write_exr(&dir.join("bright.exr"), &bright).unwrap();
    let text = scene(
        "<shape type=\"sphere\"><bsdf type=\"diffuse\"><texture type=\"bitmap\" \
         name=\"reflectance\"><string name=\"filename\" value=\"bright.exr\"/></texture>\
         </bsdf></shape>",
    );
    let desc = load_written(&dir, &text).unwrap();
    assert!(
        desc.warnings.iter().any(|w| w.contains("above 1")),
        "{:?}",
        desc.warnings
    );
    let Texture::Bitmap(b) = diffuse_texture(&desc, 0) else {
        panic!("bitmap expected");
    };
    // EXR texels are linear and kept as they are.
    assert_eq!(b.texels[2].0[0], 1.5);
}

/// Standard deviations allowed between a pixel group's mean and its closed form.
const SIGMAS: f64 = 4.0;

/// Mean and standard error of channel `c` over `pixels` of `image`.
fn mean_over(image: &Image, pixels: &[(u32, u32)], c: usize) -> (f64, f64) {
    let values: Vec<f64> = pixels
        .iter()
        .map(|&(x, y)| image.get(x, y).0[c] as f64)
        .collect();
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, (var / n).sqrt())
}

/// The scene of `a_textured_plane_under_a_uniform_sky_shows_texture_times_sky`: a camera
/// at the origin looking down −z at a `HALF`-sized rectangle at z = −3, under a sky of
/// radiance `SKY`.
const HALF: f32 = 1.5;
const SKY: f64 = 2.0;

fn textured_plane(dir: &Path, bsdf: &str) -> Scene {
    let text = format!(
        r#"<scene version="3.0.0">
            <sensor type="perspective">
                <float name="fov" value="60"/>
                <transform name="to_world"><lookat origin="0,0,0" target="0,0,-1" up="0,1,0"/></transform>
                <film type="hdrfilm"><integer name="width" value="32"/><integer name="height" value="32"/>
                    <rfilter type="box"/></film>
            </sensor>
            <emitter type="constant"><rgb name="radiance" value="{SKY}"/></emitter>
            <shape type="rectangle">
                <transform name="to_world"><scale value="{HALF}"/><translate z="-3"/></transform>
                {bsdf}
            </shape>
        </scene>"#
    );
    Scene::build(load_written(dir, &text).unwrap()).unwrap()
}

/// A reflectance (its three channels' bit patterns) and the pixels that see only it.
type PixelGroup = ([u64; 3], Vec<(u32, u32)>);

/// Groups the pixels whose whole footprint on the plane has one reflectance, as
/// `reflectance(u, v)` gives it (None to skip a point), by that reflectance.
fn pixels_by_reflectance(
    scene: &Scene,
    reflectance: impl Fn(f64, f64) -> Option<[u64; 3]>,
) -> Vec<PixelGroup> {
    let mut groups: Vec<PixelGroup> = Vec::new();
    for y in 0..32 {
        for x in 0..32 {
            // The rectangle's uv at the four corners of the pixel: (−1, −1) → (0, 0) and
            // (1, 1) → (1, 1) in its own coordinates.
            let corners: Vec<Option<[u64; 3]>> = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)]
                .iter()
                .map(|&(a, b)| {
                    let raster = raster_in_pixel(x, y, Vec2::new(a, b) * 0.998 + 0.001);
                    let ray = scene.camera.generate_ray(raster);
                    let p: Vec3 = ray.o + ray.d * ((-3.0 - ray.o.z) / ray.d.z);
                    let (u, v) = ((p.x / HALF + 1.0) / 2.0, (p.y / HALF + 1.0) / 2.0);
                    let inside = (0.0..1.0).contains(&u) && (0.0..1.0).contains(&v);
                    inside.then(|| reflectance(u as f64, v as f64)).flatten()
                })
                .collect();
            let Some(first) = corners[0] else { continue };
            if corners.iter().any(|c| *c != Some(first)) {
                continue;
            }
            match groups.iter_mut().find(|(key, _)| *key == first) {
                Some((_, pixels)) => pixels.push((x, y)),
                None => groups.push((first, vec![(x, y)])),
            }
        }
    }
    groups
}

/// A diffuse plane that sees the whole sky of radiance L and nothing else reflects ρ·L
/// (irradiance πL, Lambert's ρ/π), ρ taken from the texture where the pixel looks.
#[test]
fn a_textured_plane_under_a_uniform_sky_shows_texture_times_sky() {
    let dir = scratch("textured_plane");
    let codes = test_codes();
    write_png(&dir.join("grid.png"), 4, &codes);
    let bitmap = r#"<texture type="bitmap" name="reflectance">
        <string name="filename" value="grid.png"/><string name="filter_type" value="nearest"/>
    </texture>"#;
    let checkerboard = r#"<texture type="checkerboard" name="reflectance">
        <rgb name="color0" value="0.8, 0.3, 0.1"/><rgb name="color1" value="0.1, 0.5, 0.9"/>
        <transform name="to_uv"><scale value="2"/></transform>
    </texture>"#;
    // Texel (i, j) of the 4 × 3 image covers u in [i/4, (i+1)/4) and v in [j/3, (j+1)/3):
    // row 0 of the file at v = 0.
    let texel = |u: f64, v: f64| {
        let [r, g, b] = codes[(v * 3.0) as usize][(u * 4.0) as usize];
        Some([r, g, b].map(|c| srgb_code_to_linear(c).to_bits()))
    };
    // With uv scaled by 2, the cells are quarters of the unit square: color0 where the
    // cell's row and column have the same parity.
    let check = |u: f64, v: f64| {
        let same = ((u * 4.0) as u64 + (v * 4.0) as u64).is_multiple_of(2);
        let rho = if same {
            [0.8, 0.3, 0.1]
        } else {
            [0.1, 0.5, 0.9]
        };
        Some(rho.map(|c: f64| (c as f32 as f64).to_bits()))
    };
    for (texture, reflectance, groups_expected) in [
        (bitmap, &texel as &dyn Fn(f64, f64) -> Option<[u64; 3]>, 12),
        (checkerboard, &check, 2),
    ] {
        let scene = textured_plane(&dir, &format!("<bsdf type=\"diffuse\">{texture}</bsdf>"));
        let groups = pixels_by_reflectance(&scene, reflectance);
        assert_eq!(groups.len(), groups_expected, "every texel or cell is seen");
        let params = Params::parse::<&str>(&[]).unwrap();
        let mut pt = estimator::create("pt", &params, &scene, 7).unwrap();
        let image = render(&scene, pt.as_mut(), Budget::Passes(64), |_, _| {}).image;
        for (rho, pixels) in groups {
            assert!(pixels.len() >= 4, "{} pixels", pixels.len());
            for (c, rho_bits) in rho.iter().enumerate() {
                let expected = f64::from_bits(*rho_bits) * SKY;
                let (mean, se) = mean_over(&image, &pixels, c);
                // Plus the f32 film's rounding, for channels that happen to have no variance.
                let se = se.hypot(2e-5 * expected);
                let z = (mean - expected) / se.max(1e-9);
                assert!(
                    z.abs() <= SIGMAS,
                    "channel {c}: {mean} ± {se} against ρL = {expected} ({z:.2} σ, {} pixels)",
                    pixels.len()
                );
            }
        }
    }
}

/// Render of `scene` by `pt`: 64 passes.
fn render_pt(scene: &Scene, seed: u64) -> Image {
    let params = Params::parse::<&str>(&[]).unwrap();
    let mut pt = estimator::create("pt", &params, scene, seed).unwrap();
    render(scene, pt.as_mut(), Budget::Passes(64), |_, _| {}).image
}

/// A plastic whose diffuse reflectance is a texture renders, in each checker cell, what the
/// plastic with that cell's colour as a constant renders there (independent runs, 4 σ).
#[test]
fn a_textured_plastic_matches_the_constant_plastic_of_each_cell() {
    let dir = scratch("textured_plastic");
    let colors = ["0.8, 0.3, 0.1", "0.1, 0.5, 0.9"];
    let check = |u: f64, v: f64| {
        let same = ((u * 4.0) as u64 + (v * 4.0) as u64).is_multiple_of(2);
        Some([same as u64; 3])
    };
    for kind in ["plastic", "roughplastic"] {
        let plastic = |reflectance: &str| {
            format!(
                "<bsdf type=\"{kind}\"><float name=\"int_ior\" value=\"1.6\"/>{reflectance}</bsdf>"
            )
        };
        let textured = textured_plane(
            &dir,
            &plastic(&format!(
                "<texture type=\"checkerboard\" name=\"diffuse_reflectance\">\
                 <rgb name=\"color0\" value=\"{}\"/><rgb name=\"color1\" value=\"{}\"/>\
                 <transform name=\"to_uv\"><scale value=\"2\"/></transform></texture>",
                colors[0], colors[1]
            )),
        );
        assert!(matches!(
            &textured.description.bsdfs[0],
            BsdfDesc::Textured { .. }
        ));
        let image = render_pt(&textured, 11);
        let groups = pixels_by_reflectance(&textured, check);
        assert_eq!(groups.len(), 2);
        for (key, pixels) in groups {
            let color = colors[if key[0] == 1 { 0 } else { 1 }];
            let constant = textured_plane(
                &dir,
                &plastic(&format!(
                    "<rgb name=\"diffuse_reflectance\" value=\"{color}\"/>"
                )),
            );
            let reference = render_pt(&constant, 12);
            for c in 0..3 {
                let (a, sa) = mean_over(&image, &pixels, c);
                let (b, sb) = mean_over(&reference, &pixels, c);
                let z = (a - b) / sa.hypot(sb).max(1e-9);
                assert!(
                    z.abs() <= SIGMAS,
                    "{kind}, colour {color}, channel {c}: {a} ± {sa} against {b} ± {sb} ({z:.2} σ)"
                );
            }
        }
    }
}

/// Analytic shapes compute (u, v) only where a texture reads them: a textured sphere's hit
/// carries Mitsuba's (φ/2π, θ/π), an untextured one's (0, 0).
#[test]
fn only_textured_analytic_shapes_compute_uv() {
    let dir = scratch("textures_uv");
    let text = scene(
        r#"<shape type="sphere"><point name="center" x="-3" y="0" z="0"/>
            <bsdf type="diffuse"><texture type="checkerboard" name="reflectance"/></bsdf></shape>
        <shape type="sphere"><point name="center" x="3" y="0" z="0"/>
            <bsdf type="diffuse"/></shape>"#,
    );
    let scene = Scene::build(load_written(&dir, &text).unwrap()).unwrap();
    // Both rays meet their sphere where the normal is (0.5, 0.5, √0.5): φ = 45°, θ = 45°.
    let uv_at = |x: f32| {
        let ray = mltbench::geometry::Ray::new(Vec3::new(x + 0.5, 0.5, 5.0), -Vec3::Z);
        scene
            .geometry
            .intersect(&ray)
            .expect("the ray meets the sphere")
            .uv
    };
    let textured = uv_at(-3.0);
    assert!(
        (textured - Vec2::new(0.125, 0.25)).abs().max_element() < 1e-5,
        "{textured}"
    );
    assert_eq!(uv_at(3.0), Vec2::ZERO);
}
