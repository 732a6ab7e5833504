//! The Mitsuba loader's `spot` and `envmap` emitters: parameters and their Mitsuba 3
//! defaults land in `EmitterDesc` (expected values worked out by hand), bad input is an
//! error naming file and line, and the built lights read what the file says.

mod loader_support;

use glam::{Mat4, Vec3};
use loader_support::*;
use mltbench::image::Image;
use mltbench::io::exr::write_exr;
use mltbench::light::{Light, LightPoint, LightSet};
use mltbench::math::Rgb;
use mltbench::scene::*;

fn only_emitter(desc: &SceneDescription) -> &EmitterDesc {
    assert_eq!(desc.emitters.len(), 1, "{:?}", desc.emitters);
    &desc.emitters[0]
}

/// Writes a 4 × 3 environment map whose texel (i, j) is (i, j, 1).
fn write_envmap(dir: &std::path::Path, name: &str) -> std::path::PathBuf {
    let mut image = Image::new(4, 3);
    for j in 0..3 {
        for i in 0..4 {
            image.set(i, j, Rgb::new(i as f32, j as f32, 1.0));
        }
    }
    let path = dir.join(name);
    if let Some(parent) = path.parent() {
        std::fs::create_dir_all(parent).unwrap();
    }
    write_exr(&path, &image).unwrap();
    path
}

#[test]
fn spot_defaults_follow_mitsuba() {
    let desc = load_ok("spot_defaults", &with_sphere("<emitter type=\"spot\"/>"));
    match only_emitter(&desc) {
        EmitterDesc::Spot {
            intensity,
            to_world,
            cutoff_angle,
            beam_width,
        } => {
            assert_eq!(*intensity, Rgb::splat(1.0));
            assert_eq!(to_world.matrix, Mat4::IDENTITY);
            // Mitsuba 3: cutoff 20°, beam width 3/4 of it.
            assert_eq!(*cutoff_angle, 20.0);
            assert_eq!(*beam_width, 15.0);
        }
        other => panic!("expected a spot light, got {other:?}"),
    }
}

