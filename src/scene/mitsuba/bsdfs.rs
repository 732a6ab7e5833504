//! `<bsdf>` elements with Mitsuba 3's parameter names and defaults.
//!
//! Defaults (checked against Mitsuba 3's plugin sources):
//! - `diffuse`: reflectance 0.5.
//! - a shape without a BSDF: `diffuse` 0.5, or 0 (black) if it has an area emitter.
//! - `conductor`, `roughconductor`: `material` "none" (a perfect mirror, no Fresnel term);
//!   given `eta` and/or `k`, the missing one defaults to eta 0 / k 1; specular_reflectance 1.
//! - rough models: `distribution` beckmann, `alpha` 0.1 (or `alpha_u` + `alpha_v`, both
//!   required and equal: anisotropy is refused), `sample_visible` true; α = 0 is raised to 10⁻⁴ with a warning, as Mitsuba does.
//! - `dielectric`, `thindielectric`, `roughdielectric`: int_ior bk7 (1.5046), ext_ior air
//!   (1.000277), specular_reflectance and specular_transmittance 1.
//! - `plastic`, `roughplastic`: int_ior polypropylene (1.49), ext_ior air, diffuse_reflectance
//!   0.5, specular_reflectance 1, nonlinear false; `roughplastic` is isotropic only.
//! - `twosided`: one nested BSDF for both sides or two (front, back); none may transmit.
//! - mltbench extensions, with the defaults of Mitsuba 0.6's plugins of the same names:
//!   `phong` and `blinn` exponent 30, `ward` alpha 0.1; diffuse_reflectance 0.5,
//!   specular_reflectance 0.2.

use super::Builder;
use super::values::{Props, SpectrumValue, Value};
use super::xml::ElemId;
use crate::error::Result;
use crate::math::Rgb;
use crate::scene::spectra::{SpectrumUse, named_conductor, named_ior, spectrum_to_rgb};
use crate::scene::{BsdfDesc, IorPair, MicrofacetKind, Roughness};
use crate::texture::Texture;

/// Named IORs used as defaults (the values of Mitsuba's IOR table).
const IOR_BK7: f32 = 1.5046;
const IOR_AIR: f32 = 1.000277;
const IOR_POLYPROPYLENE: f32 = 1.49;
/// Smallest microfacet roughness Mitsuba accepts.
const MIN_ALPHA: f32 = 1e-4;
/// Largest roughness mltbench accepts. α is the microfacets' RMS slope: Mitsuba calls 0.3–0.7
/// extremely rough, and as α grows the microfacet models reflect less and less (at α = 100 a
/// rough conductor sphere returns under 10⁻⁶ of the light, in Mitsuba 3.9.1 as here). A
/// larger value is a typo, not a material; above 1 mltbench warns.
const MAX_ALPHA: f32 = 100.0;

/// Mitsuba BSDF plugins mltbench does not implement (a clearer message than "unknown").
const UNSUPPORTED: &[&str] = &[
    "principled",
    "principledthin",
    "hair",
    "measured",
    "measured_polarized",
    "blendbsdf",
    "mask",
    "bumpmap",
    "normalmap",
    "polarizer",
    "retarder",
    "circular",
    "pplastic",
    "roughcoating",
    "coating",
];

