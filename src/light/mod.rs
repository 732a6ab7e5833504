//! Lights: Mitsuba 3's `area` (on meshes, spheres and disks), `point`, `spot`,
//! `directional`, `constant` and `envmap` emitters, built from the scene description.
//!
//! # Contract
//!
//! * **Next-event estimation.** `sample_li(r, u)` picks a point on the light as seen from
//!   the reference point `r`: `wi` is the unit direction from `r` towards it, `dist` the
//!   distance (∞ for lights at infinity), `radiance` the emitted radiance arriving along
//!   `wi`, `pdf_solid_angle` the density of `wi` per steradian. The estimate of the
//!   reflected radiance is then f · radiance · |cos| / pdf_solid_angle (times visibility).
//!   `pdf_li(r, hit)` is that same density for a point `hit` of the light found another way
//!   (by BSDF sampling), for multiple importance sampling. Area lights emit only on the front
//!   side: a point facing away from `r` is never returned and has `pdf_li` 0, so the density
//!   may integrate to less than one (the rest is the chance of `None`).
//! * **Delta lights** (`point`, `spot`: a delta in position; `directional`: a delta in
//!   direction) return `delta: true`, `pdf_solid_angle = pdf_area = 1` and, in `radiance`,
//!   the quantity already integrated over the delta: I·f/d² for point and spot lights, the
//!   irradiance E for directional lights. No ray can hit them: `pdf_li` is 0.
//! * **Lights at infinity** (`directional`, `constant`, `envmap`): their "point" is the unit
//!   direction towards the light: `LightSample::p` = `wi`, and `LightPoint::p` passed to
//!   `pdf_li` / `le` is the direction of the escaped ray (pointing towards the light). For them
//!   `pdf_area` repeats the solid-angle density (the direction plays the point's role).
//! * **Emission** (light tracing, photons, BDPT light subpaths): `sample_le(u1, u2)`
//!   returns a ray leaving the light with `pdf_pos` (area measure; 1 for a delta position)
//!   and `pdf_dir` (solid angle; 1 for a delta direction), the radiance (or intensity, or
//!   irradiance, for delta lights) it carries, and `n`: the surface normal for area lights
//!   (weight Le·|n·ω|/(pdf_pos·pdf_dir)), the ray direction for lights at infinity, and
//!   zero for point and spot lights (no cosine). Lights at infinity emit from a uniform point
//!   of a disk of the scene's bounding-sphere radius R perpendicular to the direction,
//!   placed R before the sphere's centre, so pdf_pos = 1/(πR²) (the standard choice; see
//!   Pharr et al., *PBR* 3rd ed., §16.1.5). `pdf_le(p, n, dir)` returns the two densities
//!   of `sample_le` producing that ray, 1 for a delta component, as `sample_le` reports it.
//! * **Power** (`power()`, the channel mean of Φ in W, for light selection): area π·A·L;
//!   point 4π·I; spot 2π·I·[1 − (sin θc − sin θb)/(θc − θb)] (exact for Mitsuba's linear
//!   falloff); directional π R²·E; constant 4π² R²·L; envmap π R² ∫L dω. For lights at
//!   infinity this is the flux entering the scene's bounding sphere, the only finite
//!   quantity comparable with the others; it depends on the scene's extent, so it is a
//!   heuristic for selection, not a physical power.
//! * **Robustness.** Nothing here allocates per sample; no NaN or infinity leaves these
//!   functions: degenerate configurations give `None` or a zero density. An emitter with no
//!   area, or an environment map with a bad texel, is an error when the lights are built.

pub mod area;
pub mod constant;
pub mod directional;
pub mod distribution;
pub mod envmap;
pub mod light_selection;
pub mod point;
pub mod shape_sampling;
pub mod spot;

use glam::{Vec2, Vec3};

use crate::error::{Error, Location, Result};
use crate::geometry::SurfaceInteraction;
use crate::math::lanes::{F32x16, Mask16, U32x16, V3};
use crate::math::{Frame, PI, Rgb, warp};
use crate::scene::{EmitterDesc, SceneDescription, ShapeDesc, ShapeGeometry};

pub use area::AreaLight;
pub use constant::ConstantLight;
pub use directional::DirectionalLight;
pub use distribution::{Distribution1D, Distribution2D};
pub use envmap::EnvmapLight;
pub use light_selection::LightSelection;
pub use point::PointLight;
pub use shape_sampling::ShapeSampler;
pub use spot::SpotLight;

