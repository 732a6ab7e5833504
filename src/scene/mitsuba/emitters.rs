//! `<emitter>`: area lights attached to shapes, and the point, spot, directional, constant
//! and envmap emitters that stand alone. Every emitted quantity defaults to 1, as in
//! Mitsuba 3.

use glam::Vec3;

use super::Builder;
use super::values::Props;
use super::xml::ElemId;
use crate::error::Result;
use crate::math::Rgb;
use crate::scene::EmitterDesc;

/// Mitsuba emitters mltbench does not implement yet.
const UNSUPPORTED: &[&str] = &["sunsky", "sky", "sun", "projector"];

impl Builder<'_> {
    /// The radiance of an `<emitter type="area">` nested in (or referenced by) a shape.
    pub(super) fn area_radiance(&mut self, elem: ElemId) -> Result<Rgb> {
        let tree = self.tree;
        match tree.type_of(elem) {
            "area" => {}
            kind if UNSUPPORTED.contains(&kind) => {
                return Err(tree.error(
                    elem,
                    format!("emitter type \"{kind}\" is not supported yet"),
                ));
            }
            "point" | "spot" | "directional" | "constant" | "envmap" => {
                return Err(tree.error(elem, "only area emitters can be attached to a shape"));
            }
            kind => return Err(tree.error(elem, format!("unknown emitter type \"{kind}\""))),
        }
        let props = Props::collect(tree, elem)?;
        if props.has("to_world") {
            return Err(tree.error(
                props.elem_of("to_world"),
                "an area emitter takes its placement from its shape: to_world is not allowed",
            ));
        }
        let radiance = emission(&props, "radiance")?;
        props.finish()?;
        Ok(radiance)
    }

    /// An emitter written directly in the scene. Area emitters are attached to shapes
    /// instead; `false` tells the caller this one was not handled here.
    pub(super) fn standalone_emitter(&mut self, elem: ElemId) -> Result<bool> {
        let tree = self.tree;
        let kind = tree.type_of(elem);
        if kind == "area" {
            return Ok(false);
        }
        if UNSUPPORTED.contains(&kind) {
            return Err(tree.error(
                elem,
                format!("emitter type \"{kind}\" is not supported yet"),
            ));
        }
        let props = Props::collect(tree, elem)?;
        let desc = match kind {
            "point" => {
                let intensity = emission(&props, "intensity")?;
                let position = placed(&props, "position", |t| t.point(Vec3::ZERO))?;
                EmitterDesc::Point {
                    intensity,
                    position,
                }
            }
            "directional" => {
                let irradiance = emission(&props, "irradiance")?;
                let direction = placed(&props, "direction", |t| t.vector(Vec3::Z))?;
                let unit = direction.normalize_or_zero();
                if unit == Vec3::ZERO {
                    let at = if props.has("direction") {
                        "direction"
                    } else {
                        "to_world"
                    };
                    return Err(tree.error(props.elem_of(at), "the light direction is zero"));
                }
                EmitterDesc::Directional {
                    irradiance,
                    direction: unit,
                }
            }
            "spot" => self.spot(&props)?,
            "constant" => {
                self.claim_environment(elem)?;
                EmitterDesc::Constant {
                    radiance: emission(&props, "radiance")?,
                }
            }
            "envmap" => {
                self.claim_environment(elem)?;
                self.envmap(&props)?
            }
            other => return Err(tree.error(elem, format!("unknown emitter type \"{other}\""))),
        };
        props.finish()?;
        self.desc.emitters.push(desc);
        self.desc.emitter_locations.push(tree.location(elem));
        Ok(true)
    }
}

