//! Spatial indexes shared across the core: the bounding-volume hierarchies
//! over boxes (the binary SAH tree `bvh` and its 4-wide collapse `wide`,
//! used by triangle meshes and the tetrahedron locator), the uniform cell
//! lattice ([`cells`], under the union index and the mesh candidate grid),
//! integer sort keys for `f32` bounds ([`order`]), the per-thread memory of
//! an index's last answer (`recent`) and `f64` bounds rounded outwards to
//! `f32` (`round`).

pub(crate) mod bvh;
pub(crate) mod cells;
pub(crate) mod order;
pub(crate) mod recent;
pub(crate) mod round;
pub(crate) mod wide;
