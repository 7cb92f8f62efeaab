//! 1-bit BMP bitmaps in pyvcad's MyersonCompiler layout, read back with
//! the `image` crate: names, sizes, bit depth, fixed width, and per-material
//! pixels equal to the PNG bitmaps' and the summary's counts.
// Test helpers fail the test with a message where a value is missing.
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use common::{decode, model, read_tree, run, tmp};
use glam::DVec3;
use volcad_compilers::bitmaps::BitmapFormat;
use volcad_compilers::png_stack::{PngParams, export_png_stack};

/// Two disjoint 8 × 6 × 4 mm boxes, red at x < 0 and blue at x > 0.
const TWO_BOXES: &str = r#"let m = default_materials();
Union(false, [RectPrism(Vec3(-6,0,0), Vec3(8,6,4), m.id("red")), RectPrism(Vec3(6,0,0), Vec3(8,6,4), m.id("blue"))])"#;

#[test]
fn bmp_bitmaps_match_the_png_bitmaps() {
    let m = model(TWO_BOXES);
    let dir = tmp();
    let base = PngParams {
        voxel: DVec3::splat(0.5),
        seed: 7,
        per_material_bitmaps: true,
        ..PngParams::default()
    };
    let mut trees = Vec::new();
    let mut summary = None;
    for (name, format, width) in [
        ("png", BitmapFormat::Png, None),
        ("bmp", BitmapFormat::Bmp, None),
        ("wide", BitmapFormat::Bmp, Some(880)),
    ] {
        let p = PngParams {
            bitmap_format: format,
            bitmap_width: width,
            ..base.clone()
        };
        let (mm, pp, dest) = (m.clone(), p.clone(), dir.path().join(name));
        summary = Some(run(&dest, move |ctx| export_png_stack(&mm, &pp, ctx)).unwrap());
        trees.push(read_tree(&dir.path().join(name)));
    }
    let s = summary.unwrap();
    // 20 × 6 × 4 mm at 0.5 mm: 40 × 12 px, 8 layers.
    let (nx, ny, nz) = (40usize, 12usize, 8usize);
    for (material, count) in &s.counts {
        let (mut png_ones, mut bmp_black, mut wide_black) = (0u64, 0u64, 0u64);
        for z in 0..nz {
            let png = decode(&trees[0][&format!("{material}/slice_{z:05}.png")]);
            let bmp_name = format!("{material}/{}_100000_{material}.bmp", 100_000 + z);
            let raw = &trees[1][&bmp_name];
            assert_eq!(
                u16::from_le_bytes([raw[28], raw[29]]),
                1,
                "{bmp_name}: 1 bit a pixel"
            );
            assert_eq!(
                raw.len(),
                62 + 8 * ny,
                "{bmp_name}: 40 px rows padded to 8 bytes"
            );
            let bmp = image::load_from_memory_with_format(raw, image::ImageFormat::Bmp)
                .unwrap()
                .to_luma8();
            let wide =
                image::load_from_memory_with_format(&trees[2][&bmp_name], image::ImageFormat::Bmp)
                    .unwrap()
                    .to_luma8();
            assert_eq!(bmp.dimensions(), (nx as u32, ny as u32));
            assert_eq!(wide.dimensions(), (880, ny as u32));
            for y in 0..ny {
                for x in 0..nx {
                    let on = png.data[y * nx.div_ceil(8) + x / 8] & (0x80 >> (x % 8)) != 0;
                    // Material black on white, the same top view.
                    assert_eq!(
                        bmp.get_pixel(x as u32, y as u32)[0] == 0,
                        on,
                        "{bmp_name} ({x}, {y})"
                    );
                    assert_eq!(wide.get_pixel(x as u32, y as u32)[0] == 0, on);
                    png_ones += u64::from(on);
                }
                assert!((nx..880).all(|x| wide.get_pixel(x as u32, y as u32)[0] == 255));
            }
            bmp_black += bmp.pixels().filter(|p| p[0] == 0).count() as u64;
            wide_black += wide.pixels().filter(|p| p[0] == 0).count() as u64;
        }
        assert_eq!(
            (png_ones, bmp_black, wide_black),
            (*count, *count, *count),
            "{material}"
        );
    }
    // The RGBA slices are the same whatever the bitmap format.
    let slices = |t: &std::collections::BTreeMap<String, Vec<u8>>| {
        t.iter()
            .filter(|(f, _)| f.starts_with("slice_"))
            .map(|(f, b)| (f.clone(), b.clone()))
            .collect::<Vec<_>>()
    };
    assert_eq!(slices(&trees[0]), slices(&trees[1]));
    // Narrower than the layer: refused before any work.
    let p = PngParams {
        bitmap_format: BitmapFormat::Bmp,
        bitmap_width: Some(30),
        ..base
    };
    let dest = dir.path().join("narrow");
    let e = run(&dest, move |ctx| export_png_stack(&m, &p, ctx))
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("--bitmap-width: 30 px is narrower than the layer's 40 px"),
        "{e}"
    );
    assert!(!dest.exists());
}
