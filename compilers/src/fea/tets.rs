//! C3D4 tetrahedra by isosurface stuffing on the graded lattice.
//!
//! Labelle & Shewchuk 2007 ("Isosurface Stuffing: Fast Tetrahedral Meshes
//! with Good Dihedral Angles", SIGGRAPH): take a background mesh of good
//! tetrahedra, find where the surface `d = 0` crosses its edges (cut points),
//! *warp* every lattice vertex that lies within `α·|e|` of a cut point on one
//! of its edges onto that cut point (it becomes a surface vertex), then fill
//! each background tetrahedron's inside part from a stencil. Warping removes
//! the cut points that would make slivers; the remaining cuts are at least
//! `α·|e|` from both ends of their edge. On a graded lattice the warp is
//! also capped by the vertex's shortest edge (see [`STUFF`]).
//!
//! Stencils, generically. A background tetrahedron whose (warped) vertices
//! are all `−` or `0` is kept whole; one with no `−` vertex is dropped; one
//! with `−` and `+` vertices is cut. Its inside part is the convex polytope
//! whose faces are the four faces clipped to the inside (Sutherland–Hodgman,
//! kept in outward order) and the cut face (the edges that only one clipped
//! face uses, reversed). Quadrilaterals are split by the diagonal through
//! their smallest vertex key, which two tetrahedra sharing the face agree on,
//! so the mesh conforms; the polytope is then coned from its smallest-key
//! vertex (every face not containing it, with it, is one tetrahedron). For a
//! prism this is Dompierre et al. 1999's rule, which never meets the one
//! untetrahedralisable diagonal pattern. Element orientation comes from the
//! background tetrahedron, so an element that warping turned inside out is
//! detected by its negative volume.
//!
//! Where the lattice comes from: `refine.rs` (size from
//! heterogeneity, then geometry: lost thin features, boundary shape).
//!
//! The angle guarantee. Labelle & Shewchuk prove [10.7°, 164.8°] for the
//! uniform BCC lattice with their α values; this lattice (graded Kuhn
//! tetrahedra, see `lattice.rs`, graded up to the surface) has no such
//! proof, so the bound is enforced: any element outside
//! `[min_angle, max_angle]` or with non-positive volume is removed (measured
//! rate: about 6 in 10⁵, see [`STUFF`]). Removing elements from a conforming
//! mesh leaves it conforming (no vertex becomes hanging); the surface then
//! deviates locally by at most one element. The count is reported so a user
//! sees when it happens.
//!
//! Limits: sharp creases are rounded at the scale of the boundary elements
//! (`L/4` at most, see `refine.rs`), and a wall thinner than about
//! `2α` times the local element size is thinned by warping; use a smaller
//! `max_cell` (or a sizing expression) for thin-walled designs.

use std::sync::atomic::{AtomicBool, Ordering};

use glam::DVec3;
use rayon::prelude::*;
use volcad_core::Model;
use volcad_core::model::MAX_MATERIALS;

use super::lattice::{Lattice, edge};
use super::quality::{QualityReport, dihedral_range, signed_volume};

/// One material slot per element, drawn from the fractions at its centroid
/// (or, for an element whose centroid falls just outside a curved surface,
/// at the first inside point among its corners and the midpoints towards
/// them), keyed by the element index.
pub fn draw_materials(model: &Model, m: &TetMesh, seed: u64) -> Vec<Option<usize>> {
    let k = model.materials().len();
    (0..m.tets.len())
        .into_par_iter()
        .map(|e| {
            let c = m.tets[e].map(|i| m.nodes[i as usize]);
            let centroid = (c[0] + c[1] + c[2] + c[3]) * 0.25;
            let mut f = [0.0f64; MAX_MATERIALS];
            let candidates = std::iter::once(centroid)
                .chain(c.iter().map(|p| (centroid + *p) * 0.5))
                .chain(c.iter().copied());
            for p in candidates {
                if model.eval_into(p, &mut f[..k]) <= 0.0 && f[..k].iter().any(|v| *v > 0.0) {
                    return super::draw(&f[..k], seed, e as u64);
                }
            }
            None
        })
        .collect()
}

