//! Indexed triangle meshes and the checks every exported mesh must pass.
//!
//! Volume by the divergence theorem: for a closed, outward-oriented mesh,
//! `V = Σ_t a·(b × c) / 6` over triangles `(a, b, c)` (signed tetrahedra
//! from the origin; computed in f64). Watertight here means the strict
//! 2-manifold condition slicers want: every undirected edge is used by
//! exactly two triangles, once in each direction (which also makes the
//! orientation consistent), and no triangle repeats an index.

use rayon::prelude::*;

/// Triangles over shared vertices (mm), counter-clockwise seen from outside.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct IndexedMesh {
    /// Vertex positions.
    pub vertices: Vec<[f32; 3]>,
    /// Vertex indices per triangle.
    pub triangles: Vec<[u32; 3]>,
}

/// Edge statistics of a mesh (all zero for a watertight one).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct EdgeReport {
    /// Directed edges without the reverse edge (holes, flipped triangles).
    pub open: usize,
    /// Directed edges used more than once (non-manifold or flipped).
    pub repeated: usize,
    /// Triangles that use one vertex twice.
    pub degenerate: usize,
}

impl EdgeReport {
    /// True when nothing is wrong.
    pub fn is_clean(&self) -> bool {
        *self == EdgeReport::default()
    }
}

