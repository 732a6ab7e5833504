//! `<sensor type="perspective">` and `<sensor type="thinlens">` with their `<film>`,
//! `<rfilter>` and `<sampler>`, and the sensor Mitsuba makes up for scenes that have none.

use glam::{Mat3, Vec3};

use super::Builder;
use super::values::Props;
use super::xml::ElemId;
use crate::error::Result;
use crate::image::MAX_PIXELS;
use crate::math::Transform;
use crate::scene::{CropWindow, FilmDesc, FilterDesc, FovAxis, SensorDesc, ThinLensDesc};

/// Mitsuba sensors mltbench does not implement.
const UNSUPPORTED_SENSORS: &[&str] = &[
    "orthographic",
    "telecentric",
    "radiancemeter",
    "irradiancemeter",
    "distant",
    "batch",
    "spherical",
    "fisheye",
];
const KNOWN_SAMPLERS: &[&str] = &[
    "independent",
    "stratified",
    "multijitter",
    "orthogonal",
    "ldsampler",
];
/// Mitsuba 3's other reconstruction filters: mltbench warns and uses box.
const OTHER_FILTERS: &[&str] = &["tent", "mitchell", "catmullrom", "lanczos"];
/// Largest accepted film side, in pixels.
const MAX_FILM_SIDE: i64 = 1 << 16;
/// The 35 mm film a `focal_length` refers to, in millimetres.
const FILM_35MM: (f64, f64) = (36.0, 24.0);

