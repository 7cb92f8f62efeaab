//! The constrained Delaunay triangulation of one simple loop (a flat
//! region's outline, [`super::outline`]) with optional points inside, by
//! ear cutting and edge flips.
//!
//! Why not spade here: most outlines of an imported mesh's faces are one
//! loop of a few dozen points, where spade's general bulk load (hull,
//! buckets, constraint insertion by walking) is mostly overhead; see
//! docs/PERFORMANCE.md, "Contouring", for how to measure both.
//!
//! 1. The loop must be simple: no two edges meet but consecutive ones at
//!    their shared point (a sweep over the edges' boxes, exact tests).
//! 2. Ears are cut (Meisters' two-ears theorem: a simple polygon of more
//!    than three points has an ear; only points that are not strictly
//!    convex can lie in one, Eberly, "Triangulation by Ear Clipping"),
//!    every other point round the loop.
//! 3. Each inner point splits the triangle it lies in (or the two beside
//!    the inner edge it lies on); one outside the loop is not used.
//! 4. Lawson flips: an inner edge whose opposite point lies strictly in
//!    the other triangle's circumcircle is flipped until none does. Only
//!    outline edges are constrained, and they are never flipped, so the
//!    result is the constrained Delaunay triangulation (unique but for
//!    cocircular ties; de Berg et al., *Computational Geometry*, 9.1–9.3),
//!    where a quad too near cocircular for the floating-point filter to
//!    decide counts as a tie ([`surely_in_circle`]).
//!
//! Orientations are `robust`'s exact `orient2d`. `None`
//! where any step cannot be taken (not one loop, not simple, an inner
//! point on the outline or on another point, too many points); the caller
//! then takes spade's path, which decides those cases as before.

use robust::{Coord, orient2d};
use spade::Point2;

/// Loops with more points than this (a box's long face) take spade's
/// path: ear cutting tests every remaining non-convex point per ear.
const MAX_POINTS: usize = 256;

const NONE: usize = usize::MAX;

/// Triangles (indices into `pts`, counter-clockwise) of the loop given by
/// `edges` over the first `outline` points of `pts`, with `pts[outline..]`
/// inside it; `None` as the module docs say. `area2`: twice the loop's
/// signed area.
pub(super) fn triangulate(
    pts: &[Point2<f64>],
    edges: &[[usize; 2]],
    outline: usize,
    area2: f64,
) -> Option<Vec<[usize; 3]>> {
    let n = outline;
    if !(3..=MAX_POINTS).contains(&n) || edges.len() != n || area2 == 0.0 || area2.is_nan() {
        return None;
    }
    let at = |i: usize| Coord {
        x: pts[i].x,
        y: pts[i].y,
    };
    let ring = one_loop(edges, n, area2 > 0.0)?;
    if !simple(&ring, &at) {
        return None;
    }
    // Ears give n − 2 triangles and each inner point two more: room for
    // all at once (grown push by push, each growth copied them).
    let most = n - 2 + 2 * (pts.len() - outline);
    let mut mesh = Mesh {
        tris: Vec::with_capacity(most),
        nbr: Vec::with_capacity(most),
    };
    cut_ears(&ring, &at, &mut mesh)?;
    let mut hint = 0;
    for p in outline..pts.len() {
        mesh.insert(p, &at, &mut hint)?;
    }
    mesh.flip_to_delaunay(&at);
    Some(mesh.tris)
}

/// The loop's points in order, counter-clockwise (`ccw`: the edges
/// already run so); `None` unless the edges (indices below `n`) form one
/// loop through all `n` points: each point starts one edge, and following
/// them from point 0 comes back to it after exactly `n`.
pub(super) fn one_loop(edges: &[[usize; 2]], n: usize, ccw: bool) -> Option<Vec<usize>> {
    let mut next = vec![NONE; n];
    for &[a, b] in edges {
        if a >= n || b >= n || next[a] != NONE {
            return None;
        }
        next[a] = b;
    }
    let mut ring = Vec::with_capacity(n);
    let mut v = 0;
    for _ in 0..n {
        if v == NONE || (v == 0 && !ring.is_empty()) {
            return None;
        }
        ring.push(v);
        v = next[v];
    }
    if v != 0 {
        return None;
    }
    if !ccw {
        ring.reverse();
    }
    Some(ring)
}

