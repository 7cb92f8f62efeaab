//! Where a mesh is open: its boundary edges (used by one triangle only)
//! grouped into connected gaps, for the not-closed refusal.

use glam::DVec3;

/// One connected set of boundary edges.
pub(crate) struct Gap {
    /// Boundary edges in it.
    pub edges: usize,
    /// Centre of their bounding box.
    pub center: DVec3,
    /// Diagonal of their bounding box.
    pub size: f64,
}

/// The gap with the longest bounding-box diagonal (ties: more edges).
/// Boundary edges are found by sorting undirected edges; gaps are the
/// connected components of the boundary edges' vertices (union-find).
pub(crate) fn largest(vertices: &[DVec3], triangles: &[[u32; 3]]) -> Gap {
    let mut edges: Vec<(u32, u32)> = triangles
        .iter()
        .flat_map(|t| (0..3).map(move |k| (t[k].min(t[(k + 1) % 3]), t[k].max(t[(k + 1) % 3]))))
        .collect();
    edges.sort_unstable();
    let boundary: Vec<(u32, u32)> = edges
        .chunk_by(|a, b| a == b)
        .filter(|run| run.len() == 1)
        .map(|run| run[0])
        .collect();
    let mut parent: Vec<u32> = (0..vertices.len() as u32).collect();
    fn root(parent: &mut [u32], mut v: u32) -> u32 {
        while parent[v as usize] != v {
            parent[v as usize] = parent[parent[v as usize] as usize];
            v = parent[v as usize];
        }
        v
    }
    for &(a, b) in &boundary {
        let (ra, rb) = (root(&mut parent, a), root(&mut parent, b));
        parent[ra as usize] = rb;
    }
    // Per component: edge count and bounding box.
    let mut groups: std::collections::HashMap<u32, (usize, DVec3, DVec3)> =
        std::collections::HashMap::new();
    for &(a, b) in &boundary {
        let r = root(&mut parent, a);
        let g = groups
            .entry(r)
            .or_insert((0, DVec3::INFINITY, DVec3::NEG_INFINITY));
        g.0 += 1;
        for v in [a, b] {
            let p = vertices[v as usize];
            g.1 = g.1.min(p);
            g.2 = g.2.max(p);
        }
    }
    groups
        .into_values()
        .map(|(edges, lo, hi)| Gap {
            edges,
            center: (lo + hi) * 0.5,
            size: lo.distance(hi),
        })
        .max_by(|a, b| a.size.total_cmp(&b.size).then(a.edges.cmp(&b.edges)))
        .unwrap_or(Gap {
            edges: 0,
            center: DVec3::ZERO,
            size: 0.0,
        })
}
