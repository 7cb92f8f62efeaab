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

/// (Written out: `array::map` was left a call, once per triangle read.)
#[inline]
fn f64x3(p: [f32; 3]) -> [f64; 3] {
    [f64::from(p[0]), f64::from(p[1]), f64::from(p[2])]
}

#[inline]
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

#[inline]
fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// Triangles a task of [`IndexedMesh::volume_and_shape`] sums in order.
const VOLUME_CHUNK: usize = 1 << 14;

impl IndexedMesh {
    /// True when there are no triangles.
    pub fn is_empty(&self) -> bool {
        self.triangles.is_empty()
    }

    /// Positions of triangle `t` in f64. (Inlined: returned through the
    /// stack, its nine values were reloaded with wider loads than stored,
    /// a stall per triangle in the writers and checks.)
    #[inline]
    pub fn corners(&self, t: usize) -> [[f64; 3]; 3] {
        self.triangles[t].map(|i| f64x3(self.vertices[i as usize]))
    }

    /// Enclosed volume (mm³): positive for an outward-oriented closed mesh.
    /// Relative to the mesh's first vertex, so far-off meshes keep precision.
    pub fn volume(&self) -> f64 {
        self.volume_and_shape().0
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
        self.volume_and_shape().1
    }

    /// [`Self::volume`] and [`Self::shape`] in one pass on every core (each
    /// reads every triangle's corners). The volume is summed in chunks of
    /// a fixed size and the chunks' sums in order, so its bits do not
    /// depend on the thread count.
    pub fn volume_and_shape(&self) -> (f64, (f64, f64)) {
        let Some(o) = self.vertices.first().map(|p| f64x3(*p)) else {
            return (0.0, (180.0, f64::INFINITY));
        };
        if self.triangles.is_empty() {
            return (0.0, (180.0, f64::INFINITY));
        }
        // A triangle's smallest angle is opposite its shortest edge and is
        // at most 60°, where the sine rises with the angle. The sine at the
        // corner between edges u and v is |u × v| / (|u| |v|), and |u × v|
        // is twice the area for any two edges, so with squared lengths
        // l₀, l₁, l₂ the smallest squared sine is |n|² · min l / (l₀ l₁ l₂):
        // no square root, division or branch on the shortest edge a
        // triangle. Keep the smallest over triangles, with the shortest
        // squared edge, and take the roots and one asin at the end (exact
        // for needles, where the acos of the normalised dot product rounds
        // to 0). The volume is the sum of a · (b × c) / 6 relative to `o`.
        let chunk = |(k, tris): (usize, &[[u32; 3]])| {
            let (mut six_v, mut sine2, mut edge2) = (0.0, 1.0f64, f64::INFINITY);
            for t in k * VOLUME_CHUNK..k * VOLUME_CHUNK + tris.len() {
                let [a, b, c] = self.corners(t);
                let n = cross(sub(b, o), sub(c, o));
                let ao = sub(a, o);
                six_v += ao[0] * n[0] + ao[1] * n[1] + ao[2] * n[2];
                let (u, v, w) = (sub(b, a), sub(c, b), sub(a, c));
                let l = [dot(u, u), dot(v, v), dot(w, w)];
                let n = cross(u, v);
                let shortest = l[0].min(l[1]).min(l[2]);
                let all = l[0] * l[1] * l[2];
                let s2 = if all > 0.0 {
                    (dot(n, n) * shortest / all).min(1.0)
                } else {
                    0.0
                };
                sine2 = sine2.min(s2);
                edge2 = edge2.min(shortest);
            }
            (six_v, sine2, edge2)
        };
        let parts: Vec<(f64, f64, f64)> = self
            .triangles
            .par_chunks(VOLUME_CHUNK)
            .enumerate()
            .map(chunk)
            .collect();
        let (six_v, sine2, edge2) = parts
            .iter()
            .fold((0.0, 1.0f64, f64::INFINITY), |(v, s, e), p| {
                (v + p.0, s.min(p.1), e.min(p.2))
            });
        let angle = sine2.sqrt().asin().to_degrees().min(60.0);
        (six_v / 6.0, (angle, edge2.sqrt()))
    }

