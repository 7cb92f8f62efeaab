//! Vat photopolymer stacks end to end: files and image sizes, bytes the
//! same on any thread count and layer range, vat voxel counts against
//! analytic volumes, gray values following the field, and refusals that
//! leave nothing behind.

mod common;

use std::collections::BTreeMap;
use std::path::Path;
use std::sync::Arc;

use common::{decode, manifest, model, read_tree, run, scratch};
use volcad_compilers::png_stack::Dither;
use volcad_compilers::shard::plan_merge;
use volcad_compilers::vat::{Intensity, VatParams, VatPrinter, export_vat, vat_preset};
use volcad_compilers::{ExportError, Summary};
use volcad_core::Model;

/// The graded bar of assets/examples/graded_bar.rhai (15 × 10 × 5 mm, red
/// fraction x/15 + 0.5, blue the rest), with a scalar `dose` that is the
/// red fraction.
const GRADED_BAR: &str = r#"let m = default_materials();
let b = FGrade(["x/15+0.5", "-x/15+0.5"], [m.id("red"), m.id("blue")], true, RectPrism(Vec3(0,0,0), Vec3(15,10,5), m.id("gray")));
b.set_attribute("dose", "x/15+0.5");
b"#;

/// A cylinder (r = 4, h = 6 mm) of 30 % red, 70 % blue everywhere.
const CYLINDER: &str = r#"let m = default_materials();
FGrade(["0.3", "0.7"], [m.id("red"), m.id("blue")], true, Cylinder(Vec3(0,0,0), 4, 6, m.id("gray")))"#;

fn params(printer: VatPrinter, vats: &[&str], threads: Option<usize>) -> VatParams {
    VatParams {
        printer,
        intensity: Intensity::Solid,
        vats: vats
            .iter()
            .map(|v| {
                v.split('+')
                    .filter(|m| !m.is_empty())
                    .map(String::from)
                    .collect()
            })
            .collect(),
        offset: [0.0, 0.0],
        bmp: false,
        seed: 3,
        dither: Dither::Random,
        layers: None,
        shard: None,
        threads,
    }
}

/// A 100 µm screen of 240 × 160 px, 100 µm layers.
fn small() -> VatPrinter {
    VatPrinter {
        name: "custom".into(),
        pixel: [0.1, 0.1],
        screen: [240, 160],
        layer: 0.1,
        height: None,
        description: "test screen".into(),
    }
}

fn export(m: &Arc<Model>, p: &VatParams, dest: &Path) -> Result<Summary, ExportError> {
    let (m, p) = (m.clone(), p.clone());
    run(dest, move |ctx| export_vat(&m, &p, ctx))
}

/// Non-zero pixels of every image under `prefix`.
fn lit(files: &BTreeMap<String, Vec<u8>>, prefix: &str) -> u64 {
    files
        .iter()
        .filter(|(n, _)| n.starts_with(prefix))
        .map(|(_, b)| decode(b).data.iter().filter(|v| **v > 0).count() as u64)
        .sum()
}

#[test]
fn two_vats_write_whole_screens_per_layer() {
    let (_t, dest) = scratch("bar");
    let s = export(
        &model(GRADED_BAR),
        &params(small(), &["red", "blue"], None),
        &dest,
    )
    .unwrap();
    let files = read_tree(&dest);
    // 5 mm at 0.1 mm: 50 layers, one image per vat per layer, same names.
    assert_eq!(files.len(), 100);
    for v in ["vat1", "vat2"] {
        for z in 0..50 {
            let name = format!("{v}/slice_{z:05}.png");
            let png = decode(&files[&name]);
            assert_eq!((png.width, png.height), (240, 160), "{name}");
            assert_eq!(
                (png.color, png.depth),
                (png::ColorType::Grayscale, png::BitDepth::Eight)
            );
            assert!(
                png.data.iter().all(|v| *v == 0 || *v == 255),
                "{name}: solid is 255"
            );
        }
    }
    // The part (150 × 100 px) is centred: columns 45..195, rows 30..130.
    let png = decode(&files["vat1/slice_00025.png"]);
    let on = |c: usize, r: usize| {
        png.data[r * 240 + c] > 0 || decode(&files["vat2/slice_00025.png"]).data[r * 240 + c] > 0
    };
    assert!(
        on(45, 30) && on(194, 129) && !on(44, 30) && !on(195, 129) && !on(45, 29) && !on(45, 130)
    );
    // Every voxel is in exactly one vat, and the images hold the counts.
    assert_eq!(s.counts[0].1, lit(&files, "vat1/"));
    assert_eq!(s.counts[1].1, lit(&files, "vat2/"));
    assert_eq!(s.counts[0].1 + s.counts[1].1, 150 * 100 * 50);
    // Red is x/15 + 0.5 of the bar: half its volume.
    let red = s.counts[0].1 as f64 / (150.0 * 100.0 * 50.0);
    assert!((red - 0.5).abs() < 0.005, "red share {red}");
    let pixel = decode(&files["vat1/slice_00000.png"]);
    assert_eq!(pixel.width, 240);
}

