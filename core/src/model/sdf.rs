//! Closed-form signed distance functions of the primitives (negative inside,
//! exact Euclidean distance: Inigo Quilez, "distance functions"), and the
//! smooth min/max pyvcad uses.

use glam::{DVec2, DVec3};

/// Sphere of radius `r` at `c`: `|p − c| − r`.
#[inline]
pub fn sphere(p: DVec3, c: DVec3, r: f64) -> f64 {
    (p - c).length() - r
}

/// Box centred at `c` with half sides `h`: exact Euclidean distance
/// `|max(q, 0)| + min(max(q.x, q.y, q.z), 0)` with `q = |p − c| − h`.
/// (pyvcad uses the max-norm `max(q)`, which underestimates outside corners.)
#[inline]
pub fn rect_prism(p: DVec3, c: DVec3, h: DVec3) -> f64 {
    box_of_offsets((p - c).abs() - h)
}

/// The box distance from `q = |p − c| − h`. It does not decrease when any
/// `qᵢ` grows (both terms are monotone), which gives exact intervals.
#[inline]
pub fn box_of_offsets(q: DVec3) -> f64 {
    q.max(DVec3::ZERO).length() + q.max_element().min(0.0)
}

/// Z-axis cylinder of radius `r`, half height `hh`, centred at `c`: exact
/// capped-cylinder distance (Euclidean beyond the rim).
#[inline]
pub fn cylinder(p: DVec3, c: DVec3, r: f64, hh: f64) -> f64 {
    let q = p - c;
    cylinder_of(DVec2::new(q.x, q.y).length(), q.z.abs(), r, hh)
}

/// The cylinder distance from the radial distance `rho` and `|z|`; it does
/// not decrease when either grows, which gives exact intervals.
#[inline]
pub fn cylinder_of(rho: f64, z_abs: f64, r: f64, hh: f64) -> f64 {
    let d = DVec2::new(rho - r, z_abs - hh);
    d.max_element().min(0.0) + d.max(DVec2::ZERO).length()
}

/// A capsule (strut) from `a` along `ab` with radius `r`; `inv_ab2` = 1/|ab|²
/// (0 for a degenerate strut, which is a sphere).
#[inline]
pub fn capsule(p: DVec3, a: DVec3, ab: DVec3, inv_ab2: f64, r: f64) -> f64 {
    segment_dist2(p, a, ab, inv_ab2).sqrt() - r
}

/// Squared distance from `p` to the segment from `a` to `a + ab`
/// (`inv_ab2 = 1/|ab|²`, 0 for a point).
#[inline]
pub fn segment_dist2(p: DVec3, a: DVec3, ab: DVec3, inv_ab2: f64) -> f64 {
    let ap = p - a;
    let t = (ap.dot(ab) * inv_ab2).clamp(0.0, 1.0);
    (ap - ab * t).length_squared()
}

/// pyvcad's quadratic smooth minimum with k' = 4k (pyvcad 2.3.4's Union):
/// `h = max(4k − |a − b|, 0) / 4k; min(a, b) − k·h²`.
#[inline]
pub fn smooth_min(a: f64, b: f64, k: f64) -> f64 {
    let h = (4.0 * k - (a - b).abs()).max(0.0) / (4.0 * k);
    a.min(b) - k * h * h
}

/// The smooth maximum matching [`smooth_min`]: `max(a, b) + k·h²`.
#[inline]
pub fn smooth_max(a: f64, b: f64, k: f64) -> f64 {
    let h = (4.0 * k - (a - b).abs()).max(0.0) / (4.0 * k);
    a.max(b) + k * h * h
}

/// Exact signed distance to a simple 2D polygon (Quilez, "sdPolygon"):
/// distance to the nearest edge, negative inside by the crossing-number test.
#[inline]
pub fn polygon_2d(p: DVec2, v: &[DVec2]) -> f64 {
    polygon_2d_edges(p, v, None)
}

/// [`polygon_2d`] where only the edges with `surface[i]` true (edge `i`
/// runs from vertex `i − 1` to vertex `i`) are surface: the inside test
/// still uses every edge. A revolved profile's edges on the axis are inside
/// the solid, not on its surface.
#[inline]
pub fn polygon_2d_surface(p: DVec2, v: &[DVec2], surface: &[bool]) -> f64 {
    polygon_2d_edges(p, v, Some(surface))
}

#[inline(always)]
fn polygon_2d_edges(p: DVec2, v: &[DVec2], surface: Option<&[bool]>) -> f64 {
    let n = v.len();
    // Every edge holds its end points, so starting from vertex 0 changes
    // nothing when every edge counts.
    let mut d = match surface {
        None => (p - v[0]).length_squared(),
        Some(_) => f64::INFINITY,
    };
    let mut s = 1.0;
    let mut j = n - 1;
    for i in 0..n {
        let e = v[j] - v[i];
        let w = p - v[i];
        if surface.is_none_or(|m| m[i]) {
            let b = w - e * (w.dot(e) / e.length_squared()).clamp(0.0, 1.0);
            d = d.min(b.length_squared());
        }
        let c = [p.y >= v[i].y, p.y < v[j].y, e.x * w.y > e.y * w.x];
        if (c[0] && c[1] && c[2]) || (!c[0] && !c[1] && !c[2]) {
            s = -s;
        }
        j = i;
    }
    s * d.sqrt()
}

/// Combine a 2D distance `d2` with a slab distance `dw` into the exact
/// distance of the extrusion: `min(max(d2, dw), 0) + |max((d2, dw), 0)|`.
#[inline]
pub fn extrude(d2: f64, dw: f64) -> f64 {
    d2.max(dw).min(0.0) + DVec2::new(d2, dw).max(DVec2::ZERO).length()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn box_is_exact_at_corners() {
        let d = rect_prism(
            DVec3::new(2.0, 3.0, 4.0),
            DVec3::ZERO,
            DVec3::new(1.0, 2.0, 3.0),
        );
        assert!((d - 3f64.sqrt()).abs() < 1e-12);
        let inside = rect_prism(DVec3::new(0.5, 0.0, 0.0), DVec3::ZERO, DVec3::ONE);
        assert!((inside + 0.5).abs() < 1e-12);
    }

    #[test]
    fn cylinder_rim_is_euclidean() {
        let d = cylinder(DVec3::new(2.0, 0.0, 3.0), DVec3::ZERO, 1.0, 2.0);
        assert!((d - 2f64.sqrt()).abs() < 1e-12);
    }

    #[test]
    fn smooth_min_matches_pyvcad() {
        assert!((smooth_min(-1.0, -1.0, 1.0) + 2.0).abs() < 1e-12);
        assert_eq!(smooth_min(0.0, 10.0, 1.0), 0.0);
    }

    #[test]
    fn polygon_square() {
        let sq = [
            DVec2::new(0.0, 0.0),
            DVec2::new(1.0, 0.0),
            DVec2::new(1.0, 1.0),
            DVec2::new(0.0, 1.0),
        ];
        assert!((polygon_2d(DVec2::new(0.5, 0.5), &sq) + 0.5).abs() < 1e-12);
        assert!((polygon_2d(DVec2::new(2.0, 0.5), &sq) - 1.0).abs() < 1e-12);
    }
}