    /// Unit normal of the triangle with vertices `tri` (zero for a
    /// degenerate one).
    #[inline]
    pub fn normal(&self, tri: [u32; 3]) -> [f32; 3] {
        let [a, b, c] = tri.map(|i| f64x3(self.vertices[i as usize]));
        let n = cross(sub(b, a), sub(c, a));
        let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        if len > 0.0 {
            [
                (n[0] / len) as f32,
                (n[1] / len) as f32,
                (n[2] / len) as f32,
            ]
        } else {
            [0.0; 3]
        }
    }

    /// Count open, repeated and degenerate edges.
    ///
    /// Each undirected edge `{m, M}` (`m < M`) is filed under its smaller
    /// vertex as `2M + d`, `d` = 1 when the triangle runs `m → M`, 0 when
    /// `M → m` (a counting sort by `m`, linear in the edge count; a vertex
    /// files a handful). Sorted, a vertex's entries for one `M` are its
    /// `M → m` copies, then its `m → M` ones: with `f` and `b` copies,
    /// `(f − 1)⁺ + (b − 1)⁺` are repeated and `|f − b|` open (each copy of
    /// one direction pairs with one of the other). A clean vertex's
    /// sorted entries are pairs `2M, 2M + 1`: one scan, no search or hash.
    /// In parallel over ranges of vertices, each task filing, sorting and
    /// counting its own. Edges from a vertex to itself belong to
    /// degenerate triangles, counted as such.
    pub fn edge_report(&self) -> EdgeReport {
        let degenerate = self
            .triangles
            .par_iter()
            .filter(|t| t[0] == t[1] || t[1] == t[2] || t[2] == t[0])
            .count();
        let (repeated, open) = if self.vertices.len() <= PACKED_VERTICES {
            self.filed_edge_counts()
        } else {
            self.mapped_edge_counts()
        };
        EdgeReport {
            open,
            repeated,
            degenerate,
        }
    }

    /// `(repeated, open)` by filing each edge under its smaller vertex
    /// (see [`Self::edge_report`]).
    fn filed_edge_counts(&self) -> (usize, usize) {
        let nv = self.vertices.len();
        let parts = rayon::current_num_threads().clamp(1, 16).min(nv.max(1));
        let first = |p: usize| (nv * p / parts) as u32;
        let spans = if parts > 1 { self.spans() } else { Vec::new() };
        let per_part: Vec<(usize, usize)> = (0..parts)
            .into_par_iter()
            .map(|p| {
                let (lo, hi) = (first(p), first(p + 1));
                // The triangles a part must read: those of the chunks whose
                // vertices reach its range (one chunk, all, for one part).
                let tris: Vec<&[[u32; 3]]> = if spans.is_empty() {
                    vec![&self.triangles[..]]
                } else {
                    (self.triangles.chunks(SPAN_CHUNK).zip(&spans))
                        .filter(|(_, s)| s[0] < hi && s[1] >= lo)
                        .map(|(c, _)| c)
                        .collect()
                };
                // Counting sort of the part's entries by smaller vertex.
                let mut start = vec![0u32; (hi - lo) as usize + 1];
                each_filed(&tris, lo, hi, |m, _| start[(m - lo) as usize + 1] += 1);
                for i in 1..start.len() {
                    start[i] += start[i - 1];
                }
                let mut filed = vec![0u32; start[start.len() - 1] as usize];
                let mut fill = start.clone();
                each_filed(&tris, lo, hi, |m, entry| {
                    let f = &mut fill[(m - lo) as usize];
                    filed[*f as usize] = entry;
                    *f += 1;
                });
                let (mut repeated, mut open) = (0, 0);
                for w in start.windows(2) {
                    let list = &mut filed[w[0] as usize..w[1] as usize];
                    list.sort_unstable();
                    let clean = list.len().is_multiple_of(2)
                        && list
                            .chunks_exact(2)
                            .all(|c| c[0] & 1 == 0 && c[1] == c[0] + 1);
                    if !clean {
                        let (r, o) = run_counts(list);
                        repeated += r;
                        open += o;
                    }
                }
                (repeated, open)
            })
            .collect();
        per_part
            .into_iter()
            .fold((0, 0), |a, b| (a.0 + b.0, a.1 + b.1))
    }

