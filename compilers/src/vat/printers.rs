//! Vat photopolymer printers: the masked-LCD screen each layer is shown
//! on (pixels and pixel pitch) and the build height.
//!
//! A vat (MSLA) printer cures a whole layer at once through an LCD: one
//! image pixel is one screen pixel, so the voxel is the pixel pitch in X
//! and Y and the layer thickness in Z, and the image is always the whole
//! screen.

use glam::DVec3;

use crate::job::ExportError;

/// A vat printer's screen and build volume.
#[derive(Clone, Debug, PartialEq)]
pub struct VatPrinter {
    /// The name the command line takes (`--preset saturn-4-ultra`), or
    /// `custom`.
    pub name: String,
    /// Screen pixel pitch along X and Y (mm).
    pub pixel: [f64; 2],
    /// Screen size in pixels (width along X, height along Y).
    pub screen: [usize; 2],
    /// Layer thickness (mm).
    pub layer: f64,
    /// Build height (mm); `None` for a custom printer (not checked).
    pub height: Option<f64>,
    /// One line for menus and `--help`.
    pub description: String,
}

impl VatPrinter {
    /// The voxel: pixel pitch in X and Y, layer thickness in Z.
    pub fn voxel(&self) -> DVec3 {
        DVec3::new(self.pixel[0], self.pixel[1], self.layer)
    }

    /// The build area (mm): screen pixels times pitch.
    pub fn area(&self) -> [f64; 2] {
        [
            self.screen[0] as f64 * self.pixel[0],
            self.screen[1] as f64 * self.pixel[1],
        ]
    }

    /// A printer of the given pitch (µm, X and Y), screen (pixels) and
    /// layer (µm); errors name the option and the range allowed.
    pub fn custom(
        pixel_um: [f64; 2],
        screen: [usize; 2],
        layer_um: f64,
    ) -> Result<VatPrinter, ExportError> {
        // A micrometre to a centimetre: outside it the value is a typo
        // (a pitch in mm given as µm or the other way round).
        let ok = |v: f64| v.is_finite() && (1.0..=10_000.0).contains(&v);
        if !pixel_um.iter().all(|v| ok(*v)) {
            return Err(ExportError::param(
                "--pixel",
                format!(
                    "{} x {} um: the pixel pitch must be 1 to 10000 um (e.g. --pixel 19,24)",
                    pixel_um[0], pixel_um[1]
                ),
            ));
        }
        if !ok(layer_um) {
            return Err(ExportError::param(
                "--layer",
                format!("{layer_um} um: the layer must be 1 to 10000 um (e.g. --layer 50)"),
            ));
        }
        if screen.iter().any(|s| !(1..=65_535).contains(s)) {
            return Err(ExportError::param(
                "--screen",
                format!(
                    "{} x {}: each side must be 1 to 65535 pixels (e.g. --screen 11520x5120)",
                    screen[0], screen[1]
                ),
            ));
        }
        Ok(VatPrinter {
            name: "custom".into(),
            pixel: [pixel_um[0] / 1000.0, pixel_um[1] / 1000.0],
            screen,
            layer: layer_um / 1000.0,
            height: None,
            description: "custom screen".into(),
        })
    }
}

/// The presets, in menu order. Each printer's values are its maker's
/// published specification; the build area is screen pixels × pitch.
pub fn vat_presets() -> Vec<VatPrinter> {
    vec![
        // Elegoo Saturn 4 Ultra (12K): 10" mono LCD of 11520 × 5120 px,
        // XY resolution 19 × 24 µm, build volume 218.88 × 122.88 × 220 mm
        // (elegoo.com product specification; UVtools' PrusaSlicer profile
        // "Elegoo Saturn 4 Ultra 12K.ini" agrees: display 11520 × 5120 px
        // over 218.88 × 122.88 mm, max_print_height 220). Layer: 50 µm,
        // the slicer's default for standard resin.
        VatPrinter {
            name: "saturn-4-ultra".into(),
            pixel: [0.019, 0.024],
            screen: [11_520, 5_120],
            layer: 0.05,
            height: Some(220.0),
            description: "Elegoo Saturn 4 Ultra 12K: 11520 x 5120 px of 19 x 24 um, 220 mm high, 50 um layers".into(),
        },
        // Anycubic Photon Mono M7 Pro (14K): 10.1" mono LCD of
        // 13312 × 5120 px, XY resolution 16.8 × 24.8 µm, build volume
        // 223 × 126 × 230 mm (anycubic.com product specification). Checked
        // against UVtools' PrusaSlicer profile "Anycubic Photon Mono M7
        // Pro.ini" (github.com/sn4k3/UVtools): display_pixels 13312 × 5120
        // over 223.642 × 126.976 mm (16.8 × 24.8 µm exactly) and
        // max_print_height 230; its default print profile is 0.05 mm
        // layers.
        VatPrinter {
            name: "photon-mono-m7-pro".into(),
            pixel: [0.0168, 0.0248],
            screen: [13_312, 5_120],
            layer: 0.05,
            height: Some(230.0),
            description: "Anycubic Photon Mono M7 Pro 14K: 13312 x 5120 px of 16.8 x 24.8 um, 230 mm high, 50 um layers".into(),
        },
    ]
}

/// The preset called `name` (case-insensitive), or an error listing them.
pub fn vat_preset(name: &str) -> Result<VatPrinter, ExportError> {
    let all = vat_presets();
    let names: Vec<String> = all.iter().map(|p| p.name.clone()).collect();
    all.into_iter()
        .find(|p| p.name.eq_ignore_ascii_case(name))
        .ok_or_else(|| {
            ExportError::param(
                "--preset",
                format!(
                    "{name}: not a vat printer; known: {}, or give --pixel UM --screen WxH --layer UM",
                    names.join(", ")
                ),
            )
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn presets_area_is_screen_times_pitch() {
        let p = vat_preset("Saturn-4-Ultra").expect("preset");
        let [w, h] = p.area();
        assert!((w - 218.88).abs() < 1e-9 && (h - 122.88).abs() < 1e-9);
        assert!(vat_preset("nope").is_err());
        assert!(VatPrinter::custom([0.0, 19.0], [10, 10], 50.0).is_err());
        assert!(VatPrinter::custom([19.0, 19.0], [0, 10], 50.0).is_err());
        let c = VatPrinter::custom([50.0, 50.0], [100, 80], 25.0).expect("custom");
        assert_eq!(c.voxel(), DVec3::new(0.05, 0.05, 0.025));
    }
}
