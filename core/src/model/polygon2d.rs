//! Signed distance to a 2D region bounded by several closed contours (glyph
//! outlines: outer contours and holes, letters that may touch or overlap).
//!
//! * Distance: the exact Euclidean distance to the nearest edge. A grid of
//!   about two cells per edge lists, per cell, every edge that can be
//!   nearest to a point of it, sorted for an early stop (`Cells`); cells
//!   far from every edge, and points outside the grid, walk a
//!   bounding-volume hierarchy over the edges (boxes of at most `LEAF`
//!   edges, nearer child first, pruned by the squared box distance).
//! * Sign: the non-zero winding rule (TrueType's and CFF's fill rule), from
//!   the crossings of one axis-parallel ray, half-open across it so a ray
//!   through a vertex counts it once. Edges are bucketed by bands of rows
//!   and of columns, each sorted along its rays, and a point scans the
//!   shortest of its four rays: the edges of its row band right or left of
//!   it, or of its column band above or below it (the crossings on the two
//!   sides of a line sum to zero for closed contours). A line of text is
//!   wide and short, so a vertical ray meets a few edges where a
//!   horizontal one would meet the whole line's.
//!
//! Outside the region the value is the exact distance to it. Inside, where
//! contours overlap, an edge of one contour may lie inside another and the
//! value's magnitude is then a lower bound; everywhere the value is
//! 1-Lipschitz (it is `± min distance`, and changes sign only where that
//! minimum is 0), so `d(centre) ± half diagonal` bounds it over a box.

use glam::DVec2;
use rayon::prelude::*;

/// Most edges in a BVH leaf.
const LEAF: usize = 4;

/// One directed edge of a contour.
#[derive(Clone, Copy, Debug)]
struct Edge {
    a: DVec2,
    b: DVec2,
}

impl Edge {
    #[inline]
    fn dist2(&self, p: DVec2) -> f64 {
        let e = self.b - self.a;
        let w = p - self.a;
        let t = (w.dot(e) / e.length_squared()).clamp(0.0, 1.0);
        (w - e * t).length_squared()
    }

    fn lo(&self) -> DVec2 {
        self.a.min(self.b)
    }

    fn hi(&self) -> DVec2 {
        self.a.max(self.b)
    }

    /// Where the line `p[axis] = c` crosses the edge (half-open: `[min,
    /// max)` along `axis`), along the other axis and clamped to the edge's
    /// range there so every scan agrees on its side, with the crossing's
    /// winding sign for a ray toward + along the other axis: +1 for an
    /// edge passing the ray counter-clockwise.
    #[inline]
    fn crossing(&self, axis: usize, c: f64) -> Option<(f64, i32)> {
        let (a, b) = (self.a, self.b);
        let j = 1 - axis;
        if (a[axis] <= c) == (b[axis] <= c) {
            return None;
        }
        let t = a[j] + (c - a[axis]) * (b[j] - a[j]) / (b[axis] - a[axis]);
        let t = t.clamp(a[j].min(b[j]), a[j].max(b[j]));
        let up = b[axis] > a[axis];
        // Rows: upward edges pass a rightward ray counter-clockwise;
        // columns: leftward edges pass an upward ray so.
        Some((t, if up == (axis == 1) { 1 } else { -1 }))
    }
}

/// Edges bucketed by bands across one axis, for rays along the other.
#[derive(Clone, Debug)]
struct Bands {
    /// The axis the bands divide (1: rows, rays along x; 0: columns).
    axis: usize,
    lo: f64,
    h: f64,
    n: usize,
    /// `start[i]..start[i + 1]` indexes band `i`'s entries.
    start: Vec<u32>,
    /// Per band, edges by decreasing maximum along the rays (the forward
    /// ray's candidates are a prefix), with that maximum.
    by_high: Vec<(f64, u32)>,
    /// Per band, edges by increasing minimum along the rays, with it.
    by_low: Vec<(f64, u32)>,
}