/// Stuffing parameters.
#[derive(Clone, Copy, Debug)]
pub struct StuffParams {
    /// Warp threshold as a fraction of the edge length (< 0.5).
    pub alpha: f64,
    /// A warp also moves a vertex at most `graded_cap · alpha` times its
    /// shortest lattice edge (see [`STUFF`]).
    pub graded_cap: f64,
    /// Smallest dihedral angle an element may have (degrees).
    pub min_angle: f64,
    /// Largest dihedral angle an element may have (degrees).
    pub max_angle: f64,
}

/// The defaults: α = 0.33, warps capped at 1.5 α of the vertex's shortest
/// edge, and the enforced bounds [10°, 165°].
///
/// Chosen by a sweep (α 0.2 … 0.45) over 108 meshes: 36 shapes (offset
/// spheres, rotated boxes, spheres with oblique holes), each uniform and
/// graded 4× and 8×, with no bound enforced. The plain rule of Labelle &
/// Shewchuk (warp when the cut is within α|e|) does well on uniform
/// lattices (α = 0.35: 9.7° … 163.6° over 174 k elements) but, where the
/// grading meets the surface, a vertex shared by a coarse and a fine element
/// moves by α of the *long* edge and can flatten or invert the fine one
/// (α = 0.35: 8 inverted and 67 of 343 k outside [10°, 165°]). Capping the
/// move by the vertex's shortest edge removes the inversions; the cap at
/// 1.5 α keeps enough warping to avoid slivers from cuts next to a vertex
/// (cap 1.0: 600 below 10°). Result at these values: no inverted element,
/// 23 of 381 k outside [10°, 165°] (worst 4.8° and 171.5°), which the bound
/// check removes.
pub const STUFF: StuffParams = StuffParams {
    alpha: 0.33,
    graded_cap: 1.5,
    min_angle: 10.0,
    max_angle: 165.0,
};

/// A tetrahedral mesh (0-based node indices, positively oriented).
#[derive(Clone, Debug, Default)]
pub struct TetMesh {
    /// Node positions.
    pub nodes: Vec<DVec3>,
    /// Elements.
    pub tets: Vec<[u32; 4]>,
    /// Elements removed for shape (see the module doc).
    pub dropped: usize,
    /// Lattice vertices moved onto the surface.
    pub warped: usize,
    /// Lattice edges cut by the surface.
    pub cuts: usize,
    /// Quality of the elements kept.
    pub quality: QualityReport,
}

/// The root of `d` on segment `a b` (`d(a) < 0 < d(b)`): Illinois regula falsi
/// (Dowell & Jarratt 1971), superlinear and bracketed, so it always stays on
/// the edge. Returns the parameter `t ∈ [0, 1]` from `a`.
fn root(model: &Model, a: DVec3, b: DVec3, da: f64, db: f64) -> f64 {
    let (mut t0, mut t1, mut f0, mut f1) = (0.0f64, 1.0f64, da, db);
    let mut side = 0i8;
    let mut t = da / (da - db);
    for _ in 0..40 {
        t = (t0 * f1 - t1 * f0) / (f1 - f0);
        if !t.is_finite() {
            t = 0.5 * (t0 + t1);
        }
        let f = model.distance(a + (b - a) * t);
        if f == 0.0 || (t1 - t0) < 1e-12 {
            break;
        }
        if f < 0.0 {
            t0 = t;
            f0 = f;
            if side == -1 {
                f1 *= 0.5;
            }
            side = -1;
        } else {
            t1 = t;
            f1 = f;
            if side == 1 {
                f0 *= 0.5;
            }
            side = 1;
        }
        if f.abs() < 1e-12 * (b - a).length() {
            break;
        }
    }
    t.clamp(0.0, 1.0)
}

#[inline]
fn sign(d: f64) -> i8 {
    if d < 0.0 {
        -1
    } else if d > 0.0 {
        1
    } else {
        0
    }
}

/// Outward faces of a positively oriented tetrahedron `(v0, v1, v2, v3)`.
const FACES: [[usize; 3]; 4] = [[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]];
pub(crate) const EDGES: [(usize, usize); 6] = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)];

