//! # volcad-core
//!
//! The model every part of Volcad Studio samples. A **design** is a tree of
//! [`Node`]s built by a Rhai script ([`script`]); for any point p (mm) it
//! answers the **signed distance** to the surface (negative inside) and,
//! where p is inside, the **volume fractions** of the base materials of a
//! [`MaterialTable`]. Everything downstream (preview, slice stacks, meshes,
//! FEA meshes) samples these two functions.
//!
//! Data flow: `script text → (Rhai) → Node tree → Model::prepare → Model →
//! batches of points → distances + fractions` (and [`sampler`] streams a
//! grid of them slab by slab).
//!
//! ```
//! use volcad_core::{script, Model};
//! let design = script::run_script(
//!     r#"let m = default_materials();
//!        Sphere(Vec3(0, 0, 0), 10, m.id("red"))"#,
//!     "doc.rhai",
//!     &script::ScriptOptions::default(),
//! ).unwrap();
//! let model = Model::prepare(&design.root, design.materials.clone()).unwrap();
//! assert!((model.distance(glam::DVec3::new(12.0, 0.0, 0.0)) - 2.0).abs() < 1e-12);
//! ```
//!
//! ## Embedding
//!
//! The crate root holds what a program that samples designs needs:
//! [`model_of_file`] (or [`run_script`] and [`Model::prepare`]) gives a
//! [`Model`]; a [`Grid`] over its box and a [`Sampler`] made for a
//! [`Consumer`] fill a caller-owned [`Slab`] a few layers at a time, on
//! the current rayon pool. `cargo run -p volcad-core --example sample`
//! shows the whole path. The modules hold the rest: [`attribute`]s a
//! design carries, [`material`] tables, the [`node`] tree, imported
//! [`trimesh`]es and [`simfield`]s, [`text`] outlines, the legacy
//! [`vcad`] language, and the [`heap`] accounting the binaries install.
#![warn(missing_docs)]

mod aabb;
pub mod attribute;
pub mod bench;
pub mod expr;
mod fastmath;
pub mod heap;
pub mod interval;
mod lattice;
pub mod material;
pub mod model;
pub mod names;
pub mod node;
pub mod sampler;
pub mod script;
pub mod simfield;
mod spatial;
pub mod text;
pub mod trimesh;
pub mod vcad;
mod xorshift;

pub use aabb::Aabb;
pub use fastmath::round_i32;
pub use glam::DVec3;
pub use interval::Interval;
pub use material::{MaterialId, MaterialTable};
pub use model::{Model, Points, PrepareError};
pub use node::{Node, NodeKind};
pub use sampler::{Consumer, Grid, Sampler, Slab};
pub use script::{
    Design, DesignError, ScriptError, ScriptOptions, model_of, model_of_file, run_script,
};
