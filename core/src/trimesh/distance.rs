//! Distance queries: nearest triangle through the BVH, then the sign.

use glam::DVec3;

use super::TriangleMesh;
use super::candidates::Near;

/// What [`TriangleMesh::signed_distance_unless_within`] finds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Probe {
    /// A triangle lies at this distance, at most the asked one, found
    /// without the search for the nearest and its side: `|d| ≤` it.
    Within(f64),
    /// The exact signed distance.
    Exact(f64),
}
use super::triangle::Feature;
use crate::aabb::Aabb;
use crate::interval::Interval;
use crate::spatial::recent::RecentSlots;

impl TriangleMesh {
    /// Nearest triangle slot and its squared distance, if one is closer than
    /// `sqrt(max_d2)`: nearest-first traversal of the 4-wide BVH; in a leaf,
    /// the squared distance to the triangle's plane is a cheap lower bound
    /// that skips most triangles before the full Ericson test.
    ///
    /// Samplers query neighbouring points one after the other, whose nearest
    /// triangles are usually the same: the previous answer of this thread for
    /// this mesh seeds the search with a true upper bound, so the traversal
    /// prunes from the start. The seed only tightens the initial bound; the
    /// result is the same without it.
    #[inline]
    fn nearest(&self, p: DVec3, max_d2: f64) -> Option<(usize, f64)> {
        let tris = &self.tris;
        let key = tris.as_ptr() as usize;
        let mut best = max_d2;
        let mut seed = None;
        if let Some(s) = SEED
            .with(|r| r.get(key))
            .filter(|&s| (s as usize) < tris.len())
        {
            let d2 = tris[s as usize].distance_squared(p);
            if d2 < best {
                best = d2;
                seed = Some((s, d2));
            }
        }
        let found = self
            .wide
            .nearest(p, best, |s, best| {
                let t = &tris[s as usize];
                let h = t.n.dot(p - t.a);
                if h * h >= best {
                    f64::INFINITY
                } else {
                    t.distance_squared(p)
                }
            })
            .or(seed);
        if let Some((s, _)) = found {
            SEED.with(|r| r.set(key, s));
        }
        found.map(|(s, d2)| (s as usize, d2))
    }

    /// `+1` outside, `−1` inside, for a point whose nearest triangle is `slot`
    /// (at non-zero distance).
    pub(super) fn sign_at(&self, p: DVec3, slot: usize) -> f64 {
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
    pub(super) fn nearest_any(&self, p: DVec3) -> Option<(usize, f64)> {
        if let Some((dc, r)) = self.coarse.as_ref().and_then(|g| g.lookup(p)) {
            let upper = (dc.abs() + r) * (1.0 + 1e-12) + f64::MIN_POSITIVE;
            if let Some(found) = self.nearest(p, upper * upper) {
                return Some(found);
            }
        }
        self.nearest(p, f64::INFINITY)
    }

    /// Exact Euclidean distance to the surface (no band clamp), negative
    /// inside. NaN for a non-finite `p`.
    pub fn signed_distance(&self, p: DVec3) -> f64 {
        // The grid's cell lookup rejects non-finite points itself (its
        // range test is false for NaN and infinities), so the check waits
        // for the fallback, off the common path.
        if let Some(d) = self.signed_from_candidates(p) {
            return d;
        }
        if !p.is_finite() {
            return f64::NAN;
        }
        match self.nearest_any(p) {
            Some((slot, d2)) => signed(d2, || self.sign_at(p, slot)),
            // Squared distances overflowed: astronomically far, so outside.
            None => (p - self.bbox.center()).length(),
        }
    }

    /// The exact signed distance from the candidate grid, when `p`'s cell
    /// keeps a list (near the surface).
    #[inline]
    fn signed_from_candidates(&self, p: DVec3) -> Option<f64> {
        let (slot, d2, side) = self.candidates.as_ref()?.nearest(self, p)?;
        Some(self.signed_from_list(p, slot, d2, side))
    }

    /// A candidate walk's answer signed: by the side it found, else by
    /// the nearest triangle's pseudo-normals.
    #[inline]
    fn signed_from_list(&self, p: DVec3, slot: usize, d2: f64, side: i8) -> f64 {
        signed(d2, || {
            if side != 0 {
                f64::from(side)
            } else {
                self.sign_at(p, slot)
            }
        })
    }

    /// Where the candidate grid keeps a list for `p`'s cell, the exact
    /// signed distance, unless a triangle lies within `within` of `p`
    /// ([`Probe`]); `None` elsewhere.
    pub fn signed_distance_unless_within(&self, p: DVec3, within: f64) -> Option<Probe> {
        let grid = self.candidates.as_ref()?;
        Some(
            match grid.nearest_unless_within(self, p, within * within)? {
                Near::Within(d2) => Probe::Within(d2.sqrt()),
                Near::Nearest(slot, d2, side) => {
                    Probe::Exact(self.signed_from_list(p, slot, d2, side))
                }
            },
        )
    }

    /// Exact unsigned distance to the surface. NaN for a non-finite `p`.
    pub fn distance(&self, p: DVec3) -> f64 {
        // Non-finite points never have a cell (see `signed_distance`).
        if let Some((_, d2, _)) = self.candidates.as_ref().and_then(|g| g.nearest(self, p)) {
            return d2.sqrt();
        }
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
        if let Some(d) = self.signed_from_candidates(p) {
            return d;
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
            Some((slot, d2)) => signed(d2, || self.sign_at(p, slot)),
            // Nothing within max_dist: the side is known, or the exact value
            // (a valid lower bound) settles it.
            None if side != 0.0 => max_dist * side,
            None => self.signed_distance(p),
        }
    }

    /// True inside or on the surface: `signed_distance_bound(p, ε) ≤ 0`
    /// for a tiny ε, without computing the distance where the candidate
    /// grid knows the side of `p`'s whole cell (near the surface, where
    /// the exact query is the expensive part). What a union asks when it
    /// picks the child that holds a point's material.
    pub fn contains(&self, p: DVec3) -> bool {
        if let Some(side) = self.candidates.as_ref().and_then(|g| g.side(p)) {
            return side < 0;
        }
        self.signed_distance_bound(p, 1e-9) <= 0.0
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

/// `sqrt(d2)` with the sign from `sign` (not asked on the surface, `d2 = 0`).
#[inline]
fn signed(d2: f64, sign: impl FnOnce() -> f64) -> f64 {
    if d2 == 0.0 { 0.0 } else { d2.sqrt() * sign() }
}

thread_local! {
    /// The last nearest triangle of the few most recently queried meshes
    /// (keyed by the address of their triangle data).
    static SEED: RecentSlots = const { RecentSlots::new() };
}
