//! Cube corners the sampler left unevaluated: a mesh export's sampler
//! settles tiles once their bound excludes zero and writes `±∞` (the sign
//! kept) where a value it did not evaluate may lie within one voxel
//! diagonal of the surface (see `Consumer::MeshContour`). The contourer
//! reads distances only at the corners of cubes it cuts, and each such
//! corner lies within one voxel diagonal of the surface; there it
//! evaluates the `±∞` ones, each once per band of rows (four cubes of a
//! layer share a corner). A cube's samples are read here
//! ([`Contourer::cube`]).

use super::band_scratch::Stamped;
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
/// planes.
#[derive(Default)]
pub(super) struct CornerMemo {
    /// Distance bits by sample.
    slots: Stamped,
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
        self.slots.begin(2 * rows * nx);
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
        if let Some(bits) = self.slots.get(s) {
            return f32::from_bits(bits);
        }
        let v = exact(at);
        self.slots.set(s, v.to_bits());
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
        for (c, d) in (0..).zip(&mut dist) {
            if d.is_infinite() {
                *d = memo.value(*d, Self::corner_at([i, j, z], c), exact);
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