/// Stuff the inside of `model` into `lat`'s tetrahedra. `None` when cancelled.
pub fn stuff(
    model: &Model,
    lat: &Lattice,
    p: &StuffParams,
    cancel: &AtomicBool,
) -> Option<TetMesh> {
    let nv = lat.keys.len();
    // 1. Signed distance at every lattice vertex.
    let mut pos: Vec<DVec3> = (0..nv as u32).map(|i| lat.pos(i)).collect();
    let dist: Vec<f64> = pos.par_iter().map(|q| model.distance(*q)).collect();
    let mut sg: Vec<i8> = dist.iter().map(|d| sign(*d)).collect();
    if cancel.load(Ordering::Relaxed) {
        return None;
    }
    // 2. Cut points on edges with a − and a + end.
    let mut cuts = cut_points(model, lat, &pos, &dist, &sg);
    if cancel.load(Ordering::Relaxed) {
        return None;
    }
    // 3. Warp violated vertices onto cut points.
    let warped = warp(lat, p, &mut cuts, &mut pos, &mut sg);
    // 4. Stencils.
    let nodes = Nodes {
        lattice: &pos,
        cuts: &cuts.pos,
    };
    let (raw, dropped, quality) = stencils(lat, p, &cuts.edges, &sg, nodes, cancel)?;
    // 5. Compact: nodes numbered in order of first use.
    let mut map = vec![u32::MAX; nv + cuts.edges.len()];
    let mut used = Vec::new();
    let tets = raw
        .into_iter()
        .map(|t| {
            t.map(|id| {
                if map[id as usize] == u32::MAX {
                    map[id as usize] = used.len() as u32;
                    used.push(nodes.at(id));
                }
                map[id as usize]
            })
        })
        .collect();
    Some(TetMesh {
        nodes: used,
        tets,
        dropped,
        warped,
        cuts: cuts.edges.len(),
        quality,
    })
}

/// The cut points of [`stuff`]'s phase 2: one on every lattice edge whose
/// ends have opposite signs.
struct Cuts {
    /// The edges, sorted and without repeats (a fixed order, so node
    /// numbers do not depend on thread count).
    edges: Vec<(u32, u32)>,
    /// Where along each edge the surface crosses (0 at its first end).
    t: Vec<f64>,
    /// The cut points, filled in by [`warp`].
    pos: Vec<DVec3>,
}

/// Phase 2 of [`stuff`]: the edges with a − and a + end and the surface's
/// crossing on each.
fn cut_points(model: &Model, lat: &Lattice, pos: &[DVec3], dist: &[f64], sg: &[i8]) -> Cuts {
    let mut mixed: Vec<(u32, u32)> = Vec::new();
    for t in &lat.tets {
        for (i, j) in EDGES {
            let (a, b) = (t.v[i], t.v[j]);
            if sg[a as usize] * sg[b as usize] < 0 {
                mixed.push(edge(a, b));
            }
        }
    }
    mixed.sort_unstable();
    mixed.dedup();
    let cut_t: Vec<f64> = mixed
        .par_iter()
        .map(|&(a, b)| {
            let (pa, pb, da, db) = (
                pos[a as usize],
                pos[b as usize],
                dist[a as usize],
                dist[b as usize],
            );
            if da < 0.0 {
                root(model, pa, pb, da, db)
            } else {
                1.0 - root(model, pb, pa, db, da)
            }
        })
        .collect();
    Cuts {
        edges: mixed,
        t: cut_t,
        pos: Vec::new(),
    }
}

