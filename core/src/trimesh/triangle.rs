//! Point–triangle closest point and solid angle.
//!
//! Closest point after Ericson, *Real-Time Collision Detection* (2005),
//! section 5.1.5: the Voronoi regions of the three vertices, three edges and
//! the face are tested in turn with dot products. With `ap = p − a`,
//! `d1 = ab·ap`, `d2 = ac·ap`, the other four dot products of the book are
//! `d3 = d1 − ab·ab`, `d4 = d2 − ab·ac`, `d5 = d1 − ab·ac`, `d6 = d2 − ac·ac`,
//! so with the three per-triangle constants precomputed a query costs two dot
//! products plus the final squared length. In the face region the squared
//! distance is `(n·ap)²` with the unit normal `n`.

use glam::DVec3;

/// The part of a triangle that holds the closest point; the sign of a signed
/// distance comes from that feature's pseudo-normal (Bærentzen & Aanæs 2005).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Feature {
    /// Interior of the face.
    Face,
    /// Edge `k`: 0 = a→b, 1 = b→c, 2 = c→a.
    Edge(u8),
    /// Vertex `k`: 0 = a, 1 = b, 2 = c.
    Vertex(u8),
}

/// A triangle prepared for distance queries (128 bytes, two cache lines).
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub(crate) struct Tri {
    /// First vertex.
    pub a: DVec3,
    /// Unit normal `(ab × ac)/|ab × ac|`, zero for a degenerate triangle.
    /// Next to `a` so the plane-distance pre-test reads one cache line.
    pub n: DVec3,
    /// `b − a`.
    pub ab: DVec3,
    /// `c − a`.
    pub ac: DVec3,
    /// `ab·ab`.
    pub ab2: f64,
    /// `ab·ac`.
    pub abac: f64,
    /// `ac·ac`.
    pub ac2: f64,
    /// True when the triangle has (almost) no area: the face formulas would
    /// divide by zero, so the three edges are used instead.
    pub flat: bool,
}

/// `p − a` and its products with a triangle's edges (`d1 = ab·ap`,
/// `d2 = ac·ap`, and their differences from `|ab|²`, `ab·ac`, `|ac|²`):
/// what both orders of the region tests read.
#[derive(Clone, Copy)]
struct Projection {
    ap: DVec3,
    d1: f64,
    d2: f64,
    d3: f64,
    d4: f64,
    d5: f64,
    d6: f64,
}

impl Projection {
    /// The barycentric numerators `(va, vb, vc)` of the projection of `p`
    /// onto the triangle's plane: all positive inside the face.
    #[inline(always)]
    fn numerators(&self) -> (f64, f64, f64) {
        let va = self.d3 * self.d6 - self.d5 * self.d4;
        let vb = self.d5 * self.d2 - self.d1 * self.d6;
        let vc = self.d1 * self.d4 - self.d3 * self.d2;
        (va, vb, vc)
    }
}

impl Tri {
    /// Prepares triangle `(a, b, c)`.
    pub fn new(a: DVec3, b: DVec3, c: DVec3) -> Tri {
        let ab = b - a;
        let ac = c - a;
        let cross = ab.cross(ac);
        let ab2 = ab.dot(ab);
        let ac2 = ac.dot(ac);
        let len = cross.length();
        // |ab × ac|² = |ab|²|ac|² − (ab·ac)²; relative threshold on the sine
        // of the corner angle so the Ericson denominators stay meaningful.
        let flat = len.is_nan() || len <= 1e-12 * (ab2 * ac2).sqrt() || ab2 == 0.0 || ac2 == 0.0;
        Tri {
            a,
            ab,
            ac,
            n: if flat { DVec3::ZERO } else { cross / len },
            ab2,
            abac: ab.dot(ac),
            ac2,
            flat,
        }
    }

