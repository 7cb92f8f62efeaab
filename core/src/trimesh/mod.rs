//! Triangle meshes as exact signed distance fields.
//!
//! pyvcad's `Mesh` node converts a mesh into an OpenVDB narrow-band grid
//! (pyvcad 2.3.4: distances clamped to the band, resolution-dependent).
//! Volcad instead answers every query exactly from the triangles:
//!
//! * **distance**: nearest triangle through a binned-SAH BVH (`bvh.rs`)
//!   collapsed to 4-wide nodes with `f32` SIMD boxes (`wide.rs`), nearest
//!   child first, pruning on squared distances, with Ericson's
//!   closest-point-on-triangle (`triangle.rs`). A per-thread seed (the last
//!   answer for this mesh) and a coarse grid of exact distances (`coarse.rs`)
//!   give the search a tight starting radius;
//! * **sign**: for a closed, consistently oriented 2-manifold the
//!   angle-weighted pseudo-normal of the closest feature (face, edge or
//!   vertex; Bærentzen & Aanæs 2005): `p` is outside iff
//!   `(p − c)·n_feature > 0`. Any other mesh (holes, flipped or degenerate
//!   triangles, non-manifold edges) uses the generalised winding number
//!   (`winding.rs`), `inside ⇔ w > 1/2` (Jacobson et al. 2013).
//!
//! The result is a true Euclidean SDF (1-Lipschitz), so interval bounds over
//! boxes follow from one evaluation at the centre.

mod candidates;
mod certificate;
mod coarse;
mod distance;
pub use distance::Probe;
mod formats;
mod gaps;
mod grid_cache;
mod topology;
mod triangle;
mod winding;

#[cfg(test)]
mod bound_tests;
#[cfg(test)]
pub(crate) mod tests;

use std::path::{Path, PathBuf};

use glam::DVec3;

use crate::aabb::Aabb;
use crate::spatial::{bvh, wide};

use self::topology::Topology;
use self::triangle::Tri;
use self::winding::WindingTree;

