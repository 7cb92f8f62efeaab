//! Connected bodies of the exported part: the segments' meshes joined where
//! they share vertices (segment interfaces are shared exactly, so equal
//! positions are the same point), for the summary's body count and its
//! warning when a part falls apart into pieces at the voxel size.

use rayon::prelude::*;

use super::SegmentMesh;
use crate::union_find::{find, join, link};

/// Bodies of a part.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Bodies {
    /// Number of bodies.
    pub count: usize,
    /// Enclosed volume (mm³) of each body, largest first, when there are
    /// two or more (what a warning about a part that fell apart says; one
    /// body's volume is the part's, which the checks sum).
    pub volumes: Vec<f64>,
}

/// The bodies of the part made of `segs`.
pub fn bodies(segs: &[SegmentMesh]) -> Bodies {
    let mut base = Vec::with_capacity(segs.len());
    let mut n = 0u32;
    for s in segs {
        base.push(n);
        n += s.mesh.vertices.len() as u32;
    }
    let mut parent: Vec<u32> = (0..n).collect();
    for (s, &b) in segs.iter().zip(&base) {
        for t in &s.mesh.triangles {
            // (`join` twice, with the first corner's root found once.)
            let r = find(&mut parent, b + t[0]);
            let r1 = find(&mut parent, b + t[1]);
            let r = link(&mut parent, r, r1);
            let r2 = find(&mut parent, b + t[2]);
            link(&mut parent, r, r2);
        }
    }
    if segs.iter().filter(|s| !s.mesh.is_empty()).count() > 1 {
        let mut keys: Vec<([u32; 3], u32)> = segs
            .par_iter()
            .zip(&base)
            .flat_map_iter(|(s, &b)| {
                s.mesh
                    .vertices
                    .iter()
                    .enumerate()
                    .map(move |(i, v)| (v.map(|c| (c + 0.0).to_bits()), b + i as u32))
            })
            .collect();
        keys.par_sort_unstable();
        for w in keys.windows(2) {
            if w[0].0 == w[1].0 {
                join(&mut parent, w[0].1, w[1].1);
            }
        }
    }
    // Every id's root in one pass: a parent is never above its child (the
    // smaller root wins, and halving only shortens), so the parent's root
    // is known when the child is reached.
    let mut count = 0;
    for i in 0..parent.len() {
        parent[i] = parent[parent[i] as usize];
        count += usize::from(parent[i] as usize == i);
    }
    Bodies {
        count,
        volumes: if count > 1 {
            measured(segs, &base, &parent)
        } else {
            Vec::new()
        },
    }
}

/// Each body's volume (`root`: every vertex's body, the least index in
/// it, segments numbered on from `base`), summed triangle by triangle.
fn measured(segs: &[SegmentMesh], base: &[u32], root: &[u32]) -> Vec<f64> {
    let mut volume = vec![0.0f64; root.len()];
    for (s, &b) in segs.iter().zip(base) {
        for t in &s.mesh.triangles {
            let [p, q, r] = t.map(|i| s.mesh.vertices[i as usize].map(f64::from));
            let det = p[0] * (q[1] * r[2] - q[2] * r[1]) - p[1] * (q[0] * r[2] - q[2] * r[0])
                + p[2] * (q[0] * r[1] - q[1] * r[0]);
            volume[root[(b + t[0]) as usize] as usize] += det / 6.0;
        }
    }
    let mut volumes: Vec<f64> = (0..root.len())
        .filter(|&i| root[i] as usize == i)
        .map(|i| volume[i])
        .collect();
    volumes.sort_unstable_by(|a, b| b.total_cmp(a));
    volumes
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::IndexedMesh;

    /// A closed tetrahedron at `o`, counter-clockwise from outside.
    fn tet(o: [f32; 3]) -> IndexedMesh {
        let v = |d: [f32; 3]| [o[0] + d[0], o[1] + d[1], o[2] + d[2]];
        IndexedMesh {
            vertices: vec![
                v([0., 0., 0.]),
                v([1., 0., 0.]),
                v([0., 1., 0.]),
                v([0., 0., 1.]),
            ],
            triangles: vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
        }
    }

    fn seg(mesh: IndexedMesh) -> SegmentMesh {
        SegmentMesh {
            name: "s".into(),
            mesh,
            voxels: 0,
            f: 0.0,
            infill_percent: 0.0,
        }
    }

    #[test]
    fn apart_and_shared_vertices() {
        let mut two = tet([0., 0., 0.]);
        let far = tet([5., 0., 0.]);
        two.triangles
            .extend(far.triangles.iter().map(|t| t.map(|i| i + 4)));
        two.vertices.extend(far.vertices);
        let b = bodies(&[seg(two)]);
        assert_eq!(b.count, 2);
        assert!((b.volumes[0] - 1.0 / 6.0).abs() < 1e-9, "{b:?}");
        // Two segments sharing the vertex (1, 0, 0): one body.
        let b = bodies(&[seg(tet([0., 0., 0.])), seg(tet([1., 0., 0.]))]);
        assert_eq!(b.count, 1);
        assert!(b.volumes.is_empty());
        let b = bodies(&[seg(tet([0., 0., 0.])), seg(tet([3., 0., 0.]))]);
        assert_eq!(b.count, 2);
    }
}