impl Bands {
    /// About `2·√n` bands: a band then holds a few edges of each contour
    /// it passes through.
    fn new(edges: &[Edge], lo: DVec2, hi: DVec2, axis: usize) -> Self {
        let n = ((edges.len() as f64).sqrt() * 2.0)
            .ceil()
            .clamp(1.0, 4096.0) as usize;
        let span = (hi[axis] - lo[axis]).max(f64::MIN_POSITIVE);
        let mut bands = Bands {
            axis,
            lo: lo[axis],
            h: span / n as f64,
            n,
            start: vec![0],
            by_high: Vec::new(),
            by_low: Vec::new(),
        };
        let mut lists: Vec<Vec<u32>> = vec![Vec::new(); n];
        for (i, e) in edges.iter().enumerate() {
            let (b0, b1) = (bands.band(e.lo()[axis]), bands.band(e.hi()[axis]));
            for list in &mut lists[b0..=b1] {
                list.push(i as u32);
            }
        }
        let j = 1 - axis;
        for list in &lists {
            let mut high: Vec<(f64, u32)> = list
                .iter()
                .map(|&i| (edges[i as usize].hi()[j], i))
                .collect();
            high.sort_by(|a, b| b.0.total_cmp(&a.0));
            let mut low: Vec<(f64, u32)> = list
                .iter()
                .map(|&i| (edges[i as usize].lo()[j], i))
                .collect();
            low.sort_by(|a, b| a.0.total_cmp(&b.0));
            bands.by_high.extend(high);
            bands.by_low.extend(low);
            bands.start.push(bands.by_high.len() as u32);
        }
        bands
    }

    #[inline]
    fn band(&self, c: f64) -> usize {
        let i = ((c - self.lo) / self.h).floor();
        if i > 0.0 {
            (i as usize).min(self.n - 1)
        } else {
            0
        }
    }

    /// `p`'s band and the lengths of its forward and backward candidate
    /// lists.
    #[inline]
    fn counts(&self, p: DVec2) -> (usize, usize, usize) {
        let b = self.band(p[self.axis]);
        let (s, e) = (self.start[b] as usize, self.start[b + 1] as usize);
        let c = p[1 - self.axis];
        (
            b,
            self.by_high[s..e].partition_point(|&(x, _)| x > c),
            self.by_low[s..e].partition_point(|&(x, _)| x < c),
        )
    }

    /// The winding number from the first `n` candidates of band `b` on one
    /// side of `p`.
    fn scan(&self, edges: &[Edge], p: DVec2, b: usize, forward: bool, n: usize) -> i32 {
        let s = self.start[b] as usize;
        let (k, c) = (self.axis, p[1 - self.axis]);
        let mut w = 0;
        if forward {
            for &(_, i) in &self.by_high[s..s + n] {
                if let Some((t, sign)) = edges[i as usize].crossing(k, p[k])
                    && t > c
                {
                    w += sign;
                }
            }
        } else {
            // Crossings before p and at or after it sum to zero.
            for &(_, i) in &self.by_low[s..s + n] {
                if let Some((t, sign)) = edges[i as usize].crossing(k, p[k])
                    && t <= c
                {
                    w -= sign;
                }
            }
        }
        w
    }
}

#[derive(Clone, Copy, Debug)]
struct BvhNode {
    lo: DVec2,
    hi: DVec2,
    /// Leaf: first edge; inner: index of the first child (the second
    /// follows it).
    first: u32,
    /// Edges in a leaf; 0 for an inner node.
    count: u32,
}

/// A multi-contour region with its distance and containment structures.
#[derive(Clone, Debug)]
pub struct Polygon2d {
    /// Edges in BVH leaf order.
    edges: Vec<Edge>,
    nodes: Vec<BvhNode>,
    cells: Cells,
    lo: DVec2,
    hi: DVec2,
    rows: Bands,
    cols: Bands,
}

impl Polygon2d {
    /// The region of `contours` (each closed: its last vertex joins its
    /// first). Zero-length edges are dropped; `None` when no edge is left.
    pub fn new(contours: &[Vec<DVec2>]) -> Option<Self> {
        let mut edges = Vec::new();
        for c in contours {
            for (i, &a) in c.iter().enumerate() {
                let b = c[(i + 1) % c.len()];
                if a != b && a.is_finite() && b.is_finite() {
                    edges.push(Edge { a, b });
                }
            }
        }
        if edges.is_empty() {
            return None;
        }
        let mut nodes = Vec::with_capacity(2 * edges.len() / LEAF + 1);
        nodes.push(BvhNode {
            lo: DVec2::ZERO,
            hi: DVec2::ZERO,
            first: 0,
            count: 0,
        });
        let n = edges.len();
        build(&mut edges, &mut nodes, 0, 0, n);
        let (lo, hi) = (nodes[0].lo, nodes[0].hi);
        let mut poly = Polygon2d {
            cells: Cells::default(),
            rows: Bands::new(&edges, lo, hi, 1),
            cols: Bands::new(&edges, lo, hi, 0),
            edges,
            nodes,
            lo,
            hi,
        };
        poly.cells = Cells::new(&poly);
        Some(poly)
    }

