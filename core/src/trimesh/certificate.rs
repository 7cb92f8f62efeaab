//! Which entries of a cell's candidate list a query may skip unread, from
//! where the query point stands relative to the list's first triangle.
//!
//! Why: a query tests the first candidate `t₁` (the triangle nearest the
//! cell's centre), then walks the list to prove that no other triangle is
//! nearer. On the bunny lattice's points near the surface, 2.6 of the 2.61
//! entries a walk read shared a vertex with `t₁`, and only 0.17 of them
//! turned out nearer: the walk mostly read neighbours to rule them out.
//!
//! The rule. Let `x` be `p`'s nearest point on `t₁` and `u = p − x`. A
//! triangle `t` with `(y − x)·u ≤ 0` for all its points `y` is no nearer:
//! `|p − y|² = |u|² + |y − x|² − 2 (y − x)·u ≥ |u|²`. Write `n` for `t₁`'s
//! unit normal, `z(y) = n·(y − a₁)` for the height over its plane, and
//! `s_k(y) = m_k·(y − v_k)` for the distance outside edge `k`, with `m_k` the
//! edge's outward unit normal in the plane. Then, with `h = n·(p − a₁)`:
//!
//! * over the face, `u = h n`: `(y − x)·u = h z(y)`, so `t` is no nearer
//!   when it lies wholly on the far side of the plane (`z ≤ 0` for `h > 0`);
//! * over edge `k`, `u = h n + e m_k` with `e ≥ 0`: `t` is no nearer when
//!   it also lies inside that edge (`s_k ≤ 0`);
//! * at a vertex, `u = h n + α m_k + β m_j` with `α, β ≥ 0` (the normal
//!   cone, spanned by the two edges' normals): `t` must lie inside both.
//!
//! Each condition is linear in `y`, so checking `t`'s three corners
//! suffices. Eight bits per list entry hold them: the face on either side
//! of the plane, and each edge with either side. A query asks for the one
//! or two bits of the feature it stands over and skips the entries that
//! have them. The bits are set with a tolerance `tol` (the corners `t`
//! shares with `t₁` have heights of rounding size), so a skipped triangle
//! can be nearer than `x` by about `tol`: 10⁻¹² of the mesh box.

use glam::DVec3;

use super::triangle::{Feature, Tri};

/// Bits per list entry.
pub(super) const BITS: u32 = 8;

/// Bit `FACE + side`: over the face (`side` 0: `h > 0`, 1: `h ≤ 0`).
const FACE: u32 = 0;
/// Bit `EDGE + 3·side + k`: over edge `k` (a→b, b→c, c→a) on that side.
const EDGE: u32 = 2;

/// The edges that meet at vertex `k` (a, b, c).
const VERTEX_EDGES: [[u32; 2]; 3] = [[0, 2], [0, 1], [1, 2]];

/// A list's first triangle, prepared to give its entries' bits.
pub(super) struct Frame<'a> {
    t1: &'a Tri,
    /// Corners `v_k` of `t₁`.
    corners: [DVec3; 3],
    /// Outward unit normal `m_k` of edge `k` in `t₁`'s plane.
    edge_normals: [DVec3; 3],
    tol: f64,
}

impl<'a> Frame<'a> {
    /// The frame of `t1`, with tolerance `tol`; `None` when `t1` is flat
    /// (it has no plane, so it certifies nothing).
    pub fn new(t1: &'a Tri, tol: f64) -> Option<Frame<'a>> {
        if t1.flat {
            return None;
        }
        let corners = t1.corners();
        // With n = ab × ac / |ab × ac|, t₁ runs counter-clockwise around n,
        // so edge × n points away from the third corner.
        let edge_normals =
            std::array::from_fn(|k| (corners[(k + 1) % 3] - corners[k]).cross(t1.n).normalize());
        Some(Frame {
            t1,
            corners,
            edge_normals,
            tol,
        })
    }

    /// The certificate bits of triangle `t` (unshifted).
    pub fn bits(&self, t: &Tri) -> u32 {
        let y = t.corners();
        let tol = self.tol;
        let z = y.map(|y| self.t1.n.dot(y - self.t1.a));
        let below = z.iter().all(|&z| z <= tol);
        let above = z.iter().all(|&z| z >= -tol);
        let mut out = u32::from(below) << FACE | u32::from(above) << (FACE + 1);
        for (k, (m, v)) in self.edge_normals.iter().zip(&self.corners).enumerate() {
            if y.iter().all(|&y| m.dot(y - *v) <= tol) {
                out |= u32::from(below) << (EDGE + k as u32);
                out |= u32::from(above) << (EDGE + 3 + k as u32);
            }
        }
        out
    }
}

/// Per feature of the first triangle and side of its plane, the bits an
/// entry must have to be skipped, already shifted into place.
#[derive(Clone, Debug)]
pub(super) struct Skips {
    /// `[feature][side]`: the face, edges 0 to 2, vertices 0 to 2; side 0
    /// for `h > 0`. Zero when the grid keeps no bits (nothing skipped).
    need: [[u32; 2]; 7],
}

impl Skips {
    /// Masks for bits stored from bit `shift` of an entry; `enabled` false
    /// when the entries hold no bits.
    pub fn new(shift: u32, enabled: bool) -> Skips {
        let mut need = [[0u32; 2]; 7];
        if enabled {
            for side in 0..2 {
                let edge = |k: u32| 1u32 << (shift + EDGE + 3 * side + k);
                need[0][side as usize] = 1 << (shift + FACE + side);
                for k in 0..3 {
                    need[1 + k as usize][side as usize] = edge(k);
                    let [e1, e2] = VERTEX_EDGES[k as usize];
                    need[4 + k as usize][side as usize] = edge(e1) | edge(e2);
                }
            }
        }
        Skips { need }
    }