/// Phase 3 of [`stuff`]: each violated vertex moves to its nearest
/// violating cut point, at most `graded_cap · α` times its shortest lattice
/// edge (its sign becomes 0). Fills `cuts.pos` from the unmoved vertices;
/// returns how many vertices moved.
fn warp(
    lat: &Lattice,
    p: &StuffParams,
    cuts: &mut Cuts,
    pos: &mut [DVec3],
    sg: &mut [i8],
) -> usize {
    let nv = pos.len();
    let mut shortest = vec![f64::INFINITY; nv];
    for t in &lat.tets {
        for (i, j) in EDGES {
            let (a, b) = (t.v[i] as usize, t.v[j] as usize);
            let l = (pos[a] - pos[b]).length();
            shortest[a] = shortest[a].min(l);
            shortest[b] = shortest[b].min(l);
        }
    }
    let mut best: Vec<(f64, u32)> = vec![(f64::INFINITY, u32::MAX); nv];
    for (e, (&(a, b), &t)) in cuts.edges.iter().zip(&cuts.t).enumerate() {
        let len = (pos[b as usize] - pos[a as usize]).length();
        for (v, frac) in [(a, t), (b, 1.0 - t)] {
            let d = frac * len;
            let ok = frac < p.alpha && d < p.graded_cap * p.alpha * shortest[v as usize];
            if ok && d < best[v as usize].0 {
                best[v as usize] = (d, e as u32);
            }
        }
    }
    cuts.pos = cuts
        .edges
        .iter()
        .zip(&cuts.t)
        .map(|(&(a, b), &t)| pos[a as usize] + (pos[b as usize] - pos[a as usize]) * t)
        .collect();
    let mut warped = 0;
    for (v, &(_, e)) in best.iter().enumerate() {
        if e != u32::MAX {
            pos[v] = cuts.pos[e as usize];
            sg[v] = 0;
            warped += 1;
        }
    }
    warped
}

/// Node positions by id: lattice vertices first, then cut points.
#[derive(Clone, Copy)]
struct Nodes<'a> {
    lattice: &'a [DVec3],
    cuts: &'a [DVec3],
}

impl Nodes<'_> {
    #[inline]
    fn at(&self, id: u32) -> DVec3 {
        let nv = self.lattice.len();
        if (id as usize) < nv {
            self.lattice[id as usize]
        } else {
            self.cuts[id as usize - nv]
        }
    }
}

/// Phase 4 of [`stuff`]: the elements of every background tetrahedron with
/// an inside vertex (whole, or its cut stencil), each kept when positive and
/// within the dihedral-angle bounds. `None` when cancelled.
fn stencils(
    lat: &Lattice,
    p: &StuffParams,
    mixed: &[(u32, u32)],
    sg: &[i8],
    nodes: Nodes<'_>,
    cancel: &AtomicBool,
) -> Option<(Vec<[u32; 4]>, usize, QualityReport)> {
    let nv = nodes.lattice.len();
    // Stencils ask only for edges whose ends have opposite signs now;
    // warping only zeroes signs, so each such edge was mixed in phase 2.
    #[allow(clippy::expect_used)]
    let cut_id = |a: u32, b: u32| -> u32 {
        let k = mixed
            .binary_search(&edge(a, b))
            .expect("cut edge was collected");
        nv as u32 + k as u32
    };
    let mut raw: Vec<[u32; 4]> = Vec::with_capacity(lat.tets.len());
    let mut dropped = 0;
    let mut quality = QualityReport::default();
    let mut accept = |t: [u32; 4], out: &mut Vec<[u32; 4]>| {
        let c = t.map(|id| nodes.at(id));
        let (lo, hi) = dihedral_range(&c);
        if signed_volume(&c) > 0.0 && lo >= p.min_angle && hi <= p.max_angle {
            quality.add(&c);
            out.push(t);
        } else {
            dropped += 1;
        }
    };
    for (n, lt) in lat.tets.iter().enumerate() {
        if n.is_multiple_of(65536) && cancel.load(Ordering::Relaxed) {
            return None;
        }
        let mut v = lt.v;
        if signed_volume(&lat.corners(lt)) < 0.0 {
            v.swap(1, 2);
        }
        let s = v.map(|i| sg[i as usize]);
        if !s.contains(&-1) {
            continue;
        }
        if !s.contains(&1) {
            accept(v, &mut raw);
            continue;
        }
        for t in cut_stencil(&v, &s, &cut_id) {
            accept(t, &mut raw);
        }
    }
    Some((raw, dropped, quality))
}

