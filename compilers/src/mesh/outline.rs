//! Triangulation of a flat region's outline (see [`super::flat`]).
//!
//! The outline is projected along the normal's largest axis. A small
//! outline that is one convex loop (a flat cube's cut) is cut into a strip
//! of triangles with exact orientation tests alone ([`convex_strip`]); any
//! other is triangulated by a constrained Delaunay triangulation (exact
//! predicates), with a point added inside beside each clustered pair
//! of outline points: one simple loop by [`super::loop_cdt`] (ear cutting
//! and flips), anything else (holes, a loop it refuses) by spade. Both
//! keep every outline point
//! (collinear ones included; dropping one would leave a T-junction). In
//! the Delaunay path faces inside the outline are found by flood fill from
//! the hull, flipping at each outline edge. Triangles are oriented like
//! the outline (the label `x`'s outward side). The region is checked: no
//! duplicate points, no crossing outline edges (Delaunay path; a convex
//! loop has none), and the inside faces' area equal to the outline's
//! (shoelace formula) within 10⁻⁹. A region that fails any check gets `None`, and [`super::flat`]
//! contours it cube by cube with marching tetrahedra instead.

use super::loop_cdt;
use super::vertex_keys::FastMap;

use spade::{ConstrainedDelaunayTriangulation, Point2, Triangulation};

/// Relative area mismatch that rejects a region's triangulation.
const AREA_TOL: f64 = 1e-9;

/// The triangles of the planar region bounded by `outline` (edges as pairs
/// of indices into `verts`, oriented), as indices into `verts`, oriented
/// like the outline; `None` when a check fails (see the module docs).
/// `normal`: the plane's normal, any scale (only its largest component's
/// axis is used).
pub(super) fn triangulate(
    normal: [i32; 3],
    outline: impl ExactSizeIterator<Item = [u32; 2]>,
    verts: &[[f32; 3]],
) -> Option<Triangulated> {
    // Project along the normal's largest component (quantised is enough).
    let n = normal.map(i32::abs);
    let drop = if n[0] >= n[1] && n[0] >= n[2] {
        0
    } else if n[1] >= n[2] {
        1
    } else {
        2
    };
    let (u, v) = ((drop + 1) % 3, (drop + 2) % 3);
    let len = outline.len();
    let mut local: FastMap<u32, usize> = FastMap::with_capacity_and_hasher(len, Default::default());
    let mut global = Vec::with_capacity(len);
    let mut pts = Vec::with_capacity(len);
    let mut edges = Vec::with_capacity(len);
    for e in outline {
        edges.push(e.map(|g| {
            *local.entry(g).or_insert_with(|| {
                let p = verts[g as usize];
                pts.push(Point2::new(f64::from(p[u]), f64::from(p[v])));
                global.push(g);
                global.len() - 1
            })
        }));
    }
    // Each outline edge once, in one direction.
    let mut seen: FastMap<[usize; 2], ()> =
        FastMap::with_capacity_and_hasher(edges.len(), Default::default());
    for e in &edges {
        if e[0] == e[1] || seen.insert([e[0].min(e[1]), e[0].max(e[1])], ()).is_some() {
            return None;
        }
    }
    let area2: f64 = edges
        .iter()
        .map(|[a, b]| pts[*a].x * pts[*b].y - pts[*b].x * pts[*a].y)
        .sum();
    // A small outline's triangles stay within a few voxels whatever its
    // spacing (single flat cubes of curved surfaces are most regions). A
    // larger one takes the Delaunay path: a strip's zig-zag spans the
    // region with every triangle (needles of tenths of a degree across a
    // face, which gmsh's boundary recovery does not get through).
    let small = pts.len() <= SMALL_OUTLINE;
    let even = small || evenly_spaced(&pts, &edges);
    if small && let Some(strip) = convex_strip(&pts, &edges, area2) {
        return oriented(strip, &pts, &global, area2).map(|tris| Triangulated {
            tris,
            added: Vec::new(),
        });
    }
    let mut added = Vec::new();
    let outline_points = pts.len();
    if !even {
        let plane = Plane {
            normal: normal.map(f64::from),
            axes: [drop, u, v],
        };
        added = inner_points(&mut pts, &mut global, &edges, area2, verts, &plane);
    }
    // One simple loop: ear cutting and flips; anything else, or a loop
    // they refuse, spade.
    if let Some(faces) = loop_cdt::triangulate(&pts, &edges, outline_points, area2)
        && let Some(tris) = oriented(faces, &pts, &global, area2)
    {
        return Some(keep_used(tris, added));
    }
    let (count, constraints) = (pts.len(), edges.len());
    let mut conflict = false;
    let cdt = ConstrainedDelaunayTriangulation::<Point2<f64>>::try_bulk_load_cdt(
        pts.clone(),
        edges,
        |_| conflict = true,
    )
    .ok()?;
    if conflict || cdt.num_vertices() != count || cdt.num_constraints() != constraints {
        return None;
    }
    // Parity of outline crossings from the hull: 1 = inside.
    const UNSET: u8 = 2;
    let mut parity = vec![UNSET; cdt.num_inner_faces() + 1];
    let mut stack = Vec::new();
    for f in cdt.inner_faces() {
        for e in f.adjacent_edges() {
            if e.rev().face().is_outer() {
                let p = u8::from(cdt.is_constraint_edge(e.as_undirected().fix()));
                let slot = &mut parity[f.fix().index()];
                if *slot == UNSET {
                    *slot = p;
                    stack.push(f.fix());
                } else if *slot != p {
                    return None;
                }
            }
        }
    }
    while let Some(f) = stack.pop() {
        let pf = parity[f.index()];
        for e in cdt.face(f).adjacent_edges() {
            if let Some(nb) = e.rev().face().as_inner() {
                let p = pf ^ u8::from(cdt.is_constraint_edge(e.as_undirected().fix()));
                let slot = &mut parity[nb.fix().index()];
                if *slot == UNSET {
                    *slot = p;
                    stack.push(nb.fix());
                } else if *slot != p {
                    return None;
                }
            }
        }
    }
    let inside = cdt
        .inner_faces()
        .filter_map(|f| match parity[f.fix().index()] {
            1 => Some(Some(f.vertices().map(|h| h.fix().index()))),
            0 => None,
            _ => Some(None),
        });
    let faces: Option<Vec<[usize; 3]>> = inside.collect();
    let tris = oriented(faces?, &pts, &global, area2)?;
    Some(keep_used(tris, added))
}

