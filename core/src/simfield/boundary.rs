//! The boundary surface of a tetrahedral mesh.
//!
//! A face used by exactly one tetrahedron lies on the boundary. Each
//! tetrahedron is first oriented positively (`det E > 0`, swapping two
//! corners of an inverted one); its faces `(0,2,1)`, `(0,1,3)`, `(1,2,3)`,
//! `(0,3,2)` then have counter-clockwise order seen from outside, so the
//! boundary triangles come out with outward normals, as
//! [`crate::trimesh::TriangleMesh`] expects for its pseudo-normal sign.

use glam::DVec3;

/// Boundary triangles (indices into the compacted vertex list), the
/// compacted vertices, and the number of faces shared by more than two
/// tetrahedra (a non-conforming mesh).
pub(crate) struct Boundary {
    /// Vertices used by the boundary.
    pub vertices: Vec<DVec3>,
    /// Outward triangles.
    pub triangles: Vec<[u32; 3]>,
    /// Faces used by more than two tetrahedra.
    pub overused_faces: usize,
}

/// Extracts the boundary of `tets` (valid indices into `nodes`).
pub(crate) fn extract(nodes: &[DVec3], tets: &[[u32; 4]]) -> Boundary {
    const FACES: [[usize; 3]; 4] = [[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]];
    // (sorted key, oriented face)
    let mut faces: Vec<([u32; 3], [u32; 3])> = Vec::with_capacity(tets.len() * 4);
    for t in tets {
        let mut t = *t;
        let p = t.map(|i| nodes[i as usize]);
        if (p[1] - p[0]).dot((p[2] - p[0]).cross(p[3] - p[0])) < 0.0 {
            t.swap(1, 2);
        }
        for f in FACES {
            let face = [t[f[0]], t[f[1]], t[f[2]]];
            let mut key = face;
            key.sort_unstable();
            faces.push((key, face));
        }
    }
    faces.sort_unstable_by_key(|f| f.0);
    let mut triangles = Vec::new();
    let mut overused_faces = 0;
    let mut i = 0;
    while i < faces.len() {
        let mut j = i + 1;
        while j < faces.len() && faces[j].0 == faces[i].0 {
            j += 1;
        }
        match j - i {
            1 => triangles.push(faces[i].1),
            2 => {}
            _ => overused_faces += 1,
        }
        i = j;
    }
    // Compact to the vertices the boundary uses.
    let mut remap = vec![u32::MAX; nodes.len()];
    let mut vertices = Vec::new();
    for t in &mut triangles {
        for v in t.iter_mut() {
            if remap[*v as usize] == u32::MAX {
                remap[*v as usize] = vertices.len() as u32;
                vertices.push(nodes[*v as usize]);
            }
            *v = remap[*v as usize];
        }
    }
    Boundary {
        vertices,
        triangles,
        overused_faces,
    }
}
