//! `<emitter>`: area lights attached to shapes, and the point, directional and constant
//! emitters that stand alone. Every emitted quantity defaults to 1, as in Mitsuba 3.

use glam::Vec3;

use super::Builder;
use super::values::Props;
use super::xml::ElemId;
use crate::error::Result;
use crate::math::Rgb;
use crate::scene::EmitterDesc;

/// Mitsuba emitters mltbench does not implement yet.
const UNSUPPORTED: &[&str] = &["spot", "envmap", "sunsky", "sky", "sun", "projector"];

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
            "point" | "directional" | "constant" => {
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
            "constant" => {
                if let Some(previous) = self.environment {
                    return Err(tree.error(
                        elem,
                        format!(
                            "only one environment emitter per scene (the first is at line {})",
                            tree.elem(previous).line
                        ),
                    ));
                }
                self.environment = Some(elem);
                EmitterDesc::Constant {
                    radiance: emission(&props, "radiance")?,
                }
            }
            other => return Err(tree.error(elem, format!("unknown emitter type \"{other}\""))),
        };
        props.finish()?;
        self.desc.emitters.push(desc);
        Ok(true)
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
