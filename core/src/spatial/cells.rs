//! A uniform lattice of box cells: which cell holds a point, and where that
//! cell's centre is. Shared by the spatial indexes that answer one query
//! per evaluated point (the union's child grid, the mesh's candidate grid),
//! where the lookup is on the hot path.
//!
//! Why not `(g.x as usize).min(dims − 1)`: a saturating float-to-`usize`
//! cast costs about a dozen instructions on x86-64 (NaN, negative and
//! ≥ 2⁶³ cases), three of them per query. Here the range test is done in
//! floating point first (`0 ≤ g < dims`, false for NaN), after which the
//! casts cannot saturate, and are unchecked: a checked `as u32` still
//! clamps (`maxsd`, `minsd` on the path from the point to its cell's
//! list, twice a point on a mesh lattice).
//!
//! Why blocks: a cell's linear index puts the 4³ cells of a block side by
//! side (x fastest within the block, blocks x fastest), so the per-cell
//! records of a block share four cache lines and their lists are one
//! stretch of memory. Queries come in space-filling order (samplers sweep
//! small boxes, the bench and the baker go in Z-order), and with rows
//! (`x + nx·(y + ny·z)`) a walk around a point's neighbourhood touched a new
//! cache line for every step in y or z. See [`CellLattice::index`].

use glam::DVec3;

/// Cells of size `cell` from `min`, `dims` along each axis.
#[derive(Clone, Debug)]
pub struct CellLattice {
    min: DVec3,
    cell: DVec3,
    inv_cell: DVec3,
    /// `dims` as floats: the exclusive upper end of a valid coordinate.
    limit: DVec3,
    dims: [usize; 3],
    /// Blocks along x, and blocks in one xy layer.
    blocks_x: usize,
    blocks_xy: usize,
}

/// `x` rounded toward zero, for `x` in `[0, limit)` (the caller's range
/// test, false for NaN), where every `limit` is below 2³² (`new` asserts
/// it): one `cvttsd2si`, without the clamp a saturating cast adds.
#[inline(always)]
fn truncate(x: f64) -> usize {
    debug_assert!((0.0..u32::MAX as f64).contains(&x));
    // SAFETY: `x` is finite and its truncation fits in `u32` (above).
    (unsafe { x.to_int_unchecked::<u32>() }) as usize
}

/// Cells along each side of a block (a power of two).
const BLOCK: usize = 4;
const BLOCK_SHIFT: u32 = BLOCK.trailing_zeros();

impl CellLattice {
    /// `dims` must each be at least 1 and below 2³²; `cell` positive.
    pub fn new(min: DVec3, cell: DVec3, dims: [usize; 3]) -> CellLattice {
        // `truncate` relies on the upper limit (a cold check, once a grid).
        assert!(dims.iter().all(|&d| d >= 1 && d < u32::MAX as usize));
        CellLattice {
            min,
            cell,
            inv_cell: DVec3::ONE / cell,
            limit: DVec3::new(dims[0] as f64, dims[1] as f64, dims[2] as f64),
            dims,
            blocks_x: dims[0].div_ceil(BLOCK),
            blocks_xy: dims[0].div_ceil(BLOCK) * dims[1].div_ceil(BLOCK),
        }
    }

    /// Storage slots an array indexed by [`CellLattice::index`] needs: the
    /// cells of whole blocks, so at most `(d + 3)` per `d` along each axis.
    /// The slots of cells beyond `dims` are never located.
    pub fn slots(&self) -> usize {
        self.blocks_xy * self.dims[2].div_ceil(BLOCK) * BLOCK.pow(3)
    }

    /// The storage slot of cell `c`: its block's number (x fastest) times
    /// 64, plus its place in the block (x fastest). Unique, below `slots()`.
    #[inline(always)]
    pub fn index(&self, c: [usize; 3]) -> usize {
        let block = (c[0] >> BLOCK_SHIFT)
            + self.blocks_x * (c[1] >> BLOCK_SHIFT)
            + self.blocks_xy * (c[2] >> BLOCK_SHIFT);
        let m = BLOCK - 1;
        let local = (c[0] & m) | (c[1] & m) << BLOCK_SHIFT | (c[2] & m) << (2 * BLOCK_SHIFT);
        block << (3 * BLOCK_SHIFT) | local
    }

