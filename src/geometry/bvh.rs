//! All triangles of a scene in one 8-wide BVH: obvhs builds a binary BVH (PLOC +
//! reinsertion, in parallel), `cwbvh.rs` collapses it into the compressed layout of Ylitie,
//! Karras & Laine ("Efficient Incoherent Ray Traversal on GPUs Through Compressed Wide
//! BVHs", HPG 2017), and each node is then decoded into the f32 boxes traversal reads
//! (`wide_node.rs`).
//!
//! The traversal is mltbench's own, so that it can be conservative: obvhs's node test
//! drops boxes closer than t = 1e-4 and has no rounding slack, which loses hits near ray
//! origins and lets rays slip past box faces. Here the box test allows for its own rounding
//! (`WideNode::hitmask`) and boxes are tested a little beyond the segment's end
//! (`hit_pad`, for the triangle test's rounding), so a triangle the triangle test would
//! report is never culled by a box; the triangle test is watertight (`triangle.rs`).
//! Triangle data are stored in the BVH's leaf order: a leaf's triangles are contiguous and
//! need no index indirection.
//!
//! Measured on the development machine (2-core AMD EPYC, AVX2): obvhs's CWBVH traversal ran
//! 1.5–2.5× faster than its binary BVH traversal with the same triangle test, so only the
//! wide tree is kept.

use glam::{UVec2, Vec2, Vec3, Vec3A, uvec2};
use obvhs::{
    BvhBuildParams,
    aabb::Aabb,
    bvh2::reinsertion::ReinsertionOptimizer,
    ploc::{PlocBuilder, PlocSearchDistance},
};
use rayon::prelude::*;

mod stream;

pub use stream::IN_FLIGHT;

use super::cwbvh;
use super::flat::{FLAT_LIMIT, FlatTriangles, LANE_LEAVES_LIMIT};
use super::packet::{PACKET_LIMIT, PacketTriangles};
use super::triangle::{TriangleHit, TriangleRay, TriangleRecord};
use super::wide_node::WideNode;

/// Binary BVH settings for `n` triangles: obvhs's `fast_build` preset (PLOC with a short
/// search radius and a little reinsertion), with the shortest radius (1, obvhs's fast path)
/// above `SHORT_SEARCH_FROM` triangles. Measured on the development machine: on the 1M
/// displaced sphere radius 1 builds in 290 ms instead of 475 ms and traverses 4% (incoherent)
/// to 20% (coherent) faster after the 8-wide collapse; on the Cornell box + 100k sphere it
/// traverses 5% slower (incoherent), for a build that takes 50 ms either way. `medium_build`
/// was slower to build and no faster to traverse after the collapse.
pub fn build_params(n: usize) -> BvhBuildParams {
    let mut params = BvhBuildParams::fast_build();
    if n >= SHORT_SEARCH_FROM {
        params.ploc_search_distance = PlocSearchDistance::Minimum;
    }
    params
}

/// Triangle count from which PLOC searches only the immediate neighbours (`build_params`).
const SHORT_SEARCH_FROM: usize = 400_000;

/// Depth up to which traversal uses a fixed stack on the machine stack.
const FIXED_STACK: usize = 64;

/// A ray prepared for traversal: unit direction, reciprocals, octant, triangle constants.
#[derive(Clone, Copy, Debug)]
pub struct TraversalRay {
    pub o: Vec3A,
    pub d: Vec3A,
    pub inv_d: Vec3A,
    /// Rows of `WideNode::planes` holding the near and far planes along x, y, z.
    near: [usize; 3],
    far: [usize; 3],
    /// Child-order key of the ray's octant, as obvhs's builder expects it.
    oct_inv4: u32,
    pub tri: TriangleRay,
}

