//! The moves between a node's frame and its child's, for points and for
//! boxes (attributes are evaluated in the frame of the node that sets them,
//! pyvcad 3's rule; an `Identity` above a part gives a world-aligned one).

use glam::{DMat3, DVec3};

use crate::aabb::Aabb;

/// How a node maps a point of its frame into its child's.
pub(super) enum Move {
    /// Offsets, shells, grades, blends, Identity, a Difference's left side.
    Same,
    /// `p − offset`.
    Translate(DVec3),
    /// `to_local·(p − around) + around`.
    Rotate { to_local: DMat3, around: DVec3 },
    /// `p / factors`.
    Scale(DVec3),
    /// Reflection across the plane through `point` with unit `normal`.
    Mirror { point: DVec3, normal: DVec3 },
    /// pyvcad's Tile: `p − c·floor(p/c) − c/2`.
    Tile(DVec3),
}

impl Move {
    /// The point in the child's frame.
    #[inline]
    pub fn apply(&self, p: DVec3) -> DVec3 {
        match self {
            Move::Same => p,
            Move::Translate(o) => p - *o,
            Move::Rotate { to_local, around } => *to_local * (p - *around) + *around,
            Move::Scale(f) => p / *f,
            Move::Mirror { point, normal } => p - *normal * (2.0 * normal.dot(p - *point)),
            Move::Tile(c) => p - *c * crate::fastmath::floor3(p / *c) - *c * 0.5,
        }
    }

    /// A box containing every point of `b` mapped into the child's frame.
    pub fn apply_box(&self, b: &Aabb) -> Aabb {
        match self {
            Move::Same => *b,
            Move::Translate(o) => Aabb::new(b.min - *o, b.max - *o),
            Move::Rotate { to_local, around } => b.transformed(to_local, *around),
            Move::Scale(f) => b.scaled(DVec3::ONE / *f),
            Move::Mirror { point, normal } => {
                // A reflection is I − 2nnᵀ about `point`.
                let m = DMat3::IDENTITY
                    - DMat3::from_cols(*normal * normal.x, *normal * normal.y, *normal * normal.z)
                        * 2.0;
                b.transformed(&m, *point)
            }
            Move::Tile(c) => {
                let (lo, hi) = (
                    crate::fastmath::floor3(b.min / *c),
                    crate::fastmath::floor3(b.max / *c),
                );
                if b.is_finite() && lo == hi {
                    Aabb::new(self.apply(b.min), self.apply(b.max))
                } else {
                    Aabb::new(-*c * 0.5, *c * 0.5)
                }
            }
        }
    }
}
