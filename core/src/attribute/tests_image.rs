//! A picture as an attribute (`ImageField`), through scripts: values
//! against the file's own pixels, channels, bounds, and every refusal at
//! its script line.

use std::path::Path;

use glam::DVec3;

use crate::Model;
use crate::script::{ScriptOptions, model_of};

/// A script in `dir` (the design's folder).
fn model_in(dir: &Path, src: &str) -> Result<Model, String> {
    let path = dir.join("t.rhai");
    let src = format!("let m = default_materials();\n{src}");
    model_of(&src, "t.rhai", &ScriptOptions::for_file(&path)).map_err(|e| e.to_string())
}

/// A 5 × 3 picture with a different colour in every pixel.
fn picture() -> image::RgbaImage {
    image::RgbaImage::from_fn(5, 3, |i, j| {
        image::Rgba([
            (i * 60) as u8,
            (j * 120) as u8,
            (255 - i * 50 - j * 10) as u8,
            255 - (i + j) as u8 * 20,
        ])
    })
}

#[test]
fn colours_at_pixel_centres_and_bilinear_between() {
    let dir = tempfile::tempdir().unwrap();
    let img = picture();
    img.save(dir.path().join("p.png")).unwrap();
    // The picture on [0, 10] x [0, 6] of the box's own frame, the box
    // moved by 100 along x: pixels 2 mm wide, 2 mm high.
    let src = "let b = RectPrism(Vec3(5, 3, 0), Vec3(10, 6, 2), m.id(\"red\"));
               b.set_attribute(\"color\", ImageField(\"p.png\", \"z\", [0, 0, 10, 6]));
               Translate(100.0, 0.0, 0.0, b)";
    let m = model_in(dir.path(), src).unwrap();
    let idx = m.attribute_index("color").unwrap();
    let at = |x: f64, y: f64| {
        let mut c = [0.0; 4];
        m.attribute_at(idx, DVec3::new(100.0 + x, y, 0.5), &mut c)
            .unwrap();
        c
    };
    let px = |i: u32, j: u32| img.get_pixel(i, j).0.map(|v| f64::from(v) / 255.0);
    for j in 0..3 {
        for i in 0..5 {
            // Row 0 (the file's top) at the largest y.
            let c = at(2.0 * f64::from(i) + 1.0, 6.0 - (2.0 * f64::from(j) + 1.0));
            assert_eq!(c, px(i, j), "pixel {i}, {j}");
        }
    }
    // Half way between the centres of pixels (1, 0), (2, 0), (1, 1),
    // (2, 1): their mean; a quarter of the way along a row: 3:1.
    let c = at(4.0, 4.0);
    for k in 0..4 {
        let mean = (px(1, 0)[k] + px(2, 0)[k] + px(1, 1)[k] + px(2, 1)[k]) / 4.0;
        assert!((c[k] - mean).abs() < 1e-12, "{k}: {c:?}");
    }
    let c = at(3.5, 5.0);
    for k in 0..4 {
        let w = 0.75 * px(1, 0)[k] + 0.25 * px(2, 0)[k];
        assert!((c[k] - w).abs() < 1e-12, "{k}: {c:?}");
    }
    // Beyond the outer centres: the edge pixels.
    assert_eq!(at(0.2, 5.9), px(0, 0));
    assert_eq!(at(9.9, 0.1), px(4, 2));
}

#[test]
fn a_channel_is_a_scalar_with_the_pictures_bounds() {
    let dir = tempfile::tempdir().unwrap();
    picture().save(dir.path().join("p.png")).unwrap();
    let src = "let b = RectPrism(Vec3(0, 0, 0), Vec3(10, 2, 6), m.id(\"red\"));
               b.set_attribute(\"shade\", ImageField(\"p.png\", \"y\", [-5, -3, 5, 3], \"g\"));
               b.set_attribute(\"light\", ImageField(\"p.png\", \"y\", [-5, -3, 5, 3], \"luminance\"));
               b";
    let m = model_in(dir.path(), src).unwrap();
    let one = |name: &str, p: DVec3| {
        let mut o = [0.0];
        m.attribute_at(m.attribute_index(name).unwrap(), p, &mut o)
            .unwrap();
        o[0]
    };
    // Along y the plane is (x, z), z up: the bottom row (green 240) at the
    // lowest z.
    assert_eq!(one("shade", DVec3::new(0.0, 0.5, -2.0)), 240.0 / 255.0);
    assert_eq!(one("shade", DVec3::new(0.0, -0.5, 2.0)), 0.0);
    let l = one("light", DVec3::new(-4.0, 0.0, 2.0));
    // Pixel (0, 0): r 0, g 0, b 255: the blue weight.
    assert!((l - 0.0722).abs() < 1e-12, "{l}");
    let b = crate::aabb::Aabb::new(DVec3::splat(-5.0), DVec3::splat(5.0));
    let iv = m
        .attribute_interval(m.attribute_index("shade").unwrap(), &b)
        .unwrap();
    assert_eq!((iv.lo, iv.hi), (0.0, 240.0 / 255.0));
}

#[test]
fn a_jpeg_reads_as_its_colour() {
    let dir = tempfile::tempdir().unwrap();
    let img = image::RgbImage::from_pixel(16, 16, image::Rgb([200, 100, 50]));
    img.save(dir.path().join("p.jpg")).unwrap();
    let src = "let b = RectPrism(Vec3(0, 0, 0), Vec3(4, 4, 1), m.id(\"red\"));
               b.set_attribute(\"color\", ImageField(\"p.jpg\", \"z\", [-2, -2, 2, 2])); b";
    let m = model_in(dir.path(), src).unwrap();
    let mut c = [0.0; 4];
    m.attribute_at(m.attribute_index("color").unwrap(), DVec3::ZERO, &mut c)
        .unwrap();
    // JPEG is lossy: a flat colour comes back within a few levels.
    for (got, want) in c.iter().zip([200.0, 100.0, 50.0, 255.0]) {
        assert!((got * 255.0 - want).abs() < 4.0, "{c:?}");
    }
}

/// CRC-32 (ISO 3309, as PNG chunks use), bit by bit.
fn crc32(bytes: &[u8]) -> u32 {
    let mut c = !0u32;
    for b in bytes {
        c ^= u32::from(*b);
        for _ in 0..8 {
            c = if c & 1 == 1 {
                0xEDB8_8320 ^ (c >> 1)
            } else {
                c >> 1
            };
        }
    }
    !c
}

/// A PNG whose header says `w` × `h` pixels (and no image data): the
/// size check must refuse it from the header alone.
fn huge_png(w: u32, h: u32) -> Vec<u8> {
    let mut ihdr = b"IHDR".to_vec();
    ihdr.extend(w.to_be_bytes());
    ihdr.extend(h.to_be_bytes());
    ihdr.extend([8, 6, 0, 0, 0]);
    let mut v = b"\x89PNG\r\n\x1a\n".to_vec();
    v.extend(13u32.to_be_bytes());
    v.extend(&ihdr);
    v.extend(crc32(&ihdr).to_be_bytes());
    // An empty IDAT: the header ends where the image data starts.
    v.extend(0u32.to_be_bytes());
    v.extend(b"IDAT");
    v.extend(crc32(b"IDAT").to_be_bytes());
    v
}

#[test]
fn refusals_name_the_line_and_the_fix() {
    let dir = tempfile::tempdir().unwrap();
    picture().save(dir.path().join("p.png")).unwrap();
    std::fs::write(dir.path().join("text.png"), "not a picture").unwrap();
    std::fs::write(dir.path().join("big.png"), huge_png(5000, 4000)).unwrap();
    let err = |call: &str| {
        let src = format!(
            "let b = RectPrism(Vec3(0, 0, 0), Vec3(4, 4, 1), m.id(\"red\"));\nb.set_attribute({call}); b"
        );
        let e = model_in(dir.path(), &src).unwrap_err();
        assert!(e.contains("t.rhai:3:"), "{call}: {e}");
        e
    };
    let cases = [
        (
            "\"color\", ImageField(\"gone.png\", \"z\", [0, 0, 1, 1])",
            "gone.png",
        ),
        (
            "\"color\", ImageField(\"text.png\", \"z\", [0, 0, 1, 1])",
            "not a readable PNG or JPEG",
        ),
        (
            "\"color\", ImageField(\"big.png\", \"z\", [0, 0, 1, 1])",
            "5000 × 4000 pixels is more than the 16777216 allowed",
        ),
        (
            "\"color\", ImageField(\"p.png\", \"w\", [0, 0, 1, 1])",
            "axis \"w\" is not one of \"x\", \"y\", \"z\"",
        ),
        (
            "\"color\", ImageField(\"p.png\", \"z\", [0, 0, 0, 1])",
            "the rectangle [0, 0, 0, 1] has no area",
        ),
        (
            "\"color\", ImageField(\"p.png\", \"z\", [0, 0, 1])",
            "the rectangle has 3 numbers; give four",
        ),
        (
            "\"shade\", ImageField(\"p.png\", \"z\", [0, 0, 1, 1], \"hue\")",
            "channel \"hue\" is not one of \"r\", \"g\", \"b\", \"a\" or \"luminance\"",
        ),
        (
            "\"color\", ImageField(\"p.png\", \"z\", [0, 0, 1, 1], \"r\")",
            "drop the channel argument for a colour",
        ),
        (
            "\"modulus\", ImageField(\"p.png\", \"z\", [0, 0, 1, 1])",
            "add a channel argument",
        ),
    ];
    for (call, want) in cases {
        let e = err(call);
        assert!(e.contains(want), "{call}: {e}");
    }
}