impl TraversalRay {
    /// `d` must be finite and non-zero (`Geometry` scales it so that its largest component
    /// is in [1, 2)).
    #[inline(always)]
    pub fn new(o: Vec3, d: Vec3) -> Self {
        // A zero component gets an infinite reciprocal (1/±0 = ±∞): the exact slab of a
        // ray parallel to the planes (`WideNode::hitmask` reads 0·∞ = NaN, a ray starting on
        // such a plane, as no constraint). Arithmetic instead of branches (directions are
        // random): a negative component swaps the axis' near and far planes and clears its
        // octant bit; signs from the sign bits, so that −0 goes with its reciprocal −∞.
        let d3 = Vec3A::from(d);
        let neg_bits = d3.is_negative_bitmask();
        let neg = [0, 1, 2].map(|k| ((neg_bits >> k) & 1) as usize);
        let near = [0, 1, 2].map(|k| 2 * k + neg[k]);
        let far = [0, 1, 2].map(|k| 2 * k + 1 - neg[k]);
        let oct_inv4 = ((1 - neg[0] as u32) * 0x0404_0404)
            | ((1 - neg[1] as u32) * 0x0202_0202)
            | ((1 - neg[2] as u32) * 0x0101_0101);
        TraversalRay {
            o: o.into(),
            d: d3,
            inv_d: d3.recip(),
            near,
            far,
            oct_inv4,
            tri: TriangleRay::new(o, d),
        }
    }

    /// The rows of `WideNode::planes` with the near and far plane along each axis.
    #[inline(always)]
    pub fn plane_rows(&self) -> ([usize; 3], [usize; 3]) {
        (self.near, self.far)
    }

    /// The ray's octant as the child order expects it (bits 2, 1, 0 set for x, y, z ≥ 0).
    #[inline(always)]
    pub fn octant(&self) -> u32 {
        self.oct_inv4 & 0xff
    }
}

/// Where `TriangleBvh::build` reads its triangles from: `triangle_count()` triangles, each with its
/// vertices, identity and optional vertex attributes. The attributes are stored in leaf
/// order too, so that the closest hit reads them from one place instead of chasing mesh
/// indices.
pub trait TriangleSource: Sync {
    fn triangle_count(&self) -> usize;
    fn vertices(&self, i: usize) -> [Vec3; 3];
    /// (shape, primitive).
    fn ids(&self, i: usize) -> [u32; 2];
    /// Whether any triangle has vertex normals (if none has, none are stored).
    fn has_normals(&self) -> bool;
    fn normals(&self, i: usize) -> Option<[Vec3; 3]>;
    fn has_uvs(&self) -> bool;
    fn uvs(&self, i: usize) -> Option<[Vec2; 3]>;
}

/// The BVH and the triangles in its leaf order.
pub struct TriangleBvh {
    nodes: Vec<WideNode>,
    records: Vec<TriangleRecord>,
    /// Vertex normals per record (zero when the mesh has none), if any mesh has them.
    normals: Option<Vec<[Vec3; 3]>>,
    /// Vertex uvs per record (NaN when the mesh has none), if any mesh has them.
    uvs: Option<Vec<[Vec2; 3]>>,
    depth: usize,
    bounds: (Vec3, Vec3),
    /// The records laid out sixteen to a chunk (`flat.rs`). Up to `FLAT_LIMIT` triangles
    /// the queries test them all instead of walking a tree (`nodes` is then empty);
    /// otherwise the tree's traversal tests each node's hit leaf triangles in these lanes
    /// (empty beyond `LANE_LEAVES_LIMIT` triangles: one by one there).
    lanes: FlatTriangles,
    /// The same records for sixteen rays at a time (`packet.rs`): on flat scenes and trees
    /// of at most `PACKET_LIMIT` triangles.
    packet: PacketTriangles,
}

impl TriangleBvh {
    /// Builds the BVH: triangle boxes, PLOC and reinsertion (obvhs), then the 8-wide
    /// collapse (`cwbvh.rs`) and the triangle data in leaf order; the independent steps run
    /// on rayon's threads.
    pub fn build(source: &impl TriangleSource) -> TriangleBvh {
        Self::build_with_flat_limit(source, FLAT_LIMIT)
    }

