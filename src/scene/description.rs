//! The scene as read from a file: plain data, no acceleration structures.
//! The Mitsuba loader produces a `SceneDescription`; `Scene::build` turns it into something
//! that can be rendered. Keeping the two apart lets tests compare what a file *says* (this
//! type) with what it *renders*.

use glam::{Vec2, Vec3};

use crate::error::Location;
use crate::math::{Rgb, Transform};
use crate::texture::Texture;

/// Everything a scene file describes, in world space.
#[derive(Clone, Debug, Default)]
pub struct SceneDescription {
    /// The scene file this came from (for messages and reference hashes).
    pub source: std::path::PathBuf,
    /// Every file that was read to build this scene (the scene, includes, meshes), in order.
    pub files_read: Vec<std::path::PathBuf>,
    pub integrator: IntegratorDesc,
    pub sensor: SensorDesc,
    pub shapes: Vec<ShapeDesc>,
    /// Indexed by `ShapeDesc::bsdf`.
    pub bsdfs: Vec<BsdfDesc>,
    /// Area emitters point back at their shape; the others stand alone.
    pub emitters: Vec<EmitterDesc>,
    /// Where each emitter was written (same indices as `emitters`; may be shorter for
    /// descriptions made in code, see `emitter_location`).
    pub emitter_locations: Vec<Location>,
    /// Degenerate (zero-area) triangles dropped while loading meshes.
    pub skipped_triangles: usize,
    /// Non-fatal remarks (e.g. "rfilter tent: using box"), each naming file and line.
    pub warnings: Vec<String>,
}

impl SceneDescription {
    /// Where emitter `i` was written, for messages about it: its element in the scene, or
    /// the scene file when the loader did not record one.
    pub fn emitter_location(&self, i: usize) -> Location {
        self.emitter_locations
            .get(i)
            .cloned()
            .unwrap_or_else(|| Location::file(&self.source))
    }
}

/// `<integrator>`: only the path-length settings matter; mltbench picks the estimator.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IntegratorDesc {
    /// Mitsuba 3 meaning: path segments, 1 = emitters seen directly, -1 = unbounded.
    pub max_depth: i32,
    /// Depth from which Russian roulette starts (Mitsuba default 5).
    pub rr_depth: u32,
    /// Mitsuba's `hide_emitters`: emitters the camera sees first (the environment where a
    /// camera ray escapes) contribute nothing; seen through a `null` surface, in a mirror or
    /// by their light, they do.
    pub hide_emitters: bool,
}

impl Default for IntegratorDesc {
    fn default() -> Self {
        IntegratorDesc {
            max_depth: -1,
            rr_depth: 5,
            hide_emitters: false,
        }
    }
}

/// Which image axis `fov` spans (Mitsuba's `fov_axis`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum FovAxis {
    #[default]
    X,
    Y,
    Diagonal,
    Smaller,
    Larger,
}

/// `<sensor>` with its `<film>` and `<sampler>`.
#[derive(Clone, Debug, PartialEq)]
pub struct SensorDesc {
    /// Camera to world; the camera looks down +z with +y up (Mitsuba convention).
    pub to_world: Transform,
    /// Field of view in degrees along `fov_axis`.
    pub fov_degrees: f32,
    pub fov_axis: FovAxis,
    pub near_clip: f32,
    pub far_clip: f32,
    /// `thinlens`: the lens; `None` for `perspective` (a pinhole).
    pub lens: Option<ThinLensDesc>,
    pub film: FilmDesc,
    /// `<sampler sample_count>`: the default samples per pixel.
    pub sample_count: u32,
}

impl Default for SensorDesc {
    fn default() -> Self {
        SensorDesc {
            to_world: Transform::IDENTITY,
            fov_degrees: 39.597755, // 50 mm on a 36 mm-wide film; the loader always sets its own
            fov_axis: FovAxis::X,
            near_clip: 1e-2,
            far_clip: 1e4,
            lens: None,
            film: FilmDesc::default(),
            sample_count: 4,
        }
    }
}

/// The lens of `<sensor type="thinlens">` (Mitsuba 3 conventions).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThinLensDesc {
    /// Radius of the circular aperture, in scene units (≥ 0; 0 is a pinhole).
    pub aperture_radius: f32,
    /// Distance from the lens to the plane in focus, measured along the viewing axis
    /// (the plane z = focus_distance in camera space), in scene units (> 0).
    pub focus_distance: f32,
}

