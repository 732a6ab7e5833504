//! Collapsing obvhs's binary BVH into a compressed 8-wide BVH (the node layout of Ylitie,
//! Karras & Laine, HPG 2017, as obvhs's `CwBvhNode`), in one linear top-down pass.
//!
//! obvhs's own converter chooses each node's children by an SAH dynamic programme over
//! every binary node; on a million triangles it takes longer than the rest of the build
//! together. Here a node's children are found greedily instead: starting from the binary
//! node's two children, the one with the largest surface area is repeatedly replaced by its
//! own two children until there are eight (the usual wide-BVH collapse). Subtrees of at most
//! three primitives become leaves. Child boxes are quantised in f64 so that the 8-bit boxes
//! contain their children exactly (no rounding slack needed).

use glam::Vec3A;
use obvhs::{aabb::Aabb, bvh2::Bvh2, cwbvh::node::CwBvhNode};
use rayon::prelude::*;

/// Primitives per leaf (the CWBVH meta byte holds up to three).
const MAX_LEAF: u32 = 3;

/// The wide BVH and the order in which its leaves reference the input primitives.
pub struct WideBvh {
    pub nodes: Vec<CwBvhNode>,
    /// `primitive_order[i]` is the input primitive of leaf slot i.
    pub primitive_order: Vec<u32>,
    /// Number of node levels.
    pub depth: usize,
}

/// Subtrees handed to threads once the serial top of the tree has this many open tasks.
const PARALLEL_TASKS: usize = 64;

/// A wide node still to build: from binary node `binary`, into wide node `wide`, at `level`.
#[derive(Clone, Copy)]
struct Task {
    binary: u32,
    wide: u32,
    level: usize,
}

/// Nodes and leaf primitives of a (sub)tree under construction.
struct Builder<'a> {
    bvh2: &'a Bvh2,
    nodes: Vec<CwBvhNode>,
    primitive_order: Vec<u32>,
    depth: usize,
}

pub fn collapse(bvh2: &Bvh2) -> WideBvh {
    if bvh2.nodes.is_empty() {
        return WideBvh {
            nodes: Vec::new(),
            primitive_order: Vec::new(),
            depth: 0,
        };
    }
    // The top of the tree breadth-first on one thread, until there are enough subtrees...
    let mut top = Builder::new(bvh2, bvh2.primitive_indices.len());
    let mut pending = std::collections::VecDeque::from([Task {
        binary: 0,
        wide: 0,
        level: 1,
    }]);
    while pending.len() < PARALLEL_TASKS {
        let Some(task) = pending.pop_front() else {
            break;
        };
        pending.extend(top.build_node(task));
    }
    // ...then each subtree on its own, in parallel, with local indices...
    let pending: Vec<Task> = pending.into_iter().collect();
    let subtrees: Vec<Builder> = pending
        .par_iter()
        .map(|task| {
            let mut sub = Builder::new(bvh2, 0);
            sub.build_subtree(Task {
                binary: task.binary,
                wide: 0,
                level: 1,
            });
            sub
        })
        .collect();
    // ...stitched in: a subtree's root replaces its placeholder, the rest is appended.
    for (task, sub) in pending.iter().zip(subtrees) {
        let node_offset = top.nodes.len() as u32 - 1; // local node i ≥ 1 → node_offset + i
        let primitive_offset = top.primitive_order.len() as u32;
        top.nodes[task.wide as usize] = relocate(sub.nodes[0], node_offset, primitive_offset);
        top.nodes.extend(
            sub.nodes[1..]
                .iter()
                .map(|&n| relocate(n, node_offset, primitive_offset)),
        );
        top.primitive_order.extend_from_slice(&sub.primitive_order);
        top.depth = top.depth.max(task.level - 1 + sub.depth);
    }
    WideBvh {
        nodes: top.nodes,
        primitive_order: top.primitive_order,
        depth: top.depth,
    }
}

/// A subtree node moved into the whole tree: its indices shifted by the offsets.
fn relocate(mut n: CwBvhNode, node_offset: u32, primitive_offset: u32) -> CwBvhNode {
    n.child_base_idx += node_offset;
    n.primitive_base_idx += primitive_offset;
    n
}

impl<'a> Builder<'a> {
    fn new(bvh2: &'a Bvh2, capacity: usize) -> Self {
        Builder {
            bvh2,
            nodes: vec![CwBvhNode::default()], // the root, filled by the first task
            primitive_order: Vec::with_capacity(capacity),
            depth: 0,
        }
    }

    /// Builds the whole subtree of `root`, depth first.
    fn build_subtree(&mut self, root: Task) {
        let mut tasks = vec![root];
        while let Some(task) = tasks.pop() {
            tasks.extend(self.build_node(task));
        }
    }

