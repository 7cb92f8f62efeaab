//! Tetrahedron shape quality: dihedral angles and signed volume.
//!
//! The dihedral angle at edge `(i, j)` is the angle between the two faces
//! that share it. With `e` the unit edge direction and `u`, `w` the other two
//! vertices' offsets projected onto the plane normal to `e`,
//! `θ = acos(u·w / |u||w|)`. Small angles (slivers, needles) make the
//! stiffness matrix ill-conditioned; angles near 180° (caps) make the
//! interpolation error blow up (Shewchuk 2002, "What is a good linear finite
//! element?"), so both ends are reported.

use glam::DVec3;
use serde::Serialize;

/// Quality figures of a set of tetrahedra.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct QualityReport {
    /// Smallest dihedral angle, degrees.
    pub min_dihedral_deg: f64,
    /// Largest dihedral angle, degrees.
    pub max_dihedral_deg: f64,
    /// Smallest signed volume (mm³); positive when every element is positively
    /// oriented in the Abaqus/CalculiX sense.
    pub min_volume: f64,
    /// Elements measured.
    pub count: usize,
}

impl Default for QualityReport {
    fn default() -> Self {
        Self {
            min_dihedral_deg: f64::INFINITY,
            max_dihedral_deg: f64::NEG_INFINITY,
            min_volume: f64::INFINITY,
            count: 0,
        }
    }
}

impl QualityReport {
    /// Add one element.
    pub fn add(&mut self, t: &[DVec3; 4]) {
        let (lo, hi) = dihedral_range(t);
        self.min_dihedral_deg = self.min_dihedral_deg.min(lo);
        self.max_dihedral_deg = self.max_dihedral_deg.max(hi);
        self.min_volume = self.min_volume.min(signed_volume(t));
        self.count += 1;
    }
}

/// Signed volume `((b − a) × (c − a)) · (d − a) / 6`: positive when `d` lies on
/// the side that `(b − a) × (c − a)` points to, which is CalculiX's C3D4 node
/// order (face 1-2-3 counter-clockwise seen from node 4's opposite side).
#[inline]
pub fn signed_volume(t: &[DVec3; 4]) -> f64 {
    (t[1] - t[0]).cross(t[2] - t[0]).dot(t[3] - t[0]) / 6.0
}

/// Smallest and largest of the six dihedral angles, degrees. A degenerate
/// element (a zero-length edge or a flat face) gives (0, 180).
pub fn dihedral_range(t: &[DVec3; 4]) -> (f64, f64) {
    const EDGES: [(usize, usize, usize, usize); 6] = [
        (0, 1, 2, 3),
        (0, 2, 1, 3),
        (0, 3, 1, 2),
        (1, 2, 0, 3),
        (1, 3, 0, 2),
        (2, 3, 0, 1),
    ];
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for (i, j, k, l) in EDGES {
        let e = t[j] - t[i];
        let len = e.length();
        if len.is_nan() || len <= 0.0 {
            return (0.0, 180.0);
        }
        let e = e / len;
        let u = t[k] - t[i];
        let w = t[l] - t[i];
        let u = u - e * u.dot(e);
        let w = w - e * w.dot(e);
        let (nu, nw) = (u.length(), w.length());
        if nu.is_nan() || nw.is_nan() || nu <= 0.0 || nw <= 0.0 {
            return (0.0, 180.0);
        }
        let a = (u.dot(w) / (nu * nw)).clamp(-1.0, 1.0).acos().to_degrees();
        lo = lo.min(a);
        hi = hi.max(a);
    }
    (lo, hi)
}

/// Quality of tetrahedra given as 0-based node indices.
pub fn tet_quality(nodes: &[DVec3], tets: &[[u32; 4]]) -> QualityReport {
    let mut q = QualityReport::default();
    for t in tets {
        q.add(&t.map(|i| nodes[i as usize]));
    }
    q
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn regular_and_kuhn_tets() {
        let s = 1.0 / 2f64.sqrt();
        let reg = [
            DVec3::new(1.0, 0.0, -s),
            DVec3::new(-1.0, 0.0, -s),
            DVec3::new(0.0, 1.0, s),
            DVec3::new(0.0, -1.0, s),
        ];
        let (lo, hi) = dihedral_range(&reg);
        let want = (1.0f64 / 3.0).acos().to_degrees(); // 70.53°
        assert!(
            (lo - want).abs() < 1e-9 && (hi - want).abs() < 1e-9,
            "{lo} {hi}"
        );
        let kuhn = [DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::ONE];
        let (lo, hi) = dihedral_range(&kuhn);
        assert!(
            (lo - 45.0).abs() < 1e-9 && (hi - 90.0).abs() < 1e-9,
            "{lo} {hi}"
        );
        assert!((signed_volume(&kuhn) - 1.0 / 6.0).abs() < 1e-12);
        let q = tet_quality(&kuhn, &[[0, 1, 2, 3], [0, 2, 1, 3]]);
        assert_eq!(q.count, 2);
        assert!(q.min_volume < 0.0);
        let flat = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::new(1.0, 1.0, 0.0)];
        let (lo, hi) = dihedral_range(&flat);
        assert!(lo < 1e-6 && hi > 179.99, "{lo} {hi}");
    }
}