/// Why a mesh could not be loaded or built.
#[derive(Debug, thiserror::Error)]
pub enum MeshError {
    /// The file could not be read (missing, permissions, …).
    #[error("{}: cannot read mesh: {msg}", .path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The operating system's message.
        msg: String,
    },
    /// The path is a folder, FIFO, socket or device (refused before opening:
    /// reading a FIFO would block).
    #[error("{}: is {kind}, not a regular file; give the path of a mesh file (STL, OBJ, PLY, OFF or 3MF)", .path.display())]
    NotRegular {
        /// The file.
        path: PathBuf,
        /// What it is instead.
        kind: &'static str,
    },
    /// The file has no bytes at all.
    #[error("{}: the file is empty (0 bytes); expected a mesh (STL, OBJ, PLY, OFF or 3MF)", .path.display())]
    EmptyFile {
        /// The file.
        path: PathBuf,
    },
    /// The content matches no format read here.
    #[error("{}: not a mesh format read here (STL, OBJ, PLY, OFF or 3MF, told by content): {detail}", .path.display())]
    UnknownFormat {
        /// The file.
        path: PathBuf,
        /// What the content looked like.
        detail: String,
    },
    /// A text format has a malformed line.
    #[error("{}:{line}{}: {msg}", .path.display(), column_suffix(*.column))]
    Parse {
        /// The file.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// 1-based column (0 when the whole line is meant).
        column: usize,
        /// What was expected and what was found.
        msg: String,
    },
    /// A 3MF model part has a malformed element.
    #[error("{} (in `{part}` line {line}, column {column}): {msg}", .path.display())]
    ThreeMf {
        /// The file.
        path: PathBuf,
        /// The model part inside the zip.
        part: String,
        /// 1-based line in the part.
        line: usize,
        /// 1-based column.
        column: usize,
        /// What is wrong.
        msg: String,
    },
    /// The mesh has holes and validation was asked for.
    #[error(
        "{}: mesh is not closed: {open_edges} open edges (used by one triangle only); the largest gap, {gap_edges} edges around ({:.3}, {:.3}, {:.3}), spans {gap_size:.3} mm. Repair the mesh, or load it with disable_validation = true (`Mesh(\"{}\", m, true)`) to decide inside/outside by the generalized winding number",
        .path.display(), .gap_center.x, .gap_center.y, .gap_center.z, .path.display()
    )]
    NotClosed {
        /// The file.
        path: PathBuf,
        /// Edges used by exactly one triangle.
        open_edges: usize,
        /// Open edges around the largest gap.
        gap_edges: usize,
        /// Centre of the largest gap's bounding box.
        gap_center: DVec3,
        /// Diagonal of the largest gap's bounding box (mm).
        gap_size: f64,
    },
    /// A binary STL is truncated, has trailing bytes or a non-finite value.
    #[error("{}: invalid binary STL: {msg}", .path.display())]
    BinaryStl {
        /// The file.
        path: PathBuf,
        /// What is wrong (sizes, triangle number).
        msg: String,
    },
    /// The file parsed but holds no triangle (none at all, or only
    /// degenerate ones).
    #[error("{}: {}", .path.display(), empty_reason(*.read))]
    Empty {
        /// The file.
        path: PathBuf,
        /// Triangles read before degenerate ones were dropped.
        read: usize,
    },
    /// The file parsed but its contents were rejected by
    /// [`TriangleMesh::from_triangles`].
    #[error("{}: {msg}", .path.display())]
    Invalid {
        /// The file.
        path: PathBuf,
        /// The rejection.
        msg: String,
    },
    /// [`TriangleMesh::from_triangles`] got no triangle.
    #[error("mesh has no triangles")]
    NoTriangles,
    /// A triangle refers to a vertex that does not exist.
    #[error(
        "triangle {triangle} refers to vertex {index}, but there are only {vertex_count} vertices"
    )]
    BadIndex {
        /// 0-based triangle number.
        triangle: usize,
        /// The offending vertex index.
        index: u32,
        /// Number of vertices given.
        vertex_count: usize,
    },
    /// A vertex coordinate is NaN or infinite.
    #[error("vertex {index} is not finite: {position}")]
    NonFiniteVertex {
        /// 0-based vertex number.
        index: usize,
        /// Its coordinates.
        position: DVec3,
    },
}

fn empty_reason(read: usize) -> String {
    if read == 0 {
        "the file contains no triangles".into()
    } else {
        format!("all {read} triangles of the file have a repeated corner: there is no surface")
    }
}

/// `":column"` for a known column, nothing for 0.
fn column_suffix(column: usize) -> String {
    if column > 0 {
        format!(":{column}")
    } else {
        String::new()
    }
}

/// A triangle mesh prepared for exact signed-distance queries. Immutable and
/// `Sync`: share it between threads by reference.
#[derive(Clone, Debug)]
pub struct TriangleMesh {
    vertices: Vec<DVec3>,
    triangles: Vec<[u32; 3]>,
    /// Binary BVH nodes (one triangle per leaf), for the winding number.
    nodes: Vec<bvh::BvhNode>,
    /// The same tree collapsed 4-wide, for distance queries.
    wide: wide::WideBvh,
    /// Prepared triangles in BVH slot order.
    tris: Vec<Tri>,
    /// Slot → index into `triangles`.
    order: Vec<u32>,
    /// Pseudo-normal data; `None` when the sign comes from the winding number.
    pseudo: Option<PseudoNormals>,
    /// Far-field expansions for the winding number.
    winding: WindingTree,
    /// Exact distances on a coarse grid (bounds far from the surface).
    coarse: Option<coarse::CoarseGrid>,
    /// Per-cell nearest-triangle candidates (exact queries near the surface).
    candidates: Option<candidates::CandidateGrid>,
    topology: Topology,
    bbox: Aabb,
    warnings: Vec<String>,
}

