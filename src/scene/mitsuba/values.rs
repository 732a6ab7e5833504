//! Parameter values of one plugin element (`<float>`, `<rgb>`, `<spectrum>`, `<transform>`,
//! nested and referenced objects…) collected into a property bag that the plugin queries by
//! name. As in Mitsuba, a parameter the plugin never asks for is an error: it is almost always
//! a misspelling, and silently ignoring it would render something other than what was meant.

use std::cell::Cell;

use glam::Vec3;

use super::transform::parse_transform;
use super::xml::{ElemId, Tree};
use crate::error::Result;
use crate::math::{Rgb, Transform};
use crate::scene::spectra::{SpectrumUse, spectrum_to_rgb, uniform_spectrum_to_rgb};

/// Splits a list of numbers written "x, y, z" or "x y z".
pub(super) fn tokens(text: &str) -> Vec<&str> {
    text.split(|c: char| c == ',' || c.is_whitespace())
        .filter(|t| !t.is_empty())
        .collect()
}

/// A finite number; `what` names it in the message.
pub(super) fn parse_f32(tree: &Tree, elem: ElemId, what: &str, text: &str) -> Result<f32> {
    match text.trim().parse::<f32>() {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(_) => Err(tree.error(elem, format!("{what}: \"{text}\" is not a finite number"))),
        Err(_) => Err(tree.error(
            elem,
            format!("{what}: could not parse \"{text}\" as a number"),
        )),
    }
}

/// A list of finite numbers of one of the lengths in `counts`.
pub(super) fn parse_floats(
    tree: &Tree,
    elem: ElemId,
    what: &str,
    text: &str,
    counts: &[usize],
) -> Result<Vec<f32>> {
    let parts = tokens(text);
    if !counts.contains(&parts.len()) {
        let expected: Vec<String> = counts.iter().map(|c| c.to_string()).collect();
        return Err(tree.error(
            elem,
            format!(
                "{what} needs {} values, got {} (\"{text}\")",
                expected.join(" or "),
                parts.len()
            ),
        ));
    }
    parts
        .iter()
        .map(|p| parse_f32(tree, elem, what, p))
        .collect()
}

/// `x`/`y`/`z` attributes or `value` (one number for all three, or three numbers),
/// missing components taking `default`.
pub(super) fn parse_xyz(tree: &Tree, elem: ElemId, default: f32) -> Result<Vec3> {
    let has_xyz = ["x", "y", "z"].iter().any(|k| tree.attr(elem, k).is_some());
    if let Some(value) = tree.attr(elem, "value") {
        if has_xyz {
            return Err(tree.error(elem, "can't mix \"value\" and \"x\"/\"y\"/\"z\" attributes"));
        }
        let v = parse_floats(tree, elem, "value", value, &[1, 3])?;
        return Ok(if v.len() == 1 {
            Vec3::splat(v[0])
        } else {
            Vec3::new(v[0], v[1], v[2])
        });
    }
    let mut out = [default; 3];
    for (i, key) in ["x", "y", "z"].iter().enumerate() {
        if let Some(text) = tree.attr(elem, key) {
            out[i] = parse_f32(tree, elem, key, text)?;
        }
    }
    Ok(Vec3::from(out))
}

/// A `<spectrum>` value.
#[derive(Clone, Debug, PartialEq)]
pub(super) enum SpectrumValue {
    Constant(f32),
    /// (wavelength in nm, value), increasing wavelengths.
    Pairs(Vec<(f32, f32)>),
}

#[derive(Clone, Debug, PartialEq)]
pub(super) enum Value {
    Float(f32),
    Integer(i64),
    Bool(bool),
    Str(String),
    Rgb(Rgb),
    Spectrum(SpectrumValue),
    /// `<point>` or `<vector>`.
    Vector(Vec3),
    Transform(Transform),
}

impl Value {
    fn type_name(&self) -> &'static str {
        match self {
            Value::Float(_) => "<float>",
            Value::Integer(_) => "<integer>",
            Value::Bool(_) => "<boolean>",
            Value::Str(_) => "<string>",
            Value::Rgb(_) => "<rgb>",
            Value::Spectrum(_) => "<spectrum>",
            Value::Vector(_) => "<point>/<vector>",
            Value::Transform(_) => "<transform>",
        }
    }
}

