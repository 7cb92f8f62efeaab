//! A slice stack's 1-bit bitmaps, one folder per material (or resin):
//! PNGs named as the stack's slices (white = the material), or BMPs in
//! pyvcad 2.3.4's `MyersonCompiler` layout for printers that read BMP.
//!
//! # BMP layout (MyersonCompiler)
//!
//! `<folder>/<100000 + layer>_100000_<name>.bmp`, 1 bit a pixel, palette
//! 0 = black, 1 = white, **the material black** on white; optionally a
//! fixed image width (Myerson's machine: 880 px) with the layer at the
//! left (column 0 = min X) and white to the right. Rows are the top view
//! as in the PNGs (the bottom row of the image is min Y).
//!
//! The `image` crate's BMP encoder writes 8, 24 and 32 bits a pixel only,
//! so the 1-bit file is written here: the 14-byte file header, the 40-byte
//! `BITMAPINFOHEADER`, a 2-entry palette (62 bytes in all), then rows
//! bottom-up, each padded to a multiple of 4 bytes (Microsoft's BMP
//! format reference).

use glam::DVec3;

use crate::job::{ExportError, JobContext};
use crate::png_io::{self, PixelsPerMetre};
use crate::slice_image::{ImageStyle, bitmap_png};

/// The file format of per-material bitmaps.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum BitmapFormat {
    /// 1-bit PNGs named as the slices, white = the material.
    #[default]
    Png,
    /// 1-bit BMPs in MyersonCompiler's layout, black = the material.
    Bmp,
}

impl BitmapFormat {
    /// The CLI spelling.
    pub fn name(self) -> &'static str {
        match self {
            BitmapFormat::Png => "png",
            BitmapFormat::Bmp => "bmp",
        }
    }

    /// From the CLI spelling.
    pub fn parse(s: &str) -> Result<BitmapFormat, ExportError> {
        match s.to_ascii_lowercase().as_str() {
            "png" => Ok(BitmapFormat::Png),
            "bmp" => Ok(BitmapFormat::Bmp),
            _ => Err(ExportError::param(
                "--bitmap-format",
                format!("{s:?}: expected png or bmp"),
            )),
        }
    }
}

/// MyersonCompiler's fixed image width (`MAX_IMAGE_WIDTH`).
pub const MYERSON_WIDTH: usize = 880;

/// One material's folder of bitmaps.
pub(crate) struct BitmapFolder {
    /// The material's code in the layer (slot + 1).
    pub code: u8,
    /// Folder (and, for BMP, file) name.
    pub dir: String,
}

/// Folder names for `names` (in code order; a name used twice gets its
/// code appended).
pub(crate) fn folders(names: &[(String, u8)]) -> Vec<BitmapFolder> {
    let mut out: Vec<BitmapFolder> = Vec::new();
    for (i, (name, id)) in names.iter().enumerate() {
        let mut dir = png_io::folder_name(name, *id);
        if out.iter().any(|f| f.dir == dir) {
            dir = format!("{dir}_{id}");
        }
        out.push(BitmapFolder {
            code: i as u8 + 1,
            dir,
        });
    }
    out
}

/// How a stack writes its bitmaps.
#[derive(Clone, Copy, Debug)]
pub(crate) struct BitmapStyle {
    pub format: BitmapFormat,
    /// BMP image width (`None`: the layer's).
    pub width: Option<usize>,
    pub image: ImageStyle,
}

/// `100042_100000_VeroCyan.bmp` for layer 42 of folder `dir`.
pub fn myerson_name(z: usize, dir: &str) -> String {
    format!("{}_100000_{dir}.bmp", 100_000 + z)
}

/// Write layer `z`'s bitmaps (its codes, `nx × ny`) into each folder;
/// returns the files written, relative to the staging folder.
pub(crate) fn write_layer(
    ctx: &JobContext,
    [nx, ny]: [usize; 2],
    z: usize,
    slice_name: &str,
    codes: &[u8],
    folders: &[BitmapFolder],
    style: BitmapStyle,
) -> Result<Vec<String>, ExportError> {
    let mut files = Vec::new();
    let mut bits = Vec::new();
    for f in folders {
        let name = match style.format {
            BitmapFormat::Png => slice_name.to_owned(),
            BitmapFormat::Bmp => myerson_name(z, &f.dir),
        };
        let path = ctx.staging().join(&f.dir).join(&name);
        let bytes = match style.format {
            BitmapFormat::Png => bitmap_png(nx, ny, codes, f.code, &mut bits, style.image)
                .map_err(|e| {
                    ExportError::Other(format!("{}: PNG encoding: {e}", path.display()))
                })?,
            BitmapFormat::Bmp => {
                let w = style.width.unwrap_or(nx);
                bmp_mask(nx, ny, w, codes, f.code, style.image.pixel)
            }
        };
        std::fs::write(&path, bytes).map_err(|e| ExportError::io(&path, e))?;
        files.push(format!("{}/{name}", f.dir));
    }
    Ok(files)
}

