//! Mitsuba 3's `perspective` and `thinlens` sensors: a camera looking down +z in camera
//! space, +y up, pixel (0, 0) at the top left of the image.
//!
//! The model, as Mitsuba 3 defines it (its `perspective_projection`): a camera-space point
//! (x, y, z) with z > 0 lands at the normalised image position
//!
//! ```text
//! u = 1/2 − x / (2 z tan(fov_x / 2))            (u = 0 left edge, 1 right edge)
//! v = 1/2 − aspect · y / (2 z tan(fov_x / 2))   (v = 0 top edge, 1 bottom edge)
//! ```
//!
//! with aspect = width / height and raster position (u · width, v · height). So camera +y is
//! image up and camera +x is image LEFT: the frame (x, y, z) is right-handed, and a viewer
//! looking down +z with +y up has +x on the left. A `lookat` transform has the columns
//! (left, up, dir, origin) with left = up × dir, so it maps camera +x to the image's left
//! in world space: the image is never mirrored.
//!
//! Rays start on the near plane (Mitsuba 3 moves the origin to the near plane and shortens
//! `maxt` accordingly); `Ray::t_max` ends them on the far plane.
//!
//! Depth of field (`thinlens`, `ThinLens`): the pinhole becomes a lens of radius r focused
//! on the plane z = F. `sample_ray` takes a lens sample besides the raster position; camera
//! estimators draw it as the second 2D sample of each pixel sample, right after the pixel
//! position, and only for a camera with a lens (`has_lens`), so a pinhole's images do not
//! depend on it. `generate_ray` and `project` are the chief ray (through the lens centre):
//! exact for a pinhole, and for a thin lens where points on the focus plane land.
//!
//! A crop window (`crop_offset_x` … on the film) keeps the whole film's projection and
//! renders part of it: raster positions, `width` and `height` are the window's, and the
//! image area A below is the window's part of the plane (Mitsuba 3 does the same).
//!
//! Light tracing: `importance_from` (We), `pdf_direction_from` and `pdf_lens_position` are
//! the sensor response of a ray leaving a camera point (the pinhole or a lens point) and the
//! densities with which `sample_ray` produces its direction and origin; `importance` and
//! `pdf_direction` take the pinhole (or the lens centre). `connect` (pinhole only) and
//! `connect_lens` (any camera, given a lens sample) are the camera end of a light-tracing
//! connection. A light path's contribution splatted with `Film::splat` needs the splat scale
//! width · height / (number of light paths) to give per-pixel values in the same units as the
//! camera-side estimates.

mod thin_lens;

pub use thin_lens::ThinLens;

use glam::{Vec2, Vec3};

use crate::geometry::Ray;
use crate::geometry::packet::RayLanes;
use crate::math::lanes::{F32x16, Real, U32x16, V3};
use crate::math::warp::disk_concentric;
use crate::scene::{FovAxis, SensorDesc};

/// A pinhole (`<sensor type="perspective">`) or thin-lens (`<sensor type="thinlens">`)
/// camera.
#[derive(Clone, Debug)]
pub struct Camera {
    to_world: crate::math::Transform,
    /// The rendered window's size in pixels.
    width: u32,
    height: u32,
    /// The whole film's size, and the window's top-left pixel on it.
    film_width: u32,
    film_height: u32,
    offset: Vec2,
    /// tan(fov_x / 2): the half-width of the image on the camera-space plane z = 1.
    tan_half_x: f32,
    /// width / height.
    aspect: f32,
    near_clip: f32,
    far_clip: f32,
    /// Area of the window on the camera-space plane z = 1: (2 tan(fov_x / 2))² / aspect
    /// times the window's share of the film's pixels.
    plane_area: f32,
    /// The pinhole in world space.
    position: Vec3,
    /// The viewing direction (camera +z) in world space, unit length.
    forward: Vec3,
    /// The thin lens, or `None` for a pinhole.
    lens: Option<ThinLens>,
}

