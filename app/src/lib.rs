//! Volcad Studio and the volcad command line.
//!
//! * [`studio`]: the desktop IDE (eframe/egui with the wgpu backend): code
//!   editor, live volumetric viewport, parameters, export panels.
//! * [`cli`]: the headless `volcad` command line.

pub mod cli;
pub mod cpu;
pub mod studio;
