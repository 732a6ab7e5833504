//! Scenes: the description read from a file, and the built, renderable `Scene`.

pub mod cie_tables;
pub mod description;
pub mod mitsuba;
pub mod obj;
pub mod ply;
pub mod spectra;

use std::borrow::Cow;
use std::path::Path;

pub use description::*;

use crate::camera::Camera;
use crate::error::Result;
use crate::geometry::{Geometry, SurfaceInteraction};
use crate::light::LightSet;
use crate::material::Bsdf;

/// A scene ready to render: immutable and shared by all threads.
pub struct Scene {
    pub description: SceneDescription,
    pub geometry: Geometry,
    pub camera: Camera,
    /// Every emitter, in the order of `description.emitters`, and the choice among them.
    pub lights: LightSet,
    /// The BSDFs, in the order of `description.bsdfs` (`ShapeDesc::bsdf` indexes both).
    /// A textured one holds its textures' means; `bsdf_at` looks them up at a hit.
    pub bsdfs: Vec<Bsdf>,
    /// Per BSDF: true when it has a texture.
    textured: Vec<bool>,
}

impl Scene {
    /// Reads a Mitsuba 3 XML scene and builds it.
    pub fn load(path: &Path) -> Result<Scene> {
        Scene::build(mitsuba::load_file(path)?)
    }

    pub fn build(description: SceneDescription) -> Result<Scene> {
        let lights = LightSet::build(&description)?;
        let bsdfs = description.bsdfs.iter().map(Bsdf::from_desc).collect();
        let textured: Vec<bool> = description
            .bsdfs
            .iter()
            .map(BsdfDesc::is_textured)
            .collect();
        let mut geometry = Geometry::build(&description.shapes);
        // Only textures read (u, v) (area emitters' radiance is a constant).
        geometry.keep_uv_only_for(|shape| textured[description.shapes[shape as usize].bsdf]);
        let camera = Camera::new(&description.sensor);
        Ok(Scene {
            description,
            geometry,
            camera,
            lights,
            bsdfs,
            textured,
        })
    }

    /// The BSDF of shape `shape`, textures at their means (see `bsdf_at`).
    pub fn bsdf_of_shape(&self, shape: u32) -> &Bsdf {
        &self.bsdfs[self.description.shapes[shape as usize].bsdf]
    }

    /// The BSDF at a surface point: the shape's, with its textures looked up at `si.uv`.
    /// Untextured BSDFs are borrowed; a textured one is built for the point (a `twosided`
    /// or `roughplastic` one allocates).
    #[inline]
    pub fn bsdf_at(&self, si: &SurfaceInteraction) -> Cow<'_, Bsdf> {
        self.bsdf_at_uv(si.shape, si.uv)
    }

    /// `bsdf_at` for a hit on shape `shape` at (u, v) `uv` (all it reads of the hit).
    pub fn bsdf_at_uv(&self, shape: u32, uv: glam::Vec2) -> Cow<'_, Bsdf> {
        let index = self.description.shapes[shape as usize].bsdf;
        if self.textured[index] {
            Cow::Owned(self.bsdfs[index].at_point(&self.description.bsdfs[index], uv))
        } else {
            Cow::Borrowed(&self.bsdfs[index])
        }
    }

    /// The BSDF of shape `shape` wherever it has no texture: None for a textured one
    /// (`bsdf_at` looks its textures up per hit).
    pub fn untextured_bsdf(&self, shape: usize) -> Option<&Bsdf> {
        let index = self.description.shapes[shape].bsdf;
        (!self.textured[index]).then(|| &self.bsdfs[index])
    }

    /// Width of the rendered image: the film's crop window, if it has one.
    pub fn width(&self) -> u32 {
        self.description.sensor.film.window().width
    }

    /// Height of the rendered image (see `width`).
    pub fn height(&self) -> u32 {
        self.description.sensor.film.window().height
    }
}