/// The camera end of a connection from a world point (light tracing, BDPT t = 1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraConnection {
    /// Where the point lands on the film.
    pub raster: Vec2,
    /// The pinhole (or the sampled lens point) in world space.
    pub camera_position: Vec3,
    /// Unit direction from the point towards `camera_position`.
    pub direction_to_camera: Vec3,
    /// Distance from the point to `camera_position`.
    pub distance: f32,
    /// We(ω) · cos θ_camera / distance²  =  1 / (A cos³θ · distance²), with A the image
    /// area on the plane z = 1. Multiply by the path throughput, the BSDF at the point and
    /// the cosine there to get the connection's contribution (Veach 1997, §10.2). For a
    /// thin lens this already divides by the density 1 / (π r²) of the lens point, which
    /// cancels the lens area in We (pbrt-v3 §16.1.1), so the formula is the pinhole's.
    pub importance: f32,
    /// The solid-angle density of a camera ray from `camera_position` towards the point,
    /// 1 / (A cos³θ): `pdf_direction_from` without computing the direction again.
    pub pdf_direction: f32,
}

/// The horizontal field of view in degrees that Mitsuba 3 derives from `fov` along
/// `fov_axis` on a film of aspect ratio `aspect` = width / height.
pub fn horizontal_fov_degrees(fov_degrees: f64, fov_axis: FovAxis, aspect: f64) -> f64 {
    let half = (0.5 * fov_degrees).to_radians();
    let axis = match fov_axis {
        FovAxis::Smaller if aspect > 1.0 => FovAxis::Y,
        FovAxis::Smaller => FovAxis::X,
        FovAxis::Larger if aspect > 1.0 => FovAxis::X,
        FovAxis::Larger => FovAxis::Y,
        other => other,
    };
    let tan_half_x = match axis {
        FovAxis::Y => half.tan() * aspect,
        // The diagonal's half-length on z = 1 is tan(fov/2); the width follows from the
        // aspect ratio: w² (1 + 1/aspect²) = diagonal².
        FovAxis::Diagonal => half.tan() / (1.0 + 1.0 / (aspect * aspect)).sqrt(),
        _ => half.tan(),
    };
    (2.0 * tan_half_x.atan()).to_degrees()
}

impl Camera {
    /// The camera of `sensor`. The scene loader has already checked what Mitsuba rejects:
    /// 0 < fov < 180 (after conversion to the horizontal axis), 0 < near_clip < far_clip and
    /// a `to_world` without scaling. Directions are renormalised anyway, so a `to_world`
    /// that is orthonormal up to rounding is harmless.
    pub fn new(sensor: &SensorDesc) -> Camera {
        let film_width = sensor.film.width.max(1);
        let film_height = sensor.film.height.max(1);
        let window = sensor.film.window();
        let (width, height) = (window.width.max(1), window.height.max(1));
        let aspect = film_width as f64 / film_height as f64;
        let fov_x = horizontal_fov_degrees(sensor.fov_degrees as f64, sensor.fov_axis, aspect);
        let tan_half_x = (0.5 * fov_x).to_radians().tan();
        let share = (width as f64 * height as f64) / (film_width as f64 * film_height as f64);
        let plane_area = (2.0 * tan_half_x) * (2.0 * tan_half_x) / aspect * share;
        let to_world = sensor.to_world;
        Camera {
            to_world,
            width,
            height,
            film_width,
            film_height,
            offset: Vec2::new(window.x as f32, window.y as f32),
            tan_half_x: tan_half_x as f32,
            aspect: aspect as f32,
            near_clip: sensor.near_clip,
            far_clip: sensor.far_clip,
            plane_area: plane_area as f32,
            position: to_world.point(Vec3::ZERO),
            forward: to_world.vector(Vec3::Z).normalize(),
            lens: sensor.lens.as_ref().map(ThinLens::new),
        }
    }