    /// `build`, answering queries without the tree up to `flat_limit` triangles instead of
    /// `FLAT_LIMIT` (to measure and test both ways on the same triangles).
    pub fn build_with_flat_limit(source: &impl TriangleSource, flat_limit: usize) -> TriangleBvh {
        let n = source.triangle_count();
        if n == 0 {
            return TriangleBvh::default();
        }
        let params = build_params(n);
        let aabbs: Vec<Aabb> = (0..n)
            .into_par_iter()
            .map(|i| {
                let [a, b, c] = source.vertices(i).map(Vec3A::from);
                Aabb::new(a.min(b).min(c), a.max(b).max(c))
            })
            .collect();
        let mut bvh2 = PlocBuilder::with_capacity(n).build(
            params.ploc_search_distance,
            &aabbs,
            (0..n as u32).collect(),
            params.sort_precision,
            params.search_depth_threshold,
        );
        drop(aabbs);
        ReinsertionOptimizer::default().run(&mut bvh2, params.reinsertion_batch_ratio, None);
        let root = *bvh2.nodes[0].aabb();
        let wide = cwbvh::collapse(&bvh2);
        drop(bvh2);
        let order = &wide.primitive_order;
        let records = collect_large(order.par_iter().map(|&i| {
            let [shape, primitive] = source.ids(i as usize);
            TriangleRecord::new(source.vertices(i as usize), shape, primitive)
        }));
        // Read once per closest hit, but prefetched at every candidate hit: a prefetch that
        // misses the TLB stalls like a load, so these get huge pages too.
        let normals = source.has_normals().then(|| {
            collect_large(
                order
                    .par_iter()
                    .map(|&i| source.normals(i as usize).unwrap_or([Vec3::ZERO; 3])),
            )
        });
        let uvs = source.has_uvs().then(|| {
            collect_large(
                order
                    .par_iter()
                    .map(|&i| source.uvs(i as usize).unwrap_or([Vec2::NAN; 3])),
            )
        });
        // A flat scene keeps no nodes: `is_flat` is the emptiness test the tree's queries make
        // anyway.
        let nodes = if records.len() <= flat_limit {
            Vec::new()
        } else {
            collect_large(wide.nodes.par_iter().map(WideNode::decode))
        };
        // Sixteen-ray queries test every triangle in lanes on a flat scene, and on a small
        // tree when enough lanes are active (`Geometry::packet_pays`).
        let packet = if nodes.is_empty() || records.len() <= PACKET_LIMIT {
            PacketTriangles::new(&records)
        } else {
            PacketTriangles::default()
        };
        TriangleBvh {
            nodes,
            lanes: if records.len() <= LANE_LEAVES_LIMIT {
                FlatTriangles::new(&records)
            } else {
                FlatTriangles::default()
            },
            packet,
            records,
            normals,
            uvs,
            depth: wide.depth,
            bounds: (root.min.into(), root.max.into()),
        }
    }

