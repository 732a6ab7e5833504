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

/// Entries: a round queues at most 16 and leaves fewer than 16, so the queue holds at
/// most 31; the rest is room to cast from the front without moving the others each time.
const CAPACITY: usize = 256;

/// The queued entries, one array per field (positions `head..len`, oldest first).
pub(super) struct ShadowQueue {
    /// Origin x, y, z, direction x, y, z and t_max of each ray.
    ray: [[f32; CAPACITY]; 7],
    /// What the sample adds if the ray is unoccluded (r, g, b).
    lit: [[f32; CAPACITY]; 3],
    /// What it adds if the ray is occluded.
    dark: [[f32; CAPACITY]; 3],
    sample: [u32; CAPACITY],
    head: usize,
    len: usize,
}

impl Default for ShadowQueue {
    fn default() -> Self {
        ShadowQueue {
            ray: [[0.0; CAPACITY]; 7],
            lit: [[0.0; CAPACITY]; 3],
            dark: [[0.0; CAPACITY]; 3],
            sample: [0; CAPACITY],
            head: 0,
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
        if self.len + LANES > CAPACITY {
            self.compact();
        }
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

    /// Moves the entries to the front of the arrays.
    fn compact(&mut self) {
        let (head, len) = (self.head, self.len);
        for a in self
            .ray
            .iter_mut()
            .chain(&mut self.lit)
            .chain(&mut self.dark)
        {
            a.copy_within(head..len, 0);
        }
        self.sample.copy_within(head..len, 0);
        (self.head, self.len) = (0, len - head);
    }

    /// Casts the oldest sixteen entries while there are that many.
    pub fn cast_full(&mut self, geometry: &Geometry, queue: &mut [QueuedSample]) {
        while self.len - self.head >= LANES {
            self.cast_first(LANES, geometry, queue);
        }
    }

    /// Casts every entry, oldest first.
    pub fn flush(&mut self, geometry: &Geometry, queue: &mut [QueuedSample]) {
        while self.len > self.head {
            self.cast_first((self.len - self.head).min(LANES), geometry, queue);
        }
        (self.head, self.len) = (0, 0);
    }

    /// Casts the entries of sample `sample` (before something else adds to it).
    pub fn resolve(&mut self, sample: u32, geometry: &Geometry, queue: &mut [QueuedSample]) {
        if !self.sample[self.head..self.len].contains(&sample) {
            return;
        }
        // Move the sample's entries to the front, keeping both groups' order, then cast.
        self.compact();
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
        for a in self
            .ray
            .iter_mut()
            .chain(&mut self.lit)
            .chain(&mut self.dark)
        {
            permute_prefix(a, order);
        }
        permute_prefix(&mut self.sample, order);
    }

    /// Casts the first `n` (≤ 16) entries, adds their terms to their samples in order, and
    /// drops them.
    fn cast_first(&mut self, n: usize, geometry: &Geometry, queue: &mut [QueuedSample]) {
        let h = self.head;
        if h + LANES > CAPACITY {
            self.compact();
            return self.cast_first(n, geometry, queue);
        }
        let load = |a: &[f32; CAPACITY]| {
            let lanes: &[f32; LANES] = a[h..h + LANES].try_into().unwrap();
            F32x16::from_array(*lanes)
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

/// Puts `a[order[i]]` at position i, for i < order.len().
fn permute_prefix<T: Copy + Default>(a: &mut [T; CAPACITY], order: &[usize]) {
    // A round leaves at most 31 entries: a small copy does.
    const SMALL: usize = 32;
    if order.len() <= SMALL {
        let mut moved = [T::default(); SMALL];
        for (m, &o) in moved.iter_mut().zip(order) {
            *m = a[o];
        }
        a[..order.len()].copy_from_slice(&moved[..order.len()]);
    } else {
        let old = *a;
        for (x, &o) in a.iter_mut().zip(order) {
            *x = old[o];
        }
    }
}
