//! PNG bytes for slice stacks: RGBA layers and 1-bit masks, and their file
//! names.
//!
//! Encoding uses the `png` crate with its fastest setting (fdeflate, "Up"
//! row filter): slice images are mostly long runs and repeated rows, which
//! this pair compresses well and fast. The bytes
//! depend only on the pixels, so a layer encodes the same on any thread.

use std::io::Cursor;

use png::{BitDepth, ColorType, Compression, Encoder, PixelDimensions, Unit};

/// A pixel's physical size for the PNG `pHYs` chunk (PNG 1.2, section
/// 4.2.4.3): whole pixels per metre along X and Y, so image tools show a
/// slice at the printer's size (600 dpi = 23 622 px/m).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PixelsPerMetre(pub [u32; 2]);

impl PixelsPerMetre {
    /// Pixels per metre for a pixel `x_mm` by `y_mm` millimetres, rounded.
    pub fn from_mm(x_mm: f64, y_mm: f64) -> Self {
        let ppm = |mm: f64| (1000.0 / mm).round().clamp(1.0, u32::MAX as f64) as u32;
        Self([ppm(x_mm), ppm(y_mm)])
    }
}

/// Digits in slice numbers: at least 5, more when the grid has more layers,
/// so that names sort and every part of a split job uses the same width
/// (it depends on the grid's layer count only, never on the range written).
pub fn name_digits(layers: usize) -> usize {
    layers.saturating_sub(1).to_string().len().max(5)
}

/// `slice_00042.png` for global layer 42.
pub fn slice_name(z: usize, digits: usize) -> String {
    format!("slice_{z:0digits$}.png")
}

/// A folder name from a material name: letters, digits, `-`, `_`, `.` and
/// `+` kept, anything else `_`; empty or dot-only names become
/// `material_<id>`.
pub fn folder_name(name: &str, id: u8) -> String {
    let s = volcad_core::names::underscore_other(name, |c| {
        c.is_ascii_alphanumeric() || "-_.+".contains(c)
    });
    if s.chars().all(|c| c == '.' || c == '_') {
        format!("material_{id}")
    } else {
        s
    }
}

/// The encoder every slice image uses: `color` at `depth`, the physical
/// pixel size when given, the fastest setting.
pub(crate) fn encoder<W: std::io::Write>(
    out: W,
    width: usize,
    height: usize,
    color: ColorType,
    depth: BitDepth,
    pixel: Option<PixelsPerMetre>,
) -> Encoder<'static, W> {
    let mut enc = Encoder::new(out, width as u32, height as u32);
    enc.set_color(color);
    enc.set_depth(depth);
    if let Some(PixelsPerMetre([xppu, yppu])) = pixel {
        enc.set_pixel_dims(Some(PixelDimensions {
            xppu,
            yppu,
            unit: Unit::Meter,
        }));
    }
    enc.set_compression(Compression::Fastest);
    enc
}

fn encode(
    width: usize,
    height: usize,
    color: ColorType,
    depth: BitDepth,
    data: &[u8],
    pixel: Option<PixelsPerMetre>,
) -> Result<Vec<u8>, png::EncodingError> {
    let mut out = Cursor::new(Vec::with_capacity(data.len() / 8 + 256));
    {
        let enc = encoder(&mut out, width, height, color, depth, pixel);
        let mut w = enc.write_header()?;
        w.write_image_data(data)?;
        w.finish()?;
    }
    Ok(out.into_inner())
}

/// An 8-bit RGBA image, `data` row-major from the top row, 4 bytes a pixel,
/// with its physical pixel size when `pixel` is given.
pub fn encode_rgba(
    width: usize,
    height: usize,
    data: &[u8],
    pixel: Option<PixelsPerMetre>,
) -> Result<Vec<u8>, png::EncodingError> {
    encode(width, height, ColorType::Rgba, BitDepth::Eight, data, pixel)
}

/// An 8-bit grayscale image, one byte a pixel, rows from the top.
pub fn encode_gray(
    width: usize,
    height: usize,
    data: &[u8],
    pixel: Option<PixelsPerMetre>,
) -> Result<Vec<u8>, png::EncodingError> {
    encode_gray_depth(width, height, BitDepth::Eight, data, pixel)
}