    /// The least and greatest vertex of each chunk of [`SPAN_CHUNK`]
    /// triangles. A contoured mesh numbers its vertices as its triangles
    /// come, band by band, so a chunk's vertices span a narrow range: a
    /// part of [`Self::filed_edge_counts`] reads only the chunks that
    /// reach its vertices, not every triangle twice.
    fn spans(&self) -> Vec<[u32; 2]> {
        self.triangles
            .par_chunks(SPAN_CHUNK)
            .map(|c| {
                c.iter().fold([u32::MAX, 0], |[lo, hi], t| {
                    [
                        lo.min(t[0].min(t[1]).min(t[2])),
                        hi.max(t[0].max(t[1]).max(t[2])),
                    ]
                })
            })
            .collect()
    }

    /// `(repeated, open)` counted in a map of undirected edges: for meshes
    /// whose vertex indices do not leave a bit free for the direction.
    fn mapped_edge_counts(&self) -> (usize, usize) {
        let mut copies: std::collections::HashMap<(u32, u32), [usize; 2]> =
            std::collections::HashMap::new();
        for t in &self.triangles {
            for (a, b) in sides(t) {
                if a != b {
                    copies.entry((a.min(b), a.max(b))).or_default()[usize::from(a < b)] += 1;
                }
            }
        }
        copies.values().fold((0, 0), |(r, o), &[b, f]| {
            (
                r + b.saturating_sub(1) + f.saturating_sub(1),
                o + b.abs_diff(f),
            )
        })
    }

    /// Every edge shared by exactly two triangles, in opposite directions.
    pub fn is_watertight(&self) -> bool {
        !self.is_empty() && self.edge_report().is_clean()
    }
}

/// Calls `file(m, 2M + d)` for each edge of the triangles of `chunks`
/// whose smaller vertex `m` lies in `lo..hi`, in order (see
/// [`IndexedMesh::edge_report`]).
fn each_filed(chunks: &[&[[u32; 3]]], lo: u32, hi: u32, mut file: impl FnMut(u32, u32)) {
    for t in chunks.iter().flat_map(|c| c.iter()) {
        for (a, b) in sides(t) {
            let (m, big) = if a < b { (a, b) } else { (b, a) };
            if a != b && (lo..hi).contains(&m) {
                file(m, (big << 1) | u32::from(a < b));
            }
        }
    }
}

/// Triangles a chunk of [`IndexedMesh::spans`].
const SPAN_CHUNK: usize = 1 << 12;

/// The directed edges of triangle `t`, in its order.
fn sides(t: &[u32; 3]) -> [(u32, u32); 3] {
    [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])]
}

/// Vertex counts up to this file an edge's larger vertex and direction
/// in one `u32` (`2M + d`).
const PACKED_VERTICES: usize = 1 << 31;