    /// Whether the camera has a lens, i.e. whether `sample_ray` uses its lens sample.
    pub fn has_lens(&self) -> bool {
        self.lens.is_some()
    }

    /// The thin lens, if any.
    pub fn lens(&self) -> Option<&ThinLens> {
        self.lens.as_ref()
    }

    pub fn width(&self) -> u32 {
        self.width
    }

    pub fn height(&self) -> u32 {
        self.height
    }

    /// The pinhole in world space.
    pub fn position(&self) -> Vec3 {
        self.position
    }

    /// The viewing direction (camera +z) in world space.
    pub fn forward(&self) -> Vec3 {
        self.forward
    }

    /// tan(fov_x / 2): the half-width of the image on the camera-space plane z = 1.
    pub fn tan_half_fov_x(&self) -> f32 {
        self.tan_half_x
    }

    /// The area A of the image on the camera-space plane z = 1.
    pub fn image_plane_area(&self) -> f32 {
        self.plane_area
    }

    /// The camera-space direction (not normalised, z = 1) through raster position `raster`.
    fn camera_direction(&self, raster: Vec2) -> Vec3 {
        self.camera_direction_in(raster.x, raster.y).into()
    }

    /// `camera_direction` over `Real` (one raster position, or sixteen in lanes).
    #[inline(always)]
    fn camera_direction_in<T: Real>(&self, x: T, y: T) -> V3<T> {
        let c = T::splat;
        let u = (x + c(self.offset.x)) / c(self.film_width as f32);
        let v = (y + c(self.offset.y)) / c(self.film_height as f32);
        V3::new(
            (c(1.0) - c(2.0) * u) * c(self.tan_half_x),
            (c(1.0) - c(2.0) * v) * c(self.tan_half_x) / c(self.aspect),
            c(1.0),
        )
    }

    /// `sample_ray` for sixteen raster positions (x, y) and lens samples (per lane), lane
    /// by lane the same bits (`generate_ray` for a pinhole, which ignores `lens`).
    pub fn sample_ray_lanes(&self, x: F32x16, y: F32x16, lens: (F32x16, F32x16)) -> RayLanes {
        let c = F32x16::splat;
        let on_plane = self.camera_direction_in(x, y);
        let m = &self.to_world.matrix;
        // `Mat4::transform_vector3` / `transform_point3`: x_axis·v.x + y_axis·v.y +
        // z_axis·v.z (+ w_axis), row by row.
        let transform = |v: V3<F32x16>, point: bool| {
            let row = |k: usize| {
                let a = |col: glam::Vec4| c(col[k]);
                let sum = a(m.x_axis) * v.x + a(m.y_axis) * v.y + a(m.z_axis) * v.z;
                if point { sum + a(m.w_axis) } else { sum }
            };
            V3::new(row(0), row(1), row(2))
        };
        let (origin, d_camera) = match &self.lens {
            None => {
                let p = self.position;
                (V3::new(c(p.x), c(p.y), c(p.z)), on_plane.normalize())
            }
            Some(thin) => {
                // `ThinLens::point` and `ThinLens::direction`.
                let (dx, dy) = disk_concentric(lens.0, lens.1);
                let r = c(thin.radius());
                let a = V3::new(r * dx, r * dy, c(0.0));
                let d = (on_plane * c(thin.focus_distance()) - a).normalize();
                (transform(a, true), d)
            }
        };
        // `clipped_ray`.
        let d = transform(d_camera, false).normalize();
        let inv_z = c(1.0) / d_camera.z;
        let near_t = c(self.near_clip) * inv_z;
        let far_t = c(self.far_clip) * inv_z;
        RayLanes {
            o: origin + d * near_t,
            d,
            t_max: far_t - near_t,
        }
    }