    /// Fills wide node `task.wide` from binary node `task.binary`; returns the tasks of its
    /// internal children (their nodes are allocated, consecutively in slot order: traversal
    /// finds a child by counting the internal slots below it).
    fn build_node(&mut self, task: Task) -> impl Iterator<Item = Task> + use<> {
        let n2 = &self.bvh2.nodes;
        self.depth = self.depth.max(task.level);
        let (children, len) = choose_children(self.bvh2, task.binary);
        // The size checks below read the children's children: overlap those misses.
        for &c in &children[..len] {
            prefetch_children(self.bvh2, c);
        }
        let slots = order_children(self.bvh2, task.binary, &children[..len]);
        let (p, e_bits, e) = quantisation_frame(n2[task.binary as usize].aabb());
        let mut node = CwBvhNode {
            p: p.into(),
            e: e_bits,
            child_base_idx: self.nodes.len() as u32,
            primitive_base_idx: self.primitive_order.len() as u32,
            ..Default::default()
        };
        let mut offset = 0u32;
        let mut internal = [Task {
            binary: 0,
            wide: 0,
            level: 0,
        }; 8];
        let mut internal_len = 0;
        for (slot, child) in slots.iter().enumerate() {
            let Some(c) = *child else { continue };
            let caabb = n2[c as usize].aabb();
            let lo = quantise(caabb.min, p, e, f64::floor);
            let hi = quantise(caabb.max, p, e, f64::ceil);
            node.child_min_x[slot] = lo[0];
            node.child_min_y[slot] = lo[1];
            node.child_min_z[slot] = lo[2];
            node.child_max_x[slot] = hi[0];
            node.child_max_y[slot] = hi[1];
            node.child_max_z[slot] = hi[2];
            if is_small(self.bvh2, c) {
                let before = self.primitive_order.len() as u32;
                gather_primitives(self.bvh2, c, &mut self.primitive_order);
                let count = self.primitive_order.len() as u32 - before;
                // low 5 bits: offset from primitive_base_idx; high 3: count in unary
                node.child_meta[slot] = (offset | (((1 << count) - 1) << 5)) as u8;
                offset += count;
            } else {
                node.imask |= 1 << slot;
                node.child_meta[slot] = (24 + slot as u8) | 0b0010_0000;
                internal[internal_len] = Task {
                    binary: c,
                    wide: self.nodes.len() as u32,
                    level: task.level + 1,
                };
                internal_len += 1;
                self.nodes.push(CwBvhNode::default());
            }
        }
        self.nodes[task.wide as usize] = node;
        internal.into_iter().take(internal_len)
    }
}

/// Whether binary node `b` holds at most `MAX_LEAF` = 3 primitives, reading as few nodes as
/// possible (PLOC leaves hold one primitive, so two internal children mean at least four).
fn is_small(bvh2: &Bvh2, b: u32) -> bool {
    let n2 = &bvh2.nodes;
    let node = &n2[b as usize];
    if node.is_leaf() {
        return node.prim_count <= MAX_LEAF;
    }
    let (l, r) = (
        &n2[node.first_index as usize],
        &n2[node.first_index as usize + 1],
    );
    match (l.is_leaf(), r.is_leaf()) {
        (true, true) => l.prim_count + r.prim_count <= MAX_LEAF,
        (false, false) => false,
        (true, false) | (false, true) => {
            let (leaf, inner) = if l.is_leaf() { (l, r) } else { (r, l) };
            let (a, b) = (
                &n2[inner.first_index as usize],
                &n2[inner.first_index as usize + 1],
            );
            a.is_leaf() && b.is_leaf() && leaf.prim_count + a.prim_count + b.prim_count <= MAX_LEAF
        }
    }
}

/// Starts loading the children of binary node `b` (they are adjacent).
fn prefetch_children(bvh2: &Bvh2, b: u32) {
    let node = &bvh2.nodes[b as usize];
    if !node.is_leaf()
        && let Some(pair) = bvh2
            .nodes
            .get(node.first_index as usize..node.first_index as usize + 2)
    {
        #[cfg(target_arch = "x86_64")]
        // SAFETY: prefetching never faults; the pointers are inside `pair`.
        unsafe {
            use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
            _mm_prefetch::<_MM_HINT_T0>(pair.as_ptr() as *const i8);
            _mm_prefetch::<_MM_HINT_T0>((pair.as_ptr() as *const i8).add(64));
        }
        #[cfg(not(target_arch = "x86_64"))]
        let _ = pair;
    }
}