/// A region's triangles: indices into the label's vertices, or
/// [`ADDED`]` + k` for `added[k]`, a point inside the region.
pub(super) struct Triangulated {
    pub tris: Vec<[u32; 3]>,
    pub added: Vec<[f32; 3]>,
}

/// Marks an index into [`Triangulated::added`].
pub(super) const ADDED: u32 = 1 << 31;

/// The region's plane: its normal (any scale) and the dropped axis, then
/// the two projected ones.
struct Plane {
    normal: [f64; 3],
    axes: [usize; 3],
}

/// One point inside the region beside each outline edge shorter than
/// [`STRIP_EDGE_RATIO`] of the longest, half the longest edge in from its
/// middle (on the region's side), added to `pts` and `global` (as
/// [`ADDED`]` + k`); their 3D positions, on the plane. Such short edges
/// are the contourer's point clusters around samples the face passes
/// through; without inner points the Delaunay triangulation joins each to
/// a point across the region (needles of hundredths of a degree, which
/// stop gmsh's boundary recovery). A point that lands outside the region
/// leaves an outside face or fails the area check (then the region falls
/// back to marching tetrahedra).
fn inner_points(
    pts: &mut Vec<Point2<f64>>,
    global: &mut Vec<u32>,
    edges: &[[usize; 2]],
    area2: f64,
    verts: &[[f32; 3]],
    plane: &Plane,
) -> Vec<[f32; 3]> {
    let len2 = |pts: &[Point2<f64>], [a, b]: [usize; 2]| {
        let (dx, dy) = (pts[b].x - pts[a].x, pts[b].y - pts[a].y);
        dx * dx + dy * dy
    };
    let longest = edges.iter().map(|e| len2(pts, *e)).fold(0.0, f64::max);
    let short = STRIP_EDGE_RATIO * STRIP_EDGE_RATIO * longest;
    let step = 0.5 * longest.sqrt();
    let [drop, u, v] = plane.axes;
    let n = plane.normal;
    let mut added = Vec::new();
    for &[a, b] in edges {
        let l2 = len2(pts, [a, b]);
        if l2 >= short || l2 <= 0.0 {
            continue;
        }
        // The region is on the left of its outline when it turns
        // counter-clockwise (area2 > 0).
        let (dx, dy) = (pts[b].x - pts[a].x, pts[b].y - pts[a].y);
        let side = area2.signum() * step / l2.sqrt();
        let (du, dv) = (-dy * side, dx * side);
        let [pa, pb] = [a, b].map(|i| verts[global[i] as usize].map(f64::from));
        let mut p: [f64; 3] = std::array::from_fn(|k| 0.5 * (pa[k] + pb[k]));
        p[u] += du;
        p[v] += dv;
        // Along the plane: n · Δ = 0.
        p[drop] -= (n[u] * du + n[v] * dv) / n[drop];
        // Neighbouring short edges (a cluster of three or more points)
        // would add points a rounding error apart, an edge of 10⁻⁶ mm: one
        // point serves them all.
        let near = (0.1 * step) * (0.1 * step);
        let first = pts.len() - added.len();
        if pts[first..].iter().any(|q| {
            let (du, dv) = (q.x - p[u], q.y - p[v]);
            du * du + dv * dv < near
        }) {
            continue;
        }
        pts.push(Point2::new(p[u], p[v]));
        global.push(ADDED + added.len() as u32);
        added.push(p.map(|c| c as f32));
    }
    added
}