fn f64x3(p: [f32; 3]) -> [f64; 3] {
    p.map(f64::from)
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

impl IndexedMesh {
    /// True when there are no triangles.
    pub fn is_empty(&self) -> bool {
        self.triangles.is_empty()
    }

    /// Positions of triangle `t` in f64.
    pub fn corners(&self, t: usize) -> [[f64; 3]; 3] {
        self.triangles[t].map(|i| f64x3(self.vertices[i as usize]))
    }

    /// Enclosed volume (mm³): positive for an outward-oriented closed mesh.
    /// Relative to the mesh's first vertex, so far-off meshes keep precision.
    pub fn volume(&self) -> f64 {
        let Some(o) = self.vertices.first().map(|p| f64x3(*p)) else {
            return 0.0;
        };
        let mut six_v = 0.0;
        for t in 0..self.triangles.len() {
            let [a, b, c] = self.corners(t).map(|p| sub(p, o));
            let n = cross(b, c);
            six_v += a[0] * n[0] + a[1] * n[1] + a[2] * n[2];
        }
        six_v / 6.0
    }

    /// Surface area (mm²).
    pub fn area(&self) -> f64 {
        (0..self.triangles.len())
            .map(|t| {
                let [a, b, c] = self.corners(t);
                let n = cross(sub(b, a), sub(c, a));
                0.5 * (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt()
            })
            .sum()
    }

    /// The smallest interior angle (degrees) of any triangle and the
    /// shortest edge (mm): slivers and needles show here before another
    /// program trips on them. `(180, inf)` without triangles.
    pub fn shape(&self) -> (f64, f64) {
        // A triangle's smallest angle is opposite its shortest edge and is
        // at most 60°, where the sine rises with the angle. The sine at the
        // corner between edges u and v is |u × v| / (|u| |v|), and |u × v|
        // is twice the area for any two edges, so with squared lengths
        // l₀, l₁, l₂ the smallest squared sine is |n|² · min l / (l₀ l₁ l₂):
        // no square root, division or branch on the shortest edge a
        // triangle. Keep the smallest over triangles, with the shortest
        // squared edge, and take the roots and one asin at the end (exact
        // for needles, where the acos of the normalised dot product rounds
        // to 0).
        if self.triangles.is_empty() {
            return (180.0, f64::INFINITY);
        }
        let (sine2, edge2) = (0..self.triangles.len())
            .into_par_iter()
            .map(|t| {
                let [a, b, c] = self.corners(t);
                let (u, v, w) = (sub(b, a), sub(c, b), sub(a, c));
                let l = [dot(u, u), dot(v, v), dot(w, w)];
                let n = cross(u, v);
                let shortest = l[0].min(l[1]).min(l[2]);
                let all = l[0] * l[1] * l[2];
                let sine2 = if all > 0.0 {
                    (dot(n, n) * shortest / all).min(1.0)
                } else {
                    0.0
                };
                (sine2, shortest)
            })
            .reduce(|| (1.0, f64::INFINITY), |a, b| (a.0.min(b.0), a.1.min(b.1)));
        (sine2.sqrt().asin().to_degrees().min(60.0), edge2.sqrt())
    }

    /// Unit normal of triangle `t` (zero for a degenerate one).
    pub fn normal(&self, t: usize) -> [f32; 3] {
        let [a, b, c] = self.corners(t);
        let n = cross(sub(b, a), sub(c, a));
        let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        if len > 0.0 {
            n.map(|v| (v / len) as f32)
        } else {
            [0.0; 3]
        }
    }

    /// Count open, repeated and degenerate edges.
    ///
    /// Directed edges `a → b` are grouped by their start vertex (a counting
    /// sort, linear in the edge count; each vertex has a handful), in
    /// parallel over ranges of vertices, and the groups are checked in
    /// parallel. `a → b` repeated is counted once per
    /// extra copy; an edge is open when `a → b` occurs more often than `b → a` (each copy
    /// of `b → a` pairs with one copy of `a → b`).
    ///
    /// A vertex is clean when its out-neighbours `O(a)` are distinct and
    /// equal, as a multiset, to its in-neighbours `I(a)` (every `a → b`
    /// then has exactly one `b → a`). The multisets are compared by their
    /// sums of a 64-bit mix of each neighbour, `Σ_{b ∈ O(a)} h(b) =
    /// Σ_{b ∈ I(a)} h(b)` (mod 2⁶⁴), gathered while the edges are counted:
    /// one comparison a vertex instead of a search of every neighbour's
    /// list. Two different multisets with equal sums would take a collision
    /// of the mix (odds about 2⁻⁶⁴ a vertex); a vertex whose sums differ, or
    /// whose out-neighbours repeat, is counted exactly as described above.
    pub fn edge_report(&self) -> EdgeReport {
        let mut r = EdgeReport::default();
        let nv = self.vertices.len();
        r.degenerate = self
            .triangles
            .par_iter()
            .filter(|t| t[0] == t[1] || t[1] == t[2] || t[2] == t[0])
            .count();
        let EdgeLists { start, ends, into } = self.edge_lists();
        let out = |v: u32| &ends[start[v as usize] as usize..start[v as usize + 1] as usize];
        let count = |list: &[u32], x: u32| {
            if list.len() > SHORT {
                list.partition_point(|&e| e <= x) - list.partition_point(|&e| e < x)
            } else {
                list.iter().filter(|&&e| e == x).count()
            }
        };
        let seen = |list: &[u32], i: usize| {
            if list.len() > SHORT {
                i > 0 && list[i - 1] == list[i]
            } else {
                list[..i].contains(&list[i])
            }
        };
        let (repeated, open) = (0..nv as u32)
            .into_par_iter()
            .with_min_len(1 << 14)
            .map(|a| {
                let list = out(a);
                let sum = list
                    .iter()
                    .fold(0u64, |s, &b| s.wrapping_add(neighbour_mix(b)));
                // (`seen` for every entry, written out: a short list is
                // scanned before each entry, a long one is sorted.)
                let distinct = if list.len() > SHORT {
                    list.windows(2).all(|w| w[0] != w[1])
                } else {
                    (1..list.len()).all(|i| !list[..i].contains(&list[i]))
                };
                if sum == into[a as usize] && distinct {
                    return (0, 0);
                }
                let (mut repeated, mut open) = (0, 0);
                for (i, &b) in list.iter().enumerate() {
                    if seen(list, i) {
                        continue; // counted at its first copy
                    }
                    let m = count(list, b);
                    repeated += m - 1;
                    open += m.saturating_sub(count(out(b), a));
                }
                (repeated, open)
            })
            .reduce(|| (0, 0), |x, y| (x.0 + y.0, x.1 + y.1));
        r.repeated = repeated;
        r.open = open;
        r
    }

    /// The directed edges grouped by start vertex (a counting sort; long
    /// lists sorted), with each vertex's in-neighbour fingerprint (see
    /// [`Self::edge_report`]). In parallel: each task owns a range of start
    /// vertices (so it writes only its own part of `ends`) and of end
    /// vertices (their fingerprints), and reads every triangle to find its
    /// edges.
    fn edge_lists(&self) -> EdgeLists {
        let nv = self.vertices.len();
        let parts = rayon::current_num_threads().clamp(1, 16).min(nv.max(1));
        let first = |p: usize| (nv * p / parts) as u32;
        let edges = |t: &[u32; 3]| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])];
        let counted: Vec<(Vec<u32>, Vec<u64>)> = (0..parts)
            .into_par_iter()
            .map(|p| {
                let (lo, hi) = (first(p), first(p + 1));
                let mut degree = vec![0u32; (hi - lo) as usize];
                // Σ h(a) over the in-neighbours a of each vertex.
                let mut into = vec![0u64; (hi - lo) as usize];
                for t in &self.triangles {
                    for (a, b) in edges(t) {
                        if (lo..hi).contains(&a) {
                            degree[(a - lo) as usize] += 1;
                        }
                        if (lo..hi).contains(&b) {
                            let i = &mut into[(b - lo) as usize];
                            *i = i.wrapping_add(neighbour_mix(a));
                        }
                    }
                }
                (degree, into)
            })
            .collect();
        let mut start = Vec::with_capacity(nv + 1);
        start.push(0u32);
        let mut into = Vec::with_capacity(nv);
        for (degree, part_into) in counted {
            for d in degree {
                start.push(start[start.len() - 1] + d);
            }
            into.extend(part_into);
        }
        let mut ends = vec![0u32; start[nv] as usize];
        let mut pieces = Vec::with_capacity(parts);
        let mut rest = &mut ends[..];
        for p in 0..parts {
            let len = (start[first(p + 1) as usize] - start[first(p) as usize]) as usize;
            let (piece, tail) = rest.split_at_mut(len);
            pieces.push((p, piece));
            rest = tail;
        }
        pieces.into_par_iter().for_each(|(p, piece)| {
            let (lo, hi) = (first(p), first(p + 1));
            let base = start[lo as usize];
            let mut fill: Vec<u32> = start[lo as usize..hi as usize]
                .iter()
                .map(|s| s - base)
                .collect();
            for t in &self.triangles {
                for (a, b) in edges(t) {
                    if (lo..hi).contains(&a) {
                        let f = &mut fill[(a - lo) as usize];
                        piece[*f as usize] = b;
                        *f += 1;
                    }
                }
            }
            for v in lo as usize..hi as usize {
                let list = &mut piece[(start[v] - base) as usize..(start[v + 1] - base) as usize];
                if list.len() > SHORT {
                    list.sort_unstable();
                }
            }
        });
        EdgeLists { start, ends, into }
    }

    /// Every edge shared by exactly two triangles, in opposite directions.
    pub fn is_watertight(&self) -> bool {
        !self.is_empty() && self.edge_report().is_clean()
    }
}