    /// The three corners.
    #[inline]
    pub fn corners(&self) -> [DVec3; 3] {
        [self.a, self.a + self.ab, self.a + self.ac]
    }

    /// Squared distance from `p` to the triangle (hot path of the BVH query).
    #[inline(always)]
    pub fn distance_squared(&self, p: DVec3) -> f64 {
        self.distance_squared_feature(p).0
    }

    /// Squared distance from `p` to the triangle, and the feature that holds
    /// the nearest point (Ericson's region; a flat triangle answers
    /// `Feature::Edge(0)` whatever its nearest feature, since its face has no
    /// normal to stand over).
    #[inline(always)]
    pub fn distance_squared_feature(&self, p: DVec3) -> (f64, Feature) {
        if self.flat {
            return (self.closest_flat(p).0.distance_squared(p), Feature::Edge(0));
        }
        self.ericson_order(&self.projection(p))
    }

    /// As [`Tri::distance_squared_feature`], testing the face first: with
    /// the three barycentric numerators of `p`'s projection all positive
    /// it is inside the face, whose distance is the plane's (one branch
    /// where Ericson's order takes six; a list's first triangle has the
    /// point over its face three times in four).
    #[inline(always)]
    pub fn distance_squared_feature_face_first(&self, p: DVec3) -> (f64, Feature) {
        if self.flat {
            return self.distance_squared_feature(p);
        }
        let pr = self.projection(p);
        let (va, vb, vc) = pr.numerators();
        if (va > 0.0) & (vb > 0.0) & (vc > 0.0) {
            let h = self.n.dot(pr.ap);
            return (h * h, Feature::Face);
        }
        self.ericson_order(&pr)
    }

    /// `p − a` and its products with the edges, as Ericson's region tests
    /// read them (Real-Time Collision Detection, §5.1.5).
    #[inline(always)]
    fn projection(&self, p: DVec3) -> Projection {
        let ap = p - self.a;
        let d1 = self.ab.dot(ap);
        let d2 = self.ac.dot(ap);
        Projection {
            ap,
            d1,
            d2,
            d3: d1 - self.ab2,
            d4: d2 - self.abac,
            d5: d1 - self.abac,
            d6: d2 - self.ac2,
        }
    }