/// What the pseudo-normal sign test needs besides the face normals.
#[derive(Clone, Debug)]
struct PseudoNormals {
    /// Per slot and edge k (a→b, b→c, c→a): the slot of the triangle across.
    across: Vec<[u32; 3]>,
    /// Per slot: the vertex indices (into `vertex_normals`).
    corners: Vec<[u32; 3]>,
    /// Angle-weighted vertex pseudo-normals.
    vertex_normals: Vec<DVec3>,
}

impl TriangleMesh {
    /// Loads a mesh file: STL (ASCII or binary), OBJ, PLY (ASCII or
    /// binary), OFF or 3MF, told by content (`formats`). Identical vertex
    /// positions are welded, so an STL's shared edges are recognised;
    /// triangles with a repeated corner and repeated copies of a triangle are
    /// dropped. Problems that still allow a distance field (holes, …) become
    /// [`TriangleMesh::warnings`], not errors: call
    /// [`TriangleMesh::check_closed`] to refuse open meshes.
    pub fn load(path: &Path) -> Result<TriangleMesh, MeshError> {
        let loaded = formats::load(path)?;
        if loaded.triangles.is_empty() {
            return Err(MeshError::Empty {
                path: path.to_path_buf(),
                read: loaded.read_triangles,
            });
        }
        let mut mesh = Self::from_triangles(loaded.vertices, loaded.triangles).map_err(|e| {
            MeshError::Invalid {
                path: path.to_path_buf(),
                msg: e.to_string(),
            }
        })?;
        let mut warnings = loaded.warnings;
        warnings.append(&mut mesh.warnings);
        mesh.warnings = warnings;
        Ok(mesh)
    }

    /// Refuses a mesh with open edges (pyvcad's validation: "Mesh is not
    /// closed"), naming how many and where the largest gap is; `path` is the
    /// file to name.
    pub fn check_closed(&self, path: &Path) -> Result<(), MeshError> {
        if self.topology.boundary_edges == 0 {
            return Ok(());
        }
        let gap = gaps::largest(&self.vertices, &self.triangles);
        Err(MeshError::NotClosed {
            path: path.to_path_buf(),
            open_edges: self.topology.boundary_edges,
            gap_edges: gap.edges,
            gap_center: gap.center,
            gap_size: gap.size,
        })
    }

    /// Builds a mesh from indexed triangles (counter-clockwise seen from
    /// outside). Welds nothing: callers that have duplicated positions and
    /// want them joined must do it first.
    pub fn from_triangles(
        vertices: Vec<DVec3>,
        triangles: Vec<[u32; 3]>,
    ) -> Result<TriangleMesh, MeshError> {
        Self::from_triangles_cached(vertices, triangles, grid_cache::dir().as_deref())
    }

    /// [`TriangleMesh::from_triangles`] with the grid cache in `cache`
    /// (none: always built).
    pub(crate) fn from_triangles_cached(
        vertices: Vec<DVec3>,
        triangles: Vec<[u32; 3]>,
        cache: Option<&Path>,
    ) -> Result<TriangleMesh, MeshError> {
        if triangles.is_empty() {
            return Err(MeshError::NoTriangles);
        }
        if let Some((index, &position)) = vertices.iter().enumerate().find(|(_, v)| !v.is_finite())
        {
            return Err(MeshError::NonFiniteVertex { index, position });
        }
        for (t, tri) in triangles.iter().enumerate() {
            if let Some(&index) = tri.iter().find(|&&i| i as usize >= vertices.len()) {
                return Err(MeshError::BadIndex {
                    triangle: t,
                    index,
                    vertex_count: vertices.len(),
                });
            }
        }
        // The cached grids' file is read while the mesh is built.
        let slot = grid_cache::slot(&vertices, &triangles, cache);
        let (mut mesh, read) = rayon::join(
            || Self::assemble(vertices, triangles),
            || slot.as_ref().and_then(grid_cache::load),
        );
        grid_cache::attach(&mut mesh, slot, read);
        Ok(mesh)
    }