pub(super) struct Prop {
    pub name: String,
    pub value: Value,
    pub elem: ElemId,
    used: Cell<bool>,
}

/// A nested or referenced object.
pub(super) struct ObjectChild {
    /// The `name` attribute of the nested element or of the `<ref>`.
    pub name: Option<String>,
    /// The object element itself (a `<ref>` resolved).
    pub target: ElemId,
    /// Where it appears inside the owner (the nested element or the `<ref>`).
    pub via: ElemId,
    used: Cell<bool>,
}

/// The parameters and child objects of one plugin element.
pub(super) struct Props<'a> {
    tree: &'a Tree,
    owner: ElemId,
    props: Vec<Prop>,
    objects: Vec<ObjectChild>,
}

impl<'a> Props<'a> {
    /// Parses every child of `owner`; value errors are reported here, before the plugin runs.
    pub fn collect(tree: &'a Tree, owner: ElemId) -> Result<Props<'a>> {
        let mut props: Vec<Prop> = Vec::new();
        let mut objects = Vec::new();
        for &child in &tree.elem(owner).children {
            let name = tree.attr(child, "name").map(str::to_string);
            match tree.tag(child) {
                "ref" => {
                    let target = tree.resolve_ref(child)?;
                    objects.push(ObjectChild {
                        name,
                        target,
                        via: child,
                        used: Cell::new(false),
                    });
                }
                "integrator" | "sensor" | "film" | "rfilter" | "sampler" | "shape" | "bsdf"
                | "emitter" | "texture" | "medium" | "phase" | "volume" => {
                    objects.push(ObjectChild {
                        name,
                        target: child,
                        via: child,
                        used: Cell::new(false),
                    });
                }
                _ => {
                    let name = name.unwrap_or_default();
                    if let Some(previous) = props.iter().find(|p| p.name == name) {
                        return Err(tree.error(
                            child,
                            format!(
                                "parameter \"{name}\" given twice (first at line {})",
                                tree.elem(previous.elem).line
                            ),
                        ));
                    }
                    let value = parse_value(tree, child)?;
                    props.push(Prop {
                        name,
                        value,
                        elem: child,
                        used: Cell::new(false),
                    });
                }
            }
        }
        // mltbench reads a texture only as a diffuse BSDF's reflectance (`textures.rs`).
        let takes_texture = |name: &Option<String>| {
            tree.tag(owner) == "bsdf"
                && matches!(
                    (tree.type_of(owner), name.as_deref()),
                    ("diffuse", Some("reflectance"))
                        | ("plastic" | "roughplastic", Some("diffuse_reflectance"))
                )
        };
        for object in &objects {
            if tree.tag(object.target) == "texture" && !takes_texture(&object.name) {
                return Err(tree.error(
                    object.via,
                    format!(
                        "{} as \"{}\" of {}: not supported yet; mltbench reads textures \
                         only as a diffuse reflectance (diffuse's reflectance, plastic's and \
                         roughplastic's diffuse_reflectance; use a constant <rgb> or \
                         <spectrum>)",
                        tree.describe(object.target),
                        object.name.as_deref().unwrap_or(""),
                        tree.describe(owner)
                    ),
                ));
            }
        }
        Ok(Props {
            tree,
            owner,
            props,
            objects,
        })
    }

    pub fn owner(&self) -> ElemId {
        self.owner
    }

    pub fn tree(&self) -> &'a Tree {
        self.tree
    }

    pub fn has(&self, name: &str) -> bool {
        self.props.iter().any(|p| p.name == name)
    }

    /// True when parameter `name` was written as a `<float>` or `<integer>`.
    pub fn is_number(&self, name: &str) -> bool {
        self.props
            .iter()
            .any(|p| p.name == name && matches!(p.value, Value::Float(_) | Value::Integer(_)))
    }

    /// The parameter `name`, marked as used.
    pub fn get(&self, name: &str) -> Option<&Prop> {
        let prop = self.props.iter().find(|p| p.name == name)?;
        prop.used.set(true);
        Some(prop)
    }

    /// Marks parameters that are accepted but have no effect in mltbench.
    pub fn ignore(&self, names: &[&str]) {
        for name in names {
            let _ = self.get(name);
        }
    }

