//! Edge and vertex topology of a triangle soup.
//!
//! Decides how the sign of the distance is found. The angle-weighted
//! pseudo-normal test (Bærentzen & Aanæs, "Signed distance computation using
//! the angle weighted pseudonormal", IEEE TVCG 11(3), 2005) is only proven
//! for a closed, consistently oriented 2-manifold: every edge shared by
//! exactly two triangles that traverse it in opposite directions, and the
//! triangles around each vertex forming a single fan. Anything else
//! (holes, T-junctions, flipped triangles, degenerate triangles, bow-tie
//! vertices) falls back to the generalised winding number.

use glam::DVec3;

use super::triangle::Tri;

/// Marks "no neighbour" in [`Topology::neighbours`].
pub(crate) const NONE: u32 = u32::MAX;

/// What the edge analysis found.
#[derive(Clone, Debug, Default)]
pub(crate) struct Topology {
    /// Edges used by exactly one triangle.
    pub boundary_edges: usize,
    /// Edges used by more than two triangles.
    pub nonmanifold_edges: usize,
    /// Edges shared by two triangles that traverse it in the same direction.
    pub inconsistent_edges: usize,
    /// Triangles with (almost) no area or a repeated vertex index.
    pub degenerate_triangles: usize,
    /// Vertices whose incident triangles form more than one fan.
    pub nonmanifold_vertices: usize,
    /// Per triangle and edge `k` (a→b, b→c, c→a): the triangle across it,
    /// [`NONE`] unless the edge is shared by exactly two triangles.
    pub neighbours: Vec<[u32; 3]>,
}

impl Topology {
    /// True when pseudo-normals give a correct sign everywhere.
    pub fn is_closed_manifold(&self) -> bool {
        self.boundary_edges == 0
            && self.nonmanifold_edges == 0
            && self.inconsistent_edges == 0
            && self.degenerate_triangles == 0
            && self.nonmanifold_vertices == 0
    }

    /// Human-readable warnings for everything that is not a closed manifold.
    pub fn warnings(&self) -> Vec<String> {
        // Each count with the words before and after it.
        let counts = [
            (
                self.boundary_edges,
                "mesh is not closed: ",
                " boundary edges",
            ),
            (
                self.nonmanifold_edges,
                "mesh has ",
                " non-manifold edges (shared by more than two triangles)",
            ),
            (
                self.inconsistent_edges,
                "mesh is not consistently oriented: ",
                " edges are traversed in the same direction by both triangles",
            ),
            (
                self.degenerate_triangles,
                "mesh has ",
                " degenerate (zero-area) triangles",
            ),
            (
                self.nonmanifold_vertices,
                "mesh has ",
                " non-manifold vertices (several triangle fans meet)",
            ),
        ];
        let mut w: Vec<String> = counts
            .iter()
            .filter(|(n, _, _)| *n > 0)
            .map(|(n, before, after)| format!("{before}{n}{after}"))
            .collect();
        if !w.is_empty() {
            w.push(
                "inside/outside is decided by the generalised winding number (slower than pseudo-normals)"
                    .to_string(),
            );
        }
        w
    }
}

/// Analyses `triangles` (indices already validated against `vertex_count`).
pub(crate) fn analyse(vertex_count: usize, triangles: &[[u32; 3]], tris: &[Tri]) -> Topology {
    let mut topo = Topology {
        neighbours: vec![[NONE; 3]; triangles.len()],
        degenerate_triangles: triangles
            .iter()
            .zip(tris)
            .filter(|(t, g)| g.flat || t[0] == t[1] || t[1] == t[2] || t[2] == t[0])
            .count(),
        ..Topology::default()
    };
    // (low vertex, high vertex, triangle, local edge): sorting groups the uses
    // of each undirected edge.
    let mut edges: Vec<(u32, u32, u32, u8)> = Vec::with_capacity(triangles.len() * 3);
    for (t, tri) in triangles.iter().enumerate() {
        for k in 0..3 {
            let (u, v) = (tri[k], tri[(k + 1) % 3]);
            edges.push((u.min(v), u.max(v), t as u32, k as u8));
        }
    }
    edges.sort_unstable();
    let mut i = 0;
    while i < edges.len() {
        let mut j = i + 1;
        while j < edges.len() && edges[j].0 == edges[i].0 && edges[j].1 == edges[i].1 {
            j += 1;
        }
        match j - i {
            1 => topo.boundary_edges += 1,
            2 => {
                let (e0, e1) = (edges[i], edges[i + 1]);
                let from = |e: (u32, u32, u32, u8)| triangles[e.2 as usize][e.3 as usize];
                if from(e0) == from(e1) {
                    topo.inconsistent_edges += 1;
                } else {
                    topo.neighbours[e0.2 as usize][e0.3 as usize] = e1.2;
                    topo.neighbours[e1.2 as usize][e1.3 as usize] = e0.2;
                }
            }
            _ => topo.nonmanifold_edges += 1,
        }
        i = j;
    }
    if topo.boundary_edges == 0 && topo.nonmanifold_edges == 0 && topo.inconsistent_edges == 0 {
        topo.nonmanifold_vertices = count_multi_fan_vertices(vertex_count, triangles, &topo);
    }
    topo
}

/// Walks the fan around every vertex of a closed, consistently oriented,
/// edge-manifold mesh and counts vertices with more than one fan.
fn count_multi_fan_vertices(vertex_count: usize, triangles: &[[u32; 3]], topo: &Topology) -> usize {
    let mut visited = vec![false; triangles.len() * 3];
    let mut fans = vec![0u32; vertex_count];
    for start in 0..triangles.len() * 3 {
        if visited[start] {
            continue;
        }
        let v = triangles[start / 3][start % 3];
        fans[v as usize] += 1;
        let mut corner = start;
        // Each step crosses the edge c→a (in local order starting at v) to the
        // next triangle around v; a fan has at most all corners.
        for _ in 0..triangles.len() * 3 {
            visited[corner] = true;
            let (t, k) = (corner / 3, corner % 3);
            let next_t = topo.neighbours[t][(k + 2) % 3];
            if next_t == NONE {
                break;
            }
            let Some(nk) = triangles[next_t as usize].iter().position(|&x| x == v) else {
                break;
            };
            corner = next_t as usize * 3 + nk;
            if visited[corner] {
                break;
            }
        }
    }
    fans.iter().filter(|&&f| f > 1).count()
}

/// Angle-weighted vertex pseudo-normals `Σ α_i n_i` (Bærentzen & Aanæs 2005,
/// eq. 3; Thürmer & Wüthrich 1998): the sum over the triangles at a vertex of
/// the unit face normal times the triangle's angle at that vertex.
pub(crate) fn vertex_pseudo_normals(
    vertices: &[DVec3],
    triangles: &[[u32; 3]],
    tris: &[Tri],
) -> Vec<DVec3> {
    let mut out = vec![DVec3::ZERO; vertices.len()];
    for (t, g) in triangles.iter().zip(tris) {
        for k in 0..3 {
            let p = vertices[t[k] as usize];
            let u = vertices[t[(k + 1) % 3] as usize] - p;
            let v = vertices[t[(k + 2) % 3] as usize] - p;
            let angle = u.cross(v).length().atan2(u.dot(v));
            out[t[k] as usize] += g.n * angle;
        }
    }
    out
}