/// A point chosen on a light for next-event estimation (see the module contract).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightSample {
    /// The point on the light; for lights at infinity the unit direction towards them.
    pub p: Vec3,
    /// Unit geometric normal at `p` (area lights), −`wi` for lights at infinity, zero for
    /// point and spot lights.
    pub n: Vec3,
    /// The normal of the side that emits (`ShapePoint::front`); `n` for other lights.
    pub front: Vec3,
    /// Rounding-error bound of `p` on area lights (`ShapePoint::p_error`); zero otherwise.
    pub p_error: Vec3,
    /// Triangle index within the shape (0 otherwise).
    pub primitive: u32,
    /// Unit direction from the reference point towards `p`.
    pub wi: Vec3,
    /// Distance to `p`; infinite for lights at infinity.
    pub dist: f32,
    /// Emitted radiance along −`wi` (delta lights: the delta-integrated quantity).
    pub radiance: Rgb,
    /// Density of `wi` per steradian (1 for delta lights).
    pub pdf_solid_angle: f32,
    /// Density of `p` per unit area of the light (1 for delta positions; the solid-angle
    /// density for lights at infinity).
    pub pdf_area: f32,
    pub delta: bool,
}

/// `LightSample`s of area and point lights and lights at infinity in sixteen lanes (`Light::sample_li_lanes`): the
/// lanes of `ok` have a sample. Their points lie at a finite distance, and their `front` is
/// `n`.
#[derive(Clone, Copy, Debug)]
pub struct LightSampleLanes {
    pub ok: Mask16,
    pub p: V3<F32x16>,
    pub n: V3<F32x16>,
    pub p_error: V3<F32x16>,
    pub wi: V3<F32x16>,
    pub radiance: V3<F32x16>,
    pub pdf_solid_angle: F32x16,
    pub pdf_area: f32,
    /// A point light (a delta in position): `n`, `p_error` zero.
    pub delta: bool,
    /// A light at infinity (`p` is the direction `wi`, at infinite distance).
    pub at_infinity: bool,
}

/// What an area light sends towards rays that hit it, in sixteen lanes
/// (`Light::emission_lanes`): `le` and `pdf_li` as the scalar functions give them.
#[derive(Clone, Copy, Debug)]
pub struct EmissionLanes {
    /// Lanes whose point faces the ray (`le` is the radiance there, black elsewhere).
    pub emits: Mask16,
    pub radiance: V3<F32x16>,
    /// `pdf_li` of each lane's point from its reference point.
    pub pdf_li: F32x16,
}

/// From reference point `r` towards a light at `position`: (unit direction, distance,
/// squared distance); None when `r` is at the light or infinitely far from it.
pub(crate) fn towards_point(position: Vec3, r: Vec3) -> Option<(Vec3, f32, f32)> {
    let d = position - r;
    let dist2 = d.length_squared();
    if !(dist2 > 0.0 && dist2.is_finite()) {
        return None;
    }
    let dist = dist2.sqrt();
    Some((d / dist, dist, dist2))
}

impl LightSample {
    /// The sample of a light at infinity arriving from unit direction `wi` with radiance
    /// `radiance`, drawn with solid-angle density `pdf`.
    pub fn at_infinity(wi: Vec3, radiance: Rgb, pdf: f32) -> LightSample {
        LightSample {
            p: wi,
            n: -wi,
            front: -wi,
            p_error: Vec3::ZERO,
            primitive: 0,
            wi,
            dist: f32::INFINITY,
            radiance,
            pdf_solid_angle: pdf,
            pdf_area: pdf,
            delta: false,
        }
    }

    /// The sample of a delta light at `position`, reached from the reference point along
    /// unit direction `wi` at distance `dist`, carrying `radiance` (intensity / d²).
    pub fn from_point_light(position: Vec3, wi: Vec3, dist: f32, radiance: Rgb) -> LightSample {
        LightSample {
            p: position,
            n: Vec3::ZERO,
            front: Vec3::ZERO,
            p_error: Vec3::ZERO,
            primitive: 0,
            wi,
            dist,
            radiance,
            pdf_solid_angle: 1.0,
            pdf_area: 1.0,
            delta: true,
        }
    }

    /// The light point as `pdf_li` and `le` take it.
    pub fn point(&self) -> LightPoint {
        LightPoint {
            p: self.p,
            n: self.n,
            front: self.front,
            primitive: self.primitive,
        }
    }
}