impl Builder<'_> {
    /// The BSDF written at `elem`, parsed once however often it is referenced.
    pub(super) fn bsdf_desc(&mut self, elem: ElemId) -> Result<BsdfDesc> {
        if let Some(desc) = self.parsed_bsdfs.get(&elem) {
            return Ok(desc.clone());
        }
        let desc = self.guarded(elem, |b| b.parse_bsdf(elem))?;
        self.parsed_bsdfs.insert(elem, desc.clone());
        Ok(desc)
    }

    /// Index into `SceneDescription::bsdfs` of the BSDF at `elem` (shared by every shape
    /// that references it).
    pub(super) fn bsdf_index(&mut self, elem: ElemId) -> Result<usize> {
        if let Some(&index) = self.bsdf_indices.get(&elem) {
            return Ok(index);
        }
        let desc = self.bsdf_desc(elem)?;
        let index = self.desc.bsdfs.len();
        self.desc.bsdfs.push(desc);
        self.bsdf_indices.insert(elem, index);
        Ok(index)
    }

    /// Mitsuba's BSDF for shapes that name none: diffuse with reflectance 0.5, but 0 (black)
    /// on a shape with an area emitter. Mitsuba 3's `Shape` constructor (src/render/shape.cpp)
    /// sets `reflectance` 0 for emitters; with 0.5, light scattered back onto a lamp (e.g. a
    /// small emitter inside a glass sphere) came out about 2% brighter than in Mitsuba.
    pub(super) fn default_bsdf_index(&mut self, emitter: bool) -> usize {
        let reflectance = if emitter { 0.0 } else { 0.5 };
        *self.default_bsdf[emitter as usize].get_or_insert_with(|| {
            self.desc.bsdfs.push(BsdfDesc::Diffuse {
                reflectance: Rgb::splat(reflectance),
            });
            self.desc.bsdfs.len() - 1
        })
    }

    fn parse_bsdf(&mut self, elem: ElemId) -> Result<BsdfDesc> {
        let tree = self.tree;
        let kind = tree.type_of(elem);
        let props = Props::collect(tree, elem)?;
        let desc = match kind {
            "diffuse" => match self.texture_param(&props, "reflectance")? {
                Some(texture) => BsdfDesc::Textured {
                    base: Box::new(BsdfDesc::Diffuse {
                        reflectance: texture.mean(),
                    }),
                    diffuse: texture,
                },
                None => BsdfDesc::Diffuse {
                    reflectance: self.reflectance(&props, "reflectance", 0.5)?,
                },
            },
            "conductor" => {
                let eta_k = conductor_ior(&props)?;
                let specular_reflectance = self.reflectance(&props, "specular_reflectance", 1.0)?;
                BsdfDesc::Conductor {
                    eta_k,
                    specular_reflectance,
                }
            }
            "roughconductor" => {
                let eta_k = conductor_ior(&props)?;
                let specular_reflectance = self.reflectance(&props, "specular_reflectance", 1.0)?;
                let roughness = self.roughness(&props, true)?;
                BsdfDesc::RoughConductor {
                    eta_k,
                    specular_reflectance,
                    roughness,
                }
            }
            "dielectric" | "thindielectric" | "roughdielectric" => {
                let ior = ior_pair(&props, IOR_BK7, false)?;
                let specular_reflectance = self.reflectance(&props, "specular_reflectance", 1.0)?;
                let specular_transmittance =
                    self.reflectance(&props, "specular_transmittance", 1.0)?;
                match kind {
                    "dielectric" => BsdfDesc::Dielectric {
                        ior,
                        specular_reflectance,
                        specular_transmittance,
                    },
                    "thindielectric" => BsdfDesc::ThinDielectric {
                        ior,
                        specular_reflectance,
                        specular_transmittance,
                    },
                    _ => BsdfDesc::RoughDielectric {
                        ior,
                        roughness: self.roughness(&props, true)?,
                        specular_reflectance,
                        specular_transmittance,
                    },
                }
            }
            "plastic" | "roughplastic" => {
                let ior = ior_pair(&props, IOR_POLYPROPYLENE, true)?;
                let texture = self.texture_param(&props, "diffuse_reflectance")?;
                let diffuse_reflectance = match &texture {
                    Some(t) => t.mean(),
                    None => self.reflectance(&props, "diffuse_reflectance", 0.5)?,
                };
                let specular_reflectance = self.reflectance(&props, "specular_reflectance", 1.0)?;
                let nonlinear = props.boolean("nonlinear")?.unwrap_or(false);
                let plastic = if kind == "plastic" {
                    BsdfDesc::Plastic {
                        ior,
                        diffuse_reflectance,
                        specular_reflectance,
                        nonlinear,
                    }
                } else {
                    BsdfDesc::RoughPlastic {
                        ior,
                        diffuse_reflectance,
                        specular_reflectance,
                        roughness: self.roughness(&props, false)?,
                        nonlinear,
                    }
                };
                match texture {
                    Some(diffuse) => BsdfDesc::Textured {
                        base: Box::new(plastic),
                        diffuse,
                    },
                    None => plastic,
                }
            }
            "twosided" => self.twosided(&props)?,
            "null" => BsdfDesc::Null,
            "phong" | "blinn" => {
                let exponent = props.float("exponent")?.unwrap_or(30.0);
                if exponent <= 0.0 {
                    return Err(tree.error(
                        props.elem_of("exponent"),
                        format!("exponent must be positive, got {exponent}"),
                    ));
                }
                let diffuse_reflectance = self.reflectance(&props, "diffuse_reflectance", 0.5)?;
                let specular_reflectance = self.reflectance(&props, "specular_reflectance", 0.2)?;
                energy_conserving(&props, diffuse_reflectance, specular_reflectance)?;
                if kind == "phong" {
                    BsdfDesc::Phong {
                        exponent,
                        diffuse_reflectance,
                        specular_reflectance,
                    }
                } else {
                    BsdfDesc::Blinn {
                        exponent,
                        diffuse_reflectance,
                        specular_reflectance,
                    }
                }
            }
            "ward" => {
                let (alpha_u, alpha_v) = self.alphas(&props)?;
                let diffuse_reflectance = self.reflectance(&props, "diffuse_reflectance", 0.5)?;
                let specular_reflectance = self.reflectance(&props, "specular_reflectance", 0.2)?;
                energy_conserving(&props, diffuse_reflectance, specular_reflectance)?;
                BsdfDesc::Ward {
                    alpha_u,
                    alpha_v,
                    diffuse_reflectance,
                    specular_reflectance,
                }
            }
            other if UNSUPPORTED.contains(&other) => {
                return Err(tree.error(elem, format!("bsdf type \"{other}\" is not supported yet")));
            }
            other => return Err(tree.error(elem, format!("unknown bsdf type \"{other}\""))),
        };
        props.finish()?;
        Ok(desc)
    }

    /// The texture given as parameter `name` (nested or referenced), if any; an error when
    /// the parameter is also given as a value.
    fn texture_param(&mut self, props: &Props, name: &str) -> Result<Option<Texture>> {
        let tree = self.tree;
        let Some(i) = props
            .objects()
            .iter()
            .position(|o| tree.tag(o.target) == "texture" && o.name.as_deref() == Some(name))
        else {
            return Ok(None);
        };
        props.use_object(i);
        let object = &props.objects()[i];
        if props.has(name) {
            return Err(tree.error(
                object.via,
                format!(
                    "\"{name}\" given twice: as a texture and at line {}",
                    tree.elem(props.elem_of(name)).line
                ),
            ));
        }
        self.texture(object.target).map(Some)
    }

    /// `twosided`: one nested BSDF for both sides, or front and back.
    fn twosided(&mut self, props: &Props) -> Result<BsdfDesc> {
        let tree = self.tree;
        let mut sides = Vec::new();
        for (i, object) in props.objects().iter().enumerate() {
            if tree.tag(object.target) != "bsdf" {
                continue;
            }
            props.use_object(i);
            if sides.len() == 2 {
                return Err(tree.error(object.via, "twosided takes at most two nested BSDFs"));
            }
            let side = self.bsdf_desc(object.target)?;
            let transmits = matches!(
                side,
                BsdfDesc::Dielectric { .. }
                    | BsdfDesc::ThinDielectric { .. }
                    | BsdfDesc::RoughDielectric { .. }
                    | BsdfDesc::Null
                    | BsdfDesc::TwoSided { .. }
            );
            if transmits {
                return Err(tree.error(
                    object.via,
                    "twosided can only hold one-sided reflecting BSDFs (no dielectric, null or \
                     twosided)",
                ));
            }
            sides.push(side);
        }
        match sides.len() {
            0 => Err(tree.error(props.owner(), "twosided needs a nested <bsdf>")),
            1 => {
                let side = Box::new(sides.pop().expect("one side"));
                Ok(BsdfDesc::TwoSided {
                    front: side.clone(),
                    back: side,
                })
            }
            _ => {
                let back = Box::new(sides.pop().expect("two sides"));
                let front = Box::new(sides.pop().expect("two sides"));
                Ok(BsdfDesc::TwoSided { front, back })
            }
        }
    }

    /// A reflectance or transmittance: each channel in [0, 1] however it is written
    /// (Mitsuba 3 refuses only an `<rgb>` outside; it renders a `<float>` of 5 as it is and
    /// clamps a spectrum's RGB). A spectrum's samples must lie in [0, 1]; its RGB, when out of
    /// gamut, is clamped as Mitsuba does, with a warning.
    pub(super) fn reflectance(&mut self, props: &Props, name: &str, default: f32) -> Result<Rgb> {
        let Some(rgb) = props.color(name)? else {
            return Ok(Rgb::splat(default));
        };
        let prop = props.get(name).expect("color() found the parameter");
        let outside = |v: f32| !(0.0..=1.0).contains(&v);
        let bad = match &prop.value {
            Value::Spectrum(SpectrumValue::Pairs(pairs)) => pairs
                .iter()
                .find(|(_, v)| outside(*v))
                .map(|(w, v)| format!("{v} at {w} nm")),
            Value::Spectrum(SpectrumValue::Constant(v)) => outside(*v).then(|| v.to_string()),
            _ => rgb
                .0
                .iter()
                .any(|&c| outside(c))
                .then(|| format!("{:?}", rgb.0)),
        };
        if let Some(value) = bad {
            return Err(props_error(
                props,
                name,
                format!("{name} must lie in [0, 1] (a reflectance or transmittance), got {value}"),
            ));
        }
        if let Value::Spectrum(SpectrumValue::Pairs(pairs)) = &prop.value {
            let unclamped = spectrum_to_rgb(pairs, SpectrumUse::Unbounded);
            if unclamped != rgb {
                let w = self.tree.warning(
                    prop.elem,
                    &format!(
                        "{name} converts to RGB {:?}, outside [0, 1]: clamped to {:?}, as \
                         Mitsuba 3 does",
                        unclamped.0, rgb.0
                    ),
                );
                self.desc.warnings.push(w);
            }
        }
        Ok(rgb)
    }

    /// `distribution`, `alpha` / `alpha_u` + `alpha_v`, `sample_visible`.
    fn roughness(&mut self, props: &Props, anisotropic: bool) -> Result<Roughness> {
        let tree = self.tree;
        let kind = match props.string("distribution")? {
            None => MicrofacetKind::Beckmann,
            Some(name) => match name.to_ascii_lowercase().as_str() {
                "beckmann" => MicrofacetKind::Beckmann,
                "ggx" => MicrofacetKind::Ggx,
                _ => {
                    return Err(tree.error(
                        props.elem_of("distribution"),
                        format!("unknown microfacet distribution \"{name}\" (beckmann or ggx)"),
                    ));
                }
            },
        };
        let (alpha_u, alpha_v) = self.alphas(props)?;
        if alpha_u != alpha_v {
            // The models are anisotropic (tests/bsdf.rs checks them against Mitsuba in the
            // local frame), but a surface's shading frame is built from its normal alone,
            // not from dp/du as Mitsuba's is: the highlight would turn the wrong way.
            let why = if anisotropic {
                "anisotropic roughness is not supported: mltbench's shading frame does not \
                 follow the surface's dp/du as Mitsuba 3's does, so the highlight would be \
                 oriented differently"
            } else {
                "this BSDF supports only isotropic roughness"
            };
            return Err(tree.error(
                props.owner(),
                format!("alpha_u = {alpha_u} and alpha_v = {alpha_v} differ: {why}"),
            ));
        }
        let sample_visible = props.boolean("sample_visible")?.unwrap_or(true);
        Ok(Roughness {
            kind,
            alpha_u,
            alpha_v,
            sample_visible,
        })
    }

    /// `alpha` (default 0.1) or both `alpha_u` and `alpha_v`.
    fn alphas(&mut self, props: &Props) -> Result<(f32, f32)> {
        let tree = self.tree;
        let has_uv = props.has("alpha_u") || props.has("alpha_v");
        if has_uv && props.has("alpha") {
            return Err(tree.error(
                props.elem_of("alpha"),
                "give either \"alpha\" or \"alpha_u\" and \"alpha_v\", not both",
            ));
        }
        let (alpha_u, alpha_v) = if has_uv {
            match (props.float("alpha_u")?, props.float("alpha_v")?) {
                (Some(u), Some(v)) => (u, v),
                _ => {
                    return Err(tree.error(
                        props.owner(),
                        "\"alpha_u\" and \"alpha_v\" must be given together",
                    ));
                }
            }
        } else {
            let alpha = props.float("alpha")?.unwrap_or(0.1);
            (alpha, alpha)
        };
        let mut clamp = |name: &str, alpha: f32| -> Result<f32> {
            if alpha < 0.0 {
                return Err(tree.error(
                    props.elem_of(name),
                    format!("roughness must not be negative, got {alpha}"),
                ));
            }
            if alpha > MAX_ALPHA {
                return Err(tree.error(
                    props.elem_of(name),
                    format!(
                        "roughness {alpha} is above {MAX_ALPHA}: the surface would be black \
                         (α is the microfacets' RMS slope; 0.3–0.7 is already extremely rough)"
                    ),
                ));
            }
            if alpha > 1.0 {
                let w = tree.warning(
                    props.elem_of(name),
                    &format!(
                        "roughness {alpha} is above 1 (0.3–0.7 is already extremely rough): \
                         the surface darkens as α grows"
                    ),
                );
                self.desc.warnings.push(w);
            }
            if alpha < MIN_ALPHA {
                let w = tree.warning(
                    props.elem_of(name),
                    &format!(
                        "roughness {alpha} raised to {MIN_ALPHA} (as Mitsuba does); use the \
                         smooth BSDF for a perfectly specular surface"
                    ),
                );
                self.desc.warnings.push(w);
                return Ok(MIN_ALPHA);
            }
            Ok(alpha)
        };
        let name_u = if has_uv { "alpha_u" } else { "alpha" };
        let name_v = if has_uv { "alpha_v" } else { "alpha" };
        let u = clamp(name_u, alpha_u)?;
        let v = if !has_uv && alpha_u == alpha_v {
            u
        } else {
            clamp(name_v, alpha_v)?
        };
        Ok((u, v))
    }
}

