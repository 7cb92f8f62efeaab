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
    let pieces = piece_sizes(&mut parent, mesh.len());
    Topology { boundary, pieces }
}

/// The faces and pieces of a brick mesh, found while its bricks are made
/// layer by layer ([`super::bricks`]): a brick's neighbours are the grid
/// cells beside it, so no face is keyed or sorted. Gives the same pieces
/// and the same boundary faces as [`topology`] (in grid order).
pub(super) struct GridFaces {
    nx: usize,
    /// Element id per cell of the layer below the one being added, and of
    /// that layer (`u32::MAX`: no brick).
    below: Vec<u32>,
    here: Vec<u32>,
    parent: Vec<u32>,
    boundary: Vec<Face>,
}

impl GridFaces {
    /// For a grid `nx` × `ny` cells across.
    pub fn new(nx: usize, ny: usize) -> Self {
        Self {
            nx,
            below: vec![u32::MAX; nx * ny],
            here: vec![u32::MAX; nx * ny],
            parent: Vec::new(),
            boundary: Vec::new(),
        }
    }

    /// Add the layer of bricks `first..` of `mesh` (made in `(j, i)` order
    /// from the cells of `this` not `u16::MAX`); `above` marks the layer
    /// above the same way.
    pub fn layer(&mut self, mesh: &FeaMesh, first: usize, this: &[u16], above: &[u16]) {
        let (nx, ny) = (self.nx, this.len() / self.nx.max(1));
        let mut e = first as u32;
        for (c, &m) in this.iter().enumerate() {
            self.here[c] = if m == u16::MAX {
                u32::MAX
            } else {
                e += 1;
                e - 1
            };
        }
        self.parent.extend(first as u32..e);
        for c in 0..this.len() {
            let e = self.here[c];
            if e == u32::MAX {
                continue;
            }
            let (i, j) = (c % nx, c / nx);
            // (face of HEX_FACES, the neighbour's element or None when
            // it is past the grid) for −x, −y, −z: joined when a brick;
            // for +x, +y, +z: a brick there is joined from its side.
            let lower = [
                (5, (i > 0).then(|| self.here[c - 1])),
                (2, (j > 0).then(|| self.here[c - nx])),
                (0, Some(self.below[c])),
            ];
            for (f, nb) in lower {
                match nb {
                    Some(n) if n != u32::MAX => join(&mut self.parent, e, n),
                    _ => self.boundary.push(face_nodes(mesh, e as usize, f)),
                }
            }
            let brick = |m: Option<&u16>| m.is_some_and(|m| *m != u16::MAX);
            let upper = [
                (3, i + 1 < nx && brick(this.get(c + 1))),
                (4, j + 1 < ny && brick(this.get(c + nx))),
                (1, brick(above.get(c))),
            ];
            for (f, joined) in upper {
                if !joined {
                    self.boundary.push(face_nodes(mesh, e as usize, f));
                }
            }
        }
        std::mem::swap(&mut self.below, &mut self.here);
    }

    /// The boundary faces and pieces.
    pub fn finish(mut self) -> Topology {
        let n = self.parent.len();
        Topology {
            pieces: piece_sizes(&mut self.parent, n),
            boundary: self.boundary,
        }
    }
}

/// Element count of each set of `parent`, largest first.
fn piece_sizes(parent: &mut [u32], elements: usize) -> Vec<usize> {
    let mut size = vec![0usize; elements];
    for e in 0..elements as u32 {
        size[find(parent, e) as usize] += 1;
    }
    let mut pieces: Vec<usize> = size.into_iter().filter(|&s| s > 0).collect();
    pieces.sort_unstable_by(|a, b| b.cmp(a));
    pieces
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

    #[test]
    fn grid_faces_match_the_sorted_faces() {
        use volcad_core::script::{ScriptOptions, model_of};
        // Struts that fall apart at this brick size: pieces joined at
        // edges, and holes.
        let src = r#"let m = default_materials();
Intersection(false, [Tile(GraphLattice(LatticeType::BodyCenteredCubic, Vec3(5,5,5), 0.35, m.id("gray"))), Sphere(Vec3(0,0,0), 6, m.id("gray"))])"#;
        let model = model_of(src, "t.rhai", &ScriptOptions::default()).expect("design");
        let cancel = std::sync::atomic::AtomicBool::new(false);
        let mut mesh =
            crate::fea::bricks::brick_mesh(&model, 0.5, 0, u64::MAX, &cancel, &|_, _, _, _| {})
                .expect("bricks");
        let grid = mesh.topology.take().expect("found with the bricks");
        let sorted = topology(&mesh);
        assert!(grid.pieces.len() > 1, "{:?}", grid.pieces);
        assert_eq!(grid.pieces, sorted.pieces);
        let key = |b: &[Face]| {
            let mut v = b.to_vec();
            v.sort_unstable();
            v
        };
        assert_eq!(key(&grid.boundary), key(&sorted.boundary));
    }
}
