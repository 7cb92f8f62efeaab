//! Distance queries: nearest triangle through the BVH, then the sign.

use glam::DVec3;

use super::TriangleMesh;
use super::triangle::Feature;
use super::wide::Certificate;
use crate::bounds::Aabb;
use crate::interval::Interval;

impl TriangleMesh {
    /// Nearest triangle slot and its squared distance, if one is closer than
    /// `sqrt(max_d2)`: nearest-first traversal of the 4-wide BVH; in a leaf,
    /// the squared distance to the triangle's plane is a cheap lower bound
    /// that skips most triangles before the full Ericson test.
    ///
    /// Samplers query neighbouring points one after the other. Each search
    /// leaves a [`Certificate`] for its point `p0` (the nearest few triangles
    /// and a lower bound `L` of the distance of all others), kept per thread
    /// and mesh. For the next point `p`, `δ = |p − p0|`: every other triangle
    /// is at least `L − δ` away, so if the best of the few is within
    /// `L − δ` it is the answer without any traversal; otherwise it seeds
    /// the search with a tight upper bound. Results are identical either way.
    #[inline]
    fn nearest(&self, p: DVec3, max_d2: f64) -> Option<(usize, f64)> {
        let tris = &self.tris;
        let key = tris.as_ptr() as usize;
        let mut seed = None;
        if let Some(c) = cache::get(key) {
            let mut b = (u32::MAX, f64::INFINITY);
            for &(s, _) in &c.near[..c.count] {
                if let Some(t) = tris.get(s as usize) {
                    let d2 = t.distance_squared(p);
                    if d2 < b.1 {
                        b = (s, d2);
                    }
                }
            }
            if b.0 != u32::MAX {
                let margin = c.rest_sqrt - p.distance(c.p);
                TRIES.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                if margin > 0.0 {
                    MARG.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                }
                if margin > 0.0 && b.1.sqrt() <= margin {
                    HITS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                    return (b.1 < max_d2).then_some((b.0 as usize, b.1));
                }
                seed = Some(b);
            }
        }
        let mut cert = Certificate::default();
        let found = self.wide.nearest(p, max_d2, seed, &mut cert, |s, best| {
            let t = &tris[s as usize];
            let h = t.n.dot(p - t.a);
            let h2 = h * h;
            if h2 >= best {
                h2
            } else {
                t.distance_squared(p)
            }
        });
        cache::set(
            key,
            cache::Entry {
                p,
                near: cert.near,
                count: cert.count,
                rest_sqrt: cert.rest.sqrt(),
            },
        );
        found.map(|(s, d2)| (s as usize, d2))
    }

    /// `+1` outside, `−1` inside, for a point whose nearest triangle is `slot`
    /// (at non-zero distance).
    fn sign_at(&self, p: DVec3, slot: usize) -> f64 {
        if let Some(ps) = &self.pseudo {
            let t = &self.tris[slot];
            let (c, feature) = t.closest(p);
            // Bærentzen & Aanæs 2005: the pseudo-normal of the feature that
            // holds the closest point c separates inside from outside:
            // face → its normal; edge → sum of the two face normals;
            // vertex → angle-weighted sum of the incident face normals.
            let n = match feature {
                Feature::Face => t.n,
                Feature::Edge(k) => t.n + self.tris[ps.across[slot][k as usize] as usize].n,
                Feature::Vertex(k) => ps.vertex_normals[ps.corners[slot][k as usize] as usize],
            };
            let s = (p - c).dot(n);
            if s > 0.0 {
                return 1.0;
            }
            if s < 0.0 {
                return -1.0;
            }
            // Exactly perpendicular (rounding at a sliver): ask the winding number.
        }
        if self.winding_number(p) > 0.5 {
            -1.0
        } else {
            1.0
        }
    }

    /// Exact nearest triangle with no radius limit: the coarse grid's upper
    /// bound `|d(c)| + |p − c|` starts the search when `p` is in the grid.
    #[inline]
    fn nearest_any(&self, p: DVec3) -> Option<(usize, f64)> {
        if let Some((dc, r)) = self.coarse.as_ref().and_then(|g| g.lookup(p)) {
            let upper = (dc.abs() + r) * (1.0 + 1e-12) + f64::MIN_POSITIVE;
            if let Some(found) = self.nearest(p, upper * upper) {
                return Some(found);
            }
            HITS.fetch_add(1 << 40, std::sync::atomic::Ordering::Relaxed);
        }
        self.nearest(p, f64::INFINITY)
    }

    /// Exact Euclidean distance to the surface (no band clamp), negative
    /// inside. NaN for a non-finite `p`.
    pub fn signed_distance(&self, p: DVec3) -> f64 {
        if !p.is_finite() {
            return f64::NAN;
        }
        match self.nearest_any(p) {
            Some((_, d2)) if d2 == 0.0 => 0.0,
            Some((slot, d2)) => d2.sqrt() * self.sign_at(p, slot),
            // Squared distances overflowed: astronomically far, so outside.
            None => (p - self.bbox.center()).length(),
        }
    }

    /// Exact unsigned distance to the surface. NaN for a non-finite `p`.
    pub fn distance(&self, p: DVec3) -> f64 {
        if !p.is_finite() {
            return f64::NAN;
        }
        match self.nearest_any(p) {
            Some((_, d2)) => d2.sqrt(),
            None => (p - self.bbox.center()).length(),
        }
    }

