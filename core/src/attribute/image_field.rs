//! A picture as an attribute (`ImageField("photo.png", "z", [x0, y0, x1,
//! y1])`): an sRGB PNG or JPEG projected along one axis of the node's local
//! frame onto a rectangle, its colour (RGBA 0-1, a `color` Vec4) or one
//! channel as a scalar.
//!
//! Projection: along `z` the image's columns run along +x and its rows
//! down from y1 to y0 (row 0, the image's top, at the rectangle's largest
//! y), so a picture seen from above reads as it does on screen; along `x`
//! the plane is (y, z), along `y` it is (x, z), rows again from the top
//! (largest z) down. The value at a point is bilinear between the four
//! nearest pixel centres (pixel `i` has its centre at `x0 + (i + ½)·w`,
//! `w` the pixel width), clamped to the border pixels outside the centres
//! (and outside the rectangle: the edge colour extends), the same along
//! the projection axis. Values are the file's 8-bit sRGB values / 255, not
//! linearised (the `color` attribute is sRGB); `luminance` is the relative
//! luminance Y of the linearised colour (IEC 61966-2-1, Rec. 709
//! weights), 0-1.

use glam::DVec3;

/// Most pixels a picture may have (4096 × 4096): 64 MB of RGBA.
pub const MAX_PIXELS: u64 = 4096 * 4096;

/// The axis a picture is projected along.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImageAxis {
    /// Onto the (y, z) plane.
    X,
    /// Onto the (x, z) plane.
    Y,
    /// Onto the (x, y) plane.
    Z,
}

impl ImageAxis {
    /// `"x"`, `"y"` or `"z"` (any case).
    pub fn parse(s: &str) -> Option<ImageAxis> {
        match s.to_ascii_lowercase().as_str() {
            "x" => Some(ImageAxis::X),
            "y" => Some(ImageAxis::Y),
            "z" => Some(ImageAxis::Z),
            _ => None,
        }
    }

    /// The in-plane coordinates (across, up) of `p`.
    fn plane(self, p: DVec3) -> (f64, f64) {
        match self {
            ImageAxis::X => (p.y, p.z),
            ImageAxis::Y => (p.x, p.z),
            ImageAxis::Z => (p.x, p.y),
        }
    }

    /// Its name.
    pub fn name(self) -> &'static str {
        match self {
            ImageAxis::X => "x",
            ImageAxis::Y => "y",
            ImageAxis::Z => "z",
        }
    }
}

/// One number of a pixel, for a scalar attribute.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImageChannel {
    /// Red, 0-1.
    R,
    /// Green.
    G,
    /// Blue.
    B,
    /// Alpha (1 where the file has none).
    A,
    /// Relative luminance of the linearised colour.
    Luminance,
}

/// The channel names a script may give.
pub const CHANNELS: &str = "\"r\", \"g\", \"b\", \"a\" or \"luminance\"";

impl ImageChannel {
    /// `"r"`, `"g"`, `"b"`, `"a"` or `"luminance"` (any case).
    pub fn parse(s: &str) -> Option<ImageChannel> {
        match s.to_ascii_lowercase().as_str() {
            "r" | "red" => Some(ImageChannel::R),
            "g" | "green" => Some(ImageChannel::G),
            "b" | "blue" => Some(ImageChannel::B),
            "a" | "alpha" => Some(ImageChannel::A),
            "luminance" => Some(ImageChannel::Luminance),
            _ => None,
        }
    }

    fn index(self) -> usize {
        match self {
            ImageChannel::R => 0,
            ImageChannel::G => 1,
            ImageChannel::B => 2,
            ImageChannel::A => 3,
            ImageChannel::Luminance => 4,
        }
    }
}

/// An sRGB component (0-1) to linear light (IEC 61966-2-1).
fn linear(c: f64) -> f64 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// A decoded picture: 8-bit RGBA rows, the top row first.
#[derive(Debug)]
pub struct Picture {
    width: u32,
    height: u32,
    rgba: Vec<u8>,
    /// Smallest and largest of r, g, b, a and luminance over the pixels.
    ranges: [(f64, f64); 5],
}

impl Picture {
    /// A picture of `width` × `height` pixels from RGBA bytes, top row
    /// first (`None` when the sizes disagree or it is empty).
    pub fn from_rgba(width: u32, height: u32, rgba: Vec<u8>) -> Option<Picture> {
        let n = width as usize * height as usize;
        if n == 0 || rgba.len() != n * 4 {
            return None;
        }
        let mut ranges = [(f64::INFINITY, f64::NEG_INFINITY); 5];
        for px in rgba.chunks_exact(4) {
            for (r, v) in ranges.iter_mut().zip(Self::values(px)) {
                *r = (r.0.min(v), r.1.max(v));
            }
        }
        Some(Picture {
            width,
            height,
            rgba,
            ranges,
        })
    }