/// `<film type="hdrfilm">`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FilmDesc {
    /// The whole film, which the field of view spans.
    pub width: u32,
    pub height: u32,
    pub filter: FilterDesc,
    /// The part of it that is rendered (`crop_offset_x` … `crop_height`); `None` = all.
    pub crop: Option<CropWindow>,
}

/// A rectangle of a film's pixels, inside the film.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CropWindow {
    pub x: u32,
    pub y: u32,
    pub width: u32,
    pub height: u32,
}

impl FilmDesc {
    /// The pixels rendered: the crop window, or the whole film.
    pub fn window(&self) -> CropWindow {
        self.crop.unwrap_or(CropWindow {
            x: 0,
            y: 0,
            width: self.width,
            height: self.height,
        })
    }
}

impl Default for FilmDesc {
    fn default() -> Self {
        FilmDesc {
            width: 768,
            height: 576,
            filter: FilterDesc::default(),
            crop: None,
        }
    }
}

/// Pixel reconstruction filter (`<rfilter>`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FilterDesc {
    /// A sample adds to its own pixel only.
    Box,
    /// Mitsuba 3's default: a Gaussian of standard deviation `stddev` pixels, cut at 4 σ.
    Gaussian { stddev: f32 },
}

impl Default for FilterDesc {
    fn default() -> Self {
        FilterDesc::Gaussian { stddev: 0.5 }
    }
}

/// A reflectance or other colour parameter: a constant. A texture is read only for a diffuse
/// reflectance, as `BsdfDesc::Textured`.
pub type ColorParam = Rgb;

/// Index of refraction pair of a dielectric interface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IorPair {
    pub int_ior: f32,
    pub ext_ior: f32,
}

/// Microfacet normal distribution.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MicrofacetKind {
    Beckmann,
    Ggx,
}

/// Microfacet roughness: α along u and v (isotropic: equal).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Roughness {
    pub kind: MicrofacetKind,
    pub alpha_u: f32,
    pub alpha_v: f32,
    /// Mitsuba's `sample_visible` (default true).
    pub sample_visible: bool,
}

/// A BSDF as described in the scene file (evaluation lives in `material/`).
#[derive(Clone, Debug, PartialEq)]
pub enum BsdfDesc {
    Diffuse {
        reflectance: ColorParam,
    },
    /// `base` (a `diffuse`, `plastic` or `roughplastic`) whose diffuse reflectance is a
    /// texture, looked up at each hit (`Scene::bsdf_at`). `base` holds the texture's mean,
    /// which is also what sets a plastic's lobe-selection weight (Mitsuba 3 does the same).
    Textured {
        base: Box<BsdfDesc>,
        diffuse: Texture,
    },
    /// Smooth conductor. `eta`/`k` complex IOR per channel; `material="none"` gives
    /// `eta = k = None`: a perfect mirror (reflectance 1, no Fresnel term).
    Conductor {
        eta_k: Option<(Rgb, Rgb)>,
        specular_reflectance: ColorParam,
    },
    RoughConductor {
        eta_k: Option<(Rgb, Rgb)>,
        specular_reflectance: ColorParam,
        roughness: Roughness,
    },
    Dielectric {
        ior: IorPair,
        specular_reflectance: ColorParam,
        specular_transmittance: ColorParam,
    },
    ThinDielectric {
        ior: IorPair,
        specular_reflectance: ColorParam,
        specular_transmittance: ColorParam,
    },
    RoughDielectric {
        ior: IorPair,
        roughness: Roughness,
        specular_reflectance: ColorParam,
        specular_transmittance: ColorParam,
    },
    Plastic {
        ior: IorPair,
        diffuse_reflectance: ColorParam,
        specular_reflectance: ColorParam,
        nonlinear: bool,
    },
    RoughPlastic {
        ior: IorPair,
        diffuse_reflectance: ColorParam,
        specular_reflectance: ColorParam,
        roughness: Roughness,
        nonlinear: bool,
    },
    /// The same BSDF on both sides (Mitsuba `twosided`); may name a different back BSDF.
    TwoSided {
        front: Box<BsdfDesc>,
        back: Box<BsdfDesc>,
    },
    /// Index-matched boundary: rays pass straight through.
    Null,
    /// mltbench extensions: classic glossy models of the lecture (Phong, Blinn-Phong, Ward).
    Phong {
        exponent: f32,
        diffuse_reflectance: ColorParam,
        specular_reflectance: ColorParam,
    },
    Blinn {
        exponent: f32,
        diffuse_reflectance: ColorParam,
        specular_reflectance: ColorParam,
    },
    Ward {
        alpha_u: f32,
        alpha_v: f32,
        diffuse_reflectance: ColorParam,
        specular_reflectance: ColorParam,
    },
}