/// The elements filling the inside part of a positively oriented background
/// tetrahedron `v` with signs `s` (some −, some +). Vertex ids below the
/// number of lattice vertices are lattice vertices; `cut(a, b)` gives the id
/// of the cut point on edge `a b`; ids double as the ordering keys.
fn cut_stencil(v: &[u32; 4], s: &[i8; 4], cut: &impl Fn(u32, u32) -> u32) -> Vec<[u32; 4]> {
    // Clipped faces, outward.
    let mut faces: Vec<Vec<u32>> = Vec::with_capacity(5);
    for f in FACES {
        let mut poly = Vec::with_capacity(4);
        for m in 0..3 {
            let (i, j) = (f[m], f[(m + 1) % 3]);
            if s[i] <= 0 {
                poly.push(v[i]);
            }
            if s[i] * s[j] < 0 {
                poly.push(cut(v[i], v[j]));
            }
        }
        if poly.len() >= 3 {
            faces.push(poly);
        }
    }
    // The cut face: directed edges used once, reversed, chained.
    let mut half: Vec<(u32, u32)> = Vec::new();
    for f in &faces {
        for m in 0..f.len() {
            half.push((f[m], f[(m + 1) % f.len()]));
        }
    }
    let mut open: Vec<(u32, u32)> = half
        .iter()
        .filter(|&&(a, b)| !half.contains(&(b, a)))
        .map(|&(a, b)| (b, a))
        .collect();
    if open.len() >= 3 {
        let mut poly = vec![open[0].0];
        let mut cur = open[0].1;
        open.swap_remove(0);
        while let Some(k) = open.iter().position(|e| e.0 == cur) {
            poly.push(cur);
            cur = open[k].1;
            open.swap_remove(k);
        }
        if poly.len() >= 3 {
            faces.push(poly);
        }
    }
    let apex = faces.iter().flatten().copied().min().unwrap_or(0);
    let mut out = Vec::new();
    for f in &faces {
        if f.contains(&apex) {
            continue;
        }
        for [a, b, c] in triangulate(f) {
            out.push([a, c, b, apex]);
        }
    }
    out
}

/// Triangles of a convex polygon (3 or 4 vertices; a larger one is fanned
/// from its smallest vertex), quads split through the smallest key.
fn triangulate(f: &[u32]) -> Vec<[u32; 3]> {
    let m = f
        .iter()
        .enumerate()
        .min_by_key(|(_, k)| **k)
        .map(|(i, _)| i)
        .unwrap_or(0);
    let n = f.len();
    (1..n - 1)
        .map(|i| [f[m], f[(m + i) % n], f[(m + i + 1) % n]])
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stencils_fill_the_inside_part() {
        // Unit corner tetrahedron, cut ids = 10 + edge number.
        let v = [0u32, 1, 2, 3];
        let p = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z];
        let cut = |a: u32, b: u32| 10 + a.min(b) * 4 + a.max(b);
        let pos = |id: u32| -> DVec3 {
            if id < 10 {
                p[id as usize]
            } else {
                let (a, b) = (((id - 10) / 4) as usize, ((id - 10) % 4) as usize);
                (p[a] + p[b]) * 0.5
            }
        };
        let full = 1.0 / 6.0;
        for (s, want, n) in [
            ([-1, 1, 1, 1], full / 8.0, 1),
            ([-1, -1, 1, 1], full / 2.0, 3),
            ([-1, -1, -1, 1], full * 7.0 / 8.0, 3),
            ([0, -1, 1, 1], full / 4.0, 1),
            ([0, -1, -1, 1], full * 3.0 / 4.0, 2),
            ([0, 0, -1, 1], full / 2.0, 1),
        ] {
            let t = cut_stencil(&v, &s, &cut);
            assert_eq!(t.len(), n, "{s:?}");
            let vol: f64 = t.iter().map(|t| signed_volume(&t.map(pos))).sum();
            for e in &t {
                assert!(signed_volume(&e.map(pos)) > 0.0, "{s:?} {t:?}");
            }
            assert!((vol - want).abs() < 1e-12, "{s:?}: {vol} vs {want}");
        }
    }
}