#[test]
fn spot_parameters_are_read() {
    let desc = load_ok(
        "spot_params",
        &with_sphere(
            r#"<emitter type="spot">
                 <rgb name="intensity" value="1, 2, 3"/>
                 <float name="cutoff_angle" value="30"/>
                 <float name="beam_width" value="10"/>
                 <transform name="to_world"><lookat origin="1, 1, 1" target="1, 2, 1"/></transform>
               </emitter>"#,
        ),
    );
    let EmitterDesc::Spot {
        intensity,
        to_world,
        cutoff_angle,
        beam_width,
    } = only_emitter(&desc)
    else {
        panic!("expected a spot light");
    };
    assert_eq!(*intensity, Rgb::new(1.0, 2.0, 3.0));
    assert_eq!((*cutoff_angle, *beam_width), (30.0, 10.0));
    // lookat puts the local origin at `origin` and local +z towards `target`.
    assert!(approx_v(to_world.point(Vec3::ZERO), Vec3::ONE, 1e-6));
    assert!(approx_v(to_world.vector(Vec3::Z), Vec3::Y, 1e-6));

    // Only the cutoff given: beam width 3/4 of it.
    let desc = load_ok(
        "spot_cutoff",
        &with_sphere(r#"<emitter type="spot"><float name="cutoff_angle" value="40"/></emitter>"#),
    );
    let EmitterDesc::Spot { beam_width, .. } = only_emitter(&desc) else {
        panic!("expected a spot light");
    };
    assert_eq!(*beam_width, 30.0);

    // A uniform scale keeps the cone round: accepted.
    load_ok(
        "spot_uniform_scale",
        &with_sphere(
            r#"<emitter type="spot"><transform name="to_world"><scale value="2"/><rotate x="1" angle="30"/></transform></emitter>"#,
        ),
    );
}

#[test]
fn spot_light_built_from_the_file_shines_along_its_axis() {
    let desc = load_ok(
        "spot_built",
        &with_sphere(
            r#"<emitter type="spot">
                 <rgb name="intensity" value="8"/>
                 <float name="cutoff_angle" value="30"/>
                 <float name="beam_width" value="20"/>
                 <transform name="to_world"><lookat origin="0, 5, 0" target="0, 0, 0"/></transform>
               </emitter>"#,
        ),
    );
    let lights = LightSet::build(&desc).unwrap();
    let Light::Spot(spot) = lights.get(0) else {
        panic!("expected a spot light");
    };
    assert!(approx_v(spot.position, Vec3::new(0.0, 5.0, 0.0), 1e-6));
    assert!(approx_v(spot.axis, -Vec3::Y, 1e-6));
    // Straight below at distance 5: I/d² = 8/25.
    let s = lights
        .get(0)
        .sample_li(Vec3::ZERO, glam::Vec2::ZERO)
        .unwrap();
    assert!(approx(s.radiance[1], 8.0 / 25.0, 1e-5));
    // 25° off the axis: halfway down the ramp from 20° to 30°.
    let t = 25f32.to_radians();
    let x = Vec3::new(5.0 * t.tan(), 0.0, 0.0);
    let s = lights.get(0).sample_li(x, glam::Vec2::ZERO).unwrap();
    let d2 = 25.0 + x.x * x.x;
    assert!(
        approx(s.radiance[0], 0.5 * 8.0 / d2, 1e-4),
        "{:?}",
        s.radiance
    );
}

#[test]
fn bad_spots_are_errors_naming_the_line() {
    for (body, needle, what) in [
        (
            "<emitter type=\"spot\">\n<float name=\"beam_width\" value=\"25\"/></emitter>",
            "beam_width",
            "beam_width",
        ),
        (
            "<emitter type=\"spot\">\n<float name=\"cutoff_angle\" value=\"0\"/></emitter>",
            "cutoff_angle",
            "cutoff_angle",
        ),
        (
            "<emitter type=\"spot\">\n<float name=\"cutoff_angle\" value=\"200\"/></emitter>",
            "cutoff_angle",
            "cutoff_angle",
        ),
        (
            "<emitter type=\"spot\">\n<transform name=\"to_world\"><scale x=\"1\" y=\"2\" z=\"1\"/></transform></emitter>",
            "to_world",
            "scale",
        ),
        (
            "<emitter type=\"spot\">\n<float name=\"radius\" value=\"1\"/></emitter>",
            "radius",
            "radius",
        ),
    ] {
        let text = with_sphere(body);
        let message = load_err_at("bad_spot", &text, line_of(&text, needle));
        assert!(message.contains(what), "{message}");
    }
    let text = scene("<shape type=\"sphere\">\n<emitter type=\"spot\"/>\n</shape>");
    let message = load_err_at("spot_on_shape", &text, 3);
    assert!(message.contains("only area emitters"), "{message}");
}

#[test]
fn envmap_parameters_are_read() {
    let dir = scratch("envmap_params");
    let path = write_envmap(&dir, "maps/sky.exr");
    let text = with_sphere(
        r#"<emitter type="envmap">
             <string name="filename" value="maps/sky.exr"/>
             <float name="scale" value="2.5"/>
             <transform name="to_world"><rotate y="1" angle="90"/></transform>
           </emitter>"#,
    );
    let desc = load_written(&dir, &text).unwrap();
    let EmitterDesc::Envmap {
        filename,
        scale,
        to_world,
    } = only_emitter(&desc)
    else {
        panic!("expected an envmap");
    };
    assert_eq!(
        filename.canonicalize().unwrap(),
        path.canonicalize().unwrap()
    );
    assert_eq!(*scale, 2.5);
    // A rotation of 90° about +y takes +z to +x.
    assert!(approx_v(to_world.vector(Vec3::Z), Vec3::X, 1e-6));
    // The image is one of the files the scene depends on.
    assert!(desc.files_read.contains(filename), "{:?}", desc.files_read);

    // Defaults: scale 1, no rotation.
    let desc = load_written(
        &dir,
        &with_sphere(
            r#"<emitter type="envmap"><string name="filename" value="maps/sky.exr"/></emitter>"#,
        ),
    )
    .unwrap();
    let EmitterDesc::Envmap {
        scale, to_world, ..
    } = only_emitter(&desc)
    else {
        panic!("expected an envmap");
    };
    assert_eq!(*scale, 1.0);
    assert_eq!(to_world.matrix, Mat4::IDENTITY);

    // Built: looking towards −z in the world is local +x after the rotation (u = 1/4, the
    // texel centre x = 4/4 − ½ = 0.5 → halfway between columns 0 and 1) on the horizon
    // (v = ½ → row 1): (0.5, 1, 1) × 2.5.
    let desc = load_written(&dir, &text).unwrap();
    let lights = LightSet::build(&desc).unwrap();
    let l = lights
        .get(0)
        .le(&LightPoint::direction(-Vec3::Z), Vec3::ZERO);
    assert!(
        approx_v(Vec3::from_array(l.0), Vec3::new(0.5, 1.0, 1.0) * 2.5, 1e-5),
        "{l:?}"
    );
}

#[test]
fn bad_envmaps_are_errors_naming_the_line() {
    let dir = scratch("bad_envmaps");
    write_envmap(&dir, "sky.exr");
    for (body, needle, what) in [
        (
            "<emitter type=\"envmap\">\n</emitter>",
            "envmap",
            "filename",
        ),
        (
            "<emitter type=\"envmap\">\n<string name=\"filename\" value=\"nowhere.exr\"/></emitter>",
            "nowhere",
            "nowhere.exr",
        ),
        (
            "<emitter type=\"envmap\"><string name=\"filename\" value=\"sky.exr\"/>\n<float name=\"scale\" value=\"-1\"/></emitter>",
            "scale",
            "scale",
        ),
        (
            "<emitter type=\"envmap\"><string name=\"filename\" value=\"sky.exr\"/>\n<transform name=\"to_world\"><scale value=\"2\"/></transform></emitter>",
            "to_world",
            "rotation",
        ),
        (
            "<emitter type=\"constant\"/>\n<emitter type=\"envmap\"><string name=\"filename\" value=\"sky.exr\"/></emitter>",
            "envmap",
            "only one environment emitter",
        ),
        (
            "<emitter type=\"envmap\"><string name=\"filename\" value=\"sky.exr\"/></emitter>\n<emitter type=\"envmap\"><string name=\"filename\" value=\"sky.exr\"/></emitter>",
            "only_second",
            "only one environment emitter",
        ),
    ] {
        let text = with_sphere(body);
        let message = match load_written(&dir, &text) {
            Ok(_) => panic!("should not load:\n{text}"),
            Err(e) => e.to_string(),
        };
        let line = if needle == "only_second" {
            4
        } else {
            line_of(&text, needle)
        };
        assert_names(&message, &dir.join("scene.xml"), line);
        assert!(message.contains(what), "{message}");
    }
    let text = scene(
        "<shape type=\"sphere\">\n<emitter type=\"envmap\"><string name=\"filename\" value=\"sky.exr\"/></emitter>\n</shape>",
    );
    let message = load_written(&dir, &text).unwrap_err().to_string();
    assert_names(&message, &dir.join("scene.xml"), 3);
    assert!(message.contains("only area emitters"), "{message}");
}

/// Building the lights reads the image; its errors name the EXR and the `<emitter>`'s line.
#[test]
fn envmap_image_errors_name_the_scene_line_and_the_image() {
    let dir = scratch("envmap_image_errors");
    let mut image = Image::new(4, 3);
    for j in 0..3 {
        for i in 0..4 {
            image.set(i, j, Rgb::splat(0.5));
        }
    }
    image.set(2, 1, Rgb::new(0.5, f32::NAN, 0.5));
    write_exr(&dir.join("nan.exr"), &image).unwrap();
    std::fs::write(dir.join("garbage.exr"), b"not an image").unwrap();
    for (name, what) in [("nan.exr", "texel (2, 1)"), ("garbage.exr", "OpenEXR")] {
        let text = with_sphere(&format!(
            "<emitter type=\"envmap\">\n<string name=\"filename\" value=\"{name}\"/></emitter>"
        ));
        let desc = load_written(&dir, &text).unwrap();
        let message = LightSet::build(&desc).unwrap_err().to_string();
        assert_names(&message, &dir.join("scene.xml"), line_of(&text, "envmap"));
        assert!(
            message.contains(name) && message.contains(what),
            "{message}"
        );
    }
}

/// An area emitter whose shape has no area in f32 is an error at the emitter's line, for
/// spheres, disks and meshes alike.
#[test]
fn emitters_of_zero_area_are_errors() {
    let emitter = "\n<emitter type=\"area\"/>";
    for (shape, when) in [
        (
            format!(
                "<shape type=\"sphere\"><float name=\"radius\" value=\"1e-40\"/>{emitter}</shape>"
            ),
            "build",
        ),
        (
            format!(
                "<shape type=\"disk\"><transform name=\"to_world\"><scale x=\"1e-20\" y=\"1e-20\" z=\"1e30\"/></transform>{emitter}</shape>"
            ),
            "build",
        ),
        (
            format!(
                "<shape type=\"rectangle\"><transform name=\"to_world\"><scale x=\"1e-25\" y=\"1e-25\" z=\"1e30\"/></transform>{emitter}</shape>"
            ),
            "load",
        ),
    ] {
        let text = with_sphere(&shape);
        let line = line_of(&text, "<emitter");
        let dir = scratch("zero_area");
        let message = match (load_written(&dir, &text), when) {
            (Ok(desc), "build") => LightSet::build(&desc).unwrap_err().to_string(),
            (Err(e), "load") => e.to_string(),
            (other, _) => panic!("{when}: {:?}\n{text}", other.map(|_| ())),
        };
        assert_names(&message, &dir.join("scene.xml"), line);
        assert!(message.contains("emit"), "{message}");
    }
    // Small but representable: builds.
    let desc = load_ok(
        "small_area",
        &with_sphere(
            "<shape type=\"sphere\"><float name=\"radius\" value=\"1e-10\"/><emitter type=\"area\"/></shape>",
        ),
    );
    LightSet::build(&desc).unwrap();
}
