//! Closest hits for a stream of rays with several traversals in flight.
//!
//! One incoherent ray on a large scene spends most of its time waiting: each node it visits
//! names the next one, and that read misses the cache. A single traversal cannot overlap
//! those misses, so this query keeps `IN_FLIGHT` independent traversals and advances them
//! in turn, one node per step: the children a step prefetches arrive while the other rays
//! take their steps (the software pipelining of Aila & Karras, "Understanding the
//! Efficiency of Ray Traversal on GPUs", HPG 2009, with CPU prefetches in place of warps).
//! A finished slot takes the next ray of the stream, so the pipeline stays full.
//!
//! Each ray visits the same nodes and tests the same triangles in the same order as
//! `TriangleBvh::closest` (only the interleaving between rays differs), so the results are
//! identical, bit for bit.

use glam::{UVec2, uvec2};

use super::{
    FIXED_STACK, FixedStack, TraversalRay, TraversalStack, TriangleBvh, prefetch, replaces,
    tie_limit,
};
use crate::geometry::triangle::{self, TriangleHit};

/// Traversals advanced in turn. Measured with `cargo bench --bench rays` (see the README's
/// ray casting table): 4 overlaps enough misses on the 1M-triangle sphere; more adds stack
/// traffic without hiding more latency.
pub const IN_FLIGHT: usize = 8;

/// One ray's traversal, stopped between two node visits.
struct Traversal {
    /// Index of the ray in the stream.
    ray: usize,
    /// Unvisited children of the current node (as in `TriangleBvh::traverse`).
    node_group: UVec2,
    /// Triangles of the leaves the last visited node hit, not yet tested.
    tri_group: UVec2,
    stack: FixedStack<FIXED_STACK>,
    t_max: f32,
    /// How far beyond `t_max` boxes are tested (`TriangleBvh::hit_pad`).
    pad: f32,
    best: Option<(u32, TriangleHit)>,
}

impl Traversal {
    fn start(bvh: &TriangleBvh, rays: &[TraversalRay], ray: usize, t_max: f32) -> Self {
        Traversal {
            ray,
            node_group: uvec2(0, 0x8000_0000),
            tri_group: UVec2::ZERO,
            stack: FixedStack::new(),
            t_max,
            pad: bvh.hit_pad(&rays[ray]),
            best: None,
        }
    }
}

impl TriangleBvh {
    /// The closest triangle with 0 < t < t_max[i] for every ray `rays[i]`, handed to
    /// `done(i, hit)` as each traversal ends (not in stream order). Same results as calling
    /// `closest` on each ray.
    pub fn closest_stream(
        &self,
        rays: &[TraversalRay],
        t_max: &[f32],
        mut done: impl FnMut(usize, Option<(u32, TriangleHit)>),
    ) {
        assert_eq!(rays.len(), t_max.len(), "one t_max per ray");
        // Small scenes answered without the tree, and trees too deep for the fixed stacks.
        if self.nodes.is_empty() || self.depth >= FIXED_STACK {
            for (i, ray) in rays.iter().enumerate() {
                done(i, self.closest(ray, t_max[i]));
            }
            return;
        }
        let mut next = 0;
        let mut slots: [Option<Traversal>; IN_FLIGHT] = std::array::from_fn(|_| None);
        let mut active = 0;
        for slot in &mut slots {
            if next < rays.len() {
                *slot = Some(Traversal::start(self, rays, next, t_max[next]));
                next += 1;
                active += 1;
            }
        }
        while active > 0 {
            for slot in &mut slots {
                let Some(traversal) = slot else { continue };
                if self.step(&rays[traversal.ray], traversal) {
                    continue;
                }
                done(traversal.ray, traversal.best);
                if next < rays.len() {
                    *traversal = Traversal::start(self, rays, next, t_max[next]);
                    next += 1;
                } else {
                    *slot = None;
                    active -= 1;
                }
            }
        }
    }

    /// Advances one traversal: tests the triangles its last node hit (prefetched when that
    /// node was visited), then visits the next node and prefetches what it hits. False when
    /// the traversal has ended.
    #[inline(always)]
    fn step(&self, ray: &TraversalRay, s: &mut Traversal) -> bool {
        while s.tri_group.y != 0 {
            let bit = s.tri_group.y.trailing_zeros();
            s.tri_group.y &= s.tri_group.y - 1;
            let id = s.tri_group.x + bit;
            let limit = tie_limit(s.best, id, s.t_max);
            if let Some(h) = triangle::intersect(&self.records[id as usize], &ray.tri, limit)
                && replaces(s.best, id, h.t)
            {
                s.t_max = h.t;
                s.best = Some((id, h));
                // As in `closest`: start fetching the hit's surface data.
                if let Some(n) = &self.normals {
                    prefetch(&n[id as usize]);
                }
                if let Some(uv) = &self.uvs {
                    prefetch(&uv[id as usize]);
                }
            }
        }
        if s.node_group.y & 0xff00_0000 == 0 {
            match s.stack.pop() {
                Some(g) => s.node_group = g,
                None => return false,
            }
        }
        let oct = ray.oct_inv4 & 0xff;
        let hits = s.node_group.y;
        let bit = 31 - hits.leading_zeros();
        s.node_group.y &= !(1u32 << bit);
        if s.node_group.y & 0xff00_0000 != 0 {
            s.stack.push(s.node_group);
        }
        let slot = (bit - 24) ^ oct;
        let rank = (hits & !(u32::MAX << slot)).count_ones();
        let node = &self.nodes[(s.node_group.x + rank) as usize];
        let hitmask = node.hitmask(ray, s.t_max + s.pad);
        s.node_group = uvec2(node.child_base, (hitmask & 0xff00_0000) | node.imask as u32);
        s.tri_group = uvec2(node.primitive_base, hitmask & 0x00ff_ffff);
        self.prefetch_children::<true>(node, hitmask, oct);
        true
    }
}