    /// The box around all triangles (min, max); empty (+∞, −∞) without triangles.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        self.bounds
    }

    pub fn record(&self, index: u32) -> &TriangleRecord {
        &self.records[index as usize]
    }

    /// All records, in the order the queries number them.
    pub fn records(&self) -> &[TriangleRecord] {
        &self.records
    }

    /// The records' coordinates, twelve per record (`TriangleRecord::rows`), for gathers.
    pub fn record_coordinates(&self) -> &[f32] {
        const _: () = assert!(std::mem::size_of::<TriangleRecord>() == 12 * 4);
        // SAFETY: a record is exactly its twelve f32s (repr(C), no padding: asserted above).
        unsafe { std::slice::from_raw_parts(self.records.as_ptr().cast(), 12 * self.records.len()) }
    }

    /// The vertex normals' coordinates, nine per record (n0.x, n0.y, …, n2.z; zero where
    /// the mesh has none), for gathers; None when no mesh has normals.
    pub fn normal_coordinates(&self) -> Option<&[f32]> {
        const _: () = assert!(std::mem::size_of::<[Vec3; 3]>() == 9 * 4);
        let n = self.normals.as_ref()?;
        // SAFETY: `[Vec3; 3]` is nine f32s (glam's Vec3 is repr(C) x, y, z: asserted above).
        Some(unsafe { std::slice::from_raw_parts(n.as_ptr().cast(), 9 * n.len()) })
    }

    /// The records laid out for sixteen rays at a time; empty unless `is_flat`.
    pub fn packet(&self) -> &PacketTriangles {
        &self.packet
    }

    /// Vertex normals of record `index`, if its mesh has them.
    pub fn normals(&self, index: u32) -> Option<&[Vec3; 3]> {
        let n = &self.normals.as_ref()?[index as usize];
        (n[0] != Vec3::ZERO || n[1] != Vec3::ZERO || n[2] != Vec3::ZERO).then_some(n)
    }

    /// Vertex uvs of record `index`, if its mesh has them.
    pub fn uvs(&self, index: u32) -> Option<&[Vec2; 3]> {
        let uv = &self.uvs.as_ref()?[index as usize];
        (!uv[0].is_nan()).then_some(uv)
    }

    /// The tree's nodes, root first; empty for a scene answered without the tree.
    pub fn wide_nodes(&self) -> &[WideNode] {
        &self.nodes
    }

    /// Number of wide nodes; 0 for a scene answered without the tree (`is_flat`).
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// True when the queries are answered without the tree (`flat.rs`): at most
    /// `FLAT_LIMIT` triangles.
    #[inline(always)]
    pub fn is_flat(&self) -> bool {
        self.nodes.is_empty()
    }

    /// Closest triangle with 0 < t < t_max: (record index, its hit data).
    #[inline(always)]
    pub fn closest(&self, ray: &TraversalRay, t_max: f32) -> Option<(u32, TriangleHit)> {
        if self.is_flat() {
            self.closest_in::<true>(ray, t_max)
        } else {
            self.closest_in::<false>(ray, t_max)
        }
    }

    /// True when some triangle lies at 0 < t < t_max.
    #[inline(always)]
    pub fn any(&self, ray: &TraversalRay, t_max: f32) -> bool {
        if self.is_flat() {
            self.any_in::<true>(ray, t_max)
        } else {
            self.any_in::<false>(ray, t_max)
        }
    }

    /// `closest` for a BVH whose `is_flat()` is `FLAT`, for callers that choose once and keep
    /// the flat test's code out of the function that traverses the tree (`Geometry`).
    #[inline(always)]
    pub fn closest_in<const FLAT: bool>(
        &self,
        ray: &TraversalRay,
        t_max: f32,
    ) -> Option<(u32, TriangleHit)> {
        debug_assert_eq!(
            FLAT,
            self.is_flat(),
            "closest_in for the other kind of scene"
        );
        if FLAT {
            return self.lanes.closest(&self.records, &ray.tri, t_max);
        }
        let mut visitor = Closest {
            bvh: self,
            ray,
            best: None,
        };
        self.traverse_from_root(ray, t_max, &mut visitor);
        visitor.best
    }

    /// `any` for a BVH whose `is_flat()` is `FLAT` (as `closest_in`).
    #[inline(always)]
    pub fn any_in<const FLAT: bool>(&self, ray: &TraversalRay, t_max: f32) -> bool {
        debug_assert_eq!(FLAT, self.is_flat(), "any_in for the other kind of scene");
        if FLAT {
            return self.lanes.any(&self.records, &ray.tri, t_max);
        }
        self.traverse_from_root(ray, t_max, &mut Any { bvh: self, ray })
    }

    /// `traverse` over the whole tree (false for an empty one), with its stack on the call
    /// frame when the tree is shallow enough for `FIXED_STACK` entries, on the heap otherwise.
    #[inline(always)]
    fn traverse_from_root(
        &self,
        ray: &TraversalRay,
        t_max: f32,
        visitor: &mut impl Visitor,
    ) -> bool {
        if self.nodes.is_empty() {
            return false;
        }
        let mut t_max = t_max;
        let pad = self.hit_pad(ray);
        if self.depth < FIXED_STACK {
            let mut stack = FixedStack::<FIXED_STACK>::new();
            self.traverse(ray, &mut t_max, pad, &mut stack, visitor)
        } else {
            let mut stack = Vec::with_capacity(self.depth + 1);
            self.traverse(ray, &mut t_max, pad, &mut stack, visitor)
        }
    }

    /// How far beyond a segment's end the boxes are tested (`traverse`), in units of t.
    ///
    /// The box test keeps every box the exact segment (0, t_max) meets (`WideNode`), but
    /// the triangle test reports computed distances: a triangle whose computed t lies
    /// just below t_max can have its exact t above it, and its box would be dropped
    /// (it happened: the Cornell box's floor and a block's bottom face one float apart).
    /// The triangle test's error grows with the coordinates it subtracts the origin from
    /// (`triangle::t_num_error_bound`: a few units of roundoff times the largest |v − o|,
    /// over |d| for t), so the boxes are tested up to 2⁻¹² of the largest distance from the
    /// origin to the scene's box beyond t_max: hundreds of times that error for any
    /// triangle that is not a sliver, and the price is a few boxes just past the hit.
    #[inline(always)]
    fn hit_pad(&self, ray: &TraversalRay) -> f32 {
        let (lo, hi) = (Vec3A::from(self.bounds.0), Vec3A::from(self.bounds.1));
        let reach = (lo - ray.o).abs().max((hi - ray.o).abs()).max_element();
        reach * (1.0 / 4096.0) / ray.d.abs().max_element()
    }

    /// Walks the BVH front to back (Ylitie et al. 2017, Algorithm 1: node groups hold the
    /// unvisited hit children of a node as a bit mask ordered by the ray octant; triangle
    /// groups the hit leaf triangles). `visit` tests a node's hit leaf triangles together,
    /// may lower `t_max`, and returns true to stop. Returns true when stopped.
    #[inline(always)]
    fn traverse<S: TraversalStack>(
        &self,
        ray: &TraversalRay,
        t_max: &mut f32,
        pad: f32,
        stack: &mut S,
        visitor: &mut impl Visitor,
    ) -> bool {
        let oct = ray.oct_inv4 & 0xff;
        // The root alone in a group: child base 0, one hit bit in slot 7 ^ oct's place.
        let mut node_group = uvec2(0, 0x8000_0000);
        let mut tri_group = UVec2::ZERO;
        loop {
            if node_group.y & 0xff00_0000 != 0 {
                let hits = node_group.y;
                let bit = 31 - hits.leading_zeros();
                node_group.y &= !(1u32 << bit);
                if node_group.y & 0xff00_0000 != 0 {
                    stack.push(node_group);
                }
                let slot = (bit - 24) ^ oct;
                let rank = (hits & !(u32::MAX << slot)).count_ones();
                let node = &self.nodes[(node_group.x + rank) as usize];
                let hitmask = node.hitmask(ray, *t_max + pad);
                node_group = uvec2(node.child_base, (hitmask & 0xff00_0000) | node.imask as u32);
                tri_group = uvec2(node.primitive_base, hitmask & 0x00ff_ffff);
                self.prefetch_children::<false>(node, hitmask, oct);
            } else {
                node_group = UVec2::ZERO;
            }
            if tri_group.y != 0 {
                let bits = std::mem::take(&mut tri_group.y);
                if visitor.visit(tri_group.x, bits, t_max) {
                    return true;
                }
            }
            if node_group.y & 0xff00_0000 == 0 {
                match stack.pop() {
                    Some(g) => node_group = g,
                    None => return false,
                }
            }
        }
    }
}

