//! A uniform lattice of box cells: which cell holds a point, and where that
//! cell's centre is. Shared by the spatial indexes that answer one query
//! per evaluated point (the union's child grid, the mesh's candidate grid),
//! where the lookup is on the hot path.
//!
//! Why not `(g.x as usize).min(dims − 1)`: a saturating float-to-`usize`
//! cast costs about a dozen instructions on x86-64 (NaN, negative and
//! ≥ 2⁶³ cases), three of them per query. Here the range test is done in
//! floating point first (`0 ≤ g < dims`, false for NaN), after which the
//! `u32` casts are exact and cheap.

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
}

impl CellLattice {
    /// `dims` must each be at least 1 and below 2³²; `cell` positive.
    pub fn new(min: DVec3, cell: DVec3, dims: [usize; 3]) -> CellLattice {
        debug_assert!(dims.iter().all(|&d| d >= 1 && d < u32::MAX as usize));
        CellLattice {
            min,
            cell,
            inv_cell: DVec3::ONE / cell,
            limit: DVec3::new(dims[0] as f64, dims[1] as f64, dims[2] as f64),
            dims,
        }
    }

    /// The cell holding `p` (`min + k·cell ≤ p < min + (k+1)·cell` up to
    /// rounding): its linear index (x fastest) and its coordinates. `None`
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
        // In range, so the casts neither saturate nor see NaN.
        let (x, y, z) = (
            g.x as u32 as usize,
            g.y as u32 as usize,
            g.z as u32 as usize,
        );
        Some((x + self.dims[0] * (y + self.dims[1] * z), [x, y, z]))
    }

    /// Centre of cell `c`.
    #[inline(always)]
    pub fn centre(&self, c: [usize; 3]) -> DVec3 {
        self.min + (DVec3::new(c[0] as f64, c[1] as f64, c[2] as f64) + 0.5) * self.cell
    }

    /// Cells along each axis.
    pub fn dims(&self) -> [usize; 3] {
        self.dims
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
                    assert_eq!(i, x + 4 * (y + 8 * z));
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
}
