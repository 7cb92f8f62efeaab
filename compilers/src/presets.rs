//! Printer presets for slice stacks: named voxel sizes.
//!
//! An inkjet printer's voxel is its addressable grid: `25.4 / dpi` mm across
//! (X, the print-head direction, and Y, the scan direction) and one layer
//! thickness in Z. A preset only fixes the voxel size; orientation and file
//! layout are the same for every preset (see [`crate::png_stack`]).

use glam::DVec3;

/// A named voxel size for a printer.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Preset {
    /// The name the CLI takes (`--preset j750`).
    pub name: &'static str,
    /// Voxel size (mm) along X, Y, Z.
    pub voxel: DVec3,
    /// One line for menus and `--help`.
    pub description: &'static str,
}

/// Millimetres per dot at `dpi` dots per inch: `25.4 / dpi`.
const fn mm_per_dot(dpi: f64) -> f64 {
    25.4 / dpi
}

static PRESETS: [Preset; 3] = [
    Preset {
        name: "j750",
        voxel: DVec3::new(mm_per_dot(600.0), mm_per_dot(300.0), 0.027),
        description: "Stratasys J750-class, high speed: 600 x 300 dpi, 27 um layers",
    },
    Preset {
        name: "j750-hq",
        voxel: DVec3::new(mm_per_dot(600.0), mm_per_dot(300.0), 0.014),
        description: "Stratasys J750-class, high quality: 600 x 300 dpi, 14 um layers",
    },
    Preset {
        name: "cube-0.1",
        voxel: DVec3::new(0.1, 0.1, 0.1),
        description: "0.1 mm cubic voxels (previews and checks, not a printer)",
    },
];

/// All presets, in menu order.
pub fn presets() -> &'static [Preset] {
    &PRESETS
}

/// The preset called `name` (case-insensitive).
pub fn preset(name: &str) -> Option<&'static Preset> {
    PRESETS.iter().find(|p| p.name.eq_ignore_ascii_case(name))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn j750_is_600_by_300_dpi_27_um() {
        let p = preset("J750").expect("j750 preset");
        assert!((p.voxel.x - 0.042_333_3).abs() < 1e-6, "{}", p.voxel.x);
        assert!((p.voxel.y - 0.084_666_7).abs() < 1e-6, "{}", p.voxel.y);
        assert_eq!(p.voxel.z, 0.027);
        assert!(presets().iter().all(|p| p.voxel.cmpgt(DVec3::ZERO).all()));
    }
}