    /// Lower-left and upper-right corners of the edges' box.
    pub fn bounds(&self) -> (DVec2, DVec2) {
        (self.lo, self.hi)
    }

    /// Number of edges.
    pub fn edge_count(&self) -> usize {
        self.edges.len()
    }

    /// The non-zero winding number of the contours around `p`, from the
    /// shortest of its four rays.
    pub fn winding(&self, p: DVec2) -> i32 {
        if !(p.y >= self.lo.y && p.y < self.hi.y && p.x >= self.lo.x && p.x < self.hi.x) {
            return 0;
        }
        let (rb, right, left) = self.rows.counts(p);
        let (cb, up, down) = self.cols.counts(p);
        let least = right.min(left).min(up).min(down);
        if least == right {
            self.rows.scan(&self.edges, p, rb, true, right)
        } else if least == left {
            self.rows.scan(&self.edges, p, rb, false, left)
        } else if least == up {
            self.cols.scan(&self.edges, p, cb, true, up)
        } else {
            self.cols.scan(&self.edges, p, cb, false, down)
        }
    }

    /// Squared distance from `p` to the nearest edge.
    pub fn dist2(&self, p: DVec2) -> f64 {
        match self.cells.nearest2(p, &self.edges) {
            Ok(d2) => d2,
            Err(bound) => self.nearest(p, bound).0,
        }
    }

    /// The edges within squared distance `r2` of `c`, with their distances.
    fn within(&self, c: DVec2, r2: f64, out: &mut Vec<(f64, u32)>) {
        let mut stack = [0u32; 64];
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let n = &self.nodes[stack[top] as usize];
            if box_dist2(n, c) > r2 {
                continue;
            }
            if n.count > 0 {
                for k in n.first..n.first + n.count {
                    let d2 = self.edges[k as usize].dist2(c);
                    if d2 <= r2 {
                        out.push((d2.sqrt(), k));
                    }
                }
            } else if top + 2 <= stack.len() {
                stack[top] = n.first;
                stack[top + 1] = n.first + 1;
                top += 2;
            }
        }
    }

    /// The squared distance to the nearest edge and its index, below a
    /// known upper bound `best` (∞ for none).
    fn nearest(&self, p: DVec2, mut best: f64) -> (f64, u32) {
        let mut arg = u32::MAX;
        // Entries carry their box distance, computed once by the parent.
        let mut stack = [(0u32, 0.0f64); 64];
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let (i, d) = stack[top];
            if d >= best {
                continue;
            }
            let n = &self.nodes[i as usize];
            if n.count > 0 {
                let first = n.first as usize;
                for (k, e) in self.edges[first..first + n.count as usize]
                    .iter()
                    .enumerate()
                {
                    let d = e.dist2(p);
                    if d < best {
                        best = d;
                        arg = (first + k) as u32;
                    }
                }
                continue;
            }
            let (l, r) = (n.first, n.first + 1);
            let (dl, dr) = (
                box_dist2(&self.nodes[l as usize], p),
                box_dist2(&self.nodes[r as usize], p),
            );
            // The nearer child is popped first.
            let (far, near) = if dl <= dr {
                ((r, dr), (l, dl))
            } else {
                ((l, dl), (r, dr))
            };
            if top + 2 <= stack.len() {
                stack[top] = far;
                stack[top + 1] = near;
                top += 2;
            }
        }
        (best, arg)
    }

    /// Signed distance: negative where the winding number is non-zero.
    #[inline]
    pub fn signed_distance(&self, p: DVec2) -> f64 {
        let d = self.dist2(p).sqrt();
        if self.winding(p) != 0 { -d } else { d }
    }
}