    /// The cell holding `p` (`min + k·cell ≤ p < min + (k+1)·cell` up to
    /// rounding): its slot ([`CellLattice::index`]) and its coordinates. `None`
    /// outside the lattice or for a non-finite `p`.
    #[inline(always)]
    pub fn locate(&self, p: DVec3) -> Option<(usize, [usize; 3])> {
        let g = (p - self.min) * self.inv_cell;
        if !(g.x >= 0.0
            && g.y >= 0.0
            && g.z >= 0.0
            && g.x < self.limit.x
            && g.y < self.limit.y
            && g.z < self.limit.z)
        {
            return None;
        }
        let (x, y, z) = (truncate(g.x), truncate(g.y), truncate(g.z));
        Some((self.index([x, y, z]), [x, y, z]))
    }

    /// Centre of cell `c` (within `dims`).
    #[inline(always)]
    pub fn centre(&self, c: [usize; 3]) -> DVec3 {
        debug_assert!(
            (0..3).all(|i| c[i] < self.dims[i]),
            "{c:?} beyond {:?}",
            self.dims
        );
        // Through `u32` (every cell is below 2³², `new` asserts it): one
        // conversion instruction each where a `usize`'s takes several, on
        // the path of every query. The same values.
        let f = |i: usize| f64::from(c[i] as u32);
        self.min + (DVec3::new(f(0), f(1), f(2)) + 0.5) * self.cell
    }

    /// Cells along each axis.
    pub fn dims(&self) -> [usize; 3] {
        self.dims
    }

    /// The lower corner of cell `[0, 0, 0]` (what the mesh-grid cache
    /// stores, and tests rebuild centres from).
    pub(crate) fn origin(&self) -> DVec3 {
        self.min
    }

    /// The size of a cell along each axis.
    pub(crate) fn cell(&self) -> DVec3 {
        self.cell
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn locate_agrees_with_floor_and_rejects_outside_points() {
        let l = CellLattice::new(
            DVec3::new(-1.0, 2.0, 0.5),
            DVec3::new(0.5, 0.25, 2.0),
            [4, 8, 3],
        );
        let mut rng = crate::xorshift::XorShift::new(11);
        for _ in 0..10_000 {
            let p = DVec3::new(
                -2.0 + 4.0 * rng.next_f64(),
                1.0 + 4.0 * rng.next_f64(),
                -1.0 + 9.0 * rng.next_f64(),
            );
            let g = ((p - DVec3::new(-1.0, 2.0, 0.5)) * (DVec3::ONE / DVec3::new(0.5, 0.25, 2.0)))
                .floor();
            let inside =
                g.x >= 0.0 && g.y >= 0.0 && g.z >= 0.0 && g.x < 4.0 && g.y < 8.0 && g.z < 3.0;
            match l.locate(p) {
                Some((i, [x, y, z])) => {
                    assert!(inside, "{p}");
                    assert_eq!([x as f64, y as f64, z as f64], [g.x, g.y, g.z]);
                    assert_eq!(i, l.index([x, y, z]));
                    let c = l.centre([x, y, z]);
                    assert!(
                        (p - c)
                            .abs()
                            .cmple(DVec3::new(0.25, 0.125, 1.0) + 1e-12)
                            .all()
                    );
                }
                None => assert!(!inside, "{p}"),
            }
        }
        assert_eq!(l.locate(DVec3::NAN), None);
        assert_eq!(l.locate(DVec3::new(f64::INFINITY, 2.5, 1.0)), None);
        // The upper faces belong to no cell.
        assert_eq!(l.locate(DVec3::new(1.0, 2.5, 1.0)), None);
    }

    #[test]
    fn slots_are_unique_blocked_and_within_bounds() {
        for dims in [[1, 1, 1], [4, 8, 3], [5, 9, 13], [16, 4, 4]] {
            let l = CellLattice::new(DVec3::ZERO, DVec3::ONE, dims);
            let mut seen = vec![false; l.slots()];
            for z in 0..dims[2] {
                for y in 0..dims[1] {
                    for x in 0..dims[0] {
                        let i = l.index([x, y, z]);
                        assert!(!seen[i], "{dims:?} {x} {y} {z}");
                        seen[i] = true;
                        // The 4³ cells of a block are 64 consecutive slots.
                        assert_eq!(i / 64, l.index([x & !3, y & !3, z & !3]) / 64);
                    }
                }
            }
            let padded: usize = dims.iter().map(|d| d.div_ceil(4) * 4).product();
            assert_eq!(l.slots(), padded);
        }
    }
}
