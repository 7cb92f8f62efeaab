//! Cube corners the sampler left unevaluated: a mesh export's sampler
//! settles tiles once their bound excludes zero and writes `±∞` (the sign
//! kept) where a value it did not evaluate may lie within one voxel
//! diagonal of the surface (see `Consumer::MeshContour`). The contourer
//! reads distances only at the corners of cubes it cuts, and each such
//! corner lies within one voxel diagonal of the surface; there it
//! evaluates the `±∞` ones, each once per band of rows (four cubes of a
//! layer share a corner). A cube's samples are read here
//! ([`Contourer::cube`]).

use std::sync::Mutex;

use super::contour::{Contourer, Plane};
use super::interface::Cube;

/// The exact distance at a sample (by grid index), as the sampler
/// evaluates it.
pub type ExactAt<'a> = &'a (dyn Fn([usize; 3]) -> f32 + Sync);

/// The two planes of a cube layer, and what evaluates their unevaluated
/// samples.
#[derive(Clone, Copy)]
pub(super) struct Layer<'p> {
    pub lo: &'p Plane,
    pub hi: &'p Plane,
    pub exact: ExactAt<'p>,
}

/// Corner distances evaluated in one band of rows of a cube layer (or in a
/// whole layer): one slot per sample of the band's rows in the layer's two
/// planes, stamped with the band it was set in, so nothing is cleared
/// between bands.
#[derive(Default)]
pub(super) struct CornerMemo {
    /// `band << 32 | distance bits`.
    slot: Vec<u64>,
    band: u64,
    /// The band's lower plane, first row and rows, and the row length.
    z: usize,
    j0: usize,
    rows: usize,
    nx: usize,
}

impl CornerMemo {
    /// Start a band: rows `j0..j0 + rows` of planes `z` and `z + 1`
    /// (`nx` samples a row).
    pub fn begin(&mut self, z: usize, j0: usize, rows: usize, nx: usize) {
        let len = 2 * rows * nx;
        if self.slot.len() != len {
            self.slot = vec![0; len];
            self.band = 0;
        }
        self.band += 1;
        (self.z, self.j0, self.rows, self.nx) = (z, j0, rows, nx);
    }

    /// `d`, or the exact distance at `at` when `d` is unevaluated.
    #[inline]
    pub fn value(&mut self, d: f32, at: [usize; 3], exact: ExactAt) -> f32 {
        if d.is_finite() || d.is_nan() {
            return d;
        }
        let [i, j, k] = at;
        let (dj, dk) = (j.wrapping_sub(self.j0), k.wrapping_sub(self.z));
        if dj >= self.rows || dk > 1 || i >= self.nx {
            // (Outside the band: not kept.)
            return exact(at);
        }
        let s = (dk * self.rows + dj) * self.nx + i;
        let set = self.slot[s];
        if set >> 32 == self.band {
            return f32::from_bits(set as u32);
        }
        let v = exact(at);
        self.slot[s] = self.band << 32 | u64::from(v.to_bits());
        v
    }
}

impl Contourer {
    /// The cube with lowest corner `(i, j, z)`, from planes `z` and `z + 1`
    /// (corners the sampler left unevaluated are evaluated now, or taken
    /// from `memo`).
    pub(super) fn cube<'a>(
        &self,
        [i, j, z]: [usize; 3],
        layer: Layer<'a>,
        memo: &mut CornerMemo,
    ) -> Cube<'a> {
        let Layer { lo, hi, exact } = layer;
        let nx = self.grid.dims[0];
        let s = self.iface.stride();
        let idx: [usize; 8] = std::array::from_fn(|c| (j + (c >> 1 & 1)) * nx + i + (c & 1));
        let plane = |c: usize| if c & 4 == 0 { lo } else { hi };
        let planes = [&*lo.dist, &*hi.dist];
        let mut dist: [f32; 8] = std::array::from_fn(|c| planes[c >> 2][idx[c]]);
        if dist.iter().any(|d| d.is_infinite()) {
            for (c, d) in (0..).zip(&mut dist) {
                let at = Self::corner_at([i, j, z], c);
                *d = memo.value(*d, at, exact);
            }
        }
        Cube {
            base: [i, j, z],
            label: std::array::from_fn(|c| plane(c).label[idx[c]]),
            dist,
            // (One segment stores no values: nothing to slice.)
            value: if s == 0 {
                [&[]; 8]
            } else {
                std::array::from_fn(|c| &plane(c).value[idx[c] * s..(idx[c] + 1) * s])
            },
        }
    }

    /// Grid index (i, j, k) of corner `m` of the cube.
    pub(super) fn corner(cube: &Cube, m: u8) -> [usize; 3] {
        Self::corner_at(cube.base, m)
    }

    /// Corner `m` of the cube with lowest corner `base`.
    pub(super) fn corner_at([i, j, k]: [usize; 3], m: u8) -> [usize; 3] {
        [
            i + (m & 1) as usize,
            j + (m >> 1 & 1) as usize,
            k + (m >> 2 & 1) as usize,
        ]
    }
}

/// Band scratch not in use (edge slots, corner memos): a contouring task
/// borrows one ([`Pool::lend`]) and gives it back when done, so a plane
/// does not allocate and zero fresh ones.
pub(super) struct Pool<T: Default>(Mutex<Vec<T>>);

impl<T: Default> Default for Pool<T> {
    fn default() -> Self {
        Self(Mutex::new(Vec::new()))
    }
}

impl<T: Default> Pool<T> {
    /// One for a task (fresh when none is free), back in the pool when the
    /// loan is dropped.
    pub fn lend(&self) -> Loan<'_, T> {
        let item = self
            .0
            .lock()
            .ok()
            .and_then(|mut free| free.pop())
            .unwrap_or_default();
        Loan { item, pool: self }
    }
}

/// What a [`Pool`] lent.
pub(super) struct Loan<'a, T: Default> {
    item: T,
    pool: &'a Pool<T>,
}

impl<T: Default> std::ops::Deref for Loan<'_, T> {
    type Target = T;
    fn deref(&self) -> &T {
        &self.item
    }
}

impl<T: Default> std::ops::DerefMut for Loan<'_, T> {
    fn deref_mut(&mut self) -> &mut T {
        &mut self.item
    }
}

impl<T: Default> Drop for Loan<'_, T> {
    fn drop(&mut self) {
        // (A poisoned pool only means the next task allocates afresh.)
        if let Ok(mut free) = self.pool.0.lock() {
            free.push(std::mem::take(&mut self.item));
        }
    }
}