/// No two edges of the loop meet, but consecutive ones at their shared
/// point without folding back along each other.
fn simple(ring: &[usize], at: &impl Fn(usize) -> Coord<f64>) -> bool {
    let n = ring.len();
    let mut segs = Vec::with_capacity(n);
    for k in 0..n {
        let (p, q) = (at(ring[k]), at(ring[(k + 1) % n]));
        let r = at(ring[(k + 2) % n]);
        if p.x == q.x && p.y == q.y {
            return false;
        }
        // Folding back: r on the line pq, on p's side of q.
        let back = (p.x - q.x) * (r.x - q.x) + (p.y - q.y) * (r.y - q.y);
        if orient2d(p, q, r) == 0.0 && back > 0.0 {
            return false;
        }
        let lo = [p.x.min(q.x), p.y.min(q.y)];
        let hi = [p.x.max(q.x), p.y.max(q.y)];
        segs.push((lo, hi, p, q));
    }
    // Sweep in x: each edge against those whose box starts before its own
    // box ends. The order is sorted as (x key, edge) pairs, not the edges
    // themselves (72 bytes each).
    let mut order: Vec<(u64, usize)> = segs
        .iter()
        .enumerate()
        .map(|(k, s)| (ordered_bits(s.0[0]), k))
        .collect();
    order.sort_unstable();
    for (i, &(_, a)) in order.iter().enumerate() {
        let (lo, hi, p, q) = segs[a];
        for &(_, b) in &order[i + 1..] {
            let (lo_b, hi_b, r, s) = segs[b];
            if lo_b[0] > hi[0] {
                break;
            }
            let consecutive = a.abs_diff(b) == 1 || a.abs_diff(b) == n - 1;
            if consecutive || hi_b[1] < lo[1] || lo_b[1] > hi[1] {
                continue;
            }
            if segments_meet(p, q, r, s) {
                return false;
            }
        }
    }
    true
}

/// `x`'s bits as an integer in `f64::total_cmp`'s order.
fn ordered_bits(x: f64) -> u64 {
    let b = x.to_bits();
    if b >> 63 == 1 { !b } else { b | 1 << 63 }
}

/// Whether the closed segments pq and rs share a point.
fn segments_meet(p: Coord<f64>, q: Coord<f64>, r: Coord<f64>, s: Coord<f64>) -> bool {
    let (o1, o2) = (orient2d(p, q, r), orient2d(p, q, s));
    let (o3, o4) = (orient2d(r, s, p), orient2d(r, s, q));
    if o1 * o2 < 0.0 && o3 * o4 < 0.0 {
        return true;
    }
    // Touching: an end on the other segment (its box, being on its line).
    let on = |a: Coord<f64>, b: Coord<f64>, c: Coord<f64>| {
        c.x >= a.x.min(b.x) && c.x <= a.x.max(b.x) && c.y >= a.y.min(b.y) && c.y <= a.y.max(b.y)
    };
    (o1 == 0.0 && on(p, q, r))
        || (o2 == 0.0 && on(p, q, s))
        || (o3 == 0.0 && on(r, s, p))
        || (o4 == 0.0 && on(r, s, q))
}