/// Up to eight binary nodes that become the children of the wide node made from `b`.
fn choose_children(bvh2: &Bvh2, b: u32) -> ([u32; 8], usize) {
    let n2 = &bvh2.nodes;
    let node = &n2[b as usize];
    let mut children = [0u32; 8];
    if node.is_leaf() || is_small(bvh2, b) {
        children[0] = b; // a small root: one leaf child
        return (children, 1);
    }
    children[0] = node.first_index;
    children[1] = node.first_index + 1;
    // Half areas of the children that can be opened (−∞ for leaves), kept beside them.
    let openable = |c: u32| {
        let n = &n2[c as usize];
        if n.is_leaf() {
            f32::NEG_INFINITY
        } else {
            n.aabb().half_area()
        }
    };
    let mut area = [f32::NEG_INFINITY; 8];
    area[0] = openable(children[0]);
    area[1] = openable(children[1]);
    let mut len = 2;
    while len < 8 {
        let mut open = None;
        let mut largest = f32::NEG_INFINITY;
        for (i, &a) in area[..len].iter().enumerate() {
            if a > largest {
                largest = a;
                open = Some(i);
            }
        }
        let Some(i) = open else { break };
        let first = n2[children[i] as usize].first_index;
        children[i] = first;
        children[len] = first + 1;
        area[i] = openable(first);
        area[len] = openable(first + 1);
        len += 1;
    }
    (children, len)
}

/// Assigns children to the 8 slots so that traversal meets them front to back: slot s is
/// visited first by rays whose direction signs are those of corner s (bit 2: x negative,
/// bit 1: y, bit 0: z), so it should hold the child nearest that corner. Greedy: the
/// cheapest (child, slot) pair by (corner direction · child centre offset) first.
fn order_children(bvh2: &Bvh2, b: u32, children: &[u32]) -> [Option<u32>; 8] {
    let n2 = &bvh2.nodes;
    let center = n2[b as usize].aabb().center();
    // cost[8c + s]; taken pairs and the rows and columns they use are set to +∞.
    let mut cost = [f32::INFINITY; 64];
    for (c, &child) in children.iter().enumerate() {
        let v = n2[child as usize].aabb().center() - center;
        for (s, cost) in cost[8 * c..8 * c + 8].iter_mut().enumerate() {
            let d = Vec3A::new(
                if s & 4 != 0 { -1.0 } else { 1.0 },
                if s & 2 != 0 { -1.0 } else { 1.0 },
                if s & 1 != 0 { -1.0 } else { 1.0 },
            );
            *cost = d.dot(v);
        }
    }
    let mut slots = [None; 8];
    for _ in 0..children.len() {
        // The cheapest free pair (the first in (child, slot) order among equals): a
        // minimum that vectorises, then its first position.
        let min = cost.iter().fold(f32::INFINITY, |m, &k| m.min(k));
        let i = cost.iter().position(|&k| k == min).unwrap_or(0);
        let (c, s) = (i / 8, i % 8);
        slots[s] = Some(children[c]);
        cost[8 * c..8 * c + 8].fill(f32::INFINITY);
        for row in cost.chunks_exact_mut(8) {
            row[s] = f32::INFINITY;
        }
    }
    slots
}

/// The node's quantisation frame: origin p = box min, and per axis the smallest power of two
/// e with 255·e ≥ extent (checked in f64, exact), as (p, exponent bytes, e).
fn quantisation_frame(aabb: &Aabb) -> (Vec3A, [u8; 3], [f64; 3]) {
    let p = aabb.min;
    let mut bytes = [0u8; 3];
    let mut e = [0.0f64; 3];
    for k in 0..3 {
        let extent = aabb.max[k] as f64 - p[k] as f64;
        // The byte is a biased f32 exponent: 1 (2⁻¹²⁶) to 254 (2¹²⁷).
        let r = extent / 255.0;
        let mut exponent = if r > 0.0 {
            ((r.to_bits() >> 52) & 0x7ff) as i32 - 1023
        } else {
            -126
        };
        exponent = exponent.clamp(-126, 127);
        // 2^x exactly, from its bits (x is within f64's normal range).
        let pow2 = |x: i32| f64::from_bits(((x + 1023) as u64) << 52);
        while exponent < 127 && 255.0 * pow2(exponent) < extent {
            exponent += 1;
        }
        bytes[k] = (exponent + 127) as u8;
        e[k] = pow2(exponent);
    }
    (p, bytes, e)
}

/// (v − p)/e per axis, rounded by `round` (floor for minima, ceil for maxima), in [0, 255].
fn quantise(v: Vec3A, p: Vec3A, e: [f64; 3], round: fn(f64) -> f64) -> [u8; 3] {
    [0, 1, 2].map(|k| round((v[k] as f64 - p[k] as f64) / e[k]).clamp(0.0, 255.0) as u8)
}