/// Most candidates a cell lists; a cell that would need more (far from
/// every edge, where the query's ball is wide) keeps its centre's nearest
/// edge as a first bound for the BVH walk instead.
const CELL_CAP: usize = 48;

/// One cell's candidates (distance from its centre, edge), or, for a full
/// cell, its centre's nearest edge.
type CellList = Result<Vec<(f64, u32)>, u32>;

/// A grid over the region's box whose cells list every edge that can be
/// nearest to a point of the cell, by distance from the cell's centre c.
/// Exact: for q in the cell (|q − c| ≤ r, the half diagonal) the nearest
/// edge e* has d(q, e*) ≤ d(c) + r, so d(c, e*) ≤ d(c) + 2r, the list's
/// reach; and d(q, e) ≥ d(c, e) − |q − c|, so the scan stops at the first
/// entry whose bound reaches the best distance found.
#[derive(Clone, Debug, Default)]
struct Cells {
    lo: DVec2,
    side: f64,
    inv: f64,
    nx: usize,
    ny: usize,
    /// Per cell, `(start, len)` into the lists; `len == u32::MAX` marks a
    /// full cell, whose `start` is its centre's nearest edge.
    span: Vec<(u32, u32)>,
    /// Distance from the cell's centre, and the edge.
    dist: Vec<f64>,
    edge: Vec<u32>,
}

impl Cells {
    /// About two cells per edge, at most 2²⁰.
    fn new(poly: &Polygon2d) -> Self {
        let size = (poly.hi - poly.lo).max(DVec2::splat(f64::MIN_POSITIVE));
        let cells = (2 * poly.edges.len()).clamp(1, 1 << 20) as f64;
        let side = (size.x * size.y / cells)
            .sqrt()
            .max(size.max_element() / 4096.0);
        let nx = ((size.x / side).ceil() as usize).max(1);
        let ny = ((size.y / side).ceil() as usize).max(1);
        let mut g = Cells {
            lo: poly.lo,
            side,
            inv: 1.0 / side,
            nx,
            ny,
            ..Cells::default()
        };
        let r = side * std::f64::consts::FRAC_1_SQRT_2;
        // Rows in parallel (a paragraph has tens of thousands of cells),
        // merged in order, so the lists do not depend on the thread count.
        let rows: Vec<Vec<CellList>> = (0..ny)
            .into_par_iter()
            .map(|j| {
                let mut near = Vec::new();
                (0..nx)
                    .map(|i| {
                        let c = poly.lo + DVec2::new(i as f64 + 0.5, j as f64 + 0.5) * side;
                        let (d2, e) = poly.nearest(c, f64::INFINITY);
                        let reach = d2.sqrt() + 2.0 * r;
                        near.clear();
                        poly.within(c, reach * reach, &mut near);
                        if near.len() > CELL_CAP {
                            return Err(e);
                        }
                        near.sort_by(|a, b| a.0.total_cmp(&b.0));
                        Ok(near.clone())
                    })
                    .collect()
            })
            .collect();
        for cell in rows.into_iter().flatten() {
            match cell {
                Err(e) => g.span.push((e, u32::MAX)),
                Ok(list) => {
                    g.span.push((g.edge.len() as u32, list.len() as u32));
                    g.dist.extend(list.iter().map(|n| n.0));
                    g.edge.extend(list.iter().map(|n| n.1));
                }
            }
        }
        g
    }

    /// The squared distance from `p` to the nearest edge when `p`'s cell
    /// lists its candidates (`Ok`), else an upper bound to start a walk
    /// from (`Err`: ∞ outside the grid).
    #[inline]
    fn nearest2(&self, p: DVec2, edges: &[Edge]) -> Result<f64, f64> {
        let q = (p - self.lo) * self.inv;
        if !(q.x >= 0.0 && q.y >= 0.0 && q.x < self.nx as f64 && q.y < self.ny as f64) {
            return Err(f64::INFINITY);
        }
        let (i, j) = (q.x as usize, q.y as usize);
        let Some(&(start, len)) = self.span.get(j * self.nx + i) else {
            return Err(f64::INFINITY);
        };
        if len == u32::MAX {
            return Err(edges
                .get(start as usize)
                .map_or(f64::INFINITY, |e| e.dist2(p)));
        }
        let c = self.lo + DVec2::new(i as f64 + 0.5, j as f64 + 0.5) * self.side;
        let pc = (p - c).length();
        let mut best = f64::INFINITY;
        let (s, n) = (start as usize, len as usize);
        for (&dc, &e) in self.dist[s..s + n].iter().zip(&self.edge[s..s + n]) {
            let lower = dc - pc;
            if lower > 0.0 && lower * lower >= best {
                break;
            }
            best = best.min(edges[e as usize].dist2(p));
        }
        Ok(best)
    }
}