/// Whether `d` lies strictly inside the circle through the
/// counter-clockwise `a`, `b`, `c`, as far as the floating-point
/// determinant can tell: Shewchuk's first filter (`ICCERRBOUND_A`, as in
/// `robust::incircle`), answering no where it cannot decide. A yes is
/// exact (the determinant's sign is proven), so every flip taken is one
/// the exact predicate would take, and Lawson's flips still end (each
/// raises the triangulation's sorted angle vector); a quad too near
/// cocircular for the filter is left as it is, either diagonal being
/// Delaunay within rounding. Why not the exact predicate: its adaptive
/// stage zeroes about 9 KB of scratch a call, and near-cocircular quads
/// are common where outline points sit symmetrically on the voxel grid.
fn surely_in_circle(a: Coord<f64>, b: Coord<f64>, c: Coord<f64>, d: Coord<f64>) -> bool {
    /// (10 + 96ε)ε with ε = 2⁻⁵³ (Shewchuk, "Adaptive Precision
    /// Floating-Point Arithmetic and Fast Robust Geometric Predicates").
    const ICCERRBOUND_A: f64 = (10.0 + 96.0 * EPSILON) * EPSILON;
    const EPSILON: f64 = f64::EPSILON / 2.0;
    let (adx, ady) = (a.x - d.x, a.y - d.y);
    let (bdx, bdy) = (b.x - d.x, b.y - d.y);
    let (cdx, cdy) = (c.x - d.x, c.y - d.y);
    let (bdxcdy, cdxbdy) = (bdx * cdy, cdx * bdy);
    let (cdxady, adxcdy) = (cdx * ady, adx * cdy);
    let (adxbdy, bdxady) = (adx * bdy, bdx * ady);
    let alift = adx * adx + ady * ady;
    let blift = bdx * bdx + bdy * bdy;
    let clift = cdx * cdx + cdy * cdy;
    let det = alift * (bdxcdy - cdxbdy) + blift * (cdxady - adxcdy) + clift * (adxbdy - bdxady);
    let permanent = (bdxcdy.abs() + cdxbdy.abs()) * alift
        + (cdxady.abs() + adxcdy.abs()) * blift
        + (adxbdy.abs() + bdxady.abs()) * clift;
    det > ICCERRBOUND_A * permanent
}

/// Two triangles across an inner edge: `t` = a b c (the caller's), `u` =
/// b a d, and the neighbours beyond sides b c, c a, a d and d b.
struct Quad {
    u: usize,
    corners: [usize; 4],
    t_bc: usize,
    t_ca: usize,
    u_ad: usize,
    u_db: usize,
}

/// Triangles with their neighbours: `nbr[t][k]` lies across the edge
/// from `tris[t][k]` to `tris[t][(k + 1) % 3]` (`NONE` on the outline).
struct Mesh {
    tris: Vec<[usize; 3]>,
    nbr: Vec<[usize; 3]>,
}

/// Cuts the counter-clockwise simple loop `ring` into ears, into `mesh`.
fn cut_ears(ring: &[usize], at: &impl Fn(usize) -> Coord<f64>, mesh: &mut Mesh) -> Option<()> {
    let n = ring.len();
    let mut prev: Vec<usize> = (0..n).map(|k| (k + n - 1) % n).collect();
    let mut next: Vec<usize> = (0..n).map(|k| (k + 1) % n).collect();
    let convex =
        |p: usize, v: usize, x: usize| orient2d(at(ring[p]), at(ring[v]), at(ring[x])) > 0.0;
    let mut is_convex: Vec<bool> = (0..n).map(|k| convex(prev[k], k, next[k])).collect();
    // Cutting an ear only narrows its neighbours' angles, so no point
    // becomes reflex: the points an ear must be tested against are among
    // those not strictly convex at the start, kept sorted by x for the
    // ear's box.
    let mut reflex: Vec<(f64, usize)> = Vec::with_capacity(n);
    reflex.extend(
        (0..n)
            .filter(|&k| !is_convex[k])
            .map(|k| (at(ring[k]).x, k)),
    );
    reflex.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    // The triangle (and its side) beyond the current edge k → next[k];
    // NONE while that edge is the outline's.
    let mut beyond = vec![(NONE, 0usize); n];
    let (mut left, mut v, mut stalled) = (n, 0, 0);
    while left > 3 {
        let (p, x) = (prev[v], next[v]);
        if is_convex[v] && ear_is_empty(ring, at, &reflex, &is_convex, [p, v, x]) {
            let t = mesh.tris.len();
            mesh.tris.push([ring[p], ring[v], ring[x]]);
            mesh.nbr.push([NONE; 3]);
            mesh.link(t, 0, beyond[p]);
            mesh.link(t, 1, beyond[v]);
            beyond[p] = (t, 2);
            next[p] = x;
            prev[x] = p;
            left -= 1;
            is_convex[p] = convex(prev[p], p, x);
            is_convex[x] = convex(p, x, next[x]);
            // The next ear tried is two points on, not `p`: going back
            // fans every cut from one point (slivers the flips then undo);
            // going round cuts every other corner, smaller triangles
            // first, much nearer the Delaunay one.
            (v, stalled) = (next[x], 0);
        } else {
            v = x;
            stalled += 1;
            if stalled > left {
                return None;
            }
        }
    }
    let (p, x) = (prev[v], next[v]);
    let t = mesh.tris.len();
    mesh.tris.push([ring[p], ring[v], ring[x]]);
    mesh.nbr.push([NONE; 3]);
    mesh.link(t, 0, beyond[p]);
    mesh.link(t, 1, beyond[v]);
    mesh.link(t, 2, beyond[x]);
    Some(())
}

