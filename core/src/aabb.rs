//! Axis-aligned bounding boxes in millimetres.

use glam::{DMat3, DVec3};

/// An axis-aligned box `[min, max]`. Infinite extents are allowed (Tile,
/// TPMS); an empty box has `min > max`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Lowest corner.
    pub min: DVec3,
    /// Highest corner.
    pub max: DVec3,
}

impl Aabb {
    /// The box that contains nothing.
    pub const EMPTY: Aabb = Aabb {
        min: DVec3::splat(f64::INFINITY),
        max: DVec3::splat(f64::NEG_INFINITY),
    };
    /// The box that contains everything.
    pub const EVERYTHING: Aabb = Aabb {
        min: DVec3::splat(f64::NEG_INFINITY),
        max: DVec3::splat(f64::INFINITY),
    };

    /// A box from two corners.
    pub fn new(min: DVec3, max: DVec3) -> Self {
        Self { min, max }
    }

    /// A box from its centre and full side lengths.
    pub fn from_center_size(center: DVec3, size: DVec3) -> Self {
        Self::new(center - size * 0.5, center + size * 0.5)
    }

    /// True when the box contains no point.
    pub fn is_empty(&self) -> bool {
        self.min.x > self.max.x || self.min.y > self.max.y || self.min.z > self.max.z
    }

    /// True when every extent is finite (and the box is not empty).
    pub fn is_finite(&self) -> bool {
        !self.is_empty() && self.min.is_finite() && self.max.is_finite()
    }

    /// Full side lengths.
    pub fn size(&self) -> DVec3 {
        self.max - self.min
    }

    /// Centre point.
    pub fn center(&self) -> DVec3 {
        (self.min + self.max) * 0.5
    }

    /// Half the diagonal: the largest distance from the centre to a point of the box.
    pub fn half_diagonal(&self) -> f64 {
        self.size().length() * 0.5
    }

    /// Smallest box containing both.
    pub fn union(&self, o: &Aabb) -> Aabb {
        Aabb::new(self.min.min(o.min), self.max.max(o.max))
    }

    /// The overlap of both (possibly empty).
    pub fn intersection(&self, o: &Aabb) -> Aabb {
        Aabb::new(self.min.max(o.min), self.max.min(o.max))
    }

    /// True when the boxes overlap (closed boxes: touching counts).
    pub fn overlaps(&self, o: &Aabb) -> bool {
        self.min.x <= o.max.x
            && o.min.x <= self.max.x
            && self.min.y <= o.max.y
            && o.min.y <= self.max.y
            && self.min.z <= o.max.z
            && o.min.z <= self.max.z
    }

    /// True when `p` is inside or on the box.
    pub fn contains(&self, p: DVec3) -> bool {
        p.cmpge(self.min).all() && p.cmple(self.max).all()
    }

    /// The box grown by `r` on every side (shrunk for negative `r`).
    pub fn expand(&self, r: f64) -> Aabb {
        if self.is_empty() {
            return *self;
        }
        Aabb::new(self.min - DVec3::splat(r), self.max + DVec3::splat(r))
    }

    /// Euclidean distance from `p` to the box (0 inside).
    pub fn distance(&self, p: DVec3) -> f64 {
        let d = (self.min - p).max(p - self.max).max(DVec3::ZERO);
        d.length()
    }

    /// Squared Euclidean distance from `p` to the box (0 inside).
    pub fn distance_squared(&self, p: DVec3) -> f64 {
        let d = (self.min - p).max(p - self.max).max(DVec3::ZERO);
        d.length_squared()
    }

    /// The box's eight corners.
    pub fn corners(&self) -> [DVec3; 8] {
        let (a, b) = (self.min, self.max);
        [
            DVec3::new(a.x, a.y, a.z),
            DVec3::new(b.x, a.y, a.z),
            DVec3::new(a.x, b.y, a.z),
            DVec3::new(b.x, b.y, a.z),
            DVec3::new(a.x, a.y, b.z),
            DVec3::new(b.x, a.y, b.z),
            DVec3::new(a.x, b.y, b.z),
            DVec3::new(b.x, b.y, b.z),
        ]
    }

    /// The axis-aligned box around this box mapped by `q = m·(p − about) + about`.
    /// Exact for a finite box; an infinite box stays infinite.
    pub fn transformed(&self, m: &DMat3, about: DVec3) -> Aabb {
        if self.is_empty() {
            return *self;
        }
        if !self.is_finite() {
            return Aabb::EVERYTHING;
        }
        // Arvo's method: centre maps exactly, half extents by |m|.
        let c = *m * (self.center() - about) + about;
        let h = self.size() * 0.5;
        let abs = DMat3::from_cols(m.x_axis.abs(), m.y_axis.abs(), m.z_axis.abs());
        let e = abs * h;
        Aabb::new(c - e, c + e)
    }

    /// The box scaled about the origin by per-axis factors (positive or negative).
    pub fn scaled(&self, s: DVec3) -> Aabb {
        if self.is_empty() {
            return *self;
        }
        let a = self.min * s;
        let b = self.max * s;
        // 0 × inf is NaN: an infinite box stays infinite.
        let (lo, hi) = (a.min(b), a.max(b));
        if lo.is_nan() || hi.is_nan() {
            return Aabb::EVERYTHING;
        }
        Aabb::new(lo, hi)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotate_box_exactly() {
        let b = Aabb::new(DVec3::new(0.0, -2.0, -1.0), DVec3::new(10.0, 2.0, 1.0));
        let m = DMat3::from_rotation_z(90f64.to_radians());
        let r = b.transformed(&m, DVec3::ZERO);
        assert!(
            (r.min - DVec3::new(-2.0, 0.0, -1.0)).length() < 1e-9,
            "{r:?}"
        );
        assert!(
            (r.max - DVec3::new(2.0, 10.0, 1.0)).length() < 1e-9,
            "{r:?}"
        );
    }

    #[test]
    fn distance_to_box() {
        let b = Aabb::new(DVec3::ZERO, DVec3::ONE);
        assert_eq!(b.distance(DVec3::new(0.5, 0.5, 0.5)), 0.0);
        assert!((b.distance(DVec3::new(2.0, 2.0, 0.5)) - 2f64.sqrt()).abs() < 1e-12);
    }
}