    /// Accepts everything (for plugins whose parameters mltbench cannot know).
    pub fn ignore_all(&self) {
        for p in &self.props {
            p.used.set(true);
        }
        for o in &self.objects {
            o.used.set(true);
        }
    }

    fn wrong_type(&self, prop: &Prop, expected: &str) -> crate::error::Error {
        self.tree.error(
            prop.elem,
            format!(
                "parameter \"{}\" of {} must be {expected}, not {}",
                prop.name,
                self.tree.describe(self.owner),
                prop.value.type_name()
            ),
        )
    }

    pub fn float(&self, name: &str) -> Result<Option<f32>> {
        let Some(prop) = self.get(name) else {
            return Ok(None);
        };
        match prop.value {
            Value::Float(v) => Ok(Some(v)),
            Value::Integer(v) => Ok(Some(v as f32)),
            _ => Err(self.wrong_type(prop, "a <float>")),
        }
    }

    pub fn integer(&self, name: &str) -> Result<Option<i64>> {
        let Some(prop) = self.get(name) else {
            return Ok(None);
        };
        match prop.value {
            Value::Integer(v) => Ok(Some(v)),
            Value::Float(v) if v.fract() == 0.0 && v.abs() < 1e15 => Ok(Some(v as i64)),
            _ => Err(self.wrong_type(prop, "an <integer>")),
        }
    }

    pub fn boolean(&self, name: &str) -> Result<Option<bool>> {
        let Some(prop) = self.get(name) else {
            return Ok(None);
        };
        match prop.value {
            Value::Bool(v) => Ok(Some(v)),
            _ => Err(self.wrong_type(prop, "a <boolean>")),
        }
    }

    pub fn string(&self, name: &str) -> Result<Option<&'a str>> {
        let Some(prop) = self.get(name) else {
            return Ok(None);
        };
        match &prop.value {
            // The bag lives no longer than the tree: hand out the tree's copy of the text.
            Value::Str(_) => Ok(self.tree.attr(prop.elem, "value")),
            _ => Err(self.wrong_type(prop, "a <string>")),
        }
    }

    pub fn vector(&self, name: &str) -> Result<Option<Vec3>> {
        let Some(prop) = self.get(name) else {
            return Ok(None);
        };
        match prop.value {
            Value::Vector(v) => Ok(Some(v)),
            _ => Err(self.wrong_type(prop, "a <point> or <vector>")),
        }
    }

    pub fn transform(&self, name: &str) -> Result<Option<Transform>> {
        let Some(prop) = self.get(name) else {
            return Ok(None);
        };
        match prop.value {
            Value::Transform(t) => Ok(Some(t)),
            _ => Err(self.wrong_type(prop, "a <transform>")),
        }
    }

    /// A colour: `<rgb>` (one or three values), `<spectrum>`, or a `<float>` for grey.
    /// Spectra are converted as Mitsuba's RGB variants do: inside an emitter as emission,
    /// η/k/IORs unbounded, everything else as a reflectance.
    pub fn color(&self, name: &str) -> Result<Option<Rgb>> {
        let Some(prop) = self.get(name) else {
            return Ok(None);
        };
        let usage = if self.tree.tag(self.owner) == "emitter" {
            SpectrumUse::Emission
        } else if matches!(name, "eta" | "k" | "int_ior" | "ext_ior") {
            SpectrumUse::Unbounded
        } else {
            SpectrumUse::Reflectance
        };
        let rgb = match &prop.value {
            Value::Rgb(c) => *c,
            Value::Float(v) => Rgb::splat(*v),
            Value::Integer(v) => Rgb::splat(*v as f32),
            // A one-value spectrum is a constant over wavelength: inside an emitter it is
            // equal-energy white, which is not (1, 1, 1) in sRGB.
            Value::Spectrum(SpectrumValue::Constant(v)) => uniform_spectrum_to_rgb(*v, usage),
            Value::Spectrum(SpectrumValue::Pairs(pairs)) => spectrum_to_rgb(pairs, usage),
            _ => return Err(self.wrong_type(prop, "an <rgb>, <spectrum> or <float>")),
        };
        if !rgb.0.iter().all(|c| c.is_finite()) {
            return Err(self.tree.error(
                prop.elem,
                format!("\"{name}\" converts to a non-finite colour"),
            ));
        }
        Ok(Some(rgb))
    }

    /// The element a parameter was written in (for messages about its value).
    pub fn elem_of(&self, name: &str) -> ElemId {
        self.props
            .iter()
            .find(|p| p.name == name)
            .map_or(self.owner, |p| p.elem)
    }

    pub fn objects(&self) -> &[ObjectChild] {
        &self.objects
    }

    pub fn use_object(&self, index: usize) {
        self.objects[index].used.set(true);
    }

    /// Fails on the first parameter or child object the plugin did not use.
    pub fn finish(&self) -> Result<()> {
        if let Some(prop) = self.props.iter().find(|p| !p.used.get()) {
            return Err(self.tree.error(
                prop.elem,
                format!(
                    "unknown parameter \"{}\" for {} (misspelled, or not supported by mltbench)",
                    prop.name,
                    self.tree.describe(self.owner)
                ),
            ));
        }
        if let Some(object) = self.objects.iter().find(|o| !o.used.get()) {
            return Err(self.tree.error(
                object.via,
                format!(
                    "unexpected {} inside {}",
                    self.tree.describe(object.target),
                    self.tree.describe(self.owner)
                ),
            ));
        }
        Ok(())
    }
}