/// No remaining point that is not strictly convex, other than the ear's
/// own, lies in the closed triangle `[p, v, x]` (ring positions).
/// `reflex`: the candidates by x (cut points are convex, so skipped).
fn ear_is_empty(
    ring: &[usize],
    at: &impl Fn(usize) -> Coord<f64>,
    reflex: &[(f64, usize)],
    is_convex: &[bool],
    [p, v, x]: [usize; 3],
) -> bool {
    let tri = [at(ring[p]), at(ring[v]), at(ring[x])];
    let bounds = Bounds::of(&tri);
    let first = reflex.partition_point(|r| r.0 < bounds.lo[0]);
    for &(wx, w) in &reflex[first..] {
        if wx > bounds.hi[0] {
            break;
        }
        if is_convex[w] || w == p || w == x {
            continue;
        }
        let q = at(ring[w]);
        if bounds.holds(q) && in_closed(&tri, q) {
            return false;
        }
    }
    true
}

/// Whether `q` lies in the closed counter-clockwise triangle `t`.
fn in_closed([a, b, c]: &[Coord<f64>; 3], q: Coord<f64>) -> bool {
    orient2d(*a, *b, q) >= 0.0 && orient2d(*b, *c, q) >= 0.0 && orient2d(*c, *a, q) >= 0.0
}

/// A triangle's box: a few compares reject most points before the exact
/// tests.
struct Bounds {
    lo: [f64; 2],
    hi: [f64; 2],
}

impl Bounds {
    fn of(t: &[Coord<f64>; 3]) -> Bounds {
        Bounds {
            lo: [
                t[0].x.min(t[1].x).min(t[2].x),
                t[0].y.min(t[1].y).min(t[2].y),
            ],
            hi: [
                t[0].x.max(t[1].x).max(t[2].x),
                t[0].y.max(t[1].y).max(t[2].y),
            ],
        }
    }

    fn holds(&self, q: Coord<f64>) -> bool {
        q.x >= self.lo[0] && q.x <= self.hi[0] && q.y >= self.lo[1] && q.y <= self.hi[1]
    }
}

impl Mesh {
    /// Makes `t`'s side `k` and `(u, j)` neighbours (`u` may be NONE).
    fn link(&mut self, t: usize, k: usize, (u, j): (usize, usize)) {
        self.nbr[t][k] = u;
        if u != NONE {
            self.nbr[u][j] = t;
        }
    }

    /// Side `k` of `t` (a → b, `c` opposite) and the triangle `u` = b a d
    /// across it, with the four outer neighbours; `None` on the outline.
    fn quad(&self, t: usize, k: usize) -> Option<Quad> {
        let (u, j, corners) = self.across(t, k)?;
        Some(self.outer(t, k, u, j, corners))
    }