/// A point on a light reached by a ray: position, unit geometric normal, the normal of the
/// side that emits (`ShapePoint::front`), triangle. For lights at infinity, `p` is the unit
/// direction towards the light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightPoint {
    pub p: Vec3,
    pub n: Vec3,
    pub front: Vec3,
    pub primitive: u32,
}

impl LightPoint {
    /// The "point" of a light at infinity seen along `wi` (towards the light).
    pub fn direction(wi: Vec3) -> LightPoint {
        LightPoint {
            p: wi,
            n: -wi,
            front: -wi,
            primitive: 0,
        }
    }
}

impl From<&SurfaceInteraction> for LightPoint {
    fn from(si: &SurfaceInteraction) -> Self {
        LightPoint {
            p: si.p,
            n: si.ng,
            front: si.ns,
            primitive: si.primitive,
        }
    }
}

/// A ray leaving a light (see the module contract).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EmissionSample {
    pub origin: Vec3,
    /// Unit direction of travel.
    pub direction: Vec3,
    /// Surface normal (area lights), `direction` (lights at infinity), zero (point, spot).
    pub n: Vec3,
    /// The side that emits (area lights: the shading normal's side, as `ShapePoint::front`);
    /// `n` for the other lights.
    pub front: Vec3,
    /// Rounding-error bound on each coordinate of `origin` (area lights), so that rays
    /// leaving or reaching the point can be offset off its surface; zero for the others.
    pub p_error: Vec3,
    pub primitive: u32,
    /// Radiance leaving along `direction`; intensity I·f for point and spot lights;
    /// irradiance for directional lights.
    pub radiance: Rgb,
    /// Density of `origin` per unit area (1 for a delta position).
    pub pdf_pos: f32,
    /// Density of `direction` per steradian (1 for a delta direction).
    pub pdf_dir: f32,
    pub delta_pos: bool,
    pub delta_dir: bool,
}

/// A sphere enclosing every shape of the scene: where lights at infinity start their rays.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SceneSphere {
    pub center: Vec3,
    pub radius: f32,
}

impl SceneSphere {
    /// The sphere around the bounding box of the shapes' finite points (mesh vertices,
    /// spheres, the squares around disks), its radius widened by 10⁻⁵ relative so that
    /// rays from its disks start outside every shape. A scene with nothing in it gets the
    /// unit sphere.
    pub fn from_shapes(shapes: &[ShapeDesc]) -> SceneSphere {
        let mut lo = Vec3::splat(f32::INFINITY);
        let mut hi = Vec3::splat(f32::NEG_INFINITY);
        let mut add = |p: Vec3| {
            if p.is_finite() {
                lo = lo.min(p);
                hi = hi.max(p);
            }
        };
        for shape in shapes {
            match &shape.geometry {
                ShapeGeometry::Mesh(mesh) => mesh.positions.iter().for_each(|&p| add(p)),
                ShapeGeometry::Sphere { center, radius } => {
                    if radius.is_finite() {
                        add(*center - Vec3::splat(radius.abs()));
                        add(*center + Vec3::splat(radius.abs()));
                    }
                }
                ShapeGeometry::Disk { to_world } => {
                    for (x, y) in [(-1.0, -1.0), (-1.0, 1.0), (1.0, -1.0), (1.0, 1.0)] {
                        add(to_world.point(Vec3::new(x, y, 0.0)));
                    }
                }
            }
        }
        if !(lo.x <= hi.x && lo.y <= hi.y && lo.z <= hi.z) {
            return SceneSphere {
                center: Vec3::ZERO,
                radius: 1.0,
            };
        }
        let center = (lo + hi) * 0.5;
        let radius = ((hi - lo).length() * 0.5 * (1.0 + 1e-5)).max(1e-4);
        SceneSphere { center, radius }
    }

    /// A uniform point of the disk of radius R through the point R before the centre along
    /// `direction`, perpendicular to it; with its density 1/(πR²).
    pub fn sample_disk(&self, direction: Vec3, u: Vec2) -> (Vec3, f32) {
        let frame = Frame::from_normal(direction);
        let q = warp::square_to_disk_concentric(u);
        let origin = self.center + (frame.s * q.x + frame.t * q.y - direction) * self.radius;
        (origin, self.disk_pdf())
    }

    pub fn disk_pdf(&self) -> f32 {
        1.0 / (PI * self.radius * self.radius)
    }
}

/// One light, ready to sample.
#[derive(Clone, Debug, PartialEq)]
pub enum Light {
    Area(AreaLight),
    Point(PointLight),
    Spot(SpotLight),
    Directional(DirectionalLight),
    Constant(ConstantLight),
    Envmap(Box<EnvmapLight>),
}

