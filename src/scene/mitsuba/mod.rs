//! The Mitsuba 3 XML reader (docs/DESIGN.md §4).
//!
//! Two passes. `xml` reads the scene file and everything it includes into one element tree
//! (defaults substituted, ids indexed, structure checked), so references may point forward or
//! into other files. The builder then walks the scene's children in order and turns each
//! plugin element into the plain data of `SceneDescription`, asking every element for its
//! parameters by name (`values::Props`); a parameter no plugin asked for is an error, as in
//! Mitsuba. Any error aborts the load: there is never a half-built scene.
//!
//! Deliberate differences from Mitsuba 3, each a clear error rather than a silent change:
//! a scene with no shapes is rejected; media, textures other than a diffuse reflectance, and
//! unsupported plugins are
//! "not supported yet"; an undefined `$name` is an error even when no `<default>` exists.

mod bsdfs;
mod emitters;
mod geometry;
mod integrator;
mod sensor;
mod shapes;
mod textures;
mod transform;
mod values;
mod xml;

use std::collections::{HashMap, HashSet};
use std::path::Path;

use glam::Vec3;

use super::{BsdfDesc, SceneDescription, ShapeGeometry};
use crate::error::{Error, Location, Result};
use crate::texture::Texture;
use xml::{ElemId, Tree};

/// Reads a scene file and everything it includes or references.
pub fn load_file(path: &Path) -> Result<SceneDescription> {
    let text = xml::read_text(path)?;
    load_str(&text, path)
}

/// Reads a scene file with some of its `<default>` parameters set (Mitsuba's `-D`).
pub fn load_file_with(path: &Path, params: &[(String, String)]) -> Result<SceneDescription> {
    let text = xml::read_text(path)?;
    load_str_with(&text, path, params)
}

/// Reads a scene from text; `path` names it in messages and resolves relative file names.
pub fn load_str(text: &str, path: &Path) -> Result<SceneDescription> {
    load_str_with(text, path, &[])
}

/// `load_str` with `<default>` parameters set from outside.
pub fn load_str_with(
    text: &str,
    path: &Path,
    params: &[(String, String)],
) -> Result<SceneDescription> {
    let tree = xml::parse_scene_with(text, path, params)?;
    let mut builder = Builder::new(&tree, path);
    builder.build()?;
    Ok(builder.desc)
}

/// Turns the element tree into a `SceneDescription`.
pub(super) struct Builder<'a> {
    tree: &'a Tree,
    desc: SceneDescription,
    /// BSDFs parsed so far, by element (a referenced BSDF is parsed once).
    parsed_bsdfs: HashMap<ElemId, BsdfDesc>,
    /// Textures parsed so far, by element (a referenced texture is read once).
    parsed_textures: HashMap<ElemId, Texture>,
    /// Index in `desc.bsdfs` of each BSDF element used by a shape or written at top level.
    bsdf_indices: HashMap<ElemId, usize>,
    /// Index of the default BSDF of shapes without one: [not emitting, emitting].
    default_bsdf: [Option<usize>; 2],
    /// Area emitter element → the shape it is attached to.
    attached_emitters: HashMap<ElemId, usize>,
    /// The (only) environment emitter.
    environment: Option<ElemId>,
    /// Objects being parsed right now: a reference back to one of them is a cycle.
    in_progress: HashSet<ElemId>,
    /// Why each skipped shape was skipped (also among the warnings).
    skipped_shapes: Vec<String>,
}

impl<'a> Builder<'a> {
    fn new(tree: &'a Tree, path: &Path) -> Self {
        let desc = SceneDescription {
            source: path.to_path_buf(),
            files_read: tree.files.clone(),
            warnings: tree.warnings.clone(),
            ..SceneDescription::default()
        };
        Builder {
            tree,
            desc,
            parsed_bsdfs: HashMap::new(),
            parsed_textures: HashMap::new(),
            bsdf_indices: HashMap::new(),
            default_bsdf: [None, None],
            attached_emitters: HashMap::new(),
            environment: None,
            in_progress: HashSet::new(),
            skipped_shapes: Vec::new(),
        }
    }

    /// Runs `parse` for object `elem`, failing instead of recursing forever when the object
    /// (through references) contains itself.
    fn guarded<T>(
        &mut self,
        elem: ElemId,
        parse: impl FnOnce(&mut Self) -> Result<T>,
    ) -> Result<T> {
        if !self.in_progress.insert(elem) {
            return Err(self
                .tree
                .error(elem, "this object contains itself (circular reference)"));
        }
        let result = parse(self);
        self.in_progress.remove(&elem);
        result
    }