    /// The bits that let a query skip an entry, for a point whose nearest
    /// point on the first triangle is on `feature`, on the normal's side
    /// when `above`; 0 when nothing may be skipped.
    #[inline(always)]
    pub fn need(&self, feature: Feature, above: bool) -> u32 {
        let f = match feature {
            Feature::Face => 0,
            Feature::Edge(k) => 1 + k as usize,
            Feature::Vertex(k) => 4 + k as usize,
        };
        self.need[f][usize::from(!above)]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A triangle whose bits say "no nearer" really is no nearer than the
    /// first one, at points over each feature, on a bent strip of
    /// triangles; and the bits are not vacuous (some are set, some not).
    #[test]
    fn skipped_triangles_are_never_nearer() {
        let t1 = Tri::new(DVec3::ZERO, DVec3::X, DVec3::Y);
        // Neighbours folded down (convex) and up (concave) around t₁.
        let others = [
            Tri::new(DVec3::X, DVec3::new(1.0, 1.0, -0.3), DVec3::Y),
            Tri::new(DVec3::X, DVec3::new(1.0, 1.0, 0.3), DVec3::Y),
            Tri::new(DVec3::ZERO, DVec3::Y, DVec3::new(-1.0, 0.5, -0.2)),
            Tri::new(DVec3::ZERO, DVec3::Y, DVec3::new(-1.0, 0.5, 0.2)),
            Tri::new(DVec3::ZERO, DVec3::new(0.5, -1.0, 0.1), DVec3::X),
            Tri::new(DVec3::ZERO, DVec3::new(0.5, -1.0, -0.1), DVec3::X),
            Tri::new(
                DVec3::new(-0.5, -0.5, -0.4),
                DVec3::new(-0.2, -0.9, -0.4),
                DVec3::new(-0.9, -0.2, -0.4),
            ),
        ];
        let skips = Skips::new(0, true);
        let frame = Frame::new(&t1, 1e-12).expect("t₁ has a plane");
        let mut rng = crate::xorshift::XorShift::new(3);
        let (mut skipped, mut kept) = (0, 0);
        for _ in 0..20_000 {
            let p = DVec3::new(
                -1.5 + 3.0 * rng.next_f64(),
                -1.5 + 3.0 * rng.next_f64(),
                -1.0 + 2.0 * rng.next_f64(),
            );
            let (d1, feature) = t1.distance_squared_feature(p);
            let need = skips.need(feature, t1.n.dot(p - t1.a) > 0.0);
            for t in &others {
                if frame.bits(t) & need == need {
                    skipped += 1;
                    assert!(
                        t.distance_squared(p) >= d1 * (1.0 - 1e-12),
                        "{p} {feature:?}"
                    );
                } else {
                    kept += 1;
                }
            }
        }
        assert!(
            skipped > 20_000 && kept > 20_000,
            "{skipped} skipped, {kept} kept"
        );
    }

    #[test]
    fn a_flat_first_triangle_certifies_nothing() {
        let flat = Tri::new(DVec3::ZERO, DVec3::X, DVec3::X * 2.0);
        assert!(Frame::new(&flat, 1e-12).is_none());
        assert_eq!(Skips::new(4, false).need(Feature::Face, true), 0);
    }
}