/// A 16-bit grayscale image: one big-endian `u16` a pixel (as PNG stores
/// them), rows from the top.
pub fn encode_gray16(
    width: usize,
    height: usize,
    data: &[u16],
) -> Result<Vec<u8>, png::EncodingError> {
    let bytes: Vec<u8> = data.iter().flat_map(|v| v.to_be_bytes()).collect();
    encode_gray16_be(width, height, &bytes)
}

/// A 16-bit grayscale image from its big-endian bytes (two a pixel), rows
/// from the top.
pub fn encode_gray16_be(
    width: usize,
    height: usize,
    bytes: &[u8],
) -> Result<Vec<u8>, png::EncodingError> {
    encode_gray_depth(width, height, BitDepth::Sixteen, bytes, None)
}

/// Bytes per row of a 1-bit image.
pub fn bit_row_bytes(width: usize) -> usize {
    width.div_ceil(8)
}

/// A 1-bit grayscale image (1 = white), rows of [`bit_row_bytes`] bytes,
/// leftmost pixel in the most significant bit.
pub fn encode_bits(
    width: usize,
    height: usize,
    data: &[u8],
    pixel: Option<PixelsPerMetre>,
) -> Result<Vec<u8>, png::EncodingError> {
    encode_gray_depth(width, height, BitDepth::One, data, pixel)
}

/// A grayscale image of `depth` bits a pixel, `data` packed as PNG packs
/// that depth.
fn encode_gray_depth(
    width: usize,
    height: usize,
    depth: BitDepth,
    data: &[u8],
    pixel: Option<PixelsPerMetre>,
) -> Result<Vec<u8>, png::EncodingError> {
    encode(width, height, ColorType::Grayscale, depth, data, pixel)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn decode(bytes: &[u8]) -> (png::OutputInfo, Vec<u8>) {
        let mut r = png::Decoder::new(Cursor::new(bytes))
            .read_info()
            .expect("png header");
        let mut buf = vec![0; r.output_buffer_size().expect("size")];
        let info = r.next_frame(&mut buf).expect("png data");
        buf.truncate(info.buffer_size());
        (info, buf)
    }

    #[test]
    fn names_are_padded_by_grid_height() {
        assert_eq!(slice_name(42, name_digits(100)), "slice_00042.png");
        assert_eq!(slice_name(42, name_digits(123_457)), "slice_000042.png");
        assert_eq!(name_digits(100_000), 5);
        assert_eq!(folder_name("Agilus30 Clr/x", 3), "Agilus30_Clr_x");
        assert_eq!(folder_name("..", 3), "material_3");
    }

    #[test]
    fn rgba_and_bits_round_trip() {
        let rgba: Vec<u8> = (0..3 * 2 * 4).map(|i| i as u8).collect();
        let (info, back) = decode(&encode_rgba(3, 2, &rgba, None).unwrap());
        assert_eq!(
            (info.width, info.height, info.color_type, info.bit_depth),
            (3, 2, ColorType::Rgba, BitDepth::Eight)
        );
        assert_eq!(back, rgba);
        let bits = vec![0b1010_0000, 0b0100_0000];
        let (info, back) = decode(&encode_bits(3, 2, &bits, None).unwrap());
        assert_eq!(
            (info.color_type, info.bit_depth),
            (ColorType::Grayscale, BitDepth::One)
        );
        assert_eq!(back, bits);
    }

    #[test]
    fn phys_carries_the_printer_resolution() {
        // J750: 600 x 300 dpi = 23 622 x 11 811 pixels per metre.
        let ppm = PixelsPerMetre::from_mm(25.4 / 600.0, 25.4 / 300.0);
        assert_eq!(ppm, PixelsPerMetre([23_622, 11_811]));
        let bytes = encode_rgba(1, 1, &[1, 2, 3, 4], Some(ppm)).unwrap();
        let r = png::Decoder::new(Cursor::new(&bytes)).read_info().unwrap();
        let d = r.info().pixel_dims.expect("pHYs chunk");
        assert_eq!((d.xppu, d.yppu, d.unit), (23_622, 11_811, Unit::Meter));
        let (info, back) = decode(&encode_gray16(2, 1, &[258, 9]).unwrap());
        assert_eq!(info.bit_depth, BitDepth::Sixteen);
        assert_eq!(back, vec![1, 2, 0, 9]);
    }
}