impl TriangleBvh {
    /// Starts loading the hit children of `node` (internal nodes, and leaf triangles when
    /// `TRIANGLES`) so that their cache misses overlap instead of following one another.
    /// A single traversal tests a node's triangles right after visiting it, too soon for a
    /// prefetch to help (measured: 2% slower with it on the 100k scene); the stream tests
    /// them a step later.
    #[inline(always)]
    fn prefetch_children<const TRIANGLES: bool>(&self, node: &WideNode, hitmask: u32, oct: u32) {
        let mut internal = hitmask >> 24;
        while internal != 0 {
            let slot = internal.trailing_zeros() ^ oct;
            internal &= internal - 1;
            let rank = (node.imask as u32 & !(u32::MAX << slot)).count_ones();
            if let Some(child) = self.nodes.get((node.child_base + rank) as usize) {
                // The node's four cache lines.
                let start = child as *const WideNode as usize;
                for line in 0..4 {
                    prefetch_address(start + 64 * line);
                }
            }
        }
        let tris = hitmask & 0x00ff_ffff;
        if TRIANGLES && tris != 0 {
            // The hit leaves' triangles are contiguous: their first and last lines.
            let first = node.primitive_base + tris.trailing_zeros();
            let last = node.primitive_base + 31 - tris.leading_zeros();
            if let Some(run) = self.records.get(first as usize..=last as usize) {
                // Every cache line of the run, not just its ends (leaves of several nodes'
                // worth of triangles span several lines); at most 8 lines.
                let start = run.as_ptr() as usize;
                let end = start + std::mem::size_of_val(run);
                let mut line = start & !63;
                while line < end.min(start + 8 * 64) {
                    prefetch_address(line);
                    line += 64;
                }
            }
        }
    }
}