    /// [`Self::quad`]'s triangle `u`, the side `j` of `u` that is b → a,
    /// and the corners a b c d, without the outer neighbours: the flips
    /// read these for every edge they test and the rest only for the few
    /// they flip.
    #[inline(always)]
    fn across(&self, t: usize, k: usize) -> Option<(usize, usize, [usize; 4])> {
        let u = self.nbr[t][k];
        if u == NONE {
            return None;
        }
        let [a, b, c] = [0, 1, 2].map(|i| self.tris[t][(k + i) % 3]);
        let j = self.side_of(u, b, a);
        Some((u, j, [a, b, c, self.tris[u][(j + 2) % 3]]))
    }

    /// The quad of [`Self::across`]'s answer.
    #[inline(always)]
    fn outer(&self, t: usize, k: usize, u: usize, j: usize, corners: [usize; 4]) -> Quad {
        Quad {
            u,
            corners,
            t_bc: self.nbr[t][(k + 1) % 3],
            t_ca: self.nbr[t][(k + 2) % 3],
            u_ad: self.nbr[u][(j + 1) % 3],
            u_db: self.nbr[u][(j + 2) % 3],
        }
    }

    /// The side of `u` that is the edge b → a.
    #[inline(always)]
    fn side_of(&self, u: usize, b: usize, a: usize) -> usize {
        let t = self.tris[u];
        (0..3)
            .find(|&j| t[j] == b && t[(j + 1) % 3] == a)
            .unwrap_or(0)
    }

    /// Points `u`'s side that faced `old` at `new` instead.
    fn repoint(&mut self, u: usize, old: usize, new: usize) {
        if u != NONE
            && let Some(s) = self.nbr[u].iter_mut().find(|s| **s == old)
        {
            *s = new;
        }
    }

    /// Inserts point `p` into the triangle it lies in: three triangles, or
    /// four where it lies on an inner edge; nothing when it lies outside
    /// every triangle. `None` on the outline or on a point. `hint`: where
    /// to start looking (the last insertion's triangle: inner points come
    /// in outline order, each near the last).
    fn insert(
        &mut self,
        p: usize,
        at: &impl Fn(usize) -> Coord<f64>,
        hint: &mut usize,
    ) -> Option<()> {
        let q = at(p);
        let Some((t, o)) = self.walk(*hint, q, at).or_else(|| self.scan(q, at)) else {
            return Some(());
        };
        *hint = t;
        match o.iter().filter(|&&x| x == 0.0).count() {
            0 => {
                self.split(t, p);
                Some(())
            }
            1 => {
                let k = (0..3).find(|&k| o[k] == 0.0)?;
                self.split_edge(t, k, p)
            }
            _ => None,
        }
    }

    /// `q`'s side of each of `t`'s edges (positive: left, inside).
    fn sides(&self, t: usize, q: Coord<f64>, at: &impl Fn(usize) -> Coord<f64>) -> [f64; 3] {
        let [a, b, c] = self.tris[t].map(at);
        [orient2d(a, b, q), orient2d(b, c, q), orient2d(c, a, q)]
    }

    /// The triangle holding `q` (closed), and `q`'s sides of it, by
    /// walking from `t` across an edge `q` lies beyond; `None` where the
    /// walk meets the outline or goes on too long (a walk may circle in a
    /// triangulation that is not Delaunay).
    fn walk(
        &self,
        mut t: usize,
        q: Coord<f64>,
        at: &impl Fn(usize) -> Coord<f64>,
    ) -> Option<(usize, [f64; 3])> {
        for _ in 0..self.tris.len() {
            let o = self.sides(t, q, at);
            match (0..3).find(|&k| o[k] < 0.0) {
                None => return Some((t, o)),
                Some(k) if self.nbr[t][k] != NONE => t = self.nbr[t][k],
                Some(_) => return None,
            }
        }
        None
    }

    /// The triangle holding `q`, by trying each; `None` outside them all.
    fn scan(&self, q: Coord<f64>, at: &impl Fn(usize) -> Coord<f64>) -> Option<(usize, [f64; 3])> {
        (0..self.tris.len()).find_map(|t| {
            if !Bounds::of(&self.tris[t].map(at)).holds(q) {
                return None;
            }
            let o = self.sides(t, q, at);
            o.iter().all(|&x| x >= 0.0).then_some((t, o))
        })
    }