impl Light {
    /// Builds the light `desc` describes, written at `location` in the scene. `sphere`
    /// bounds the scene (`SceneSphere::from_shapes`). Errors (at `location`, naming the
    /// shape or image file): an area emitter on a shape with no area or a missing shape, an
    /// unreadable or invalid environment map, a degenerate placement.
    pub fn from_desc(
        desc: &EmitterDesc,
        scene: &SceneDescription,
        sphere: SceneSphere,
        location: &Location,
    ) -> Result<Light> {
        let fail = |message: String| Error::input(location.clone(), message);
        Ok(match desc {
            EmitterDesc::Area { radiance, shape } => {
                let Some(shape_desc) = scene.shapes.get(*shape) else {
                    return Err(fail(format!(
                        "an area emitter refers to shape {shape}, but the scene has {} shapes",
                        scene.shapes.len()
                    )));
                };
                let sampler = ShapeSampler::new(shape_desc).map_err(|why| {
                    fail(format!(
                        "area emitter on shape \"{}\" cannot emit: {why}",
                        shape_desc.name
                    ))
                })?;
                Light::Area(AreaLight::new(sampler, *shape, *radiance))
            }
            EmitterDesc::Point {
                intensity,
                position,
            } => {
                if !position.is_finite() {
                    return Err(fail(format!(
                        "point light position {position:?} is not finite"
                    )));
                }
                Light::Point(PointLight::new(*position, *intensity))
            }
            EmitterDesc::Spot {
                intensity,
                to_world,
                cutoff_angle,
                beam_width,
            } => Light::Spot(
                SpotLight::new(to_world, *intensity, *cutoff_angle, *beam_width)
                    .ok_or_else(|| fail("spot light with a degenerate to_world".to_string()))?,
            ),
            EmitterDesc::Directional {
                irradiance,
                direction,
            } => Light::Directional(
                DirectionalLight::new(*direction, *irradiance, sphere).ok_or_else(|| {
                    fail(format!(
                        "directional light direction {direction:?} cannot be normalised"
                    ))
                })?,
            ),
            EmitterDesc::Constant { radiance } => {
                Light::Constant(ConstantLight::new(*radiance, sphere))
            }
            EmitterDesc::Envmap {
                filename,
                scale,
                to_world,
            } => Light::Envmap(Box::new(
                // The image's own message (naming the EXR) after the emitter's location.
                EnvmapLight::load(filename, *scale, to_world, sphere)
                    .map_err(|e| fail(e.to_string()))?,
            )),
        })
    }

    /// A delta in position or direction: no ray can hit it.
    pub fn is_delta(&self) -> bool {
        matches!(
            self,
            Light::Point(_) | Light::Spot(_) | Light::Directional(_)
        )
    }

    /// At infinity: reached by rays that escape the scene.
    pub fn is_infinite(&self) -> bool {
        matches!(
            self,
            Light::Directional(_) | Light::Constant(_) | Light::Envmap(_)
        )
    }

    /// The shape an area light sits on.
    pub fn shape(&self) -> Option<usize> {
        match self {
            Light::Area(a) => Some(a.shape_index),
            _ => None,
        }
    }

    /// Channel mean of the emitted power (see the module contract).
    pub fn power(&self) -> f32 {
        match self {
            Light::Area(l) => l.power(),
            Light::Point(l) => l.power(),
            Light::Spot(l) => l.power(),
            Light::Directional(l) => l.power(),
            Light::Constant(l) => l.power(),
            Light::Envmap(l) => l.power(),
        }
    }

    /// A point of the light for next-event estimation from `ref_point`.
    #[inline]
    pub fn sample_li(&self, ref_point: Vec3, u: Vec2) -> Option<LightSample> {
        let s = match self {
            Light::Area(l) => l.sample_li(ref_point, u),
            Light::Point(l) => l.sample_li(ref_point),
            Light::Spot(l) => l.sample_li(ref_point),
            Light::Directional(l) => l.sample_li(),
            Light::Constant(l) => l.sample_li(u),
            Light::Envmap(l) => l.sample_li(u),
        }?;
        let ok = s.radiance.is_valid_radiance()
            && s.pdf_solid_angle > 0.0
            && s.pdf_solid_angle.is_finite()
            && s.pdf_area.is_finite()
            && s.wi.is_finite();
        ok.then_some(s)
    }