/// Refuse a fixed width narrower than the layer (before any work).
pub(crate) fn check_width(
    width: Option<usize>,
    nx: usize,
    voxel: DVec3,
) -> Result<(), ExportError> {
    match width {
        Some(0) => Err(ExportError::param(
            "--bitmap-width",
            "0 px: give the printer's image width, e.g. 880",
        )),
        Some(w) if w < nx => Err(ExportError::param(
            "--bitmap-width",
            format!(
                "{w} px is narrower than the layer's {nx} px ({:.3} mm at {:.4} mm a voxel in X); use --bitmap-width {nx} or more, or a voxel of at least {:.4} mm in X",
                nx as f64 * voxel.x,
                voxel.x,
                nx as f64 * voxel.x / w as f64
            ),
        )),
        _ => Ok(()),
    }
}

/// Bytes of a BMP row of `width` 1-bit pixels: padded to 4.
pub fn bmp_row_bytes(width: usize) -> usize {
    width.div_ceil(32) * 4
}

/// A 1-bit BMP, `width × ny`, black (0) where the layer's voxel is `code`
/// and white (1) elsewhere, voxel row 0 (min Y) as the bottom row.
pub fn bmp_mask(
    nx: usize,
    ny: usize,
    width: usize,
    codes: &[u8],
    code: u8,
    pixel: Option<PixelsPerMetre>,
) -> Vec<u8> {
    let rb = bmp_row_bytes(width);
    let used = width.div_ceil(8);
    let mut data = vec![0u8; rb * ny];
    // Bottom-up: stored row j is voxel row j (min Y first).
    for (j, row) in codes.chunks_exact(nx).enumerate() {
        let out = &mut data[j * rb..j * rb + used];
        out.fill(0xFF);
        for (i, c) in row.iter().enumerate() {
            if *c == code {
                out[i / 8] &= !(0x80 >> (i % 8));
            }
        }
    }
    let mut out = bmp_header(width, ny, data.len(), pixel);
    out.extend_from_slice(&data);
    out
}

/// Bytes before a 1-bit BMP's pixels: file header, `BITMAPINFOHEADER`,
/// two palette entries.
pub const BMP_HEADER: usize = 14 + 40 + 8;

/// File header, `BITMAPINFOHEADER` and the black/white palette.
fn bmp_header(width: usize, height: usize, data: usize, pixel: Option<PixelsPerMetre>) -> Vec<u8> {
    const HEADER: usize = BMP_HEADER;
    let PixelsPerMetre([px, py]) = pixel.unwrap_or(PixelsPerMetre([0, 0]));
    let mut h = Vec::with_capacity(HEADER + data);
    let u32le = |h: &mut Vec<u8>, v: usize| h.extend_from_slice(&(v as u32).to_le_bytes());
    h.extend_from_slice(b"BM");
    u32le(&mut h, HEADER + data);
    u32le(&mut h, 0); // two reserved u16
    u32le(&mut h, HEADER);
    u32le(&mut h, 40);
    u32le(&mut h, width); // positive height: rows bottom-up
    u32le(&mut h, height);
    h.extend_from_slice(&1u16.to_le_bytes()); // planes
    h.extend_from_slice(&1u16.to_le_bytes()); // bits a pixel
    u32le(&mut h, 0); // BI_RGB, uncompressed
    u32le(&mut h, data);
    u32le(&mut h, px as usize);
    u32le(&mut h, py as usize);
    u32le(&mut h, 2); // palette entries
    u32le(&mut h, 0); // all important
    h.extend_from_slice(&[0, 0, 0, 0, 255, 255, 255, 0]); // BGRx: black, white
    h
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bmp_header_and_rows() {
        // 3 × 2 layer, code 1 at (0, 0) and (2, 1), 40 px wide.
        let codes = [1, 0, 2, 0, 2, 1];
        let b = bmp_mask(3, 2, 40, &codes, 1, Some(PixelsPerMetre([23_622, 11_811])));
        assert_eq!(&b[..2], b"BM");
        assert_eq!(
            u32::from_le_bytes([b[2], b[3], b[4], b[5]]) as usize,
            b.len()
        );
        assert_eq!(b[10], 62, "pixel data after 62 header bytes");
        assert_eq!(u16::from_le_bytes([b[28], b[29]]), 1, "1 bit a pixel");
        assert_eq!(b.len(), 62 + 2 * 8, "40 px = 5 bytes, padded to 8 a row");
        assert_eq!(u32::from_le_bytes([b[38], b[39], b[40], b[41]]), 23_622);
        // Row 0 (bottom, min Y): pixel 0 black; row 1: pixel 2 black.
        assert_eq!(b[62], 0b0111_1111);
        assert_eq!(&b[63..67], &[0xFF; 4]);
        assert_eq!(b[70], 0b1101_1111);
        assert_eq!(myerson_name(42, "VeroCyan"), "100042_100000_VeroCyan.bmp");
        assert!(check_width(Some(2), 3, DVec3::ONE).is_err());
        assert!(check_width(Some(880), 3, DVec3::ONE).is_ok());
    }
}