    /// The primary ray through raster position `raster` (continuous pixel coordinates:
    /// x in [0, width), y in [0, height), (0, 0) = top-left corner of the top-left pixel).
    /// Its direction is unit length and it starts at the near clip plane; `t_max` ends it on
    /// the far clip plane (both planes are z = const in camera space, as in Mitsuba 3).
    /// For a thin lens this is the chief ray, through the lens centre.
    pub fn generate_ray(&self, raster: Vec2) -> Ray {
        let d_camera = self.camera_direction(raster).normalize();
        self.clipped_ray(self.position, d_camera)
    }

    /// The primary ray through raster position `raster` and lens sample `lens` ∈ [0, 1)²:
    /// for a thin lens, from the lens point of `lens` towards the point of the focus plane
    /// that `raster` sees (`ThinLens`); for a pinhole, `generate_ray(raster)`, ignoring
    /// `lens`. Clipped as `generate_ray`'s; its weight is 1 (Mitsuba 3's `sample_ray`).
    pub fn sample_ray(&self, raster: Vec2, lens: Vec2) -> Ray {
        let Some(thin) = &self.lens else {
            return self.generate_ray(raster);
        };
        let a = thin.point(lens);
        let d_camera = thin.direction(a, self.camera_direction(raster));
        self.clipped_ray(self.to_world.point(a), d_camera)
    }

    /// The camera point a ray of `generate_ray` or `sample_ray` leaves from: the pinhole,
    /// or its point of the lens (the ray's origin moved back from the near clip plane).
    pub fn ray_start(&self, ray: &Ray) -> Vec3 {
        if self.lens.is_none() {
            return self.position;
        }
        let dz = self.to_world.inverse.transform_vector3(ray.d).z;
        ray.o - ray.d * (self.near_clip / dz)
    }

    /// The ray from world point `origin` (on the camera plane z = 0) along the unit
    /// camera-space direction `d_camera`, cut to the clip planes z = near and z = far.
    fn clipped_ray(&self, origin: Vec3, d_camera: Vec3) -> Ray {
        let d = self.to_world.vector(d_camera).normalize();
        let inv_z = 1.0 / d_camera.z;
        let near_t = self.near_clip * inv_z;
        let far_t = self.far_clip * inv_z;
        Ray {
            o: origin + d * near_t,
            d,
            t_max: far_t - near_t,
        }
    }

    /// The raster position a world point projects to, or None when it is behind the
    /// camera, outside the image or outside the clip range. As in Mitsuba 3 the image
    /// bounds are inclusive: the result lies in [0, width] × [0, height]. For a thin lens
    /// this is the projection through the lens centre.
    pub fn project(&self, p: Vec3) -> Option<Vec2> {
        let q = self.to_world.inverse.transform_point3(p);
        if !self.in_clip_range(q) {
            return None;
        }
        self.raster_of(q)
    }

    /// Where world point `p` lands seen through lens sample `lens` (see `sample_ray`): the
    /// raster position whose ray from that lens point passes through `p`, or None outside
    /// the image or the clip range. For a pinhole, `project(p)`.
    pub fn project_through_lens(&self, p: Vec3, lens: Vec2) -> Option<Vec2> {
        let Some(thin) = &self.lens else {
            return self.project(p);
        };
        let q = self.to_world.inverse.transform_point3(p);
        if !self.in_clip_range(q) {
            return None;
        }
        self.raster_of(thin.on_plane(thin.point(lens), q))
    }

    /// Whether camera-space point `q` lies between the clip planes (NaN does not).
    fn in_clip_range(&self, q: Vec3) -> bool {
        q.z >= self.near_clip && q.z <= self.far_clip
    }

    /// The raster position of the pinhole projection of camera-space point `q` (q.z > 0),
    /// or None outside the rendered window (bounds inclusive).
    fn raster_of(&self, q: Vec3) -> Option<Vec2> {
        let s = 0.5 / (q.z * self.tan_half_x);
        let u = 0.5 - q.x * s;
        let v = 0.5 - self.aspect * q.y * s;
        let raster = Vec2::new(
            u * self.film_width as f32 - self.offset.x,
            v * self.film_height as f32 - self.offset.y,
        );
        let size = Vec2::new(self.width as f32, self.height as f32);
        (raster.cmpge(Vec2::ZERO).all() && raster.cmple(size).all()).then_some(raster)
    }