/// `phong`, `blinn`, `ward`: their lobes are normalised so that the albedo stays at most
/// ρ_d + ρ_s, which must therefore not exceed 1 in any channel.
fn energy_conserving(props: &Props, diffuse: Rgb, specular: Rgb) -> Result<()> {
    let sum = diffuse + specular;
    if sum.0.iter().any(|&c| c > 1.0) {
        let at = if props.has("specular_reflectance") {
            "specular_reflectance"
        } else {
            "diffuse_reflectance"
        };
        return Err(props_error(
            props,
            at,
            format!(
                "diffuse_reflectance + specular_reflectance is {:?}: above 1 the surface \
                 reflects more light than it receives",
                sum.0
            ),
        ));
    }
    Ok(())
}

fn props_error(props: &Props, name: &str, message: String) -> crate::error::Error {
    props.tree().error(props.elem_of(name), message)
}

/// `material` (a named metal, or "none" for a perfect mirror) or `eta` / `k`.
fn conductor_ior(props: &Props) -> Result<Option<(Rgb, Rgb)>> {
    let material = props.string("material")?;
    let has_eta_k = props.has("eta") || props.has("k");
    match material {
        Some(name) if name != "none" => {
            if has_eta_k {
                return Err(props_error(
                    props,
                    "material",
                    "give either \"material\" or \"eta\"/\"k\", not both".into(),
                ));
            }
            named_conductor(name).map(Some).ok_or_else(|| {
                props_error(
                    props,
                    "material",
                    format!("unknown conductor material \"{name}\""),
                )
            })
        }
        _ if has_eta_k => {
            // Mitsuba's defaults when only one is given: eta 0, k 1.
            let eta = props.color("eta")?.unwrap_or(Rgb::splat(0.0));
            let k = props.color("k")?.unwrap_or(Rgb::splat(1.0));
            if !eta.0.iter().chain(k.0.iter()).all(|c| *c >= 0.0) {
                return Err(props_error(
                    props,
                    "eta",
                    "eta and k must not be negative".into(),
                ));
            }
            Ok(Some((eta, k)))
        }
        _ => Ok(None),
    }
}