/// Appends the input primitives below binary node `b` (a subtree of at most `MAX_LEAF`
/// one-primitive leaves, as PLOC builds them).
fn gather_primitives(bvh2: &Bvh2, b: u32, out: &mut Vec<u32>) {
    let mut stack = [0u32; 2 * MAX_LEAF as usize];
    stack[0] = b;
    let mut len = 1;
    while len > 0 {
        len -= 1;
        let n = &bvh2.nodes[stack[len] as usize];
        if n.is_leaf() {
            let first = n.first_index as usize;
            out.extend_from_slice(&bvh2.primitive_indices[first..first + n.prim_count as usize]);
        } else {
            stack[len] = n.first_index + 1;
            stack[len + 1] = n.first_index;
            len += 2;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use obvhs::{BvhBuildParams, ploc::PlocBuilder};

    /// Random boxes of varied sizes, some degenerate (flat) and some repeated.
    fn boxes(n: usize, seed: u64) -> Vec<Aabb> {
        let mut s = seed;
        let mut next = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 40) as f32 / (1u64 << 24) as f32
        };
        (0..n)
            .map(|i| {
                let c = Vec3A::new(next(), next(), next()) * 1e3 - 300.0;
                let mut h = Vec3A::new(next(), next(), next()) * (0.1 + 20.0 * next());
                if i % 5 == 0 {
                    h.y = 0.0;
                }
                Aabb::new(c - h, c + h)
            })
            .collect()
    }

    /// Walks the wide tree checking the layout traversal relies on; returns how often each
    /// primitive was reached.
    fn check(wide: &WideBvh, aabbs: &[Aabb]) -> Vec<u32> {
        let mut seen = vec![0u32; aabbs.len()];
        let mut stack = vec![(0usize, 1usize)];
        let mut max_level = 0;
        while let Some((w, level)) = stack.pop() {
            max_level = max_level.max(level);
            let node = &wide.nodes[w];
            let e = node.e.map(|b| f64::powi(2.0, b as i32 - 127));
            let mut offset_end = 0;
            for slot in 0..8 {
                let meta = node.child_meta[slot];
                if meta == 0 {
                    continue;
                }
                // The dequantised child box, exactly.
                let lo = [
                    node.child_min_x[slot],
                    node.child_min_y[slot],
                    node.child_min_z[slot],
                ];
                let hi = [
                    node.child_max_x[slot],
                    node.child_max_y[slot],
                    node.child_max_z[slot],
                ];
                let corner = |q: [u8; 3], k: usize| node.p[k] as f64 + q[k] as f64 * e[k];
                let contains = |b: &Aabb| {
                    (0..3).all(|k| {
                        corner(lo, k) <= b.min[k] as f64 && b.max[k] as f64 <= corner(hi, k)
                    })
                };
                if node.imask & (1 << slot) != 0 {
                    assert_eq!(meta, (24 + slot as u8) | 0b0010_0000);
                    let child = node.child_node_index(slot) as usize;
                    assert!(child > w && child < wide.nodes.len());
                    // The child's own frame lies inside the box given for it here.
                    let cb = wide.nodes[child].aabb();
                    assert!(contains(&Aabb::new(cb.min, cb.min)));
                    stack.push((child, level + 1));
                } else {
                    let (first, count) = node.child_primitives(slot);
                    assert!((1..=MAX_LEAF).contains(&count));
                    offset_end = offset_end.max(first - node.primitive_base_idx + count);
                    for i in first..first + count {
                        let prim = wide.primitive_order[i as usize] as usize;
                        seen[prim] += 1;
                        assert!(
                            contains(&aabbs[prim]),
                            "primitive {prim} outside its leaf box"
                        );
                    }
                }
            }
            assert!(offset_end <= 24);
        }
        assert_eq!(max_level, wide.depth);
        seen
    }

    #[test]
    fn collapse_keeps_every_primitive_once_inside_exact_boxes() {
        for (n, seed) in [
            (1usize, 1u64),
            (2, 2),
            (3, 3),
            (4, 4),
            (9, 5),
            (5000, 6),
            (100_000, 7),
        ] {
            let aabbs = boxes(n, seed);
            let params = BvhBuildParams::fast_build();
            let bvh2 = PlocBuilder::with_capacity(n).build(
                params.ploc_search_distance,
                &aabbs,
                (0..n as u32).collect(),
                params.sort_precision,
                params.search_depth_threshold,
            );
            let wide = collapse(&bvh2);
            assert_eq!(wide.primitive_order.len(), n);
            let seen = check(&wide, &aabbs);
            assert!(
                seen.iter().all(|&c| c == 1),
                "n = {n}: a primitive is missing or repeated"
            );
            if n >= 5000 {
                // A well-filled tree: most nodes have several children.
                let children: usize = wide
                    .nodes
                    .iter()
                    .map(|nd| nd.child_meta.iter().filter(|&&m| m != 0).count())
                    .sum();
                assert!(children as f64 / wide.nodes.len() as f64 > 5.0);
            }
        }
    }
}
