//! Marching cubes for one label: how the contour of a cube with only
//! inside and void samples crosses the cube's faces, as closed loops of
//! points on the cube's twelve edges, and how each loop is triangulated.
//!
//! A one-label grid has no interfaces, so it does not need the Kuhn split's
//! face diagonals that keep three and four labels consistent (see
//! [`super::contour`]): each face is cut by straight segments between the
//! points on its four edges, and the loops they form are triangulated
//! without inner points. That is about a third of the triangles of
//! marching tetrahedra on curved surfaces, with the same edge points.
//!
//! A face with two inside corners on one diagonal is ambiguous; it is
//! resolved by the face alone, so both cubes that share it cut it alike:
//! the inside corners are joined when they are the face's lowest and
//! highest corners (the ends of the Kuhn split's diagonal, so the topology
//! is the one marching tetrahedra gives on that face), and separated
//! otherwise.
//!
//! A loop of `k` points is fanned from a point that shares no cube face
//! with any point but its two neighbours in the loop: the fan's inner
//! edges then run through the cube, never along a face, where the cube
//! across could lay the same edge (four triangles on one edge). Where no
//! such point exists, the loop is fanned from a point at its centroid.

use std::sync::OnceLock;

use super::kuhn::{Pt, edge};

/// One loop of a cube case: its points in order, and the point to fan
/// from (`None`: an added centre point).
#[derive(Clone, Debug, Default)]
pub(super) struct Loop {
    pub points: Vec<Pt>,
    pub apex: Option<usize>,
}

/// Every case's loops, by the mask of inside corners (bit `c` for corner
/// `c`, x = 1, y = 2, z = 4).
pub(super) fn case(mask: u8) -> &'static [Loop] {
    static TABLE: OnceLock<Vec<Vec<Loop>>> = OnceLock::new();
    &TABLE.get_or_init(|| (0..=255u8).map(loops).collect())[mask as usize]
}

/// The corners of face (`axis`, `side`), counter-clockwise seen from
/// outside the cube, starting at its lowest corner.
fn face_corners(axis: usize, side: u8) -> [u8; 4] {
    let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
    let c0 = side << axis;
    let q = [c0, c0 | 1 << u, c0 | 1 << u | 1 << v, c0 | 1 << v];
    // Counter-clockwise about +axis; the low face looks along -axis.
    if side == 1 {
        q
    } else {
        [q[0], q[3], q[2], q[1]]
    }
}

/// The cut segments of face (`axis`, `side`) for the inside corners
/// `mask`, oriented as the contourer's tet faces are (from the edge
/// entering the inside, counter-clockwise, to the edge leaving it): none,
/// one, or two on an ambiguous face.
pub(super) fn face_segments(mask: u8, axis: usize, side: u8) -> impl Iterator<Item = (Pt, Pt)> {
    let q = face_corners(axis, side);
    let inside = q.map(|c| mask >> c & 1 == 1);
    // Edge k runs from q[k] to q[k + 1]; it enters the inside when q[k]
    // is out and q[k + 1] in.
    let enters = move |k: usize| !inside[k] && inside[(k + 1) % 4];
    let leaves = move |k: usize| inside[k] && !inside[(k + 1) % 4];
    let cut = move |k: usize| edge(q[k], q[(k + 1) % 4]);
    let ambiguous = (0..4).filter(|&k| enters(k)).count() == 2;
    // Ambiguous: inside corners alternate. Joined when they are the
    // lowest and highest corners (q[0] and q[2]); otherwise each entering
    // edge pairs with the next leaving one, as on a plain face.
    let joined = inside[0];
    (0..4).filter(move |&k| enters(k)).map(move |k| {
        let to = if ambiguous {
            if joined { (k + 3) % 4 } else { (k + 1) % 4 }
        } else {
            (1..4)
                .map(|d| (k + d) % 4)
                .find(|&j| leaves(j))
                .unwrap_or(k)
        };
        (cut(k), cut(to))
    })
}

/// The faces (bit `2·axis + side`) an edge point lies on.
fn faces_of(p: Pt) -> u8 {
    let Pt::Edge(a, b) = p else {
        return 0;
    };
    let dir = (a ^ b).trailing_zeros() as usize;
    (0..3)
        .filter(|&t| t != dir)
        .fold(0, |m, t| m | 1 << (2 * t + usize::from(a >> t & 1)))
}

/// A point of `ring` that shares a face with no point but its neighbours.
fn apex(ring: &[Pt]) -> Option<usize> {
    let k = ring.len();
    if k == 3 {
        return Some(0);
    }
    (0..k).find(|&i| (2..k - 1).all(|d| faces_of(ring[i]) & faces_of(ring[(i + d) % k]) == 0))
}

/// The loops of the case `mask`.
fn loops(mask: u8) -> Vec<Loop> {
    let mut segs = Vec::new();
    for axis in 0..3 {
        for side in 0..2 {
            segs.extend(face_segments(mask, axis, side));
        }
    }
    let mut out = Vec::new();
    while let Some((first, mut end)) = segs.pop() {
        let mut points = vec![first];
        while end != first {
            points.push(end);
            // Every point has one segment out: the faces' cuts close up.
            let Some(i) = segs.iter().position(|s| s.0 == end) else {
                break;
            };
            end = segs.swap_remove(i).1;
        }
        let apex = apex(&points);
        out.push(Loop { points, apex });
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_case_closes_into_loops_of_three_or_more() {
        for mask in 0..=255u8 {
            let ls = case(mask);
            let points: usize = ls.iter().map(|l| l.points.len()).sum();
            // Each cut edge of the cube holds one point of one loop.
            let cut = (0..8u8)
                .flat_map(|a| (0..3).map(move |t| (a, a | 1 << t)))
                .filter(|&(a, b)| a != b && (mask >> a & 1) != (mask >> b & 1))
                .count();
            assert_eq!(points, cut, "case {mask:08b}");
            assert!(ls.iter().all(|l| l.points.len() >= 3), "case {mask:08b}");
        }
        assert!(case(0).is_empty() && case(255).is_empty());
    }

    #[test]
    fn a_face_is_cut_alike_from_both_cubes() {
        // The face x = 1 of one cube is the face x = 0 of the next: the
        // same segments, in opposite directions.
        for m in 0..16u8 {
            // Corners of face x = 1 (1, 3, 5, 7) and x = 0 (0, 2, 4, 6).
            let hi = (0..4).fold(0u8, |a, k| a | (m >> k & 1) << (2 * k + 1));
            let lo = hi >> 1;
            let a: Vec<_> = face_segments(hi, 0, 1).collect();
            let b: Vec<_> = face_segments(lo, 0, 0).collect();
            let shift = |p: Pt| match p {
                Pt::Edge(x, y) => Pt::Edge(x >> 1 << 1, y >> 1 << 1),
                other => other,
            };
            let mut a: Vec<_> = a.into_iter().map(|(p, q)| (shift(q), shift(p))).collect();
            let mut b: Vec<_> = b.into_iter().map(|(p, q)| (shift(p), shift(q))).collect();
            let key = |s: &(Pt, Pt)| format!("{s:?}");
            a.sort_by_key(key);
            b.sort_by_key(key);
            assert_eq!(a, b, "face mask {m:04b}");
        }
    }
}
