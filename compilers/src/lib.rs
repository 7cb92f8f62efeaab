//! # volcad-compilers
//!
//! Export jobs: a prepared [`volcad_core::Model`] plus parameters in, files
//! out. Every job runs through [`job`] (background thread, progress channel,
//! cancel, staging folder renamed on success, `manifest.json`) and samples the
//! model through the core's one grid sampler (`volcad_core::sampler`).
//!
//! * [`png_stack`]: inkjet slice stacks, one PNG per layer.
//! * [`gcvf`]: GrabCAD Voxel Print packages for PolyJet printers.
//! * [`mesh`]: segmented meshes (STL, OBJ, one 3MF with per-part settings).
//! * [`fea`]: Abaqus/CalculiX `.inp` meshes (C3D8R bricks, adaptive C3D4 tets).
//! * [`shard`]: layer stacks split into N layer ranges and merged back.
#![warn(missing_docs)]

pub mod fea;
pub mod gcvf;
pub mod job;
pub mod keep_out;
pub mod lazy_random;

pub mod bitmaps;
pub mod color;
pub mod design;
pub mod dither;
pub mod draws;
mod estimate;
pub mod mesh;
pub mod par_deflate;
pub mod plan;
pub mod png_io;
mod png_params;
pub mod png_stack;
mod png_summary;
mod presets;
pub mod printer_table;
pub mod resources;
pub mod row_png;
pub mod shard;
pub mod slice_image;
pub mod thin;
mod union_find;
pub mod vat;
pub mod zip_writer;

pub use job::{ExportError, JobHandle, Progress, Summary};