impl Builder<'_> {
    pub(super) fn parse_sensor(&mut self, elem: ElemId) -> Result<SensorDesc> {
        let tree = self.tree;
        let thin_lens = match tree.type_of(elem) {
            "perspective" => false,
            "thinlens" => true,
            kind if UNSUPPORTED_SENSORS.contains(&kind) => {
                return Err(
                    tree.error(elem, format!("sensor type \"{kind}\" is not supported yet"))
                );
            }
            kind => return Err(tree.error(elem, format!("unknown sensor type \"{kind}\""))),
        };
        let props = Props::collect(tree, elem)?;
        let mut sensor = SensorDesc::default();

        if let Some(to_world) = props.transform("to_world")? {
            if has_scale(&to_world) {
                return Err(tree.error(
                    props.elem_of("to_world"),
                    "scale factors in the camera-to-world transformation are not allowed",
                ));
            }
            sensor.to_world = to_world;
        }
        (sensor.fov_degrees, sensor.fov_axis) = field_of_view(&props)?;

        sensor.near_clip = props.float("near_clip")?.unwrap_or(sensor.near_clip);
        sensor.far_clip = props.float("far_clip")?.unwrap_or(sensor.far_clip);
        if sensor.near_clip <= 0.0 {
            return Err(tree.error(
                props.elem_of("near_clip"),
                "near_clip must be greater than zero",
            ));
        }
        if sensor.near_clip >= sensor.far_clip {
            return Err(tree.error(
                props.elem_of("near_clip"),
                format!(
                    "near_clip ({}) must be smaller than far_clip ({})",
                    sensor.near_clip, sensor.far_clip
                ),
            ));
        }
        if thin_lens {
            sensor.lens = Some(self.thin_lens(elem, &props, sensor.far_clip)?);
        } else {
            // Depth of field does not exist for a pinhole camera.
            props.ignore(&["focus_distance"]);
        }
        // Motion blur: mltbench renders one instant.
        props.ignore(&["shutter_open", "shutter_close"]);
        for name in ["principal_point_offset_x", "principal_point_offset_y"] {
            if props.float(name)?.is_some_and(|v| v != 0.0) {
                return Err(tree.error(props.elem_of(name), format!("{name} is not supported yet")));
            }
        }

        let (mut film_seen, mut sampler_seen) = (false, false);
        for (i, object) in props.objects().iter().enumerate() {
            match tree.tag(object.target) {
                "film" => {
                    if film_seen {
                        return Err(tree.error(object.via, "a sensor takes only one <film>"));
                    }
                    film_seen = true;
                    props.use_object(i);
                    sensor.film = self.parse_film(object.target)?;
                }
                "sampler" => {
                    if sampler_seen {
                        return Err(tree.error(object.via, "a sensor takes only one <sampler>"));
                    }
                    sampler_seen = true;
                    props.use_object(i);
                    sensor.sample_count = self.parse_sampler(object.target)?;
                }
                _ => {}
            }
        }
        props.finish()?;
        Ok(sensor)
    }

    /// `thinlens`'s `aperture_radius` (required: Mitsuba 3 has no default) and
    /// `focus_distance` (default: `far_clip`, as in Mitsuba 3's code; its documentation
    /// says 0). A radius of 0 warns, as Mitsuba does, and gives the pinhole's rays (Mitsuba
    /// substitutes Dr.Jit's float epsilon: the same rays to float precision). Mitsuba
    /// accepts a negative radius (a mirrored aperture); mltbench rejects it as a likely typo.
    fn thin_lens(&mut self, elem: ElemId, props: &Props, far_clip: f32) -> Result<ThinLensDesc> {
        let tree = self.tree;
        let Some(aperture_radius) = props.float("aperture_radius")? else {
            return Err(tree.error(
                elem,
                "sensor type \"thinlens\" needs aperture_radius (it has no default)",
            ));
        };
        if !(aperture_radius >= 0.0 && aperture_radius.is_finite()) {
            return Err(tree.error(
                props.elem_of("aperture_radius"),
                format!("aperture_radius must be a finite number ≥ 0, got {aperture_radius}"),
            ));
        }
        if aperture_radius == 0.0 {
            let w = tree.warning(
                props.elem_of("aperture_radius"),
                "aperture_radius is 0: the thin lens is a pinhole",
            );
            self.desc.warnings.push(w);
        }
        let focus_distance = props.float("focus_distance")?.unwrap_or(far_clip);
        if !(focus_distance > 0.0 && focus_distance.is_finite()) {
            return Err(tree.error(
                props.elem_of("focus_distance"),
                format!("focus_distance must be a finite number > 0, got {focus_distance}"),
            ));
        }
        Ok(ThinLensDesc {
            aperture_radius,
            focus_distance,
        })
    }

    fn parse_film(&mut self, elem: ElemId) -> Result<FilmDesc> {
        let tree = self.tree;
        let kind = tree.type_of(elem);
        if kind != "hdrfilm" {
            return Err(tree.error(elem, format!("film type \"{kind}\" is not supported yet")));
        }
        let props = Props::collect(tree, elem)?;
        let mut film = FilmDesc::default();
        for (name, side) in [("width", &mut film.width), ("height", &mut film.height)] {
            if let Some(v) = props.integer(name)? {
                if !(1..=MAX_FILM_SIDE).contains(&v) {
                    return Err(tree.error(
                        props.elem_of(name),
                        format!("film {name} must be between 1 and {MAX_FILM_SIDE}, got {v}"),
                    ));
                }
                *side = v as u32;
            }
        }
        // Each side is bounded above, their product here: a 65536² film would ask for
        // hundreds of GiB of accumulators and abort the process.
        let pixels = u64::from(film.width) * u64::from(film.height);
        if pixels > MAX_PIXELS {
            // Name the side written last (the other may be a default), and both lines.
            let at = ["height", "width"]
                .into_iter()
                .filter(|name| props.has(name))
                .max_by_key(|name| tree.elem(props.elem_of(name)).line)
                .map_or(elem, |name| props.elem_of(name));
            let lines: Vec<String> = ["width", "height"]
                .into_iter()
                .filter(|name| props.has(name))
                .map(|name| format!("{name} at line {}", tree.elem(props.elem_of(name)).line))
                .collect();
            return Err(tree.error(
                at,
                format!(
                    "a film of {} × {} = {pixels} pixels ({}) is larger than mltbench renders \
                     (at most {MAX_PIXELS} pixels, e.g. 16384 × 16384)",
                    film.width,
                    film.height,
                    lines.join(", ")
                ),
            ));
        }
        // Output format settings do not change the radiance mltbench computes.
        props.ignore(&[
            "file_format",
            "pixel_format",
            "component_format",
            "sample_border",
            "compensate",
        ]);
        film.crop = crop_window(&props, film.width, film.height)?;
        for (i, object) in props.objects().iter().enumerate() {
            if tree.tag(object.target) == "rfilter" {
                props.use_object(i);
                film.filter = self.parse_rfilter(object.target)?;
            }
        }
        props.finish()?;
        Ok(film)
    }

    fn parse_rfilter(&mut self, elem: ElemId) -> Result<FilterDesc> {
        let tree = self.tree;
        let props = Props::collect(tree, elem)?;
        let filter = match tree.type_of(elem) {
            "box" => FilterDesc::Box,
            "gaussian" => {
                let stddev = props.float("stddev")?.unwrap_or(0.5);
                if stddev <= 0.0 {
                    return Err(tree.error(
                        props.elem_of("stddev"),
                        format!("stddev must be positive, got {stddev}"),
                    ));
                }
                FilterDesc::Gaussian { stddev }
            }
            other if OTHER_FILTERS.contains(&other) => {
                props.ignore_all();
                let w = tree.warning(
                    elem,
                    &format!("reconstruction filter \"{other}\" is not supported: using box"),
                );
                self.desc.warnings.push(w);
                FilterDesc::Box
            }
            other => {
                return Err(tree.error(
                    elem,
                    format!(
                        "unknown reconstruction filter type \"{other}\" (Mitsuba 3 has box, \
                         gaussian, tent, mitchell, catmullrom and lanczos)"
                    ),
                ));
            }
        };
        props.finish()?;
        Ok(filter)
    }

    /// Any sampler type: only `sample_count` (default 4) matters, mltbench draws its own
    /// random numbers.
    fn parse_sampler(&mut self, elem: ElemId) -> Result<u32> {
        let tree = self.tree;
        let props = Props::collect(tree, elem)?;
        let kind = tree.type_of(elem);
        if KNOWN_SAMPLERS.contains(&kind) {
            props.ignore(&["seed", "jitter", "strength", "scramble_seed", "dimension"]);
        } else {
            let w = tree.warning(
                elem,
                &format!("unknown sampler type \"{kind}\": only sample_count is used"),
            );
            self.desc.warnings.push(w);
        }
        let count = match props.integer("sample_count")? {
            None => SensorDesc::default().sample_count,
            Some(n) if n >= 1 && n <= u32::MAX as i64 => n as u32,
            Some(n) => {
                return Err(tree.error(
                    props.elem_of("sample_count"),
                    format!("sample_count must be between 1 and {}, got {n}", u32::MAX),
                ));
            }
        };
        if !KNOWN_SAMPLERS.contains(&kind) {
            props.ignore_all();
        }
        props.finish()?;
        Ok(count)
    }
}