/// `tris` with only the added points they use, renumbered in order.
fn keep_used(mut tris: Vec<[u32; 3]>, added: Vec<[f32; 3]>) -> Triangulated {
    let mut new = vec![u32::MAX; added.len()];
    let mut kept = Vec::new();
    for t in &mut tris {
        for i in t.iter_mut().filter(|i| **i >= ADDED) {
            let k = (*i - ADDED) as usize;
            if new[k] == u32::MAX {
                new[k] = kept.len() as u32;
                kept.push(added[k]);
            }
            *i = ADDED + new[k];
        }
    }
    Triangulated { tris, added: kept }
}

/// Outlines of at most this many points are triangulated without inner
/// points.
const SMALL_OUTLINE: usize = 16;
/// Outline edges shorter than this fraction of the longest send the
/// region to the Delaunay path.
const STRIP_EDGE_RATIO: f64 = 0.25;

/// Whether no outline edge is much shorter than the longest. Where a face
/// passes through samples, the contourer's points cluster within `T_MIN`
/// of each sample; a strip joins such a short edge to a point across the
/// region, a needle of a few hundredths of a degree that stops gmsh's
/// boundary recovery, where the Delaunay triangulation joins it to the
/// nearest outline point.
fn evenly_spaced(pts: &[Point2<f64>], edges: &[[usize; 2]]) -> bool {
    let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
    for &[a, b] in edges {
        let (dx, dy) = (pts[b].x - pts[a].x, pts[b].y - pts[a].y);
        let len2 = dx * dx + dy * dy;
        lo = lo.min(len2);
        hi = hi.max(len2);
    }
    lo >= STRIP_EDGE_RATIO * STRIP_EDGE_RATIO * hi
}

/// `faces` (local indices) as global indices oriented like the outline, or
/// `None` when their areas do not add up to the outline's (an overlap or a
/// gap) or there are none.
fn oriented(
    faces: Vec<[usize; 3]>,
    pts: &[Point2<f64>],
    global: &[u32],
    area2: f64,
) -> Option<Vec<[u32; 3]>> {
    let mut out = Vec::with_capacity(faces.len());
    let mut sum2 = 0.0;
    for [a, b, c] in faces {
        let (pa, pb, pc) = (pts[a], pts[b], pts[c]);
        let s = (pb.x - pa.x) * (pc.y - pa.y) - (pb.y - pa.y) * (pc.x - pa.x);
        sum2 += s.abs();
        out.push(if (s > 0.0) == (area2 > 0.0) {
            [global[a], global[b], global[c]]
        } else {
            [global[a], global[c], global[b]]
        });
    }
    if out.is_empty() || (sum2 - area2.abs()).abs() > AREA_TOL * area2.abs() {
        return None;
    }
    Some(out)
}