    /// Ericson's region tests in his order (vertices, then edges, then the
    /// face) on a non-flat triangle: each numerator is computed when its
    /// test is reached, so points off the face end after few of them.
    #[inline(always)]
    fn ericson_order(&self, pr: &Projection) -> (f64, Feature) {
        let Projection {
            ap,
            d1,
            d2,
            d3,
            d4,
            d5,
            d6,
        } = *pr;
        if d1 <= 0.0 && d2 <= 0.0 {
            return (ap.dot(ap), Feature::Vertex(0));
        }
        if d3 >= 0.0 && d4 <= d3 {
            let bp = ap - self.ab;
            return (bp.dot(bp), Feature::Vertex(1));
        }
        let vc = d1 * d4 - d3 * d2;
        if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
            let q = ap - self.ab * (d1 / self.ab2);
            return (q.dot(q), Feature::Edge(0));
        }
        if d6 >= 0.0 && d5 <= d6 {
            let cp = ap - self.ac;
            return (cp.dot(cp), Feature::Vertex(2));
        }
        let vb = d5 * d2 - d1 * d6;
        if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
            let q = ap - self.ac * (d2 / self.ac2);
            return (q.dot(q), Feature::Edge(2));
        }
        let va = d3 * d6 - d5 * d4;
        let e43 = d4 - d3;
        let e56 = d5 - d6;
        if va <= 0.0 && e43 >= 0.0 && e56 >= 0.0 {
            let w = e43 / (e43 + e56);
            let q = ap - self.ab - (self.ac - self.ab) * w;
            return (q.dot(q), Feature::Edge(1));
        }
        let h = self.n.dot(ap);
        (h * h, Feature::Face)
    }

    /// Closest point on the triangle to `p` and the feature that holds it.
    pub fn closest(&self, p: DVec3) -> (DVec3, Feature) {
        if self.flat {
            return self.closest_flat(p);
        }
        let a = self.a;
        let ap = p - a;
        let d1 = self.ab.dot(ap);
        let d2 = self.ac.dot(ap);
        if d1 <= 0.0 && d2 <= 0.0 {
            return (a, Feature::Vertex(0));
        }
        let d3 = d1 - self.ab2;
        let d4 = d2 - self.abac;
        if d3 >= 0.0 && d4 <= d3 {
            return (a + self.ab, Feature::Vertex(1));
        }
        let vc = d1 * d4 - d3 * d2;
        if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
            return (a + self.ab * (d1 / self.ab2), Feature::Edge(0));
        }
        let d5 = d1 - self.abac;
        let d6 = d2 - self.ac2;
        if d6 >= 0.0 && d5 <= d6 {
            return (a + self.ac, Feature::Vertex(2));
        }
        let vb = d5 * d2 - d1 * d6;
        if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
            return (a + self.ac * (d2 / self.ac2), Feature::Edge(2));
        }
        let va = d3 * d6 - d5 * d4;
        let e43 = d4 - d3;
        let e56 = d5 - d6;
        if va <= 0.0 && e43 >= 0.0 && e56 >= 0.0 {
            let w = e43 / (e43 + e56);
            return (a + self.ab + (self.ac - self.ab) * w, Feature::Edge(1));
        }
        // va + vb + vc = |ab × ac|² (constant per triangle).
        let inv = 1.0 / (va + vb + vc);
        (
            a + self.ab * (vb * inv) + self.ac * (vc * inv),
            Feature::Face,
        )
    }

    /// Closest point for a degenerate triangle: the best of its three edges.
    fn closest_flat(&self, p: DVec3) -> (DVec3, Feature) {
        let [a, b, c] = self.corners();
        let mut best = (a, Feature::Vertex(0));
        let mut best_d2 = f64::INFINITY;
        for (k, (s, e)) in [(a, b), (b, c), (c, a)].into_iter().enumerate() {
            let (q, t) = closest_on_segment(p, s, e);
            let d2 = q.distance_squared(p);
            if d2 < best_d2 {
                best_d2 = d2;
                best = if t <= 0.0 {
                    (q, Feature::Vertex(k as u8))
                } else if t >= 1.0 {
                    (q, Feature::Vertex(((k + 1) % 3) as u8))
                } else {
                    (q, Feature::Edge(k as u8))
                };
            }
        }
        best
    }
}

/// Closest point on segment `[s, e]` and its parameter `t ∈ [0, 1]`.
fn closest_on_segment(p: DVec3, s: DVec3, e: DVec3) -> (DVec3, f64) {
    let d = e - s;
    let l2 = d.dot(d);
    if l2 <= 0.0 {
        return (s, 0.0);
    }
    let t = ((p - s).dot(d) / l2).clamp(0.0, 1.0);
    (s + d * t, t)
}

