//! mltbench: a research bench for light-transport estimators.
//!
//! Data flows one way: scene file → `scene::Scene` → estimator passes → `film::Film` →
//! `image::Image` → files. See docs/DESIGN.md for the map of the crate.

pub mod camera;
pub mod cpu;
pub mod error;
pub mod estimator;
pub mod experiment;
pub mod film;
pub mod geometry;
pub mod image;
pub mod interrupt;
pub mod io;
pub mod lecture;
pub mod light;
pub mod material;
pub mod math;
pub mod path;
pub mod render;
pub mod sampler;
pub mod scene;
pub mod texture;

pub use error::{Error, Result};