/// The triangles of an outline that is one convex loop, as a strip, or
/// `None` for any other outline (which the Delaunay path takes).
///
/// Why: a planar face of a box or a slab is a rectangle whose sides carry
/// a point at every voxel, exactly collinear and, four at a time, exactly
/// cocircular, so many of the Delaunay triangulation's in-circle tests
/// take `robust`'s exact path (whose scratch arrays, 26 KB a call, are
/// zeroed on every call: a `memset` that dominates a box's faces). A
/// convex loop needs only orientation tests: every triangle of three of its
/// points is inside it, so zig-zagging between its two ends from a
/// strictly convex corner, taking the side whose triangle turns strictly
/// left (`robust::orient2d`, exact), covers it with `n − 2` triangles and
/// no overlap. Convex means: one loop through every point, every turn left
/// or straight, consecutive points distinct, and x and y each change
/// direction at most twice around it (which rules out a star that turns
/// left at every point but winds twice).
fn convex_strip(pts: &[Point2<f64>], edges: &[[usize; 2]], area2: f64) -> Option<Vec<[usize; 3]>> {
    let n = pts.len();
    if n < 3 || edges.len() != n || area2.is_nan() || area2 == 0.0 {
        return None;
    }
    let mut ring = loop_cdt::one_loop(edges, n, area2 > 0.0)?;
    let at = |i: usize| robust::Coord {
        x: pts[i].x,
        y: pts[i].y,
    };
    let orient = |a: usize, b: usize, c: usize| robust::orient2d(at(a), at(b), at(c));
    let mut start = None;
    // Per axis: the direction of the first and of the last edge that moves
    // along it, and the changes of direction between them.
    let mut dirs = [(0i8, 0i8, 0usize); 2];
    for k in 0..n {
        let (u, w) = (ring[(k + n - 1) % n], ring[(k + 1) % n]);
        let o = orient(u, ring[k], w);
        if o < 0.0 || !o.is_finite() {
            return None;
        }
        if o > 0.0 && start.is_none() {
            start = Some(k);
        }
        let (p, q) = (at(ring[k]), at(w));
        if p.x == q.x && p.y == q.y {
            return None;
        }
        for (d, (first, last, turns)) in [q.x.total_cmp(&p.x), q.y.total_cmp(&p.y)]
            .into_iter()
            .zip(&mut dirs)
        {
            let d = d as i8;
            if d != 0 {
                if *first == 0 {
                    *first = d;
                } else if d != *last {
                    *turns += 1;
                }
                *last = d;
            }
        }
    }
    // Around the loop, the last edge turns back into the first.
    let [(fx, lx, tx), (fy, ly, ty)] = dirs;
    let (turns_x, turns_y) = (tx + usize::from(fx != lx), ty + usize::from(fy != ly));
    if turns_x > 2 || turns_y > 2 {
        return None;
    }
    let s = start?;
    ring.rotate_left(s);
    let mut tris = Vec::with_capacity(n - 2);
    tris.push([ring[n - 1], ring[0], ring[1]]);
    let (mut lo, mut hi) = (1, n - 1);
    let mut from_lo = true;
    while hi - lo > 1 {
        let a = orient(ring[lo], ring[lo + 1], ring[hi]) > 0.0;
        let b = orient(ring[lo], ring[hi - 1], ring[hi]) > 0.0;
        let take_lo = match (a, b) {
            (true, true) => from_lo,
            (true, false) => true,
            (false, true) => false,
            (false, false) => return None,
        };
        if take_lo {
            tris.push([ring[lo], ring[lo + 1], ring[hi]]);
            lo += 1;
        } else {
            tris.push([ring[lo], ring[hi - 1], ring[hi]]);
            hi -= 1;
        }
        from_lo = !take_lo;
    }
    Some(tris)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `loop_pts` as vertices in the z = 0 plane and the loop's edges.
    fn outline(loop_pts: &[[f32; 2]]) -> (Vec<[f32; 3]>, Vec<[u32; 2]>) {
        let verts = loop_pts.iter().map(|p| [p[0], p[1], 0.0]).collect();
        let n = loop_pts.len() as u32;
        let edges = (0..n).map(|i| [i, (i + 1) % n]).collect();
        (verts, edges)
    }

    fn area2(verts: &[[f32; 3]], t: [u32; 3]) -> f64 {
        let p = t.map(|i| verts[i as usize].map(f64::from));
        (p[1][0] - p[0][0]) * (p[2][1] - p[0][1]) - (p[1][1] - p[0][1]) * (p[2][0] - p[0][0])
    }

    /// A rectangle with a point every `step` along its sides, counter-
    /// clockwise (or clockwise when `cw`): a box's face.
    fn rectangle(w: usize, h: usize, cw: bool) -> Vec<[f32; 2]> {
        let mut p = Vec::new();
        (0..w).for_each(|i| p.push([i as f32 * 0.25, 0.0]));
        (0..h).for_each(|j| p.push([w as f32 * 0.25, j as f32 * 0.25]));
        (0..w).for_each(|i| p.push([(w - i) as f32 * 0.25, h as f32 * 0.25]));
        (0..h).for_each(|j| p.push([0.0, (h - j) as f32 * 0.25]));
        if cw {
            p.reverse();
        }
        p
    }

    fn strip_of(loop_pts: &[[f32; 2]]) -> Option<Vec<[usize; 3]>> {
        let pts: Vec<Point2<f64>> = loop_pts
            .iter()
            .map(|p| Point2::new(f64::from(p[0]), f64::from(p[1])))
            .collect();
        let n = pts.len();
        let edges: Vec<[usize; 2]> = (0..n).map(|i| [i, (i + 1) % n]).collect();
        let area2: f64 = edges
            .iter()
            .map(|[a, b]| pts[*a].x * pts[*b].y - pts[*b].x * pts[*a].y)
            .sum();
        convex_strip(&pts, &edges, area2)
    }

    #[test]
    fn convex_loops_become_strips_that_tile_them() {
        for cw in [false, true] {
            let r = rectangle(40, 7, cw);
            let n = r.len();
            assert_eq!(strip_of(&r).map(|t| t.len()), Some(n - 2), "a convex loop");
            let (verts, edges) = outline(&r);
            let tris = triangulate([0, 0, 1], edges.into_iter(), &verts)
                .expect("triangulated")
                .tris;
            assert_eq!(tris.len(), n - 2);
            // Every point kept, every triangle turning like the outline
            // (strictly: no sliver of zero area), areas adding up.
            let mut used = vec![false; n];
            let sign = if cw { -1.0 } else { 1.0 };
            let mut sum = 0.0;
            for t in &tris {
                t.iter().for_each(|&i| used[i as usize] = true);
                let a = area2(&verts, *t) * sign;
                assert!(a > 0.0, "{t:?}: {a}");
                sum += a;
            }
            assert!(used.iter().all(|&u| u));
            let want = 2.0 * 40.0 * 7.0 * 0.0625;
            assert!((sum - want).abs() < 1e-9 * want, "{sum} vs {want}");
        }
    }

    #[test]
    fn other_outlines_take_the_delaunay_path() {
        // An L (a reflex corner), a star that turns left at every point
        // but winds twice, and a square with a hole (two loops).
        let l = [
            [0.0, 0.0],
            [2.0, 0.0],
            [2.0, 1.0],
            [1.0, 1.0],
            [1.0, 2.0],
            [0.0, 2.0],
        ];
        assert!(strip_of(&l).is_none());
        let star: Vec<[f32; 2]> = (0..5)
            .map(|k| {
                let a = std::f32::consts::TAU * (2 * k) as f32 / 5.0;
                [a.cos(), a.sin()]
            })
            .collect();
        assert!(strip_of(&star).is_none());
        // A rectangle whose bottom side's points wobble by 10⁻⁴ (some turn
        // right): not convex, so Delaunay triangulates it.
        let mut wobbly = rectangle(30, 5, false);
        for (i, p) in wobbly.iter_mut().enumerate().take(30).skip(1) {
            p[1] = if i % 3 == 0 { 1e-4 } else { -1e-4 };
        }
        assert!(strip_of(&wobbly).is_none());
        let (verts, edges) = outline(&wobbly);
        let tris = triangulate([0, 0, 1], edges.into_iter(), &verts)
            .expect("the wobbly one")
            .tris;
        assert_eq!(tris.len(), wobbly.len() - 2);
        let (verts, edges) = outline(&l);
        let tris = triangulate([0, 0, 1], edges.into_iter(), &verts)
            .expect("the L")
            .tris;
        assert_eq!(tris.len(), 4);
        let sum: f64 = tris.iter().map(|t| area2(&verts, *t)).sum();
        assert!((sum - 6.0).abs() < 1e-12, "{sum}");
        let mut verts: Vec<[f32; 3]> = Vec::new();
        let mut edges = Vec::new();
        for (square, cw) in [(4.0f32, false), (1.0, true)] {
            let base = verts.len() as u32;
            let mut c = [
                [-square, -square],
                [square, -square],
                [square, square],
                [-square, square],
            ];
            if cw {
                c.reverse();
            }
            verts.extend(c.iter().map(|p| [p[0], p[1], 0.0]));
            edges.extend((0..4).map(|i| [base + i, base + (i + 1) % 4]));
        }
        let pts: Vec<Point2<f64>> = verts
            .iter()
            .map(|p| Point2::new(f64::from(p[0]), f64::from(p[1])))
            .collect();
        let local: Vec<[usize; 2]> = edges.iter().map(|e| e.map(|i| i as usize)).collect();
        assert!(convex_strip(&pts, &local, 1.0).is_none(), "two loops");
        let tris = triangulate([0, 0, 1], edges.into_iter(), &verts)
            .expect("the holed square")
            .tris;
        let sum: f64 = tris.iter().map(|t| area2(&verts, *t)).sum();
        assert!((sum - (64.0 - 4.0) * 2.0).abs() < 1e-9, "{sum}");
    }

    #[test]
    fn clustered_points_get_inner_points_instead_of_needles() {
        // A 20 × 6 rectangle whose top and bottom sides carry a second
        // point 0.05 beside each of their points, as where a face passes
        // through samples.
        let mut loop_pts = Vec::new();
        for i in 0..20 {
            loop_pts.extend([[i as f32, 0.0], [i as f32 + 0.05, 0.0]]);
        }
        loop_pts.extend((0..6).map(|j| [20.0, j as f32]));
        for i in (1..=20).rev() {
            loop_pts.extend([[i as f32, 6.0], [i as f32 - 0.05, 6.0]]);
        }
        loop_pts.push([0.0, 6.0]);
        loop_pts.extend((1..6).rev().map(|j| [0.0, j as f32]));
        let (verts, edges) = outline(&loop_pts);
        let t = triangulate([0, 0, 1], edges.into_iter(), &verts).expect("triangulated");
        assert!(!t.added.is_empty());
        let mut all = verts.clone();
        all.extend(&t.added);
        let at = |i: u32| {
            let i = if i >= ADDED {
                verts.len() + (i - ADDED) as usize
            } else {
                i as usize
            };
            glam::DVec2::new(f64::from(all[i][0]), f64::from(all[i][1]))
        };
        let mut sum = 0.0;
        let mut smallest = 180.0f64;
        for tri in &t.tris {
            let p = tri.map(at);
            sum += (p[1] - p[0]).perp_dot(p[2] - p[0]);
            for k in 0..3 {
                let (u, w) = (p[(k + 1) % 3] - p[k], p[(k + 2) % 3] - p[k]);
                smallest = smallest.min(u.angle_to(w).abs().to_degrees());
            }
        }
        assert!((sum - 240.0).abs() < 1e-6, "{sum}");
        // Without inner points a short side meets a point 6 across: 0.5°.
        assert!(smallest > 2.0, "{smallest}°");
    }
}