/// A vertex has a handful of edges: its list is scanned. Long lists (a fan
/// in an imported mesh) are sorted and searched, so a hub of degree D costs
/// D log D, not D².
const SHORT: usize = 32;

/// Directed edges by start vertex: vertex `v`'s end vertices are
/// `ends[start[v]..start[v + 1]]`; `into[v]` sums the mix of its
/// in-neighbours.
struct EdgeLists {
    start: Vec<u32>,
    ends: Vec<u32>,
    into: Vec<u64>,
}

/// The 64-bit mix of a vertex index whose sums fingerprint a vertex's
/// neighbours in [`IndexedMesh::edge_report`] (splitmix64: a bijection of
/// the index that spreads every input bit over the output).
fn neighbour_mix(v: u32) -> u64 {
    crate::dither::splitmix64(0, u64::from(v))
}

/// Triangles by vertex positions (bits), each rotated to start at its
/// least, sorted: two meshes with the same triangles at the same points
/// compare equal whatever their vertex order (tests).
#[cfg(test)]
pub(super) fn tri_set(m: &IndexedMesh) -> Vec<[[u32; 3]; 3]> {
    let mut out: Vec<_> = m
        .triangles
        .iter()
        .map(|t| {
            let p = t.map(|i| m.vertices[i as usize].map(f32::to_bits));
            let r = (0..3).min_by_key(|i| p[*i]).unwrap_or(0);
            [p[r], p[(r + 1) % 3], p[(r + 2) % 3]]
        })
        .collect();
    out.sort_unstable();
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The unit cube, outward oriented (12 triangles).
    pub(crate) fn cube() -> IndexedMesh {
        let v = [
            [0., 0., 0.],
            [1., 0., 0.],
            [1., 1., 0.],
            [0., 1., 0.],
            [0., 0., 1.],
            [1., 0., 1.],
            [1., 1., 1.],
            [0., 1., 1.],
        ];
        let t = [
            [0, 2, 1],
            [0, 3, 2],
            [4, 5, 6],
            [4, 6, 7],
            [0, 1, 5],
            [0, 5, 4],
            [3, 7, 6],
            [3, 6, 2],
            [0, 4, 7],
            [0, 7, 3],
            [1, 2, 6],
            [1, 6, 5],
        ];
        IndexedMesh {
            vertices: v.to_vec(),
            triangles: t.to_vec(),
        }
    }

    #[test]
    fn cube_is_watertight_with_unit_volume() {
        let m = cube();
        assert!(m.is_watertight());
        assert!((m.volume() - 1.0).abs() < 1e-12);
        assert!((m.area() - 6.0).abs() < 1e-12);
        assert_eq!(m.normal(0), [0.0, 0.0, -1.0]);
        let (angle, edge) = m.shape();
        assert!((angle - 45.0).abs() < 1e-9 && edge == 1.0, "{angle} {edge}");
        let needle = IndexedMesh {
            vertices: vec![[0., 0., 0.], [1., 0., 0.], [0.5, 1e-4, 0.]],
            triangles: vec![[0, 1, 2]],
        };
        let (angle, edge) = needle.shape();
        assert!(
            angle > 0.0 && angle < 0.02 && (edge - 0.5).abs() < 1e-6,
            "{angle} {edge}"
        );
    }

    #[test]
    fn flipped_or_missing_triangles_are_caught() {
        let mut m = cube();
        m.triangles[3] = [m.triangles[3][0], m.triangles[3][2], m.triangles[3][1]];
        let r = m.edge_report();
        assert!(!m.is_watertight() && r.repeated > 0 && r.open > 0, "{r:?}");
        let mut m = cube();
        m.triangles.pop();
        assert_eq!(m.edge_report().open, 3);
        let mut m = cube();
        m.triangles.push(m.triangles[0]);
        assert!(!m.is_watertight());
    }

    /// A double cone of `n` ring vertices: the apexes have `n` edges each
    /// (the sorted path of `edge_report`).
    fn double_cone(n: u32) -> IndexedMesh {
        let mut vertices = vec![[0.0, 0.0, 1.0], [0.0, 0.0, -1.0]];
        for i in 0..n {
            let a = i as f32 / n as f32 * std::f32::consts::TAU;
            vertices.push([a.cos(), a.sin(), 0.0]);
        }
        let ring = |i: u32| 2 + i % n;
        let mut triangles = Vec::new();
        for i in 0..n {
            triangles.push([0, ring(i), ring(i + 1)]);
            triangles.push([1, ring(i + 1), ring(i)]);
        }
        IndexedMesh {
            vertices,
            triangles,
        }
    }

    #[test]
    fn hubs_of_high_degree_are_checked_too() {
        for n in [5, 200] {
            let m = double_cone(n);
            assert!(m.is_watertight(), "{n}");
            let mut open = m.clone();
            open.triangles.remove(7);
            assert_eq!(open.edge_report().open, 3, "{n}");
            let mut twice = m.clone();
            twice.triangles.push(m.triangles[4]);
            let r = twice.edge_report();
            assert_eq!((r.repeated, r.open), (3, 3), "{n}: {r:?}");
            let mut flipped = m.clone();
            let t = flipped.triangles[2];
            flipped.triangles[2] = [t[0], t[2], t[1]];
            let r = flipped.edge_report();
            // Each flipped edge doubles its neighbour's and leaves no reverse.
            assert_eq!((r.repeated, r.open), (3, 6), "{n}: {r:?}");
        }
    }
}