/// What traversal does with the hit leaf triangles of a node.
trait Visitor {
    /// Tests records `base + b` for the bits b of `bits` (in that order, sixteen at a time:
    /// `FlatTriangles::hits_of`), may lower `t_max`; true stops the traversal.
    fn visit(&mut self, base: u32, bits: u32, t_max: &mut f32) -> bool;
}

/// Closest hit: keep the nearest, shrink the segment to it.
struct Closest<'a> {
    bvh: &'a TriangleBvh,
    ray: &'a TraversalRay,
    best: Option<(u32, TriangleHit)>,
}

impl Visitor for Closest<'_> {
    #[inline(always)]
    fn visit(&mut self, base: u32, bits: u32, t_max: &mut f32) -> bool {
        let (bvh, best) = (self.bvh, &mut self.best);
        // The node's lowest record could tie with the best hit so far: test up to just
        // beyond it (`tie_limit`), and let `replaces` keep the lower index.
        let first = base + bits.trailing_zeros();
        let mut limit = tie_limit(*best, first, *t_max);
        bvh.lanes.hits_of(
            &bvh.records,
            &self.ray.tri,
            base,
            bits,
            &mut limit,
            |id, h, limit| {
                if !replaces(*best, id as u32, h.t) {
                    return false;
                }
                *best = Some((id as u32, h));
                // The node's later records come after the new best: no tie can replace it.
                *limit = h.t;
                // The surface data of the closest hit will be read from these: start
                // fetching them while traversal goes on.
                if let Some(n) = &bvh.normals {
                    prefetch(&n[id]);
                }
                if let Some(uv) = &bvh.uvs {
                    prefetch(&uv[id]);
                }
                false
            },
        );
        if let Some((_, h)) = best {
            *t_max = h.t;
        }
        false
    }
}

