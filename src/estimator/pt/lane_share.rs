//! How much of a scene's path vertices `pt`'s SIMD lanes handle themselves, measured while
//! it renders, and the choice it drives.
//!
//! The lanes scatter at every surface but `null` ones (diffuse, smooth mirrors and glass
//! in lane arithmetic, other BSDFs around their scalar calls) and add the emission of area
//! lights on meshes and disks and of the environment; every other vertex (`null` surfaces,
//! other emitters) is handed to the scalar code one lane at a time, which costs a
//! transposition of the path's state out of the lanes and back. Where most vertices go that
//! way, tracing one path at a time is faster (10–20% on scenes made mostly of such
//! surfaces, when rough BSDFs went that way too).
//! The image is the same bit for bit either way (`tests/pt.rs`), so the choice, made
//! batch by batch from the counts so far, changes only the speed.

use std::sync::atomic::{AtomicU64, Ordering};

/// Path vertices a batch advanced in lanes, and how many of them the scalar code handled.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Coverage {
    pub vertices: u64,
    pub scalar: u64,
}

/// Vertices seen before the share decides (a few batches' worth).
const MIN_VERTICES: u64 = 1 << 16;

/// The share of scalar-handled vertices above which one path at a time is faster.
const MAX_SCALAR_SHARE: f64 = 0.3;

/// The counts of every batch so far, shared by the worker threads.
#[derive(Debug, Default)]
pub(super) struct LaneShare {
    vertices: AtomicU64,
    scalar: AtomicU64,
}

impl LaneShare {
    pub fn add(&self, c: Coverage) {
        self.vertices.fetch_add(c.vertices, Ordering::Relaxed);
        self.scalar.fetch_add(c.scalar, Ordering::Relaxed);
    }

    /// The share of vertices the scalar code handled so far (0 before any batch).
    pub fn scalar_share(&self) -> f64 {
        let vertices = self.vertices.load(Ordering::Relaxed);
        self.scalar.load(Ordering::Relaxed) as f64 / vertices.max(1) as f64
    }

    /// Whether the next batch should go to the lanes: yes until `MIN_VERTICES` have been
    /// counted, then while the scalar share stays at most `MAX_SCALAR_SHARE`.
    pub fn lanes_pay(&self) -> bool {
        self.vertices.load(Ordering::Relaxed) < MIN_VERTICES
            || self.scalar_share() <= MAX_SCALAR_SHARE
    }
}
