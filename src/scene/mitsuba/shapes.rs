//! `<shape>`: meshes from OBJ/PLY files, Mitsuba's `rectangle`, `cube`, `disk` and `sphere`,
//! each with its BSDF, optional area emitter and media.

use std::path::PathBuf;

use glam::Vec3;

use super::Builder;
use super::geometry::{Placement, cube, place_mesh, rectangle, reverse_winding, sphere};
use super::values::Props;
use super::xml::ElemId;
use crate::error::Result;
use crate::math::Transform;
use crate::scene::obj::read_obj;
use crate::scene::ply::read_ply;
use crate::scene::{EmitterDesc, ShapeDesc, ShapeGeometry, TriangleMesh};

/// Mitsuba shapes mltbench does not implement yet.
const UNSUPPORTED: &[&str] = &[
    "shapegroup",
    "instance",
    "serialized",
    "cylinder",
    "bsplinecurve",
    "linearcurve",
    "sdfgrid",
    "ellipsoids",
    "ellipsoidsmesh",
    "merge",
];

/// A shape's world-space geometry, or why it has none (a mesh without triangles).
type Placed = std::result::Result<ShapeGeometry, String>;

impl Builder<'_> {
    pub(super) fn parse_shape(&mut self, elem: ElemId) -> Result<()> {
        let tree = self.tree;
        let kind = tree.type_of(elem);
        match kind {
            "obj" | "ply" | "rectangle" | "cube" | "disk" | "sphere" => {}
            k if UNSUPPORTED.contains(&k) => {
                return Err(tree.error(elem, format!("shape type \"{k}\" is not supported yet")));
            }
            k => return Err(tree.error(elem, format!("unknown shape type \"{k}\""))),
        }
        let props = Props::collect(tree, elem)?;
        let to_world = props.transform("to_world")?.unwrap_or(Transform::IDENTITY);
        let flip_normals = props.boolean("flip_normals")?.unwrap_or(false);

        let geometry = match kind {
            "obj" | "ply" => self.mesh_file(&props, kind, to_world, flip_normals)?,
            "rectangle" | "cube" => {
                // Flat either way; accepted for meshes as in Mitsuba.
                props.ignore(&["face_normals"]);
                let mut mesh = if kind == "rectangle" {
                    rectangle()
                } else {
                    cube()
                };
                // Mitsuba's rectangle is analytic with normal to_world⁻ᵀ·(0,0,1): keep it
                // under mirroring transforms by reversing the winding.
                if kind == "rectangle" && to_world.flips_handedness() {
                    reverse_winding(&mut mesh);
                }
                let placement = Placement {
                    to_world,
                    face_normals: true,
                    flip_normals,
                };
                self.placed_mesh(elem, mesh, &placement)?
            }
            "disk" => Ok(ShapeGeometry::Disk { to_world }),
            _ => {
                let center = props.vector("center")?.unwrap_or(Vec3::ZERO);
                let radius = props.float("radius")?.unwrap_or(1.0);
                if radius <= 0.0 {
                    return Err(tree.error(
                        props.elem_of("radius"),
                        format!("sphere radius must be positive, got {radius}"),
                    ));
                }
                let (center, radius) = sphere(&to_world, center, radius)
                    .map_err(|message| tree.error(props.elem_of("to_world"), message))?;
                Ok(ShapeGeometry::Sphere { center, radius })
            }
        };

        let mut bsdf = None;
        let mut emitter = None;
        let (mut interior, mut exterior) = (None, None);
        for (i, object) in props.objects().iter().enumerate() {
            match tree.tag(object.target) {
                "bsdf" => {
                    if bsdf.is_some() {
                        return Err(tree.error(object.via, "a shape can have only one BSDF"));
                    }
                    props.use_object(i);
                    bsdf = Some(self.bsdf_index(object.target)?);
                }
                "emitter" => {
                    if emitter.is_some() {
                        return Err(tree.error(object.via, "a shape can have only one emitter"));
                    }
                    props.use_object(i);
                    if let Some(&shape) = self.attached_emitters.get(&object.target) {
                        return Err(tree.error(
                            object.via,
                            format!(
                                "this area emitter is already attached to shape \"{}\"",
                                self.desc.shapes[shape].name
                            ),
                        ));
                    }
                    emitter = Some((object.target, self.area_radiance(object.target)?));
                }
                "medium" => {
                    props.use_object(i);
                    let slot = match object.name.as_deref() {
                        Some("interior") => &mut interior,
                        Some("exterior") => &mut exterior,
                        _ => {
                            return Err(tree.error(
                                object.via,
                                "a medium in a shape must be named \"interior\" or \"exterior\"",
                            ));
                        }
                    };
                    match tree
                        .attr(object.via, "id")
                        .filter(|_| tree.tag(object.via) == "ref")
                    {
                        Some(id) => *slot = Some(id.to_string()),
                        None => {
                            return Err(tree.error(
                                object.target,
                                "participating media are not supported yet",
                            ));
                        }
                    }
                }
                "sensor" => {
                    return Err(tree.error(
                        object.via,
                        "sensors attached to shapes are not supported yet",
                    ));
                }
                _ => {}
            }
        }
        props.finish()?;

        let geometry = match geometry {
            Ok(geometry) => geometry,
            Err(why) => {
                if let Some((emitter_elem, _)) = emitter {
                    return Err(tree.error(
                        emitter_elem,
                        format!("this area emitter cannot emit: {why}"),
                    ));
                }
                let w = tree.warning(elem, &format!("{why}: shape skipped"));
                self.desc.warnings.push(w.clone());
                self.skipped_shapes.push(w);
                return Ok(());
            }
        };
        let bsdf = match bsdf {
            Some(index) => index,
            None => self.default_bsdf_index(emitter.is_some()),
        };
        let index = self.desc.shapes.len();
        let emitter_index = emitter.map(|(emitter_elem, radiance)| {
            self.attached_emitters.insert(emitter_elem, index);
            self.desc.emitters.push(EmitterDesc::Area {
                radiance,
                shape: index,
            });
            self.desc
                .emitter_locations
                .push(tree.location(emitter_elem));
            self.desc.emitters.len() - 1
        });
        let name = match tree.attr(elem, "id") {
            Some(id) => id.to_string(),
            None => format!(
                "{kind}@{}:{}",
                tree.file_of(elem).display(),
                tree.elem(elem).line
            ),
        };
        self.desc.shapes.push(ShapeDesc {
            name,
            geometry,
            bsdf,
            emitter: emitter_index,
            flip_normals,
            interior_medium: interior,
            exterior_medium: exterior,
        });
        Ok(())
    }

    /// `obj` / `ply`: `filename` resolved through the search folders, read, placed.
    fn mesh_file(
        &mut self,
        props: &Props,
        kind: &str,
        to_world: Transform,
        flip_normals: bool,
    ) -> Result<Placed> {
        let tree = self.tree;
        let owner = props.owner();
        let Some(filename) = props.string("filename")? else {
            return Err(tree.error(owner, format!("a {kind} shape needs a \"filename\"")));
        };
        let face_normals = props.boolean("face_normals")?.unwrap_or(false);
        // Mitsuba flips the v coordinate of OBJ files by default (OBJ's v points up).
        let flip_tex_coords = kind == "obj" && props.boolean("flip_tex_coords")?.unwrap_or(true);
        let named_at = props.elem_of("filename");
        let path = tree
            .find_file(filename, tree.elem(named_at).file, "mesh file")
            .map_err(|message| tree.error(named_at, message))?;
        self.note_file(path.clone());
        let mut mesh = if kind == "obj" {
            read_obj(&path)
        } else {
            read_ply(&path)
        }
        .map_err(|e| tree.error(owner, format!("could not read the mesh: {e}")))?;
        if flip_tex_coords && let Some(uvs) = &mut mesh.uvs {
            for uv in uvs.iter_mut() {
                uv.y = 1.0 - uv.y;
            }
        }
        let placement = Placement {
            to_world,
            face_normals,
            flip_normals,
        };
        self.placed_mesh(owner, mesh, &placement)
    }

    /// Places an object-space mesh; Err(why) when no triangle survives.
    fn placed_mesh(
        &mut self,
        elem: ElemId,
        mesh: TriangleMesh,
        placement: &Placement,
    ) -> Result<Placed> {
        let faces = mesh.indices.len();
        let (mesh, skipped) = place_mesh(mesh, placement)
            .map_err(|problem| self.tree.error(elem, problem.to_string()))?;
        self.desc.skipped_triangles += skipped;
        if mesh.indices.is_empty() {
            return Ok(Err(if faces == 0 {
                "the mesh has no faces (points or lines are not read)".to_string()
            } else {
                format!(
                    "all {faces} triangles of the mesh are degenerate (zero-area or non-finite)"
                )
            }));
        }
        if skipped > 0 {
            let w = self.tree.warning(
                elem,
                &format!("{skipped} degenerate (zero-area or non-finite) triangles skipped"),
            );
            self.desc.warnings.push(w);
        }
        Ok(Ok(ShapeGeometry::Mesh(mesh)))
    }

    pub(super) fn note_file(&mut self, path: PathBuf) {
        if !self.desc.files_read.contains(&path) {
            self.desc.files_read.push(path);
        }
    }
}
