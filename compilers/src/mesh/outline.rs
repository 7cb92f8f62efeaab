//! Triangulation of a flat region's outline (see [`super::flat`]).
//!
//! The outline is projected along the normal's largest axis and
//! triangulated by a constrained Delaunay triangulation (spade, exact
//! predicates), which keeps every outline point (collinear ones included;
//! dropping one would leave a T-junction). Faces inside the outline are
//! found by flood fill from the hull, flipping at each outline edge, and
//! oriented like the outline (the label `x`'s outward side). The region
//! is checked: no duplicate points, no crossing outline edges, and the
//! inside faces' area equal to the outline's (shoelace formula) within
//! 10⁻⁹. A region that fails any check gets `None`, and [`super::flat`]
//! contours it cube by cube with marching tetrahedra instead.

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
) -> Option<Vec<[u32; 3]>> {
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
    let count = pts.len();
    let mut conflict = false;
    let cdt = ConstrainedDelaunayTriangulation::<Point2<f64>>::try_bulk_load_cdt(
        pts.clone(),
        edges.clone(),
        |_| conflict = true,
    )
    .ok()?;
    if conflict || cdt.num_vertices() != count || cdt.num_constraints() != edges.len() {
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
    let mut out = Vec::new();
    let mut sum2 = 0.0;
    for f in cdt.inner_faces() {
        match parity[f.fix().index()] {
            1 => {}
            0 => continue,
            _ => return None,
        }
        let [a, b, c] = f.vertices().map(|h| h.fix().index());
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