impl Builder<'_> {
    /// Mitsuba 3 allows one environment emitter (`constant` or `envmap`) per scene.
    fn claim_environment(&mut self, elem: ElemId) -> Result<()> {
        if let Some(previous) = self.environment {
            return Err(self.tree.error(
                elem,
                format!(
                    "only one environment emitter per scene (the first is at line {})",
                    self.tree.elem(previous).line
                ),
            ));
        }
        self.environment = Some(elem);
        Ok(())
    }

    /// `spot`: `intensity`, `cutoff_angle` (degrees, default 20), `beam_width` (degrees,
    /// default 3/4 of the cutoff), `to_world`.
    fn spot(&self, props: &Props) -> Result<EmitterDesc> {
        let tree = self.tree;
        let intensity = emission(props, "intensity")?;
        let cutoff_angle = props.float("cutoff_angle")?.unwrap_or(20.0);
        if !(cutoff_angle > 0.0 && cutoff_angle <= 180.0) {
            return Err(tree.error(
                props.elem_of("cutoff_angle"),
                format!("cutoff_angle must be in (0, 180] degrees, got {cutoff_angle}"),
            ));
        }
        let beam_width = props.float("beam_width")?.unwrap_or(cutoff_angle * 0.75);
        if !(beam_width >= 0.0 && beam_width <= cutoff_angle) {
            return Err(tree.error(
                props.elem_of("beam_width"),
                format!(
                    "beam_width must be between 0 and cutoff_angle ({cutoff_angle}) degrees, \
                     got {beam_width}"
                ),
            ));
        }
        let to_world = props.transform("to_world")?.unwrap_or_default();
        if uniform_scale(&to_world).is_none() {
            return Err(tree.error(
                props.elem_of("to_world"),
                "the to_world of a spot light may rotate, translate and scale uniformly, \
                 but not scale unevenly or shear (the cone would no longer be round)",
            ));
        }
        Ok(EmitterDesc::Spot {
            intensity,
            to_world,
            cutoff_angle,
            beam_width,
        })
    }

    /// `envmap`: `filename` (resolved like mesh files and recorded in `files_read`),
    /// `scale` (default 1), `to_world` (a rotation).
    fn envmap(&mut self, props: &Props) -> Result<EmitterDesc> {
        let tree = self.tree;
        let Some(filename) = props.string("filename")? else {
            return Err(tree.error(props.owner(), "an envmap emitter needs a \"filename\""));
        };
        let named_at = props.elem_of("filename");
        let path = tree
            .find_file(filename, tree.elem(named_at).file, "environment map")
            .map_err(|message| tree.error(named_at, message))?;
        let scale = props.float("scale")?.unwrap_or(1.0);
        if !(scale.is_finite() && scale >= 0.0) {
            return Err(tree.error(
                props.elem_of("scale"),
                format!("scale must be finite and not negative, got {scale}"),
            ));
        }
        let to_world = props.transform("to_world")?.unwrap_or_default();
        if uniform_scale(&to_world).is_none_or(|s| (s - 1.0).abs() > 1e-4) {
            return Err(tree.error(
                props.elem_of("to_world"),
                "the to_world of an envmap must be a rotation (Mitsuba 3 does not \
                 renormalise directions after a scaling)",
            ));
        }
        if !self.desc.files_read.contains(&path) {
            self.desc.files_read.push(path.clone());
        }
        Ok(EmitterDesc::Envmap {
            filename: path,
            scale,
            to_world,
        })
    }
}

/// The factor s when the linear part of `t` is s times an orthogonal matrix (a rotation or
/// reflection scaled uniformly), to a relative tolerance of 10⁻⁴; None otherwise.
fn uniform_scale(t: &crate::math::Transform) -> Option<f32> {
    let m = glam::Mat3::from_mat4(t.matrix).as_dmat3();
    let g = m.transpose() * m; // = s² I for a similarity
    let s2 = (g.x_axis.x + g.y_axis.y + g.z_axis.z) / 3.0;
    if !(s2.is_finite() && s2 > 0.0) {
        return None;
    }
    let off = (g - glam::DMat3::from_diagonal(glam::DVec3::splat(s2))).to_cols_array();
    if off.iter().all(|v| v.abs() <= 1e-4 * s2) {
        Some(s2.sqrt() as f32)
    } else {
        None
    }
}

/// An emitted quantity (default 1): finite and not negative.
fn emission(props: &Props, name: &str) -> Result<Rgb> {
    let Some(rgb) = props.color(name)? else {
        return Ok(Rgb::splat(1.0));
    };
    if !rgb.is_valid_radiance() {
        return Err(props.tree().error(
            props.elem_of(name),
            format!("{name} must be finite and not negative, got {rgb:?}"),
        ));
    }
    Ok(rgb)
}

/// A position or direction given directly by `name`, or by `to_world` (not both).
fn placed(
    props: &Props,
    name: &str,
    from_transform: impl Fn(&crate::math::Transform) -> Vec3,
) -> Result<Vec3> {
    let tree = props.tree();
    if props.has(name) && props.has("to_world") {
        return Err(tree.error(
            props.elem_of(name),
            format!("give either \"{name}\" or \"to_world\", not both"),
        ));
    }
    if let Some(v) = props.vector(name)? {
        return Ok(v);
    }
    Ok(props.transform("to_world")?.map_or_else(
        || from_transform(&crate::math::Transform::IDENTITY),
        |t| from_transform(&t),
    ))
}