    /// The mesh of valid `vertices` and `triangles` (flipped when inside
    /// out), without its grids.
    fn assemble(vertices: Vec<DVec3>, mut triangles: Vec<[u32; 3]>) -> TriangleMesh {
        let prep = |tris: &[[u32; 3]]| -> Vec<Tri> {
            tris.iter()
                .map(|t| {
                    Tri::new(
                        vertices[t[0] as usize],
                        vertices[t[1] as usize],
                        vertices[t[2] as usize],
                    )
                })
                .collect()
        };
        let mut prepared = prep(&triangles);
        let mut topology = topology::analyse(vertices.len(), &triangles, &prepared);
        let mut warnings = topology.warnings();
        // A closed mesh with all normals pointing inwards would come out
        // inside-out: flip it (volume by the divergence theorem).
        if topology.is_closed_manifold() && signed_volume(&vertices, &triangles) < 0.0 {
            for t in &mut triangles {
                t.swap(1, 2);
            }
            prepared = prep(&triangles);
            topology = topology::analyse(vertices.len(), &triangles, &prepared);
            warnings.push("mesh was inside out (negative volume): triangle winding flipped".into());
        }

        let boxes: Vec<Aabb> = prepared
            .iter()
            .map(|t| {
                let [a, b, c] = t.corners();
                Aabb::new(a.min(b).min(c), a.max(b).max(c))
            })
            .collect();
        let (tree, order) = bvh::build(&boxes, 1);
        let wide = wide::WideBvh::new(&tree);
        let tris: Vec<Tri> = order.iter().map(|&i| prepared[i as usize]).collect();
        let winding = WindingTree::new(&tree.ranges, &tris);

        let pseudo = topology.is_closed_manifold().then(|| {
            let mut slot_of = vec![0u32; order.len()];
            for (s, &i) in order.iter().enumerate() {
                slot_of[i as usize] = s as u32;
            }
            PseudoNormals {
                across: order
                    .iter()
                    .map(|&i| topology.neighbours[i as usize].map(|n| slot_of[n as usize]))
                    .collect(),
                corners: order.iter().map(|&i| triangles[i as usize]).collect(),
                vertex_normals: topology::vertex_pseudo_normals(&vertices, &triangles, &prepared),
            }
        });
        let bbox = boxes.iter().fold(Aabb::EMPTY, |acc, b| acc.union(b));
        TriangleMesh {
            vertices,
            triangles,
            nodes: tree.nodes,
            wide,
            tris,
            order,
            pseudo,
            winding,
            coarse: None,
            candidates: None,
            topology,
            bbox,
            warnings,
        }
    }

    /// Axis-aligned bounds of the triangles.
    pub fn bbox(&self) -> Aabb {
        self.bbox
    }

    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// The vertex positions (after welding, for loaded files).
    pub fn vertices(&self) -> &[DVec3] {
        &self.vertices
    }

    /// The triangles as vertex indices, counter-clockwise from outside
    /// (flipped if the input was inside out; see [`TriangleMesh::warnings`]).
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// Edges used by exactly one triangle (0 for a closed mesh).
    pub fn boundary_edge_count(&self) -> usize {
        self.topology.boundary_edges
    }

    /// True when the sign comes from pseudo-normals (closed, consistently
    /// oriented 2-manifold without degenerate triangles); false when it
    /// comes from the slower generalised winding number.
    pub fn is_closed_manifold(&self) -> bool {
        self.pseudo.is_some()
    }

    /// Problems found while building, e.g. `"mesh is not closed: 12 boundary
    /// edges"`. Empty for a clean closed mesh.
    pub fn warnings(&self) -> Vec<String> {
        self.warnings.clone()
    }

    /// Enclosed volume `Σ a·(b × c)/6` (divergence theorem); meaningful for
    /// closed meshes.
    pub fn volume(&self) -> f64 {
        signed_volume(&self.vertices, &self.triangles)
    }
}

/// `Σ a·(b × c)/6` over the triangles.
fn signed_volume(vertices: &[DVec3], triangles: &[[u32; 3]]) -> f64 {
    triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| vertices[i as usize]);
            a.dot(b.cross(c))
        })
        .sum::<f64>()
        / 6.0
}