    /// Signed distance with an early out for samplers that only care about
    /// the band `|d| < max_dist`: the exact signed distance when it is
    /// smaller than `max_dist` in magnitude, otherwise a value with the
    /// correct sign and a magnitude in `[max_dist, |d|]` (a lower bound of
    /// the true magnitude).
    ///
    /// Far from the surface the coarse grid answers in O(1)
    /// (`|d(p)| ≥ |d(c)| − |p − c|`, same side as `c`); outside the grid the
    /// point is outside the mesh box. Otherwise the BVH search starts with
    /// `max_dist²` as its best distance, so it ends after a few box tests
    /// when nothing is that close.
    pub fn signed_distance_bound(&self, p: DVec3, max_dist: f64) -> f64 {
        if !p.is_finite() || max_dist.is_nan() {
            return f64::NAN;
        }
        if !(max_dist > 0.0 && max_dist < f64::INFINITY) {
            return self.signed_distance(p);
        }
        let mut side = 0.0;
        match self.coarse.as_ref().and_then(|g| g.lookup(p)) {
            Some((dc, r)) => {
                let lower = dc.abs() - r;
                if lower >= max_dist {
                    return lower.copysign(dc);
                }
                if lower > 0.0 {
                    side = 1f64.copysign(dc);
                }
            }
            None => {
                let lower = self.bbox.distance(p);
                if lower >= max_dist {
                    return lower;
                }
                if lower > 0.0 {
                    side = 1.0;
                }
            }
        }
        match self.nearest(p, max_dist * max_dist) {
            Some((_, d2)) if d2 == 0.0 => 0.0,
            Some((slot, d2)) => d2.sqrt() * self.sign_at(p, slot),
            // Nothing within max_dist: the side is known, or the exact value
            // (a valid lower bound) settles it.
            None if side != 0.0 => max_dist * side,
            None => self.signed_distance(p),
        }
    }

    /// Generalised winding number (Jacobson et al. 2013) by the hierarchical
    /// approximation of Barill et al. 2018 (exact near field, second-order
    /// far field): ≈1 inside a closed outward mesh, ≈0 outside, fractional
    /// near holes. NaN for a non-finite `p`.
    pub fn winding_number(&self, p: DVec3) -> f64 {
        if !p.is_finite() {
            return f64::NAN;
        }
        self.winding.evaluate(&self.nodes, &self.tris, p)
    }

    /// True when `p` is strictly inside (negative signed distance; points on
    /// the surface are not inside).
    pub fn is_inside(&self, p: DVec3) -> bool {
        self.signed_distance(p) < 0.0
    }

    /// Conservative bounds of the signed distance over the box `b`. The
    /// exact SDF is 1-Lipschitz, so every value in `b` lies within
    /// `d(centre) ± half_diagonal`. An empty box gives `[+∞, +∞]` (nothing
    /// to bound); an infinite box `[−R, +∞]` with `R` the mesh box's half
    /// diagonal (no point is deeper inside than that).
    pub fn interval(&self, b: &Aabb) -> Interval {
        if b.is_empty() {
            return Interval {
                lo: f64::INFINITY,
                hi: f64::INFINITY,
            };
        }
        if !b.is_finite() {
            return Interval {
                lo: -self.bbox.half_diagonal(),
                hi: f64::INFINITY,
            };
        }
        let d = self.signed_distance(b.center());
        let h = b.half_diagonal();
        Interval {
            lo: (d - h).max(-self.bbox.half_diagonal()),
            hi: d + h,
        }
    }

    /// Closest point on the surface and the index of its triangle (into
    /// [`TriangleMesh::triangles`]). `None` for a non-finite `p`.
    pub fn closest_point(&self, p: DVec3) -> Option<(DVec3, usize)> {
        if !p.is_finite() {
            return None;
        }
        let (slot, _) = self.nearest_any(p)?;
        Some((self.tris[slot].closest(p).0, self.order[slot] as usize))
    }
}

/// Per-thread memory of the last search certificate of the few most
/// recently queried meshes (keyed by the address of their triangle data; a
/// stale key of a dropped mesh only costs a few wasted triangle tests).
mod cache {
    use std::cell::RefCell;

    use glam::DVec3;

    const WAYS: usize = 4;

    /// A certificate for the query point `p`.
    #[derive(Clone, Copy, Debug, Default)]
    pub struct Entry {
        pub p: DVec3,
        pub near: [(u32, f64); 4],
        pub count: usize,
        pub rest_sqrt: f64,
    }

    thread_local! {
        static LAST: RefCell<[(usize, Entry); WAYS]> = RefCell::new([(0, Entry::default()); WAYS]);
    }

    /// The certificate remembered for mesh `key`.
    #[inline]
    pub fn get(key: usize) -> Option<Entry> {
        LAST.with_borrow(|a| a.iter().find(|e| e.0 == key).map(|e| e.1))
    }

    /// Remembers `entry` for mesh `key` (most recent first).
    #[inline]
    pub fn set(key: usize, entry: Entry) {
        LAST.with_borrow_mut(|a| {
            let i = a.iter().position(|e| e.0 == key).unwrap_or(WAYS - 1);
            a.copy_within(0..i, 1);
            a[0] = (key, entry);
        })
    }
}

pub static HITS: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
pub static TRIES: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
pub static MARG: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