/// `int_ior` / `ext_ior` as numbers or names; plastics need them to differ.
fn ior_pair(props: &Props, int_default: f32, must_differ: bool) -> Result<IorPair> {
    let int_ior = ior(props, "int_ior")?.unwrap_or(int_default);
    let ext_ior = ior(props, "ext_ior")?.unwrap_or(IOR_AIR);
    if must_differ && int_ior == ext_ior {
        return Err(props_error(
            props,
            "int_ior",
            format!("int_ior and ext_ior must differ (both {int_ior})"),
        ));
    }
    Ok(IorPair { int_ior, ext_ior })
}

fn ior(props: &Props, name: &str) -> Result<Option<f32>> {
    let Some(prop) = props.get(name) else {
        return Ok(None);
    };
    let value = match &prop.value {
        Value::Float(v) => *v,
        Value::Integer(v) => *v as f32,
        Value::Str(text) => named_ior(&text.to_ascii_lowercase()).ok_or_else(|| {
            props_error(
                props,
                name,
                format!("unknown index of refraction name \"{text}\""),
            )
        })?,
        _ => {
            return Err(props_error(
                props,
                name,
                format!("{name} must be a <float> or a <string> name such as \"bk7\""),
            ));
        }
    };
    if value <= 0.0 {
        return Err(props_error(
            props,
            name,
            format!("{name} must be positive, got {value}"),
        ));
    }
    Ok(Some(value))
}