#[inline]
fn box_dist2(n: &BvhNode, p: DVec2) -> f64 {
    let d = (n.lo - p).max(p - n.hi).max(DVec2::ZERO);
    d.length_squared()
}

/// Build node `at` over `edges[start..end]`: median split of the edge
/// midpoints along the box's longer axis. The depth is about log2(n / LEAF),
/// far below the query stack's 64 entries for any text.
fn build(edges: &mut [Edge], nodes: &mut Vec<BvhNode>, at: usize, start: usize, end: usize) {
    let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
    for e in &edges[start..end] {
        lo = lo.min(e.lo());
        hi = hi.max(e.hi());
    }
    if end - start <= LEAF {
        nodes[at] = BvhNode {
            lo,
            hi,
            first: start as u32,
            count: (end - start) as u32,
        };
        return;
    }
    let axis = usize::from(hi.y - lo.y > hi.x - lo.x);
    let mid = (start + end) / 2;
    edges[start..end].select_nth_unstable_by(mid - start, |a, b| {
        (a.a + a.b)[axis].total_cmp(&(b.a + b.b)[axis])
    });
    let first = nodes.len();
    let blank = nodes[at];
    nodes.push(blank);
    nodes.push(blank);
    nodes[at] = BvhNode {
        lo,
        hi,
        first: first as u32,
        count: 0,
    };
    build(edges, nodes, first, start, mid);
    build(edges, nodes, first + 1, mid, end);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::xorshift::XorShift;

    /// The reference: every edge, and even-odd containment by counting all
    /// crossings of a rightward ray.
    pub(crate) fn brute(contours: &[Vec<DVec2>], p: DVec2) -> f64 {
        let mut d2 = f64::INFINITY;
        let mut inside = false;
        for c in contours {
            for i in 0..c.len() {
                let (a, b) = (c[i], c[(i + 1) % c.len()]);
                if a == b {
                    continue;
                }
                d2 = d2.min(Edge { a, b }.dist2(p));
                if (a.y > p.y) != (b.y > p.y) && p.x < a.x + (p.y - a.y) * (b.x - a.x) / (b.y - a.y)
                {
                    inside = !inside;
                }
            }
        }
        if inside { -d2.sqrt() } else { d2.sqrt() }
    }

    fn ring(c: DVec2, r: f64, n: usize, ccw: bool) -> Vec<DVec2> {
        (0..n)
            .map(|i| {
                let t = std::f64::consts::TAU * i as f64 / n as f64;
                let t = if ccw { t } else { -t };
                c + DVec2::new(t.cos(), t.sin()) * r
            })
            .collect()
    }

    #[test]
    fn rings_with_holes_match_brute_force() {
        // Three "o" shapes: an outer ring and an opposite-wound hole each.
        let mut contours = Vec::new();
        for k in 0..3 {
            let c = DVec2::new(3.0 * k as f64, 0.5 * k as f64);
            contours.push(ring(c, 1.2, 37, false));
            contours.push(ring(c + DVec2::new(0.1, 0.0), 0.6, 23, true));
        }
        let poly = Polygon2d::new(&contours).unwrap();
        let mut rng = XorShift::new(7);
        for _ in 0..4000 {
            let p = DVec2::new(-3.0 + 13.0 * rng.next_f64(), -3.0 + 7.0 * rng.next_f64());
            let (got, want) = (poly.signed_distance(p), brute(&contours, p));
            assert!((got - want).abs() < 1e-12, "{p}: {got} vs {want}");
        }
    }

    #[test]
    fn listed_and_full_cells_are_exact() {
        let style = crate::text::TextStyle {
            height: 4.0,
            aspect: crate::text::FontAspect::Regular,
            font: "DejaVu Sans".into(),
            h_align: crate::text::HorizontalAlignment::Left,
            v_align: crate::text::VerticalAlignment::Top,
        };
        let o = crate::text::outline("Wide gaps\n\n\n  between  lines", &style).unwrap();
        let poly = Polygon2d::new(&o.contours).unwrap();
        let full = poly.cells.span.iter().filter(|s| s.1 == u32::MAX).count();
        assert!(full > 0 && full < poly.cells.span.len(), "{full}");
        let mut rng = XorShift::new(21);
        let (lo, hi) = poly.bounds();
        for _ in 0..3000 {
            let p = lo + (hi - lo) * DVec2::new(rng.next_f64(), rng.next_f64());
            let want = brute(&o.contours, p);
            assert!((poly.signed_distance(p) - want).abs() < 1e-12, "{p}");
        }
    }

    #[test]
    fn all_four_rays_agree() {
        // Vertices on a 0.25 lattice, queried on the same lattice: rays
        // through vertices and along edges at every turn.
        let q = |x: f64, y: f64| DVec2::new(x, y);
        let contours = vec![
            vec![
                q(0.0, 0.0),
                q(2.0, 0.0),
                q(2.0, 1.0),
                q(1.0, 0.5),
                q(0.0, 1.0),
            ],
            vec![q(0.25, 0.25), q(0.25, 0.5), q(0.5, 0.25)],
            vec![q(3.0, 0.0), q(4.0, 1.0), q(3.0, 2.0), q(2.5, 1.0)],
        ];
        let poly = Polygon2d::new(&contours).unwrap();
        for i in -2..=18 {
            for j in -2..=10 {
                let p = q(0.25 * f64::from(i), 0.25 * f64::from(j));
                if poly.dist2(p) == 0.0 {
                    continue; // on an edge: either answer is right
                }
                let want = i32::from(brute(&contours, p) < 0.0);
                let inside = p.cmpge(poly.lo).all() && p.cmplt(poly.hi).all();
                for bands in [&poly.rows, &poly.cols] {
                    let (b, fwd, back) = bands.counts(p);
                    let w = |f, n| {
                        if inside {
                            bands.scan(&poly.edges, p, b, f, n).abs()
                        } else {
                            0
                        }
                    };
                    assert_eq!(w(true, fwd), want, "{p} forward, axis {}", bands.axis);
                    assert_eq!(w(false, back), want, "{p} backward, axis {}", bands.axis);
                }
                assert_eq!(poly.winding(p).abs(), want, "{p}");
            }
        }
    }

    #[test]
    fn rays_through_vertices_count_once() {
        // A diamond whose vertices sit on the query rows and columns.
        let d = vec![
            DVec2::new(0.0, -1.0),
            DVec2::new(1.0, 0.0),
            DVec2::new(0.0, 1.0),
            DVec2::new(-1.0, 0.0),
        ];
        let poly = Polygon2d::new(std::slice::from_ref(&d)).unwrap();
        for (p, inside) in [
            (DVec2::new(0.0, 0.0), true),
            (DVec2::new(-0.5, 0.0), true),
            (DVec2::new(0.5, 0.0), true),
            (DVec2::new(-2.0, 0.0), false),
            (DVec2::new(2.0, 0.0), false),
            (DVec2::new(-2.0, 1.0), false),
            (DVec2::new(0.0, 0.99), true),
        ] {
            assert_eq!(poly.winding(p) != 0, inside, "{p}");
        }
    }

    #[test]
    fn overlapping_contours_are_a_union() {
        // Two squares wound the same way overlap: non-zero fills the overlap.
        let sq = |x: f64| {
            vec![
                DVec2::new(x, 0.0),
                DVec2::new(x + 2.0, 0.0),
                DVec2::new(x + 2.0, 2.0),
                DVec2::new(x, 2.0),
            ]
        };
        let poly = Polygon2d::new(&[sq(0.0), sq(1.0)]).unwrap();
        assert_eq!(poly.winding(DVec2::new(1.5, 1.0)), 2);
        assert!(poly.signed_distance(DVec2::new(1.5, 1.0)) < 0.0);
        assert!((poly.signed_distance(DVec2::new(4.0, 1.0)) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn degenerate_input_is_refused() {
        assert!(Polygon2d::new(&[]).is_none());
        assert!(Polygon2d::new(&[vec![DVec2::ONE, DVec2::ONE]]).is_none());
    }
}