/// `fov` + `fov_axis`, or `focal_length` (default 50 mm). A focal length is, as in Mitsuba,
/// the field of view along the diagonal of a 36 × 24 mm film; the camera applies it to the
/// diagonal of the actual film.
fn field_of_view(props: &Props) -> Result<(f32, FovAxis)> {
    let tree = props.tree();
    if props.has("fov") && props.has("focal_length") {
        return Err(tree.error(
            props.elem_of("fov"),
            "give either fov or focal_length, not both",
        ));
    }
    if let Some(fov) = props.float("fov")? {
        if !(fov > 0.0 && fov < 180.0) {
            return Err(tree.error(
                props.elem_of("fov"),
                format!("fov must be between 0 and 180 degrees (exclusive), got {fov}"),
            ));
        }
        let axis = match props.string("fov_axis")? {
            None => FovAxis::X,
            Some(name) => match name.to_ascii_lowercase().as_str() {
                "x" => FovAxis::X,
                "y" => FovAxis::Y,
                "diagonal" => FovAxis::Diagonal,
                "smaller" => FovAxis::Smaller,
                "larger" => FovAxis::Larger,
                _ => {
                    return Err(tree.error(
                        props.elem_of("fov_axis"),
                        format!("fov_axis \"{name}\" must be x, y, diagonal, smaller or larger"),
                    ));
                }
            },
        };
        return Ok((fov, axis));
    }
    if props.has("fov_axis") {
        return Err(tree.error(
            props.elem_of("fov_axis"),
            "fov_axis only applies together with fov",
        ));
    }
    let focal_mm: f64 = match props.get("focal_length") {
        None => 50.0,
        Some(_) if props.is_number("focal_length") => {
            f64::from(props.float("focal_length")?.unwrap_or(50.0))
        }
        Some(_) => {
            let text = props.string("focal_length")?.unwrap_or("50mm").trim();
            let number = text.strip_suffix("mm").unwrap_or(text).trim();
            number.parse::<f64>().map_err(|_| {
                tree.error(
                    props.elem_of("focal_length"),
                    format!("could not parse focal length \"{text}\" (expected e.g. \"50mm\")"),
                )
            })?
        }
    };
    if !(focal_mm > 0.0 && focal_mm.is_finite()) {
        return Err(tree.error(
            props.elem_of("focal_length"),
            format!("focal length must be positive, got {focal_mm}"),
        ));
    }
    let diagonal = FILM_35MM.0.hypot(FILM_35MM.1);
    let fov = (2.0 * (diagonal / (2.0 * focal_mm)).atan()).to_degrees();
    Ok((fov as f32, FovAxis::Diagonal))
}