/// The closest-hit rule of every triangle query: a hit replaces the best one so far when
/// it is nearer, or exactly as near with a lower record index. The flat and sixteen-ray
/// tests meet the records in index order and keep the first of equal t; the tree meets
/// them in traversal order, so it needs the index to keep the same one.
#[inline(always)]
pub(crate) fn replaces(best: Option<(u32, TriangleHit)>, id: u32, t: f32) -> bool {
    match best {
        None => true,
        Some((best_id, h)) => t < h.t || (t == h.t && id < best_id),
    }
}

/// The segment end to test records from index `first` on against: `t_max` (the best t, or
/// the ray's end before any hit), or two floats beyond the best t when `first` precedes the
/// best record, so that an exact tie passes the triangle test's t < t_max
/// (`triangle::hit_from`) and reaches `replaces`.
#[inline(always)]
pub(crate) fn tie_limit(best: Option<(u32, TriangleHit)>, first: u32, t_max: f32) -> f32 {
    match best {
        Some((best_id, h)) if first < best_id => h.t.next_up().next_up(),
        _ => t_max,
    }
}

/// Any hit: stop at the first.
struct Any<'a> {
    bvh: &'a TriangleBvh,
    ray: &'a TraversalRay,
}

impl Visitor for Any<'_> {
    #[inline(always)]
    fn visit(&mut self, base: u32, bits: u32, t_max: &mut f32) -> bool {
        let bvh = self.bvh;
        bvh.lanes
            .hits_of(&bvh.records, &self.ray.tri, base, bits, t_max, |_, _, _| {
                true
            })
    }
}

/// Plain triangles without vertex attributes.
pub struct TriangleList<'a> {
    pub vertices: &'a [[Vec3; 3]],
    pub ids: &'a [[u32; 2]],
}

impl TriangleSource for TriangleList<'_> {
    fn triangle_count(&self) -> usize {
        self.vertices.len()
    }
    fn vertices(&self, i: usize) -> [Vec3; 3] {
        self.vertices[i]
    }
    fn ids(&self, i: usize) -> [u32; 2] {
        self.ids[i]
    }
    fn has_normals(&self) -> bool {
        false
    }
    fn normals(&self, _: usize) -> Option<[Vec3; 3]> {
        None
    }
    fn has_uvs(&self) -> bool {
        false
    }
    fn uvs(&self, _: usize) -> Option<[Vec2; 3]> {
        None
    }
}

impl Default for TriangleBvh {
    fn default() -> Self {
        TriangleBvh {
            nodes: Vec::new(),
            records: Vec::new(),
            normals: None,
            uvs: None,
            depth: 0,
            bounds: (Vec3::INFINITY, Vec3::NEG_INFINITY),
            lanes: FlatTriangles::default(),
            packet: PacketTriangles::default(),
        }
    }
}

/// Collects a large array that traversal reads at random. On Linux, the allocation is
/// first marked for transparent huge pages (2 MiB): random reads over tens of megabytes
/// miss the TLB on nearly every access with 4 KiB pages (measured on the development
/// machine: 250 ns → 160 ns per dependent random read over 64 MiB).
fn collect_large<T: Send>(items: impl IndexedParallelIterator<Item = T>) -> Vec<T> {
    let mut v = Vec::with_capacity(items.len());
    advise_huge_pages(&v);
    v.par_extend(items);
    v
}

#[cfg(target_os = "linux")]
fn advise_huge_pages<T>(v: &Vec<T>) {
    let bytes = v.capacity() * std::mem::size_of::<T>();
    if bytes < 4 << 20 {
        return;
    }
    const PAGE: usize = 4096;
    let start = v.as_ptr() as usize;
    let aligned = (start + PAGE - 1) & !(PAGE - 1);
    let end = start + bytes;
    if end > aligned {
        // SAFETY: the range lies inside the vector's (still untouched) allocation;
        // MADV_HUGEPAGE only changes how the kernel backs those pages, never their contents.
        // Failure (e.g. THP disabled) just leaves ordinary pages.
        unsafe {
            libc::madvise(
                aligned as *mut libc::c_void,
                end - aligned,
                libc::MADV_HUGEPAGE,
            );
        }
    }
}

