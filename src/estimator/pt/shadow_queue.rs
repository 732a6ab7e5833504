//! Shadow rays of next-event estimation waiting to be cast sixteen at a time.
//!
//! In a round of the wavefront only the lanes whose light sample can contribute cast a
//! shadow ray (about nine of sixteen on the Cornell box), so casting them in the round
//! that made them would leave the packet test's lanes idle. Queued instead, they are cast
//! as soon as sixteen wait. Each entry carries what its sample adds for it: the radiance
//! if the ray is unoccluded, `throughput × black` if it is (what the scalar code adds when
//! the light is blocked: zero, or NaN for a non-finite throughput).
//!
//! Order: a sample's radiance is a sum, and floating-point sums depend on their order.
//! Entries are resolved first in, first out, and a sample's entries were queued in the
//! order its path made them, so they are added in that order. Whatever else adds to a
//! sample (emission found by the scalar code, a scattering event the lanes leave to it)
//! first resolves that sample's entries (`resolve`). So every sample receives exactly the
//! additions of the scalar path tracer, in its order.

use super::wavefront::QueuedSample;
use crate::geometry::Geometry;
use crate::geometry::packet::RayLanes;
use crate::math::Rgb;
use crate::math::lanes::{F32x16, LANES, Mask16, U32x16, V3};

/// Room for the entries of one round (16) besides fewer than a packet's worth (15) left
/// over from earlier rounds.
const CAPACITY: usize = 48;

/// The queued entries, one array per field (positions `0..len`, oldest first).
pub(super) struct ShadowQueue {
    /// Origin x, y, z, direction x, y, z and t_max of each ray.
    ray: [[f32; CAPACITY]; 7],
    /// What the sample adds if the ray is unoccluded (r, g, b).
    lit: [[f32; CAPACITY]; 3],
    /// What it adds if the ray is occluded.
    dark: [[f32; CAPACITY]; 3],
    sample: [u32; CAPACITY],
    len: usize,
}

impl Default for ShadowQueue {
    fn default() -> Self {
        ShadowQueue {
            ray: [[0.0; CAPACITY]; 7],
            lit: [[0.0; CAPACITY]; 3],
            dark: [[0.0; CAPACITY]; 3],
            sample: [0; CAPACITY],
            len: 0,
        }
    }
}

impl ShadowQueue {
    /// Queues the rays of the lanes of `m` (lane order), for samples `sample`.
    pub fn push(
        &mut self,
        m: Mask16,
        ray: &RayLanes,
        lit: &V3<F32x16>,
        dark: &V3<F32x16>,
        sample: U32x16,
    ) {
        debug_assert!(self.len + LANES <= CAPACITY, "cast before queueing more");
        let at = self.len;
        let fields = [
            (ray.o.x, 0),
            (ray.o.y, 1),
            (ray.o.z, 2),
            (ray.d.x, 3),
            (ray.d.y, 4),
            (ray.d.z, 5),
            (ray.t_max, 6),
        ];
        for (v, k) in fields {
            v.compress_store(m, &mut self.ray[k][at..]);
        }
        for (k, (l, d)) in [(lit.x, dark.x), (lit.y, dark.y), (lit.z, dark.z)]
            .into_iter()
            .enumerate()
        {
            l.compress_store(m, &mut self.lit[k][at..]);
            d.compress_store(m, &mut self.dark[k][at..]);
        }
        sample.compress_store(m, &mut self.sample[at..]);
        self.len += m.count() as usize;
    }

    /// Casts the oldest sixteen entries while there are that many.
    pub fn cast_full(&mut self, geometry: &Geometry, queue: &mut [QueuedSample]) {
        while self.len >= LANES {
            self.cast_first(LANES, geometry, queue);
        }
    }

    /// Casts every entry, oldest first.
    pub fn flush(&mut self, geometry: &Geometry, queue: &mut [QueuedSample]) {
        while self.len > 0 {
            self.cast_first(self.len.min(LANES), geometry, queue);
        }
    }

    /// Casts the entries of sample `sample` (before something else adds to it).
    pub fn resolve(&mut self, sample: u32, geometry: &Geometry, queue: &mut [QueuedSample]) {
        // Move the sample's entries to the front, keeping both groups' order, then cast.
        let mut order = [0usize; CAPACITY];
        let entries = 0..self.len;
        let theirs = entries.clone().filter(|&i| self.sample[i] == sample);
        let others = entries.filter(|&i| self.sample[i] != sample);
        let mut mine = 0;
        for (k, i) in theirs.chain(others).enumerate() {
            order[k] = i;
            mine += (self.sample[i] == sample) as usize;
        }
        if mine == 0 {
            return;
        }
        self.reorder(&order[..self.len]);
        while mine > 0 {
            let n = mine.min(LANES);
            self.cast_first(n, geometry, queue);
            mine -= n;
        }
    }

    /// Puts entry `order[i]` at position i.
    fn reorder(&mut self, order: &[usize]) {
        let gather = |a: &[f32; CAPACITY]| -> [f32; CAPACITY] {
            std::array::from_fn(|i| if i < order.len() { a[order[i]] } else { 0.0 })
        };
        for k in 0..7 {
            self.ray[k] = gather(&self.ray[k]);
        }
        for k in 0..3 {
            self.lit[k] = gather(&self.lit[k]);
            self.dark[k] = gather(&self.dark[k]);
        }
        let sample = self.sample;
        self.sample = std::array::from_fn(|i| if i < order.len() { sample[order[i]] } else { 0 });
    }

    /// Casts the first `n` (≤ 16) entries, adds their terms to their samples in order, and
    /// drops them.
    fn cast_first(&mut self, n: usize, geometry: &Geometry, queue: &mut [QueuedSample]) {
        let load = |a: &[f32; CAPACITY]| {
            F32x16::from_array(std::array::from_fn(|i| if i < n { a[i] } else { 0.0 }))
        };
        let [ox, oy, oz, dx, dy, dz, t_max] = self.ray.each_ref().map(load);
        let rays = RayLanes {
            o: V3::new(ox, oy, oz),
            d: V3::new(dx, dy, dz),
            t_max,
        };
        let blocked = geometry.occluded_lanes(&rays, Mask16::first(n));
        for i in 0..n {
            let term = if blocked.get(i) {
                &self.dark
            } else {
                &self.lit
            };
            let value = &mut queue[self.sample[i] as usize].value;
            *value += Rgb::new(term[0][i], term[1][i], term[2][i]);
        }
        // Drop them: the rest moves to the front.
        for a in self
            .ray
            .iter_mut()
            .chain(&mut self.lit)
            .chain(&mut self.dark)
        {
            a.copy_within(n..self.len, 0);
        }
        self.sample.copy_within(n..self.len, 0);
        self.len -= n;
    }

    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
}