/// Mitsuba's `has_scale`: the linear part times its transpose differs from the identity.
fn has_scale(t: &Transform) -> bool {
    let m = Mat3::from_mat4(t.matrix);
    let p = m * m.transpose();
    (0..3).any(|i| {
        let expected = Vec3::AXES[i];
        (p.col(i) - expected).abs().max_element() > 1e-3
    })
}

/// The sensor Mitsuba creates for a scene without one: 45° along x, looking down +z from in
/// front of the scene's bounding box so that all of it is in view.
pub(super) fn default_sensor(bbox_min: Vec3, bbox_max: Vec3) -> SensorDesc {
    let mut sensor = SensorDesc {
        fov_degrees: 45.0,
        fov_axis: FovAxis::X,
        ..SensorDesc::default()
    };
    let extents = bbox_max - bbox_min;
    let center = (bbox_min + bbox_max) * 0.5;
    let size = extents.max_element();
    if !(size > 0.0 && size.is_finite()) {
        return sensor;
    }
    let distance = size / (2.0 * 22.5f32.to_radians().tan());
    sensor.far_clip = size * 5.0 + distance;
    sensor.near_clip = distance / 100.0;
    sensor.to_world = Transform::new(glam::Mat4::from_translation(Vec3::new(
        center.x,
        center.y,
        bbox_min.z - distance,
    )))
    .unwrap_or(Transform::IDENTITY);
    sensor
}

/// `crop_offset_x`, `crop_offset_y`, `crop_width`, `crop_height` (Mitsuba 3's `hdrfilm`:
/// offsets default to 0, sizes to the film's; the window must lie inside the film). `None`
/// when none is given.
fn crop_window(props: &Props, width: u32, height: u32) -> Result<Option<CropWindow>> {
    let names = [
        "crop_offset_x",
        "crop_offset_y",
        "crop_width",
        "crop_height",
    ];
    if !names.iter().any(|name| props.has(name)) {
        return Ok(None);
    }
    let tree = props.tree();
    let read = |name: &str, default: u32, least: i64| -> Result<u32> {
        match props.integer(name)? {
            None => Ok(default),
            Some(v) if v >= least && v <= MAX_FILM_SIDE => Ok(v as u32),
            Some(v) => Err(tree.error(
                props.elem_of(name),
                format!("{name} must be between {least} and {MAX_FILM_SIDE}, got {v}"),
            )),
        }
    };
    let window = CropWindow {
        x: read("crop_offset_x", 0, 0)?,
        y: read("crop_offset_y", 0, 0)?,
        width: read("crop_width", width, 1)?,
        height: read("crop_height", height, 1)?,
    };
    for (axis, offset, size, side) in [
        ("x", window.x, window.width, width),
        ("y", window.y, window.height, height),
    ] {
        if u64::from(offset) + u64::from(size) > u64::from(side) {
            // Name whichever of the two was written last.
            let [o, s] = if axis == "x" {
                ["crop_offset_x", "crop_width"]
            } else {
                ["crop_offset_y", "crop_height"]
            };
            let at = [o, s]
                .into_iter()
                .filter(|name| props.has(name))
                .max_by_key(|name| tree.elem(props.elem_of(name)).line)
                .map(|name| props.elem_of(name))
                .expect("one of them is given");
            return Err(tree.error(
                at,
                format!(
                    "the crop window leaves the film along {axis}: offset {offset} + size \
                     {size} > {side}"
                ),
            ));
        }
    }
    Ok(Some(window))
}