    /// Decode the PNG or JPEG at `path` (`shown` names it in errors);
    /// refused above [`MAX_PIXELS`] before it is decoded.
    pub fn load(path: &std::path::Path, shown: &str) -> Result<Picture, String> {
        let open = || {
            image::ImageReader::open(path)
                .and_then(|r| r.with_guessed_format())
                .map_err(|e| format!("{shown}: {e}"))
        };
        let (w, h) = open()?.into_dimensions().map_err(|e| {
            format!("{shown}: not a readable PNG or JPEG ({e}); save the picture as PNG or JPEG")
        })?;
        let pixels = u64::from(w) * u64::from(h);
        if pixels > MAX_PIXELS {
            return Err(format!(
                "{shown}: {w} × {h} pixels is more than the {MAX_PIXELS} allowed (4096 × 4096); scale the picture down"
            ));
        }
        let img = open()?.decode().map_err(|e| {
            format!("{shown}: not a readable PNG or JPEG ({e}); save the picture as PNG or JPEG")
        })?;
        let rgba = img.to_rgba8();
        Picture::from_rgba(w, h, rgba.into_raw())
            .ok_or_else(|| format!("{shown}: the picture has no pixels"))
    }

    /// Width and height in pixels.
    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// r, g, b, a (0-1) and luminance of one pixel's bytes.
    fn values(px: &[u8]) -> [f64; 5] {
        let c = |i: usize| f64::from(px[i]) / 255.0;
        let y = 0.2126 * linear(c(0)) + 0.7152 * linear(c(1)) + 0.0722 * linear(c(2));
        [c(0), c(1), c(2), c(3), y]
    }

    /// r, g, b, a and luminance of pixel (`col`, `row`), row 0 the top.
    pub fn pixel(&self, col: u32, row: u32) -> [f64; 5] {
        let i = (row as usize * self.width as usize + col as usize) * 4;
        Self::values(&self.rgba[i..i + 4])
    }
}

/// A picture placed on a rectangle of a plane: what `ImageField` makes.
#[derive(Debug)]
pub struct ImageMap {
    picture: std::sync::Arc<Picture>,
    axis: ImageAxis,
    /// `[u0, v0, u1, v1]`: the rectangle's corners in the plane's
    /// coordinates, `u0 < u1`, `v0 < v1`.
    rect: [f64; 4],
    /// The file, for messages.
    file: String,
}

impl ImageMap {
    /// `picture` on `rect` (`[u0, v0, u1, v1]`) of the plane across
    /// `axis`; an error when the rectangle has no area or is not finite.
    pub fn new(
        picture: std::sync::Arc<Picture>,
        axis: ImageAxis,
        rect: [f64; 4],
        file: &str,
    ) -> Result<ImageMap, String> {
        let [u0, v0, u1, v1] = rect;
        if !rect.iter().all(|v| v.is_finite()) || u1 <= u0 || v1 <= v0 {
            return Err(format!(
                "the rectangle [{u0}, {v0}, {u1}, {v1}] has no area; give [low, low, high, high] corners with the first of each pair below the second, e.g. [-20, -20, 20, 20]"
            ));
        }
        Ok(ImageMap {
            picture,
            axis,
            rect,
            file: file.to_owned(),
        })
    }

    /// The file's name as the script gave it.
    pub fn file(&self) -> &str {
        &self.file
    }

    /// The projection axis.
    pub fn axis(&self) -> ImageAxis {
        self.axis
    }

    /// The picture.
    pub fn picture(&self) -> &Picture {
        &self.picture
    }

    /// Smallest and largest value of `channel` (bilinear weights are a
    /// convex combination, so every sample lies within).
    pub fn range(&self, channel: ImageChannel) -> (f64, f64) {
        self.picture.ranges[channel.index()]
    }

    /// The bilinear corners along one side: the two pixel indices and the
    /// second one's weight, for plane coordinate `t` over `lo..hi` split
    /// into `n` pixels (`flip`: index 0 at `hi`).
    fn taps(t: f64, lo: f64, hi: f64, n: u32, flip: bool) -> (u32, u32, f64) {
        let s = (t - lo) / (hi - lo);
        let s = if flip { 1.0 - s } else { s };
        // Pixel centres sit at (i + ½) / n.
        let f = (s * f64::from(n) - 0.5).clamp(0.0, f64::from(n - 1));
        let f = if f.is_nan() { 0.0 } else { f };
        let i = f.floor() as u32;
        let j = (i + 1).min(n - 1);
        (i, j, f - f64::from(i))
    }