    fn build(&mut self) -> Result<()> {
        let tree = self.tree;
        let mut seen = HashSet::new();
        let mut integrator: Option<ElemId> = None;
        let mut sensor: Option<ElemId> = None;
        let mut loose_area_emitters = Vec::new();
        for &child in &tree.elem(tree.root).children {
            // A <ref> directly in the scene stands for the object it names.
            let elem = if tree.tag(child) == "ref" {
                tree.resolve_ref(child)?
            } else {
                child
            };
            if !seen.insert(elem) {
                continue;
            }
            match tree.tag(elem) {
                "integrator" => {
                    if let Some(first) = integrator {
                        return Err(tree.error(
                            elem,
                            format!(
                                "only one integrator per scene (the first is at line {})",
                                tree.elem(first).line
                            ),
                        ));
                    }
                    integrator = Some(elem);
                    self.desc.integrator = self.parse_integrator(elem)?;
                }
                "sensor" => {
                    let parsed = self.parse_sensor(elem)?;
                    if sensor.is_none() {
                        sensor = Some(elem);
                        self.desc.sensor = parsed;
                    } else {
                        let w = tree.warning(elem, "only the first sensor is used");
                        self.desc.warnings.push(w);
                    }
                }
                "shape" => self.parse_shape(elem)?,
                "bsdf" => {
                    self.bsdf_index(elem)?;
                }
                "emitter" if !self.standalone_emitter(elem)? => loose_area_emitters.push(elem),
                // Read where a BSDF uses it; read here too, so that a broken one is an error.
                "texture" => {
                    self.texture(elem)?;
                }
                "medium" | "phase" | "volume" => {
                    return Err(tree.error(elem, "participating media are not supported yet"));
                }
                // Films, samplers and filters are used where a sensor refers to them.
                _ => {}
            }
        }
        for elem in loose_area_emitters {
            if !self.attached_emitters.contains_key(&elem) {
                return Err(tree.error(
                    elem,
                    "an area emitter must be nested in (or referenced by) a shape",
                ));
            }
        }
        if self.desc.shapes.is_empty() {
            // Warnings are printed only with a scene: say here why shapes were skipped.
            let why = if self.skipped_shapes.is_empty() {
                String::new()
            } else {
                format!(" ({})", self.skipped_shapes.join("; "))
            };
            return Err(Error::input(
                Location::file(tree.file_of(tree.root)),
                format!("scene has no shapes{why}"),
            ));
        }
        if integrator.is_none() {
            let w = format!(
                "{}: no <integrator>: using path tracing with max_depth -1, rr_depth 5",
                tree.file_of(tree.root).display()
            );
            self.desc.warnings.push(w);
        }
        if sensor.is_none() {
            let (min, max) = self.bounding_box();
            self.desc.sensor = sensor::default_sensor(min, max);
            let w = format!(
                "{}: no <sensor>: using Mitsuba's default (45° perspective in front of the scene)",
                tree.file_of(tree.root).display()
            );
            self.desc.warnings.push(w);
        }
        if self.desc.emitters.is_empty() {
            let w = format!(
                "{}: the scene has no emitters",
                tree.file_of(tree.root).display()
            );
            self.desc.warnings.push(w);
        }
        Ok(())
    }

    /// World-space bounds of all shapes.
    fn bounding_box(&self) -> (Vec3, Vec3) {
        let mut min = Vec3::splat(f32::INFINITY);
        let mut max = Vec3::splat(f32::NEG_INFINITY);
        let mut add = |p: Vec3| {
            min = min.min(p);
            max = max.max(p);
        };
        for shape in &self.desc.shapes {
            match &shape.geometry {
                ShapeGeometry::Mesh(mesh) => {
                    for tri in &mesh.indices {
                        for &i in tri {
                            add(mesh.positions[i as usize]);
                        }
                    }
                }
                ShapeGeometry::Sphere { center, radius } => {
                    add(*center - Vec3::splat(*radius));
                    add(*center + Vec3::splat(*radius));
                }
                ShapeGeometry::Disk { to_world } => {
                    // The unit disk's extent along each world axis.
                    let m = to_world.matrix;
                    let (u, v) = (m.x_axis.truncate(), m.y_axis.truncate());
                    let half = (u * u + v * v).map(f32::sqrt);
                    let center = to_world.point(Vec3::ZERO);
                    add(center - half);
                    add(center + half);
                }
            }
        }
        (min, max)
    }
}
