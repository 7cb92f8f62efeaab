//! Faces of an FEA mesh: which are on the boundary, and which elements hold
//! together through shared faces.
//!
//! Every element face is keyed by its sorted node ids; one sort brings the
//! two copies of an inner face together. A face seen once is on the
//! boundary; a face seen twice joins its two elements (union–find). Elements
//! touching only along an edge or at a corner stay apart: such a joint has
//! no area, so under load its stress is unbounded and the solver's answer
//! for the pieces means nothing.

use rayon::prelude::*;

use super::{Element, FeaMesh};
use crate::union_find::{find, join};

/// Corner indices of each face of a C3D8R brick (CalculiX order: bottom
/// 0-1-2-3, top 4-5-6-7), each face's corners in order around it.
const HEX_FACES: [[usize; 4]; 6] = [
    [0, 1, 2, 3],
    [4, 5, 6, 7],
    [0, 1, 5, 4],
    [1, 2, 6, 5],
    [2, 3, 7, 6],
    [3, 0, 4, 7],
];
/// The same for a C3D4 tetrahedron (the fourth index unused).
const TET_FACES: [[usize; 4]; 4] = [[0, 1, 2, 0], [0, 1, 3, 0], [0, 2, 3, 0], [1, 2, 3, 0]];

/// A face's nodes in order around it: three or four 0-based ids, the fourth
/// `u32::MAX` for a triangle.
pub type Face = [u32; 4];

/// The boundary faces and the connected pieces of a mesh.
#[derive(Clone, Debug, Default)]
pub struct Topology {
    /// Faces that belong to one element only.
    pub boundary: Vec<Face>,
    /// Element count of each piece (elements joined through shared faces),
    /// largest first.
    pub pieces: Vec<usize>,
}

fn faces(element: Element) -> &'static [[usize; 4]] {
    match element {
        Element::C3D8R => &HEX_FACES,
        Element::C3D4 => &TET_FACES,
    }
}

fn face_nodes(mesh: &FeaMesh, e: usize, f: usize) -> Face {
    let conn = mesh.element_nodes(e);
    let corners = faces(mesh.element)[f];
    let mut out = corners.map(|c| conn[c]);
    if mesh.element == Element::C3D4 {
        out[3] = u32::MAX;
    }
    out
}

/// Boundary faces and pieces of `mesh` (one sort of every face).
pub fn topology(mesh: &FeaMesh) -> Topology {
    let per = faces(mesh.element).len();
    let mut keys: Vec<(Face, u32, u8)> = (0..mesh.len())
        .into_par_iter()
        .flat_map_iter(|e| {
            (0..per).map(move |f| {
                let mut k = face_nodes(mesh, e, f);
                k.sort_unstable();
                (k, e as u32, f as u8)
            })
        })
        .collect();
    keys.par_sort_unstable();
    let mut parent: Vec<u32> = (0..mesh.len() as u32).collect();
    let mut boundary = Vec::new();
    let mut i = 0;
    while i < keys.len() {
        let mut j = i + 1;
        while j < keys.len() && keys[j].0 == keys[i].0 {
            j += 1;
        }
        if j - i == 1 {
            let (_, e, f) = keys[i];
            boundary.push(face_nodes(mesh, e as usize, f as usize));
        }
        for k in i + 1..j {
            join(&mut parent, keys[i].1, keys[k].1);
        }
        i = j;
    }
    let mut size = vec![0usize; mesh.len()];
    for e in 0..mesh.len() as u32 {
        size[find(&mut parent, e) as usize] += 1;
    }
    let mut pieces: Vec<usize> = size.into_iter().filter(|&s| s > 0).collect();
    pieces.sort_unstable_by(|a, b| b.cmp(a));
    Topology { boundary, pieces }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    /// Two unit bricks side by side along x, and a third touching the
    /// second only along an edge.
    fn bricks(edge_only: bool) -> FeaMesh {
        let mut m = FeaMesh::new(Element::C3D8R);
        let mut node = |p: DVec3| -> u32 {
            if let Some(i) = m.nodes.iter().position(|q| *q == p) {
                return i as u32;
            }
            m.nodes.push(p);
            m.nodes.len() as u32 - 1
        };
        let mut conn = Vec::new();
        let mut origins = vec![DVec3::ZERO, DVec3::X];
        if edge_only {
            origins.push(DVec3::new(2.0, 1.0, 0.0));
        }
        for o in &origins {
            for (dx, dy, dz) in [
                (0., 0., 0.),
                (1., 0., 0.),
                (1., 1., 0.),
                (0., 1., 0.),
                (0., 0., 1.),
                (1., 0., 1.),
                (1., 1., 1.),
                (0., 1., 1.),
            ] {
                conn.push(node(*o + DVec3::new(dx, dy, dz)));
            }
        }
        m.conn = conn;
        m.mat = vec![0; origins.len()];
        m
    }

    #[test]
    fn shared_faces_join_and_edges_do_not() {
        let t = topology(&bricks(false));
        assert_eq!(t.pieces, vec![2]);
        assert_eq!(t.boundary.len(), 10);
        let t = topology(&bricks(true));
        assert_eq!(t.pieces, vec![2, 1]);
        assert_eq!(t.boundary.len(), 16);
    }
}