    /// The importance We(ω) of a ray leaving the pinhole (or the lens centre) in unit
    /// world-space direction ω: `importance_from(position(), ω)`.
    pub fn importance(&self, direction: Vec3) -> f32 {
        self.importance_from(self.position, direction)
    }

    /// The solid-angle density of the chief ray's direction when the raster position is
    /// uniform over the image: `pdf_direction_from(position(), ω)`.
    pub fn pdf_direction(&self, direction: Vec3) -> f32 {
        self.pdf_direction_from(self.position, direction)
    }

    /// The importance We(x, ω) of a ray leaving camera point x (world space: the pinhole, or
    /// a point of a thin lens's aperture) in unit direction ω, where it lands inside the
    /// image: 1 / (A cos⁴θ) for a pinhole and 1 / (A π r² cos⁴θ) for a thin lens of radius r,
    /// with A the image area on the plane z = 1 (pbrt-v3 §16.1.1). 0 outside the image,
    /// behind the camera and, for a lens, for x off the aperture. With these, a ray of
    /// `sample_ray` has weight We·cos θ / (`pdf_lens_position` · `pdf_direction_from`) = 1,
    /// as in Mitsuba 3 (whose `importance` is this times cos θ).
    pub fn importance_from(&self, origin: Vec3, direction: Vec3) -> f32 {
        match self.image_cos_theta(origin, direction) {
            Some(cos) => {
                1.0 / (self.plane_area * self.lens_area().unwrap_or(1.0) * cos * cos * cos * cos)
            }
            None => 0.0,
        }
    }

    /// The solid-angle density of the direction of `sample_ray` from camera point x when the
    /// raster position is uniform over the image: 1 / (A cos³θ) where the ray lands inside
    /// the image, 0 elsewhere. The same for a lens point as for the pinhole: the rays from
    /// one lens point through the focus plane spread like the pinhole's through z = 1.
    pub fn pdf_direction_from(&self, origin: Vec3, direction: Vec3) -> f32 {
        match self.image_cos_theta(origin, direction) {
            Some(cos) => 1.0 / (self.plane_area * cos * cos * cos),
            None => 0.0,
        }
    }

    /// The density of a camera ray's origin per unit area of the aperture, 1 / (π r²), for
    /// a thin lens with uniform lens samples; None for a pinhole (or a lens of radius 0),
    /// whose rays all start at one point.
    pub fn pdf_lens_position(&self) -> Option<f32> {
        self.lens_area().map(|a| 1.0 / a)
    }

    /// π r² for a thin lens of radius r > 0.
    fn lens_area(&self) -> Option<f32> {
        let r = self.lens.as_ref()?.radius();
        (r > 0.0).then_some(std::f32::consts::PI * r * r)
    }

    /// cos θ between `direction` and the viewing axis, when the ray from camera point
    /// `origin` in that direction lands inside the image: for a pinhole where it crosses the
    /// plane z = 1 (`origin` is the pinhole), for a thin lens where it crosses the focus
    /// plane, seen through the lens centre (`ThinLens::on_plane`); None for an origin off
    /// the aperture.
    fn image_cos_theta(&self, origin: Vec3, direction: Vec3) -> Option<f32> {
        let Some(thin) = &self.lens else {
            return self.plane_cos_theta(direction);
        };
        let a = self.to_world.inverse.transform_point3(origin);
        // A point of the aperture, up to the rounding of the transforms.
        let slack = 1e-4 * (1.0 + thin.radius());
        if !(a.truncate().length() <= thin.radius() + slack && a.z.abs() <= slack) {
            return None;
        }
        let d = self.forward_camera_direction(direction)?;
        let a = a.truncate().extend(0.0);
        self.raster_of(thin.on_plane(a, a + d))?;
        Some(d.z)
    }