fn parse_value(tree: &Tree, elem: ElemId) -> Result<Value> {
    let value = tree.attr(elem, "value").unwrap_or("");
    Ok(match tree.tag(elem) {
        "float" => Value::Float(parse_f32(tree, elem, "value", value)?),
        "integer" => match value.trim().parse::<i64>() {
            Ok(v) => Value::Integer(v),
            Err(_) => {
                return Err(tree.error(elem, format!("could not parse \"{value}\" as an integer")));
            }
        },
        "boolean" => match value.trim().to_ascii_lowercase().as_str() {
            "true" => Value::Bool(true),
            "false" => Value::Bool(false),
            _ => {
                return Err(tree.error(
                    elem,
                    format!("could not parse \"{value}\" as a boolean (true or false)"),
                ));
            }
        },
        "string" => Value::Str(value.to_string()),
        "rgb" => {
            let v = parse_floats(tree, elem, "<rgb> value", value, &[1, 3])?;
            Value::Rgb(if v.len() == 1 {
                Rgb::splat(v[0])
            } else {
                Rgb::new(v[0], v[1], v[2])
            })
        }
        "spectrum" => Value::Spectrum(parse_spectrum(tree, elem)?),
        "point" | "vector" => Value::Vector(parse_xyz(tree, elem, 0.0)?),
        "transform" => Value::Transform(parse_transform(tree, elem)?),
        other => return Err(tree.error(elem, format!("<{other}> is not a parameter"))),
    })
}

fn parse_spectrum(tree: &Tree, elem: ElemId) -> Result<SpectrumValue> {
    if tree.attr(elem, "filename").is_some() {
        return Err(tree.error(elem, "spectra read from files are not supported yet"));
    }
    let Some(value) = tree.attr(elem, "value") else {
        return Err(tree.error(elem, "<spectrum> needs a \"value\" attribute"));
    };
    let parts = tokens(value);
    if parts.len() == 1 && !parts[0].contains(':') {
        return Ok(SpectrumValue::Constant(parse_f32(
            tree,
            elem,
            "<spectrum> value",
            parts[0],
        )?));
    }
    if parts.is_empty() {
        return Err(tree.error(elem, "<spectrum> value is empty"));
    }
    let mut pairs = Vec::with_capacity(parts.len());
    for part in parts {
        let Some((wavelength, v)) = part.split_once(':') else {
            return Err(tree.error(
                elem,
                format!("\"{part}\": expected wavelength:value pairs (e.g. \"400:0.5, 700:0.8\")"),
            ));
        };
        let wavelength = parse_f32(tree, elem, "wavelength", wavelength)?;
        let v = parse_f32(tree, elem, "spectrum value", v)?;
        if wavelength <= 0.0 {
            return Err(tree.error(elem, format!("wavelength {wavelength} must be positive")));
        }
        if let Some(&(previous, _)) = pairs.last()
            && wavelength <= previous
        {
            return Err(tree.error(
                elem,
                format!("wavelengths must increase ({wavelength} follows {previous})"),
            ));
        }
        pairs.push((wavelength, v));
    }
    Ok(SpectrumValue::Pairs(pairs))
}