/// `(repeated, open)` of one vertex's sorted entries (see
/// [`IndexedMesh::edge_report`]).
fn run_counts(list: &[u32]) -> (usize, usize) {
    let (mut repeated, mut open) = (0, 0);
    for run in list.chunk_by(|a, b| a >> 1 == b >> 1) {
        let forward = run.iter().filter(|&&e| e & 1 == 1).count();
        let back = run.len() - forward;
        repeated += forward.saturating_sub(1) + back.saturating_sub(1);
        open += forward.abs_diff(back);
    }
    (repeated, open)
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

    /// A sphere's volume and shape have the same bits on one thread and on
    /// several (its triangles span several chunks).
    #[test]
    fn volume_and_shape_do_not_depend_on_threads() {
        let m = sphere(0.1);
        assert!(
            m.triangles.len() > 3 * VOLUME_CHUNK,
            "{}",
            m.triangles.len()
        );
        let on = |threads| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build();
            pool.expect("pool").install(|| m.volume_and_shape())
        };
        let one = on(1);
        assert_eq!(one, on(4));
        let exact = 4.0 / 3.0 * std::f64::consts::PI * 125.0;
        assert!((one.0 - exact).abs() < 0.01 * exact, "{} vs {exact}", one.0);
    }

    /// A sphere of radius 5 mm marched at `voxel` (triangles in contour
    /// order).
    fn sphere(voxel: f64) -> IndexedMesh {
        let grid = volcad_core::sampler::Grid::covering(
            &volcad_core::Aabb::new(glam::DVec3::splat(-6.0), glam::DVec3::splat(6.0)),
            glam::DVec3::splat(voxel),
            u128::MAX,
        )
        .expect("grid");
        let values: Vec<f32> = (0..grid.count() as usize)
            .map(|v| {
                let [nx, ny, _] = grid.dims;
                let (x, y, z) = (v % nx, v / nx % ny, v / (nx * ny));
                (grid.center(x, y, z).length() - 5.0) as f32
            })
            .collect();
        super::super::marching_cubes(&grid, &values)
    }

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
        assert_eq!(m.normal(m.triangles[0]), [0.0, 0.0, -1.0]);
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
    fn filing_and_the_map_count_alike() {
        // Clean, holed, doubled, flipped and degenerate meshes, with hubs
        // of a handful of edges and of hundreds (the sorted path).
        for n in [5, 200] {
            let m = double_cone(n);
            let mut variants = vec![m.clone(), cube()];
            let mut v = m.clone();
            v.triangles.remove(3);
            variants.push(v);
            let mut v = m.clone();
            v.triangles.extend_from_slice(&m.triangles[..3]);
            variants.push(v);
            let mut v = m.clone();
            v.triangles[1].swap(1, 2);
            v.triangles[2] = [v.triangles[2][0], v.triangles[2][0], v.triangles[2][1]];
            variants.push(v);
            for (i, v) in variants.iter().enumerate() {
                assert_eq!(v.filed_edge_counts(), v.mapped_edge_counts(), "{n} {i}");
            }
        }
        let mut pinched = cube();
        pinched.triangles[0] = [0, 0, 2];
        let r = pinched.edge_report();
        assert_eq!(r.degenerate, 1, "{r:?}");
        assert!(!pinched.is_watertight());
    }

    /// A sphere of many chunks ([`SPAN_CHUNK`]), clean and with defects
    /// far apart, its triangles in contour order and shuffled (chunks whose
    /// vertices span everything): the parts' chunk filter files what the
    /// map counts, on any thread count.
    #[test]
    fn chunked_filing_counts_what_the_map_does() {
        let clean = sphere(0.15);
        let n = clean.triangles.len();
        assert!(n > 8 * SPAN_CHUNK, "{n}");
        let mut holed = clean.clone();
        holed.triangles.remove(n / 3);
        holed.triangles.push(clean.triangles[n - 7]);
        let t = holed.triangles[n / 2];
        holed.triangles[n / 2] = [t[0], t[2], t[1]];
        let mut shuffled = holed.clone();
        let mut rng = volcad_core::bench::XorShift::new(3);
        for i in (1..shuffled.triangles.len()).rev() {
            let j = (rng.next_f64() * (i + 1) as f64) as usize;
            shuffled.triangles.swap(i, j.min(i));
        }
        for m in [&clean, &holed, &shuffled] {
            let want = m.mapped_edge_counts();
            for threads in [1, 2, 5] {
                let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build();
                let got = pool.expect("pool").install(|| m.filed_edge_counts());
                assert_eq!(got, want, "{threads} threads");
            }
        }
        assert_eq!(clean.mapped_edge_counts(), (0, 0));
        assert_ne!(holed.mapped_edge_counts(), (0, 0));
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