    /// World direction `direction` in camera space, unit length, when it points forward
    /// (z > 0).
    fn forward_camera_direction(&self, direction: Vec3) -> Option<Vec3> {
        let d = self
            .to_world
            .inverse
            .transform_vector3(direction)
            .normalize();
        (d.z > 0.0).then_some(d)
    }

    /// cos θ between `direction` and the viewing axis, when the direction passes through
    /// the image (bounds inclusive, as in Mitsuba 3).
    fn plane_cos_theta(&self, direction: Vec3) -> Option<f32> {
        let d = self.forward_camera_direction(direction)?;
        self.raster_of(d / d.z)?;
        Some(d.z)
    }

    /// The camera end of a connection from world point `p` to a pinhole: None when `p` is
    /// outside the image or the clip range, and always None for a thin lens, whose lens
    /// point must be sampled (`connect_lens`). Visibility is the caller's business.
    pub fn connect(&self, p: Vec3) -> Option<CameraConnection> {
        if self.lens.is_some() {
            return None;
        }
        self.connect_from(p, self.position, self.project(p)?)
    }

    /// The camera end of a connection from world point `p` to the lens point of lens sample
    /// `lens` (uniform over the aperture when `lens` is uniform over the square); for a
    /// pinhole the same as `connect(p)`.
    pub fn connect_lens(&self, p: Vec3, lens: Vec2) -> Option<CameraConnection> {
        let Some(thin) = &self.lens else {
            return self.connect(p);
        };
        let raster = self.project_through_lens(p, lens)?;
        self.connect_from(p, self.to_world.point(thin.point(lens)), raster)
    }

    /// The connection from `p` to the camera point `camera_position` (world space) at which
    /// `p` lands on `raster`.
    fn connect_from(
        &self,
        p: Vec3,
        camera_position: Vec3,
        raster: Vec2,
    ) -> Option<CameraConnection> {
        let to_camera = camera_position - p;
        let distance = to_camera.length();
        if distance.is_nan() || distance <= 0.0 {
            return None;
        }
        let direction_to_camera = to_camera / distance;
        let d = self
            .to_world
            .inverse
            .transform_vector3(-direction_to_camera)
            .normalize();
        let cos = d.z;
        if cos.is_nan() || cos <= 0.0 {
            return None;
        }
        let importance = 1.0 / (self.plane_area * cos * cos * cos * distance * distance);
        Some(CameraConnection {
            raster,
            camera_position,
            direction_to_camera,
            distance,
            importance,
            pdf_direction: 1.0 / (self.plane_area * cos * cos * cos),
        })
    }
}

/// `raster_in_pixel` for sixteen pixels (x, y) and offsets (ux, uy), lane by lane the same
/// bits.
pub fn raster_in_pixel_lanes(x: U32x16, y: U32x16, ux: F32x16, uy: F32x16) -> (F32x16, F32x16) {
    let inside = |i: U32x16, t: F32x16| {
        let lo = i.to_f32();
        let p = lo + t;
        let hi = lo + F32x16::splat(1.0);
        // The float below hi (hi ≥ 1: one step down in its bits).
        let below = F32x16::from_bits(hi.to_bits() - U32x16::splat(1));
        F32x16::select(p.lt(hi), p, below)
    };
    (inside(x, ux), inside(y, uy))
}

/// A raster position inside pixel (x, y) at offset `u` ∈ [0, 1)², guaranteed to round
/// down to that pixel: in f32, x + u can round up to x + 1 when u is just below 1.
pub fn raster_in_pixel(x: u32, y: u32, u: Vec2) -> Vec2 {
    fn inside(i: u32, t: f32) -> f32 {
        let lo = i as f32;
        let p = lo + t;
        if p < lo + 1.0 {
            p
        } else {
            (lo + 1.0).next_down()
        }
    }
    Vec2::new(inside(x, u.x), inside(y, u.y))
}