    /// Splits triangle `t` at inner point `p` into three.
    fn split(&mut self, t: usize, p: usize) {
        let [a, b, c] = self.tris[t];
        let [na, nb, nc] = self.nbr[t];
        let (u, w) = (self.tris.len(), self.tris.len() + 1);
        self.tris[t] = [a, b, p];
        self.nbr[t] = [na, u, w];
        self.tris.push([b, c, p]);
        self.nbr.push([nb, w, t]);
        self.tris.push([c, a, p]);
        self.nbr.push([nc, t, u]);
        self.repoint(nb, t, u);
        self.repoint(nc, t, w);
    }

    /// Splits side `k` of `t` (an inner edge a → b) and both triangles
    /// beside it at `p`, which lies on it; `None` on the outline.
    fn split_edge(&mut self, t: usize, k: usize, p: usize) -> Option<()> {
        let q = self.quad(t, k)?;
        let (u, [a, b, c, d]) = (q.u, q.corners);
        let (t2, u2) = (self.tris.len(), self.tris.len() + 1);
        // t: a p c, t2: p b c, u: b p d, u2: p a d.
        self.tris[t] = [a, p, c];
        self.nbr[t] = [u2, t2, q.t_ca];
        self.tris[u] = [b, p, d];
        self.nbr[u] = [t2, u2, q.u_db];
        self.tris.push([p, b, c]);
        self.nbr.push([u, q.t_bc, t]);
        self.tris.push([p, a, d]);
        self.nbr.push([t, q.u_ad, u]);
        self.repoint(q.t_bc, t, t2);
        self.repoint(q.u_ad, u, u2);
        Some(())
    }

    /// Lawson's flips until every inner edge is locally Delaunay.
    ///
    /// A stack of sides (triangle, side): each inner edge once to begin
    /// with, then after each flip the four outer sides of its quad, the
    /// only edges a flip can make illegal (the new diagonal is legal). A
    /// side whose triangle a later flip rewrote names another edge of it;
    /// that flip pushed the sides it took over.
    fn flip_to_delaunay(&mut self, at: &impl Fn(usize) -> Coord<f64>) {
        // Each inner edge once (about 3/2 a triangle), and room for the
        // flips' pushes.
        let mut stack: Vec<(usize, usize)> = Vec::with_capacity(3 * self.tris.len());
        stack.extend(
            (0..self.tris.len())
                .flat_map(|t| (0..3).map(move |k| (t, k)))
                .filter(|&(t, k)| {
                    let u = self.nbr[t][k];
                    u != NONE && t < u
                }),
        );
        while let Some((t, k)) = stack.pop() {
            if let Some(u) = self.flip(t, k, at) {
                stack.extend([(t, 0), (t, 1), (u, 0), (u, 1)]);
            }
        }
    }

    /// Flips side `k` of `t` (a → b, with `c` opposite) when the point
    /// `d` across it lies strictly in the circle through a, b, c; returns
    /// the other triangle it changed.
    fn flip(&mut self, t: usize, k: usize, at: &impl Fn(usize) -> Coord<f64>) -> Option<usize> {
        let (u, j, corners) = self.across(t, k)?;
        let [a, b, c, d] = corners;
        if !surely_in_circle(at(a), at(b), at(c), at(d)) {
            return None;
        }
        // Strictly inside makes the quad a d b c strictly convex, so both
        // new triangles turn left (checked all the same, exactly).
        if orient2d(at(c), at(a), at(d)) <= 0.0 || orient2d(at(d), at(b), at(c)) <= 0.0 {
            return None;
        }
        let q = self.outer(t, k, u, j, corners);
        self.tris[t] = [c, a, d];
        self.nbr[t] = [q.t_ca, q.u_ad, u];
        self.tris[u] = [d, b, c];
        self.nbr[u] = [q.u_db, q.t_bc, t];
        self.repoint(q.u_ad, u, t);
        self.repoint(q.t_bc, t, u);
        Some(u)
    }
}

#[cfg(test)]
mod tests;
