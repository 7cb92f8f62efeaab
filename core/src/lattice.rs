//! Unit cells of `GraphLattice`: edge lists in a cell centred at the origin.
//!
//! Coordinates are written for a unit cube `[-1/2, 1/2]³` and scaled by the
//! cell size. BCC, FCC, Cubic and Kelvin match pyvcad 2.3.4's `LatticeType`
//! (pyvcad 2.3.4's lattices); Octet is ours.

use glam::DVec3;

use crate::node::LatticeType;

/// The struts of one unit cell of `kind`, scaled to `cell` (full side lengths).
pub(crate) fn unit_cell_edges(kind: LatticeType, cell: DVec3) -> Vec<(DVec3, DVec3)> {
    let h = 0.5;
    let corners: Vec<DVec3> = (0..8)
        .map(|i| {
            DVec3::new(
                if i & 1 == 0 { -h } else { h },
                if i & 2 == 0 { -h } else { h },
                if i & 4 == 0 { -h } else { h },
            )
        })
        .collect();
    let face_centres: Vec<DVec3> = [
        DVec3::X,
        DVec3::NEG_X,
        DVec3::Y,
        DVec3::NEG_Y,
        DVec3::Z,
        DVec3::NEG_Z,
    ]
    .iter()
    .map(|v| *v * h)
    .collect();
    let mut edges = Vec::new();
    // Pairs of points at squared distance `d2` (within tolerance), each once.
    let pairs_at = |pts: &[DVec3], d2: f64, edges: &mut Vec<(DVec3, DVec3)>| {
        for i in 0..pts.len() {
            for j in i + 1..pts.len() {
                if ((pts[i] - pts[j]).length_squared() - d2).abs() < 1e-9 {
                    edges.push((pts[i], pts[j]));
                }
            }
        }
    };
    match kind {
        LatticeType::BodyCenteredCubic => pairs_at(&corners, 3.0, &mut edges),
        LatticeType::Cubic => pairs_at(&corners, 1.0, &mut edges),
        LatticeType::FaceCenteredCubic => pairs_at(&corners, 2.0, &mut edges),
        LatticeType::Octet => {
            pairs_at(&corners, 2.0, &mut edges);
            pairs_at(&face_centres, 0.5, &mut edges);
        }
        LatticeType::KelvinCell => {
            // Truncated octahedron: permutations of (0, ±1/4, ±1/2).
            let mut verts = Vec::new();
            for a in [-0.25, 0.25] {
                for b in [-0.5, 0.5] {
                    verts.push(DVec3::new(0.0, a, b));
                    verts.push(DVec3::new(0.0, b, a));
                    verts.push(DVec3::new(a, 0.0, b));
                    verts.push(DVec3::new(b, 0.0, a));
                    verts.push(DVec3::new(a, b, 0.0));
                    verts.push(DVec3::new(b, a, 0.0));
                }
            }
            pairs_at(&verts, 0.125, &mut edges);
        }
    }
    edges
        .into_iter()
        .map(|(a, b)| (a * cell, b * cell))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn edge_counts() {
        let c = DVec3::splat(2.0);
        assert_eq!(unit_cell_edges(LatticeType::BodyCenteredCubic, c).len(), 4);
        assert_eq!(unit_cell_edges(LatticeType::FaceCenteredCubic, c).len(), 12);
        assert_eq!(unit_cell_edges(LatticeType::Cubic, c).len(), 12);
        assert_eq!(unit_cell_edges(LatticeType::KelvinCell, c).len(), 36);
        assert_eq!(unit_cell_edges(LatticeType::Octet, c).len(), 24);
    }

    #[test]
    fn bcc_spans_the_cell() {
        let e = unit_cell_edges(LatticeType::BodyCenteredCubic, DVec3::new(5.0, 5.0, 5.0));
        for (a, b) in e {
            assert!(((a - b).length() - 75f64.sqrt()).abs() < 1e-9);
        }
    }
}
