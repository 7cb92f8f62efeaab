//! One layer's material codes as an image: RGBA (each pixel its
//! material's colour) or a 1-bit mask of one material, in either of the
//! two orientations the exports use, with the printer's pixel size.

use crate::png_io::{self, PixelsPerMetre, bit_row_bytes};

/// Where voxel column `i`, row `j` of a layer lands in the image.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Orientation {
    /// Column 0 = min X, row 0 = max Y: an image viewer shows the layer as
    /// seen from above (+Z), +X right, +Y up (our PNG stacks).
    TopView,
    /// Column 0 = max X, row 0 = min Y: pyvcad 2.3.4's slice images
    /// (`DirectMaterialCompiler`, `GCVFExporter`): the top view turned 180°.
    Pyvcad,
}

impl Orientation {
    /// Image row of voxel row `j` of `ny`.
    #[inline]
    pub fn row(self, j: usize, ny: usize) -> usize {
        match self {
            Orientation::TopView => ny - 1 - j,
            Orientation::Pyvcad => j,
        }
    }

    /// Image column of voxel column `i` of `nx`.
    #[inline]
    pub fn col(self, i: usize, nx: usize) -> usize {
        match self {
            Orientation::TopView => i,
            Orientation::Pyvcad => nx - 1 - i,
        }
    }
}

/// How a layer's images are made.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImageStyle {
    /// Where each voxel goes.
    pub orientation: Orientation,
    /// The physical pixel size written into each PNG.
    pub pixel: Option<PixelsPerMetre>,
}

/// The layer's RGBA pixels into `out` (`4·nx·ny` bytes, every one
/// written; rows from the top): each voxel its material's colour
/// `pal[code]` (a code past the palette is transparent black).
fn rgba_into(nx: usize, codes: &[u8], pal: &[[u8; 4]], o: Orientation, out: &mut [u8]) {
    // One table lookup and one 4-byte store a pixel, without bounds checks
    // or the orientation's branch in the loop.
    let mut table = [[0u8; 4]; 256];
    for (t, c) in table.iter_mut().zip(pal) {
        *t = *c;
    }
    let ny = codes.len() / nx.max(1);
    for (j, row) in codes.chunks_exact(nx).enumerate() {
        let r = o.row(j, ny);
        let px = out[r * nx * 4..(r + 1) * nx * 4].chunks_exact_mut(4);
        match o {
            Orientation::TopView => {
                for (px, c) in px.zip(row) {
                    px.copy_from_slice(&table[*c as usize]);
                }
            }
            Orientation::Pyvcad => {
                for (px, c) in px.rev().zip(row) {
                    px.copy_from_slice(&table[*c as usize]);
                }
            }
        }
    }
}

/// The layer's RGBA PNG.
// Speed copy of compilers/src/row_png.rs::rgba_png (same bytes): this one
// holds the whole RGBA image and costs less CPU (docs/PERFORMANCE.md,
// "Speed copies").
pub fn rgba_png(
    nx: usize,
    ny: usize,
    codes: &[u8],
    pal: &[[u8; 4]],
    style: ImageStyle,
) -> Result<Vec<u8>, png::EncodingError> {
    // One pixel buffer a thread, reused layer after layer: a fresh one is
    // zeroed by the allocator before every pixel is written anyway.
    thread_local! {
        static RGBA: std::cell::RefCell<Vec<u8>> = const { std::cell::RefCell::new(Vec::new()) };
    }
    RGBA.with_borrow_mut(|rgba| {
        rgba.resize(nx * ny * 4, 0);
        rgba_into(nx, codes, pal, style.orientation, rgba);
        png_io::encode_rgba(nx, ny, rgba, style.pixel)
    })
}

/// The layer's mask of material `code` into `bits` (rows of
/// [`bit_row_bytes`], leftmost pixel in the top bit): 1 where the voxel
/// is `code` when `set` is true, else 0 there and 1 elsewhere.
pub fn mask_bits(
    nx: usize,
    ny: usize,
    codes: &[u8],
    code: u8,
    o: Orientation,
    set: bool,
    bits: &mut Vec<u8>,
) {
    let rb = bit_row_bytes(nx);
    bits.clear();
    bits.resize(rb * ny, if set { 0 } else { 0xFF });
    for (j, row) in codes.chunks_exact(nx).enumerate() {
        let r = o.row(j, ny);
        let out = &mut bits[r * rb..(r + 1) * rb];
        for (i, c) in row.iter().enumerate() {
            if *c == code {
                let x = o.col(i, nx);
                out[x / 8] ^= 0x80 >> (x % 8);
            }
        }
    }
}

/// The layer's 1-bit PNG of material `code`: white where the voxel is it.
/// `bits` is scratch space, reused for a layer's several materials.
pub fn bitmap_png(
    nx: usize,
    ny: usize,
    codes: &[u8],
    code: u8,
    bits: &mut Vec<u8>,
    style: ImageStyle,
) -> Result<Vec<u8>, png::EncodingError> {
    mask_bits(nx, ny, codes, code, style.orientation, true, bits);
    png_io::encode_bits(nx, ny, bits, style.pixel)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pyvcad_orientation_is_the_top_view_turned_half_a_turn() {
        // 3 × 2 voxels, one marked at (x 0, y 0): the top view puts it
        // bottom left, pyvcad top right.
        let codes = [1, 0, 0, 0, 0, 0];
        let pal = [[0; 4], [9; 4]];
        let (mut top, mut py) = (vec![0u8; 24], vec![0u8; 24]);
        rgba_into(3, &codes, &pal, Orientation::TopView, &mut top);
        rgba_into(3, &codes, &pal, Orientation::Pyvcad, &mut py);
        assert_eq!(top[12], 9);
        assert_eq!(py[8], 9);
        assert_eq!(top.iter().filter(|v| **v == 9).count(), 4);
        let mut bits = Vec::new();
        mask_bits(3, 2, &codes, 1, Orientation::Pyvcad, false, &mut bits);
        assert_eq!(bits, vec![0b1101_1111, 0xFF]);
    }
}
