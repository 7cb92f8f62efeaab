//! Signed distance to a 2D region bounded by several closed contours (glyph
//! outlines: outer contours and holes, letters that may touch or overlap).
//!
//! * Distance: the exact Euclidean distance to the nearest edge, found with
//!   a bounding-volume hierarchy over the edges (boxes of at most
//!   [`LEAF`] edges, children visited nearer first, pruned by the squared
//!   box distance).
//! * Sign: the non-zero winding rule (TrueType's and CFF's fill rule), from
//!   the crossings of a horizontal ray, half-open in y so a ray through a
//!   vertex counts it once. Edges are bucketed by horizontal bands and
//!   sorted by x, so a point only tests the edges of its band on the side
//!   of its shorter ray (the crossings on the two sides sum to zero for
//!   closed contours).
//!
//! Outside the region the value is the exact distance to it. Inside, where
//! contours overlap, an edge of one contour may lie inside another and the
//! value's magnitude is then a lower bound; everywhere the value is
//! 1-Lipschitz (it is `± min distance`, and changes sign only where that
//! minimum is 0), so `d(centre) ± half diagonal` bounds it over a box.

use glam::DVec2;

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

    /// +1 or −1 when the horizontal line through `y` crosses the edge
    /// upward or downward (half-open: `[min y, max y)`), with the crossing's
    /// x clamped to the edge's x range so every scan agrees on its side.
    #[inline]
    fn crossing(&self, y: f64) -> Option<(f64, i32)> {
        let (a, b) = (self.a, self.b);
        if (a.y <= y) == (b.y <= y) {
            return None;
        }
        let x = a.x + (y - a.y) * (b.x - a.x) / (b.y - a.y);
        let x = x.clamp(a.x.min(b.x), a.x.max(b.x));
        Some((x, if b.y > a.y { 1 } else { -1 }))
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
    lo: DVec2,
    hi: DVec2,
    /// Bands of equal height over `lo.y..hi.y`.
    band_h: f64,
    bands: usize,
    /// `band_start[i]..band_start[i + 1]` indexes band `i`'s entries.
    band_start: Vec<u32>,
    /// Per band, edges by decreasing max x (the rightward ray's candidates
    /// are a prefix), with that max x.
    by_right: Vec<(f64, u32)>,
    /// Per band, edges by increasing min x (the leftward ray's), with it.
    by_left: Vec<(f64, u32)>,
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
            edges,
            nodes,
            lo,
            hi,
            band_h: 1.0,
            bands: 1,
            band_start: Vec::new(),
            by_right: Vec::new(),
            by_left: Vec::new(),
        };
        poly.build_bands();
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

    /// About `2·√n` bands: a band then holds a few edges of each contour it
    /// passes through.
    fn build_bands(&mut self) {
        let bands = ((self.edges.len() as f64).sqrt() * 2.0)
            .ceil()
            .clamp(1.0, 4096.0) as usize;
        let height = (self.hi.y - self.lo.y).max(f64::MIN_POSITIVE);
        self.band_h = height / bands as f64;
        self.bands = bands;
        let mut lists: Vec<Vec<u32>> = vec![Vec::new(); bands];
        for (i, e) in self.edges.iter().enumerate() {
            let (b0, b1) = (self.band_of(e.lo().y), self.band_of(e.hi().y));
            for list in &mut lists[b0..=b1] {
                list.push(i as u32);
            }
        }
        self.band_start.push(0);
        for list in &lists {
            let mut right: Vec<(f64, u32)> = list
                .iter()
                .map(|&i| (self.edges[i as usize].hi().x, i))
                .collect();
            right.sort_by(|a, b| b.0.total_cmp(&a.0));
            let mut left: Vec<(f64, u32)> = list
                .iter()
                .map(|&i| (self.edges[i as usize].lo().x, i))
                .collect();
            left.sort_by(|a, b| a.0.total_cmp(&b.0));
            self.by_right.extend(right);
            self.by_left.extend(left);
            self.band_start.push(self.by_right.len() as u32);
        }
    }

    #[inline]
    fn band_of(&self, y: f64) -> usize {
        let i = ((y - self.lo.y) / self.band_h).floor();
        if i > 0.0 {
            (i as usize).min(self.bands - 1)
        } else {
            0
        }
    }

    /// The non-zero winding number of the contours around `p`.
    pub fn winding(&self, p: DVec2) -> i32 {
        if !(p.y >= self.lo.y && p.y < self.hi.y && p.x >= self.lo.x && p.x <= self.hi.x) {
            return 0;
        }
        let b = self.band_of(p.y);
        let (s, e) = (self.band_start[b] as usize, self.band_start[b + 1] as usize);
        let right = &self.by_right[s..e];
        let left = &self.by_left[s..e];
        let n_right = right.partition_point(|&(x, _)| x > p.x);
        let n_left = left.partition_point(|&(x, _)| x < p.x);
        let mut w = 0;
        if n_right <= n_left {
            for &(_, i) in &right[..n_right] {
                if let Some((x, s)) = self.edges[i as usize].crossing(p.y)
                    && x > p.x
                {
                    w += s;
                }
            }
        } else {
            // Crossings left of p and at or right of it sum to zero.
            for &(_, i) in &left[..n_left] {
                if let Some((x, s)) = self.edges[i as usize].crossing(p.y)
                    && x <= p.x
                {
                    w -= s;
                }
            }
        }
        w
    }

    /// Squared distance from `p` to the nearest edge.
    pub fn dist2(&self, p: DVec2) -> f64 {
        let mut best = f64::INFINITY;
        let mut stack = [0u32; 64];
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let n = &self.nodes[stack[top] as usize];
            if box_dist2(n, p) >= best {
                continue;
            }
            if n.count > 0 {
                let first = n.first as usize;
                for e in &self.edges[first..first + n.count as usize] {
                    best = crate::fastmath::min_plain(best, e.dist2(p));
                }
                continue;
            }
            let (l, r) = (n.first, n.first + 1);
            let (dl, dr) = (
                box_dist2(&self.nodes[l as usize], p),
                box_dist2(&self.nodes[r as usize], p),
            );
            // The nearer child is popped first.
            let (far, near) = if dl <= dr { (r, l) } else { (l, r) };
            if top + 2 <= stack.len() {
                stack[top] = far;
                stack[top + 1] = near;
                top += 2;
            }
        }
        best
    }

    /// Signed distance: negative where the winding number is non-zero.
    #[inline]
    pub fn signed_distance(&self, p: DVec2) -> f64 {
        let d = self.dist2(p).sqrt();
        if self.winding(p) != 0 { -d } else { d }
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