impl BsdfDesc {
    /// The diffuse albedo used by the `eyelight` preview, or None for non-diffuse BSDFs.
    pub fn diffuse_albedo(&self) -> Option<Rgb> {
        match self {
            BsdfDesc::Diffuse { reflectance } => Some(*reflectance),
            BsdfDesc::Textured { base, .. } => base.diffuse_albedo(),
            BsdfDesc::TwoSided { front, .. } => front.diffuse_albedo(),
            _ => None,
        }
    }

    /// The diffuse albedo at surface coordinates `uv` (textures looked up there).
    pub fn diffuse_albedo_at(&self, uv: Vec2) -> Option<Rgb> {
        match self {
            BsdfDesc::Textured { base, diffuse } => match base.as_ref() {
                BsdfDesc::Diffuse { .. } => Some(diffuse.eval(uv)),
                _ => None,
            },
            BsdfDesc::TwoSided { front, .. } => front.diffuse_albedo_at(uv),
            _ => self.diffuse_albedo(),
        }
    }

    /// True when some parameter is a texture: the BSDF differs from point to point.
    pub fn is_textured(&self) -> bool {
        match self {
            BsdfDesc::Textured { .. } => true,
            BsdfDesc::TwoSided { front, back } => front.is_textured() || back.is_textured(),
            _ => false,
        }
    }
}

/// Emitters. Area emitters are attached to a shape (`ShapeDesc::emitter`).
#[derive(Clone, Debug, PartialEq)]
pub enum EmitterDesc {
    /// Uniform radiance on the front side of shape `shape`.
    Area { radiance: Rgb, shape: usize },
    /// Isotropic point light of radiant intensity `intensity` (W/sr).
    Point { intensity: Rgb, position: Vec3 },
    /// Distant light along `direction` (the way light travels) with irradiance `irradiance`.
    Directional { irradiance: Rgb, direction: Vec3 },
    /// Uniform radiance from every direction at infinity.
    Constant { radiance: Rgb },
    /// Mitsuba 3 `spot`: radiant intensity `intensity` (W/sr) at the centre of a cone along
    /// the local +z axis placed by `to_world` (a rigid motion, possibly uniformly scaled),
    /// full up to `beam_width` and falling off linearly in angle to zero at `cutoff_angle`.
    /// Both angles are in degrees, as written in the scene (0 ≤ beam_width ≤ cutoff_angle).
    Spot {
        intensity: Rgb,
        to_world: Transform,
        cutoff_angle: f32,
        beam_width: f32,
    },
    /// Mitsuba 3 `envmap`: a latitude-longitude OpenEXR image of radiance (times `scale`)
    /// at infinity, oriented by `to_world` (a rotation). `filename` is already resolved.
    Envmap {
        filename: std::path::PathBuf,
        scale: f32,
        to_world: Transform,
    },
}

/// A triangle mesh in world space. Invariant: indices are in range, triangles have area > 0.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TriangleMesh {
    pub positions: Vec<Vec3>,
    /// Per-vertex shading normals (unit length), when the mesh has them and
    /// `face_normals` is false.
    pub normals: Option<Vec<Vec3>>,
    pub uvs: Option<Vec<Vec2>>,
    pub indices: Vec<[u32; 3]>,
}

/// The geometry of a shape, already in world space.
#[derive(Clone, Debug, PartialEq)]
pub enum ShapeGeometry {
    Mesh(TriangleMesh),
    /// Analytic sphere (not tessellated).
    Sphere {
        center: Vec3,
        radius: f32,
    },
    /// Analytic disk: the unit disk in the local xy plane (normal +z) under `to_world`.
    Disk {
        to_world: Transform,
    },
}

/// A shape with its material, emitter and media.
#[derive(Clone, Debug, PartialEq)]
pub struct ShapeDesc {
    /// The `id` attribute, or `type@file:line` when it has none; for messages.
    pub name: String,
    pub geometry: ShapeGeometry,
    /// Index into `SceneDescription::bsdfs` (a shape with no BSDF gets a diffuse one of
    /// reflectance 0.5, or 0 if it emits, as in Mitsuba).
    pub bsdf: usize,
    /// Index into `SceneDescription::emitters` of its area emitter.
    pub emitter: Option<usize>,
    /// Normals point inward instead of outward (already applied to mesh normals and winding;
    /// for analytic shapes the intersector reads it).
    pub flip_normals: bool,
    pub interior_medium: Option<String>,
    pub exterior_medium: Option<String>,
}