#[test]
fn same_bytes_on_one_and_two_threads_and_in_a_layer_range() {
    let m = model(CYLINDER);
    let (_t1, a) = scratch("a");
    let (_t2, b) = scratch("b");
    let (_t3, c) = scratch("c");
    let mut p = params(small(), &["red", "blue"], Some(1));
    p.dither = Dither::Diffusion;
    export(&m, &p, &a).unwrap();
    p.threads = Some(2);
    export(&m, &p, &b).unwrap();
    let (fa, fb) = (read_tree(&a), read_tree(&b));
    assert_eq!(fa, fb);
    assert_eq!(manifest(&a), manifest(&b));
    p.layers = Some(20..31);
    export(&m, &p, &c).unwrap();
    let fc = read_tree(&c);
    assert_eq!(fc.len(), 22);
    for (name, bytes) in &fc {
        assert_eq!(Some(bytes), fa.get(name), "{name} as in the whole stack");
    }
}

#[test]
fn shards_merge_into_the_whole_stack() {
    let m = model(GRADED_BAR);
    let (_t, whole) = scratch("whole");
    let mut p = params(small(), &["red", "blue"], None);
    p.intensity = Intensity::Fraction("red".into());
    export(&m, &p, &whole).unwrap();
    let parts: Vec<_> = (1..=3)
        .map(|k| {
            let (t, d) = scratch("part");
            let mut q = p.clone();
            q.shard = Some(format!("{k}/3").parse().unwrap());
            export(&m, &q, &d).unwrap();
            (t, d)
        })
        .collect();
    let dirs: Vec<_> = parts.iter().map(|(_, d)| d.clone()).collect();
    let plan = plan_merge(&dirs).unwrap();
    let (_t2, merged) = scratch("merged");
    run(&merged, move |ctx| plan.run(ctx)).unwrap();
    assert_eq!(read_tree(&merged), read_tree(&whole));
    assert_eq!(
        String::from_utf8(manifest(&merged)).unwrap(),
        String::from_utf8(manifest(&whole)).unwrap()
    );
}

#[test]
fn four_vat_counts_match_the_cylinder_volume() {
    let m = model(CYLINDER);
    let (_t, dest) = scratch("cyl");
    // Two vats hold nothing: every voxel still lands in exactly one vat.
    let p = params(small(), &["red", "", "blue", ""], None);
    let s = export(&m, &p, &dest).unwrap();
    let files = read_tree(&dest);
    assert_eq!(files.len(), 4 * 60);
    let v = 0.1f64.powi(3);
    let total: u64 = s.counts.iter().map(|c| c.1).sum();
    for (i, c) in s.counts.iter().enumerate() {
        assert_eq!(c.1, lit(&files, &format!("vat{}/", i + 1)), "{}", c.0);
    }
    let cyl = std::f64::consts::PI * 16.0 * 6.0;
    let err = |got: f64, want: f64| (got - want).abs() / want;
    assert!(
        err(total as f64 * v, cyl) < 0.01,
        "{} vs {cyl}",
        total as f64 * v
    );
    assert!(
        err(s.counts[0].1 as f64 * v, 0.3 * cyl) < 0.01,
        "red {:?}",
        s.counts
    );
    assert!(
        err(s.counts[2].1 as f64 * v, 0.7 * cyl) < 0.01,
        "blue {:?}",
        s.counts
    );
    assert_eq!(s.counts[1].1 + s.counts[3].1, 0);
}

/// Mean gray of each part column (x) over every layer of a one-vat stack.
fn column_means(files: &BTreeMap<String, Vec<u8>>) -> Vec<f64> {
    let mut sum = vec![0.0; 150];
    let mut n = vec![0.0; 150];
    for b in files.values() {
        let png = decode(b);
        for r in 30..130 {
            for c in 0..150 {
                sum[c] += f64::from(png.data[r * 240 + 45 + c]);
                n[c] += 1.0;
            }
        }
    }
    sum.iter().zip(&n).map(|(s, n)| s / n).collect()
}