/// Signed solid angle of triangle `(a, b, c)` seen from `q`, after
/// Van Oosterom & Strackee, "The solid angle of a plane triangle", IEEE
/// Trans. Biomed. Eng. 30 (1983): with `x = a − q` etc.,
/// `tan(Ω/2) = x·(y × z) / (|x||y||z| + (x·y)|z| + (y·z)|x| + (z·x)|y|)`.
/// Positive when `q` is behind the counter-clockwise (outward) face, so the
/// sum over a closed outward mesh is `4π` inside and 0 outside.
#[inline]
pub(crate) fn solid_angle(q: DVec3, a: DVec3, b: DVec3, c: DVec3) -> f64 {
    let x = a - q;
    let y = b - q;
    let z = c - q;
    let lx = x.length();
    let ly = y.length();
    let lz = z.length();
    let det = x.dot(y.cross(z));
    let den = lx * ly * lz + x.dot(y) * lz + y.dot(z) * lx + z.dot(x) * ly;
    2.0 * det.atan2(den)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Straightforward reference: minimum over the face projection (if inside)
    /// and the three edges.
    fn reference(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> f64 {
        let n = (b - a).cross(c - a).normalize();
        let q = p - n * n.dot(p - a);
        let inside = [(a, b), (b, c), (c, a)]
            .iter()
            .all(|&(s, e)| (e - s).cross(q - s).dot(n) >= 0.0);
        let mut best = f64::INFINITY;
        if inside {
            best = q.distance(p);
        }
        for (s, e) in [(a, b), (b, c), (c, a)] {
            best = best.min(closest_on_segment(p, s, e).0.distance(p));
        }
        best
    }

    #[test]
    fn matches_reference_in_all_regions() {
        let (a, b, c) = (
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(2.0, 0.1, 0.0),
            DVec3::new(0.3, 1.5, 0.2),
        );
        let t = Tri::new(a, b, c);
        for i in -8..12 {
            for j in -8..12 {
                for k in -3..4 {
                    let p = DVec3::new(i as f64 * 0.25, j as f64 * 0.25, k as f64 * 0.3);
                    let r = reference(p, a, b, c);
                    assert!((t.distance_squared(p).sqrt() - r).abs() < 1e-12, "{p}");
                    assert!((t.closest(p).0.distance(p) - r).abs() < 1e-12, "{p}");
                }
            }
        }
    }

    /// The face-first test answers as Ericson's order: the same squared
    /// distance, bit for bit, and the same feature. (The two could differ
    /// only on a region boundary, by rounding; random points miss them.)
    #[test]
    fn face_first_agrees_with_ericson_order() {
        let mut rng = crate::xorshift::XorShift::new(5);
        let mut r = |s: f64| s * (2.0 * rng.next_f64() - 1.0);
        let mut faces = 0;
        for _ in 0..200 {
            let t = Tri::new(
                DVec3::new(r(1.0), r(1.0), r(1.0)),
                DVec3::new(r(1.0), r(1.0), r(1.0)),
                DVec3::new(r(1.0), r(1.0), r(1.0)),
            );
            for _ in 0..200 {
                let p = DVec3::new(r(2.0), r(2.0), r(2.0));
                let (d, f) = t.distance_squared_feature(p);
                assert_eq!(t.distance_squared_feature_face_first(p), (d, f), "{p}");
                faces += usize::from(f == Feature::Face);
            }
        }
        assert!(faces > 2_000, "{faces} points over a face");
    }

    #[test]
    fn degenerate_triangle_uses_edges() {
        let t = Tri::new(DVec3::ZERO, DVec3::X, DVec3::X * 2.0);
        assert!(t.flat);
        let p = DVec3::new(1.5, 1.0, 0.0);
        assert!((t.distance_squared(p) - 1.0).abs() < 1e-15);
        let t = Tri::new(DVec3::ZERO, DVec3::ZERO, DVec3::ZERO);
        assert!((t.distance_squared(DVec3::X) - 1.0).abs() < 1e-15);
    }

    #[test]
    fn solid_angle_of_cube_face_is_a_sixth() {
        // Face z = 1 of the cube [-1,1]^3 as two CCW triangles, seen from 0.
        let (p0, p1, p2, p3) = (
            DVec3::new(-1.0, -1.0, 1.0),
            DVec3::new(1.0, -1.0, 1.0),
            DVec3::new(1.0, 1.0, 1.0),
            DVec3::new(-1.0, 1.0, 1.0),
        );
        let w = solid_angle(DVec3::ZERO, p0, p1, p2) + solid_angle(DVec3::ZERO, p0, p2, p3);
        assert!((w - 4.0 * std::f64::consts::PI / 6.0).abs() < 1e-12);
    }
}
