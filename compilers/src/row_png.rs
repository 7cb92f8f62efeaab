//! A layer's RGBA PNG made a row at a time: the bytes
//! [`crate::slice_image::rgba_png`] writes, without holding the layer's
//! whole RGBA image (4 bytes a voxel) at once.
//!
//! `png`'s fastest setting (what [`crate::png_io`] uses) filters every row
//! with "Up" (PNG 1.2, section 6.3: each byte minus the byte above it, the
//! row above the first being zeros), feeds the filter byte and the row to
//! fdeflate's `Compressor` as one piece, and stores the image instead
//! (filter byte 0, raw rows, stored deflate blocks) when that would be
//! smaller; the zlib stream goes into IDAT chunks of at most 2³¹ − 1
//! bytes. Doing the same here with two rows of RGBA gives the same bytes
//! (the tests compare them), so a GCVF layer needs the compressed image
//! and two rows rather than the whole RGBA image beside the slab.
//!
//! The PNG stack keeps the whole-image encoder: feeding fdeflate a row at
//! a time costs it a few percent more CPU (alternate `volcad export png
//! assets/examples/graded_bar.rhai --voxel 0.025` with both), where memory
//! is not its limit.

use std::io::Cursor;

use png::{BitDepth, ColorType};

use crate::png_io::encoder;
use crate::slice_image::ImageStyle;

/// `png`'s largest IDAT chunk (`Writer::MAX_IDAT_CHUNK_LEN`).
const MAX_IDAT: usize = (u32::MAX >> 1) as usize;
/// The "Up" filter's type byte.
const UP: u8 = 2;

/// Image row `r` of the layer's codes, each pixel its colour.
fn fill_row(
    r: usize,
    nx: usize,
    ny: usize,
    codes: &[u8],
    pal: &[[u8; 4]],
    style: ImageStyle,
    row: &mut [u8],
) {
    let o = style.orientation;
    // Both orientations map a row or column to itself when applied twice.
    let j = o.row(r, ny);
    for (i, c) in codes[j * nx..(j + 1) * nx].iter().enumerate() {
        let x = o.col(i, nx);
        row[x * 4..x * 4 + 4].copy_from_slice(&pal[*c as usize]);
    }
}

/// The zlib stream of the layer's rows, as `png` makes it.
fn zlib(
    nx: usize,
    ny: usize,
    codes: &[u8],
    pal: &[[u8; 4]],
    style: ImageStyle,
) -> std::io::Result<Vec<u8>> {
    let len = nx * 4;
    let mut prev = vec![0u8; len];
    let mut row = vec![0u8; len];
    let mut filtered = vec![0u8; len + 1];
    filtered[0] = UP;
    let mut z = fdeflate::Compressor::new(Cursor::new(Vec::new()))?;
    for r in 0..ny {
        fill_row(r, nx, ny, codes, pal, style, &mut row);
        for ((f, a), b) in filtered[1..].iter_mut().zip(&row).zip(&prev) {
            *f = a.wrapping_sub(*b);
        }
        z.write_data(&filtered)?;
        std::mem::swap(&mut prev, &mut row);
    }
    let packed = z.finish()?.into_inner();
    let raw = (len + 1) * ny;
    if packed.len() <= fdeflate::StoredOnlyCompressor::<()>::compressed_size(raw) {
        return Ok(packed);
    }
    // Incompressible: stored blocks of unfiltered rows.
    let mut s = fdeflate::StoredOnlyCompressor::new(Cursor::new(Vec::new()))?;
    for r in 0..ny {
        fill_row(r, nx, ny, codes, pal, style, &mut row);
        s.write_data(&[0])?;
        s.write_data(&row)?;
    }
    Ok(s.finish()?.into_inner())
}

/// The layer's RGBA PNG (`codes` x fastest from min Y, each its colour
/// `pal[code]`), byte for byte [`crate::slice_image::rgba_png`]'s.
// Speed copy of compilers/src/slice_image.rs::rgba_png (same bytes): this
// one encodes row by row and holds no RGBA image (docs/PERFORMANCE.md,
// "Speed copies").
pub fn rgba_png(
    nx: usize,
    ny: usize,
    codes: &[u8],
    pal: &[[u8; 4]],
    style: ImageStyle,
) -> Result<Vec<u8>, png::EncodingError> {
    let data = zlib(nx, ny, codes, pal, style)?;
    let mut out = Vec::with_capacity(data.len() + 256);
    let enc = encoder(
        &mut out,
        nx,
        ny,
        ColorType::Rgba,
        BitDepth::Eight,
        style.pixel,
    );
    let mut w = enc.write_header()?;
    for chunk in data.chunks(MAX_IDAT) {
        w.write_chunk(png::chunk::IDAT, chunk)?;
    }
    drop(data);
    w.finish()?;
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::png_io::PixelsPerMetre;
    use crate::slice_image::{self, Orientation};

    fn xorshift(s: &mut u64) -> u64 {
        *s ^= *s << 13;
        *s ^= *s >> 7;
        *s ^= *s << 17;
        *s
    }

    #[test]
    fn the_same_bytes_as_the_whole_image_encoder() {
        let mut seed = 0x9E37_79B9_7F4A_7C15u64;
        let pal = [[0, 0, 0, 0], [255, 0, 0, 255], [0, 90, 200, 255]];
        // Random noise over 255 random colours does not compress: the
        // stored fallback.
        let noisy: Vec<[u8; 4]> = (0..256)
            .map(|_| (xorshift(&mut seed) as u32).to_le_bytes())
            .collect();
        for (nx, ny) in [(1, 1), (7, 3), (64, 40), (301, 77)] {
            // A disc of two materials, then pure noise.
            let disc: Vec<u8> = (0..nx * ny)
                .map(|k| {
                    let (i, j) = ((k % nx) as f64, (k / nx) as f64);
                    let r = (i - nx as f64 / 2.0).hypot(j - ny as f64 / 2.0);
                    match r < nx.min(ny) as f64 / 3.0 {
                        true => 1 + (xorshift(&mut seed) % 2) as u8,
                        false => 0,
                    }
                })
                .collect();
            let noise: Vec<u8> = (0..nx * ny).map(|_| xorshift(&mut seed) as u8).collect();
            for (codes, pal) in [(&disc, &pal[..]), (&noise, &noisy[..])] {
                for orientation in [Orientation::Pyvcad, Orientation::TopView] {
                    for pixel in [None, Some(PixelsPerMetre::from_mm(0.042, 0.085))] {
                        let style = ImageStyle { orientation, pixel };
                        let want = slice_image::rgba_png(nx, ny, codes, pal, style).unwrap();
                        let got = rgba_png(nx, ny, codes, pal, style).unwrap();
                        assert!(got == want, "{nx} x {ny} {orientation:?} {pixel:?}");
                    }
                }
            }
        }
        // The noise took the stored path.
        let (nx, ny) = (301, 77);
        let noise: Vec<u8> = (0..nx * ny).map(|_| xorshift(&mut seed) as u8).collect();
        let style = ImageStyle {
            orientation: Orientation::Pyvcad,
            pixel: None,
        };
        let z = zlib(nx, ny, &noise, &noisy, style).unwrap();
        let stored = fdeflate::StoredOnlyCompressor::<()>::compressed_size((nx * 4 + 1) * ny);
        assert_eq!(z.len(), stored);
    }
}