    /// r, g, b, a and luminance at local point `p`. Luminance is the
    /// bilinear mix of the pixels' luminances.
    pub fn sample(&self, p: DVec3) -> [f64; 5] {
        let (u, v) = self.axis.plane(p);
        let [u0, v0, u1, v1] = self.rect;
        let pic = &self.picture;
        let (c0, c1, tu) = Self::taps(u, u0, u1, pic.width, false);
        let (r0, r1, tv) = Self::taps(v, v0, v1, pic.height, true);
        let (a, b) = (pic.pixel(c0, r0), pic.pixel(c1, r0));
        let (c, d) = (pic.pixel(c0, r1), pic.pixel(c1, r1));
        std::array::from_fn(|k| {
            let top = a[k] + (b[k] - a[k]) * tu;
            let bottom = c[k] + (d[k] - c[k]) * tu;
            top + (bottom - top) * tv
        })
    }

    /// The attribute's numbers at `p` into `out`: RGBA (`channel` `None`)
    /// or the one channel.
    pub fn value(&self, p: DVec3, channel: Option<ImageChannel>, out: &mut [f64]) {
        let s = self.sample(p);
        match channel {
            Some(c) => out[0] = s[c.index()],
            None => {
                for (o, v) in out.iter_mut().zip(s) {
                    *o = v;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Arc;

    /// 2 × 2: red, green / blue, white; alpha 255 but the white 0.
    fn four() -> ImageMap {
        let px = vec![
            255, 0, 0, 255, 0, 255, 0, 255, //
            0, 0, 255, 255, 255, 255, 255, 0,
        ];
        let pic = Arc::new(Picture::from_rgba(2, 2, px).unwrap());
        ImageMap::new(pic, ImageAxis::Z, [0.0, 0.0, 2.0, 2.0], "t.png").unwrap()
    }

    #[test]
    fn pixel_centres_and_between() {
        let m = four();
        let at = |x: f64, y: f64| m.sample(DVec3::new(x, y, 7.0));
        // Row 0 (the top) is at the largest y.
        assert_eq!(at(0.5, 1.5)[..4], [1.0, 0.0, 0.0, 1.0]);
        assert_eq!(at(1.5, 1.5)[..4], [0.0, 1.0, 0.0, 1.0]);
        assert_eq!(at(0.5, 0.5)[..4], [0.0, 0.0, 1.0, 1.0]);
        assert_eq!(at(1.5, 0.5)[..4], [1.0, 1.0, 1.0, 0.0]);
        // The middle: the mean of all four.
        assert_eq!(at(1.0, 1.0)[..4], [0.5, 0.5, 0.5, 0.75]);
        // A quarter of the way from red to green along the top row.
        let v = at(0.75, 1.5);
        assert!((v[0] - 0.75).abs() < 1e-12 && (v[1] - 0.25).abs() < 1e-12);
        // Outside the centres and the rectangle: the border pixels.
        assert_eq!(at(-5.0, 9.0)[..4], [1.0, 0.0, 0.0, 1.0]);
        assert_eq!(at(0.1, 0.2)[..4], [0.0, 0.0, 1.0, 1.0]);
        // Luminance of pure green: the Rec. 709 weight.
        assert!((at(1.5, 1.5)[4] - 0.7152).abs() < 1e-12);
        assert_eq!(m.range(ImageChannel::A), (0.0, 1.0));
    }

    #[test]
    fn other_axes_use_z_as_up() {
        let m = four();
        let pic = m.picture.clone();
        let x = ImageMap::new(pic.clone(), ImageAxis::X, [0.0, 0.0, 2.0, 2.0], "t").unwrap();
        // Along x the plane is (y, z): y across, z up.
        assert_eq!(x.sample(DVec3::new(9.0, 1.5, 1.5))[..3], [0.0, 1.0, 0.0]);
        let y = ImageMap::new(pic, ImageAxis::Y, [0.0, 0.0, 2.0, 2.0], "t").unwrap();
        assert_eq!(y.sample(DVec3::new(0.5, 9.0, 0.5))[..3], [0.0, 0.0, 1.0]);
    }

    #[test]
    fn bad_rectangles_and_names() {
        let pic = four().picture.clone();
        for r in [
            [0.0, 0.0, 0.0, 1.0],
            [0.0, 2.0, 1.0, 1.0],
            [0.0, 0.0, f64::NAN, 1.0],
        ] {
            let e = ImageMap::new(pic.clone(), ImageAxis::Z, r, "t").unwrap_err();
            assert!(e.contains("has no area"), "{e}");
        }
        assert_eq!(ImageAxis::parse("Z"), Some(ImageAxis::Z));
        assert_eq!(ImageAxis::parse("w"), None);
        assert_eq!(
            ImageChannel::parse("Luminance"),
            Some(ImageChannel::Luminance)
        );
        assert_eq!(ImageChannel::parse("hue"), None);
        assert!(Picture::from_rgba(2, 2, vec![0; 15]).is_none());
    }
}