    /// `sample_li` for the lanes of `m` (reference points `r`, 2D samples `ux`, `uy`),
    /// lane by lane the same bits; None for lights the lanes cannot sample (all but point
    /// lights, lights at infinity, area lights on meshes and on spheres seen from outside).
    #[inline]
    pub fn sample_li_lanes(
        &self,
        r: V3<F32x16>,
        ux: F32x16,
        uy: F32x16,
        m: Mask16,
    ) -> Option<LightSampleLanes> {
        let mut s = match self {
            Light::Area(l) => l.sample_li_lanes(r, ux, uy, m)?,
            Light::Point(l) => l.sample_li_lanes(r, m),
            Light::Envmap(l) => l.sample_li_lanes(ux, uy, m)?,
            Light::Constant(l) => l.sample_li_lanes(ux, uy, m),
            _ => return None,
        };
        // The checks of `sample_li`.
        let zero = F32x16::splat(0.0);
        let valid = |c: F32x16| c.is_finite() & c.ge(zero);
        s.ok &= valid(s.radiance.x) & valid(s.radiance.y) & valid(s.radiance.z);
        if !s.pdf_area.is_finite() {
            s.ok = Mask16::NONE;
        }
        s.ok &= s.pdf_solid_angle.gt(zero) & s.pdf_solid_angle.is_finite() & s.wi.is_finite();
        Some(s)
    }

    /// For rays that hit this light at points `p` (geometric normal `n`, emitting side
    /// `front`) travelling towards `w` (unit, away from the light), from reference points
    /// `r`: `le` and `pdf_li` (Light's cleaning included), lane by lane the same bits as the
    /// scalar functions; None for lights the lanes cannot do (all but area lights on meshes,
    /// disks and spheres).
    #[inline]
    pub fn emission_lanes(
        &self,
        p: V3<F32x16>,
        n: V3<F32x16>,
        front: V3<F32x16>,
        w: V3<F32x16>,
        r: V3<F32x16>,
    ) -> Option<EmissionLanes> {
        let Light::Area(l) = self else {
            return None;
        };
        let mut e = l.emission_lanes(p, n, front, w, r)?;
        let zero = F32x16::splat(0.0);
        e.pdf_li = F32x16::select(e.pdf_li.is_finite() & e.pdf_li.gt(zero), e.pdf_li, zero);
        Some(e)
    }

    /// Solid-angle density of `sample_li(ref_point, ·)` producing `hit` (0 for delta lights).
    /// A density too large for f32 (a light seen from astronomically far away) is 0: no
    /// sample could have been drawn there either (`sample_li` drops such samples).
    pub fn pdf_li(&self, ref_point: Vec3, hit: &LightPoint) -> f32 {
        let pdf = match self {
            Light::Area(l) => l.pdf_li(ref_point, hit),
            Light::Point(_) | Light::Spot(_) | Light::Directional(_) => 0.0,
            Light::Constant(l) => l.pdf_li(),
            Light::Envmap(l) => l.pdf_direction(hit.p),
        };
        if pdf.is_finite() && pdf > 0.0 {
            pdf
        } else {
            0.0
        }
    }

    /// Radiance the light sends from `hit` towards `w` (area lights; black behind), or, for
    /// lights at infinity, arriving from direction `hit.p` (`w` unused). Delta lights: black.
    pub fn le(&self, hit: &LightPoint, w: Vec3) -> Rgb {
        match self {
            Light::Area(l) => l.le(hit, w),
            Light::Constant(l) => l.radiance,
            Light::Envmap(l) => l.le(hit.p),
            Light::Point(_) | Light::Spot(_) | Light::Directional(_) => Rgb::BLACK,
        }
    }

    /// What the emission point `e` of `sample_le` sends towards unit direction `w`, for a
    /// path that leaves it in `w` instead of `e.direction` (connecting the light to another
    /// vertex): radiance for area lights (black behind them), intensity (times the falloff)
    /// for point and spot lights. Lights at infinity: black, since no direction but their
    /// own leaves their emission disk towards a given point.
    pub fn emitted_towards(&self, e: &EmissionSample, w: Vec3) -> Rgb {
        match self {
            Light::Area(l) if e.front.dot(w) > 0.0 => l.radiance,
            Light::Point(l) => l.intensity,
            Light::Spot(l) => l.intensity * l.falloff(w),
            _ => Rgb::BLACK,
        }
    }