#[test]
fn gray_follows_the_attribute_and_the_fraction_along_the_bar() {
    let m = model(GRADED_BAR);
    for intensity in [
        Intensity::Attribute {
            name: "dose".into(),
            range: Some((0.0, 1.0)),
        },
        Intensity::Attribute {
            name: "dose".into(),
            range: None,
        },
        Intensity::Fraction("red".into()),
    ] {
        let (_t, dest) = scratch("bar");
        let mut p = params(small(), &[], None);
        p.intensity = intensity.clone();
        export(&m, &p, &dest).unwrap();
        let means = column_means(&read_tree(&dest));
        for (c, got) in means.iter().enumerate() {
            // Column c's centre is at x = -7.5 + 0.1 (c + 0.5).
            let x = -7.5 + 0.1 * (c as f64 + 0.5);
            let want = 255.0 * (x / 15.0 + 0.5);
            assert!(
                (got - want).abs() < 1.0,
                "{intensity:?}: column {c}: {got} vs {want}"
            );
        }
    }
}

#[test]
fn bmp_images_are_8_bit_screens() {
    let (_t, dest) = scratch("bar");
    let mut p = params(small(), &[], None);
    p.bmp = true;
    p.offset = [3.0, -2.0];
    export(&model(GRADED_BAR), &p, &dest).unwrap();
    let files = read_tree(&dest);
    assert_eq!(files.len(), 50);
    let img = image::load_from_memory(&files["slice_00010.bmp"])
        .unwrap()
        .to_luma8();
    assert_eq!(img.dimensions(), (240, 160));
    // Moved 3 mm right and 2 mm down: columns 75..225, rows 50..150.
    assert!(img.get_pixel(75, 50)[0] == 255 && img.get_pixel(224, 149)[0] == 255);
    assert!(img.get_pixel(74, 50)[0] == 0 && img.get_pixel(75, 49)[0] == 0);
    // The pixel size: 100 µm = 10 000 px/m (biXPelsPerMeter,
    // biYPelsPerMeter after the 14-byte file header and 24 bytes of the
    // 40-byte BITMAPINFOHEADER).
    let b = &files["slice_00010.bmp"];
    let u32_at = |o: usize| u32::from_le_bytes([b[o], b[o + 1], b[o + 2], b[o + 3]]);
    assert_eq!(u32_at(14), 40, "BITMAPINFOHEADER");
    assert_eq!((u32_at(38), u32_at(42)), (10_000, 10_000));
}

#[test]
fn bmp_pixel_size_follows_a_non_square_pitch() {
    let (_t, dest) = scratch("pitch");
    let mut printer = small();
    // The Saturn 4 Ultra's pitch: 19 × 24 µm.
    printer.pixel = [0.019, 0.024];
    printer.screen = [1000, 600];
    let mut p = params(printer, &[], None);
    p.bmp = true;
    p.layers = Some(10..11);
    export(&model(GRADED_BAR), &p, &dest).unwrap();
    let b = &read_tree(&dest)["slice_00010.bmp"];
    let u32_at = |o: usize| u32::from_le_bytes([b[o], b[o + 1], b[o + 2], b[o + 3]]);
    // 1000 / 0.019 = 52 631.6 and 1000 / 0.024 = 41 666.7 px/m, rounded.
    assert_eq!((u32_at(38), u32_at(42)), (52_632, 41_667));
}

#[test]
fn refusals_name_both_sizes_and_leave_nothing() {
    let m = model(GRADED_BAR);
    let refuse = |p: &VatParams| {
        let (t, dest) = scratch("out");
        let e = export(&m, p, &dest).unwrap_err().to_string();
        assert!(!dest.exists(), "{e}: nothing written");
        assert_eq!(std::fs::read_dir(t.path()).unwrap().count(), 0, "{e}");
        e
    };
    let narrow = VatPrinter::custom([100.0, 100.0], [120, 160], 100.0).unwrap();
    let e = refuse(&params(narrow, &[], None));
    assert!(
        e.contains("150 × 100 px (15.00 × 10.00 mm)")
            && e.contains("120 × 160 px (12.00 × 16.00 mm)"),
        "{e}"
    );
    let mut tall = vat_preset("saturn-4-ultra").unwrap();
    tall.height = Some(4.0);
    let e = refuse(&params(tall, &[], None));
    assert!(
        e.contains("5.00 mm high") && e.contains("at most 4.00 mm"),
        "{e}"
    );
    let mut p = params(small(), &[], None);
    p.intensity = Intensity::Attribute {
        name: "modulus".into(),
        range: None,
    };
    let e = refuse(&p);
    assert!(
        e.contains("--intensity") && e.contains("it has dose"),
        "{e}"
    );
    p.intensity = Intensity::Fraction("green".into());
    assert!(refuse(&p).contains("it uses red, blue"));
    let e = refuse(&params(small(), &["red"], None));
    assert!(e.contains("blue in no vat"), "{e}");
    let e = refuse(&params(small(), &["red", "blue", "red"], None));
    assert!(e.contains("1, 2 or 4"), "{e}");
    let mut p = params(small(), &[], None);
    p.offset = [5.0, 0.0];
    assert!(refuse(&p).contains("at most 4.50 mm in X"));
}