#[cfg(not(target_os = "linux"))]
fn advise_huge_pages<T>(_: &Vec<T>) {}

/// Hint the CPU to bring `*v`'s cache line in (no effect on results).
#[inline(always)]
fn prefetch<T>(v: &T) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: prefetching never faults and `v` is a valid reference.
    unsafe {
        use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
        _mm_prefetch::<_MM_HINT_T0>(v as *const T as *const i8);
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = v;
}

/// Hint the CPU to bring the cache line at `address` in (never faults, any address).
#[inline(always)]
fn prefetch_address(address: usize) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: a prefetch is only a hint: it never faults, whatever the address.
    unsafe {
        use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
        _mm_prefetch::<_MM_HINT_T0>(address as *const i8);
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = address;
}

trait TraversalStack {
    fn push(&mut self, v: UVec2);
    fn pop(&mut self) -> Option<UVec2>;
}

/// A stack in a fixed array (every level of the tree pushes at most one group, so a tree
/// shallower than N cannot overflow it); left uninitialised, no per-ray clearing.
struct FixedStack<const N: usize> {
    data: [std::mem::MaybeUninit<UVec2>; N],
    len: usize,
}

impl<const N: usize> FixedStack<N> {
    fn new() -> Self {
        FixedStack {
            data: [std::mem::MaybeUninit::uninit(); N],
            len: 0,
        }
    }
}

impl<const N: usize> TraversalStack for FixedStack<N> {
    #[inline(always)]
    fn push(&mut self, v: UVec2) {
        self.data[self.len].write(v);
        self.len += 1;
    }
    #[inline(always)]
    fn pop(&mut self) -> Option<UVec2> {
        if self.len == 0 {
            return None;
        }
        self.len -= 1;
        // SAFETY: entries below `len` were written by `push`.
        Some(unsafe { self.data[self.len].assume_init() })
    }
}

impl TraversalStack for Vec<UVec2> {
    #[inline(always)]
    fn push(&mut self, v: UVec2) {
        Vec::push(self, v);
    }
    #[inline(always)]
    fn pop(&mut self) -> Option<UVec2> {
        Vec::pop(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn axis_aligned_rays_with_signed_zeros_hit() {
        // −0 direction components must pick planes consistent with their reciprocal's sign.
        let tris = [
            [Vec3::ZERO, Vec3::X, Vec3::Y],
            [Vec3::Z, Vec3::Z + Vec3::X, Vec3::Z + Vec3::Y],
        ];
        let ids = [[0, 0], [0, 1]];
        let list = TriangleList {
            vertices: &tris,
            ids: &ids,
        };
        // Through the tree (the slab planes chosen by sign), and without it.
        for flat_limit in [0, usize::MAX] {
            let bvh = TriangleBvh::build_with_flat_limit(&list, flat_limit);
            assert_eq!(bvh.is_flat(), flat_limit > 0);
            for (o, d, expected) in [
                (Vec3::new(0.2, 0.2, 2.0), -Vec3::Z, 1),
                (Vec3::new(0.2, 0.2, 2.0), Vec3::new(0.0, -0.0, -1.0), 1),
                (Vec3::new(0.2, 0.2, -1.0), Vec3::new(-0.0, -0.0, 1.0), 0),
                (Vec3::new(0.2, 0.2, 0.5), Vec3::new(-0.0, 0.0, -1.0), 0),
            ] {
                let hit = bvh.closest(&TraversalRay::new(o, d), f32::INFINITY);
                assert_eq!(
                    hit.map(|(id, _)| bvh.record(id).ids()[1]),
                    Some(expected),
                    "{o} {d}, flat limit {flat_limit}"
                );
            }
        }
    }
}