    /// A ray leaving the light: `u1` picks the position, `u2` the direction.
    pub fn sample_le(&self, u1: Vec2, u2: Vec2) -> Option<EmissionSample> {
        let s = match self {
            Light::Area(l) => l.sample_le(u1, u2),
            Light::Point(l) => l.sample_le(u2),
            Light::Spot(l) => l.sample_le(u2),
            Light::Directional(l) => l.sample_le(u1),
            Light::Constant(l) => l.sample_le(u1, u2),
            Light::Envmap(l) => l.sample_le(u1, u2),
        }?;
        let ok = s.radiance.is_valid_radiance()
            && s.pdf_pos > 0.0
            && s.pdf_pos.is_finite()
            && s.pdf_dir > 0.0
            && s.pdf_dir.is_finite()
            && s.origin.is_finite()
            && s.direction.is_finite();
        ok.then_some(s)
    }

    /// (pdf_pos, pdf_dir) of `sample_le` producing the ray from `p` (normal `n`, area
    /// lights) in direction `dir`; delta components count 1, as `sample_le` reports them.
    pub fn pdf_le(&self, _p: Vec3, n: Vec3, dir: Vec3) -> (f32, f32) {
        let (pos, d) = match self {
            Light::Area(l) => l.pdf_le(n, dir),
            Light::Point(l) => l.pdf_le(),
            Light::Spot(l) => l.pdf_le(dir),
            Light::Directional(l) => l.pdf_le(),
            Light::Constant(l) => l.pdf_le(dir),
            Light::Envmap(l) => l.pdf_le(dir),
        };
        let clean = |x: f32| if x.is_finite() && x > 0.0 { x } else { 0.0 };
        (clean(pos), clean(d))
    }
}

/// All lights of a scene, the area light of each shape, and the choice among them.
#[derive(Clone, Debug)]
pub struct LightSet {
    /// In the order of `SceneDescription::emitters` (same indices).
    lights: Vec<Light>,
    /// Per shape, the index of its area light.
    shape_lights: Vec<Option<usize>>,
    /// Indices of the lights at infinity that rays can hit (constant, envmap).
    environment: Vec<usize>,
    selection: LightSelection,
    sphere: SceneSphere,
}

impl LightSet {
    /// Builds every emitter of the scene (see `Light::from_desc` for the errors).
    pub fn build(scene: &SceneDescription) -> Result<LightSet> {
        let sphere = SceneSphere::from_shapes(&scene.shapes);
        let mut lights = Vec::with_capacity(scene.emitters.len());
        let mut shape_lights = vec![None; scene.shapes.len()];
        let mut environment = Vec::new();
        for (i, desc) in scene.emitters.iter().enumerate() {
            let light = Light::from_desc(desc, scene, sphere, &scene.emitter_location(i))?;
            if let Some(shape) = light.shape() {
                shape_lights[shape] = Some(i);
            }
            if light.is_infinite() && !light.is_delta() {
                environment.push(i);
            }
            lights.push(light);
        }
        let powers: Vec<f32> = lights.iter().map(Light::power).collect();
        Ok(LightSet {
            lights,
            shape_lights,
            environment,
            selection: LightSelection::new(&powers),
            sphere,
        })
    }

    pub fn len(&self) -> usize {
        self.lights.len()
    }

    pub fn is_empty(&self) -> bool {
        self.lights.is_empty()
    }

    pub fn lights(&self) -> &[Light] {
        &self.lights
    }

    pub fn get(&self, i: usize) -> &Light {
        &self.lights[i]
    }

    /// The index of the area light on shape `shape`, if it emits.
    pub fn light_of_shape(&self, shape: usize) -> Option<usize> {
        self.shape_lights.get(shape).copied().flatten()
    }

    /// Lights that a ray escaping the scene sees (constant and envmap).
    pub fn environment(&self) -> &[usize] {
        &self.environment
    }

    pub fn sphere(&self) -> SceneSphere {
        self.sphere
    }

    /// Chooses a light by power: (index, probability, `u` rescaled for reuse).
    pub fn sample(&self, u: f32) -> Option<(usize, f32, f32)> {
        self.selection.sample(u)
    }

    /// The light `sample` chooses and its probability, for the lanes of `m`; None when
    /// there is no light to choose.
    #[inline]
    pub fn choose_lanes(&self, u: F32x16, m: Mask16) -> Option<(U32x16, F32x16)> {
        self.selection.choose_lanes(u, m)
    }

    /// Probability that `sample` chooses light `i`.
    pub fn pmf(&self, i: usize) -> f32 {
        self.selection.pmf(i)
    }
}
