//! GrabCAD Voxel Print packages end to end: the archive's structure against
//! what pyvcad 2.3.4's `GCVFExporter` writes for the graded bar, material
//! counts against analytic volumes, byte-identical archives across thread
//! counts, and refusals that leave nothing behind.

// A failed setup step (a scratch folder, a file read) fails the test.
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use std::io::{Cursor, Read};
use std::path::Path;
use std::sync::Arc;

use common::{decode, model, tmp};
use glam::DVec3;
use volcad_compilers::gcvf::{GcvfParams, export_gcvf};
use volcad_compilers::job;
use volcad_compilers::png_stack::{Dither, preset};
use volcad_compilers::{ExportError, Summary};
use volcad_core::Model;

/// The graded bar of assets/examples/graded_bar.rhai (15 × 10 × 5 mm, red
/// at +x, blue at −x).
const GRADED_BAR: &str = r#"let m = default_materials();
FGrade(["x/15+0.5", "-x/15+0.5"], [m.id("red"), m.id("blue")], true, RectPrism(Vec3(0,0,0), Vec3(15,10,5), m.id("gray")))"#;

fn params(voxel: DVec3, threads: Option<usize>) -> GcvfParams {
    GcvfParams {
        voxel,
        seed: 7,
        dither: Dither::Random,
        map: vec![
            ("red".into(), "VeroMgnt".into()),
            ("blue".into(), "VeroCyan".into()),
        ],
        threads,
        file_name: "part.gcvf".into(),
        liquid_keep_out: None,
    }
}

fn export(m: &Arc<Model>, p: &GcvfParams, dest: &Path) -> Result<Summary, ExportError> {
    let (m, mut p) = (m.clone(), p.clone());
    p.file_name = dest.file_name().unwrap().to_string_lossy().to_string();
    job::spawn_file(dest.to_path_buf(), "test".into(), move |ctx| {
        export_gcvf(&m, &p, ctx)
    })
    .join()
}

fn entry(z: &mut zip::ZipArchive<Cursor<Vec<u8>>>, name: &str) -> Vec<u8> {
    let mut out = Vec::new();
    z.by_name(name)
        .unwrap_or_else(|_| panic!("{name} in the archive"))
        .read_to_end(&mut out)
        .unwrap();
    out
}

/// The element names of `xml` in document order (closing tags and
/// comments left out).
fn tags(xml: &str) -> Vec<&str> {
    xml.split('<')
        .skip(1)
        .filter(|t| !t.starts_with('/') && !t.starts_with('!') && !t.starts_with('?'))
        .map(|t| t.split(['>', ' ']).next().unwrap())
        .collect()
}

fn field<'a>(xml: &'a str, tag: &str) -> Vec<&'a str> {
    xml.split(&format!("<{tag}>"))
        .skip(1)
        .map(|s| s.split('<').next().unwrap())
        .collect()
}

#[test]
fn graded_bar_matches_pyvcad_structure() {
    let j750 = preset("j750").unwrap().voxel;
    let dir = tmp();
    let dest = dir.path().join("bar.gcvf");
    let s = export(&model(GRADED_BAR), &params(j750, None), &dest).unwrap();
    assert_eq!(
        std::fs::read_dir(dir.path()).unwrap().count(),
        1,
        "only the archive"
    );
    let mut z = zip::ZipArchive::new(Cursor::new(std::fs::read(&dest).unwrap())).unwrap();
    // pyvcad 2.3.4 (GCVFExporter, same bar, voxel 25.4/600, 25.4/300,
    // 0.027 mm): 355 × 119 px, 186 slices gcvf_export_0..185, plus these four.
    let mut names: Vec<String> = z.file_names().map(String::from).collect();
    names.sort();
    let mut want: Vec<String> = (0..186).map(|k| format!("gcvf_export_{k}.png")).collect();
    want.extend(["ConfigFile.xml", "Mesh.stl", "MeshBbx.ktn", "Zbuffer.png"].map(String::from));
    want.sort();
    assert_eq!(names, want);
    let xml = String::from_utf8(entry(&mut z, "ConfigFile.xml")).unwrap();
    bar_config_matches_pyvcad(&xml);
    assert_eq!(s.counts.iter().map(|c| c.1).sum::<u64>(), 355 * 119 * 186);
    bar_slices_match_pyvcad(&mut z);
    bar_mesh_matches_pyvcad(&mut z);
}

/// The graded bar's ConfigFile.xml against pyvcad 2.3.4's: element order,
/// values, materials and voxel counts.
fn bar_config_matches_pyvcad(xml: &str) {
    // pyvcad 2.3.4's element order.
    assert_eq!(
        tags(xml),
        [
            "GCVF",
            "Version",
            "Resolution",
            "XDpi",
            "YDpi",
            "SliceThicknessNanoMeter",
            "SliceDimensions",
            "SliceWidth",
            "SliceHeight",
            "SliceRange",
            "StartIndex",
            "NumberOfSlices",
            "BitDepth",
            "MaxNumberOfColors",
            "DataSemantics",
            "CreationMode",
            "ImageFilePrefix",
            "MaterialList",
            "BackGroundMaterialRGBA",
            "Material",
            "Name",
            "RGBA",
            "VoxelCount",
            "Material",
            "Name",
            "RGBA",
            "VoxelCount"
        ]
    );
    for (tag, value) in [
        ("Version", "2"),
        ("XDpi", "600"),
        ("YDpi", "300"),
        ("SliceThicknessNanoMeter", "27000"),
        ("SliceWidth", "355"),
        ("SliceHeight", "119"),
        ("StartIndex", "0"),
        ("NumberOfSlices", "186"),
        ("BitDepth", "4"),
        ("MaxNumberOfColors", "6"),
        ("DataSemantics", "Materials"),
        ("CreationMode", "MODEL_ONLY"),
        ("ImageFilePrefix", "gcvf_export_"),
        ("BackGroundMaterialRGBA", "0 0 0 0"),
    ] {
        assert_eq!(field(xml, tag), [value], "{tag}");
    }
    // Our materials come in the design's id order (pyvcad: FGrade order).
    let mut mats: Vec<(&str, &str)> = field(xml, "Name")
        .into_iter()
        .zip(field(xml, "RGBA"))
        .collect();
    mats.sort();
    assert_eq!(
        mats,
        [("VeroCyan", "0 255 255 255"), ("VeroMgnt", "255 0 255 255")]
    );
    // Every voxel of the grid is inside the bar, as in pyvcad's file
    // (3 925 490 VeroMgnt + 3 932 080 VeroCyan = 355 · 119 · 186).
    let counts: Vec<u64> = field(xml, "VoxelCount")
        .iter()
        .map(|c| c.parse().unwrap())
        .collect();
    assert_eq!(counts.iter().sum::<u64>(), 355 * 119 * 186);
    for c in &counts {
        assert!(
            (*c as f64 / (355.0 * 119.0 * 186.0) - 0.5).abs() < 0.01,
            "{counts:?}"
        );
    }
}

/// The graded bar's slices and Z-buffer against pyvcad 2.3.4's.
fn bar_slices_match_pyvcad(z: &mut zip::ZipArchive<Cursor<Vec<u8>>>) {
    // Slices: 8-bit RGBA; X flipped as pyvcad's: VeroMgnt (+x) in column 0.
    let first = decode(&entry(z, "gcvf_export_0.png"));
    assert_eq!((first.width, first.height), (355, 119));
    assert_eq!(
        (first.color, first.depth),
        (png::ColorType::Rgba, png::BitDepth::Eight)
    );
    let column = |x: usize| {
        (0..119)
            .filter(|y| first.data[(y * 355 + x) * 4..][..4] == [255, 0, 255, 255])
            .count()
    };
    assert!(
        column(0) > 110 && column(354) < 9,
        "{} {}",
        column(0),
        column(354)
    );
    // Z-buffer: 16-bit, the top layer's index everywhere (pyvcad: 185).
    let zb = decode(&entry(z, "Zbuffer.png"));
    assert_eq!(
        (zb.width, zb.height, zb.depth),
        (355, 119, png::BitDepth::Sixteen)
    );
    assert!(
        zb.data
            .chunks_exact(2)
            .all(|v| u16::from_be_bytes([v[0], v[1]]) == 185)
    );
}

/// The graded bar's MeshBbx.ktn and Mesh.stl against pyvcad 2.3.4's.
fn bar_mesh_matches_pyvcad(z: &mut zip::ZipArchive<Cursor<Vec<u8>>>) {
    // MeshBbx.ktn: pyvcad's (0, 0, 0, 355, 119, 186).
    let ktn: Vec<f32> = entry(z, "MeshBbx.ktn")
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes(b.try_into().unwrap()))
        .collect();
    assert_eq!(ktn, [0.0, 0.0, 0.0, 355.0, 119.0, 186.0]);
    // Mesh.stl: pyvcad's spans x 0..15, y −10..0, z 0..5 mm; ours sits in
    // the same frame, within the grid's overhang (under one voxel a side).
    let stl = entry(z, "Mesh.stl");
    let n = u32::from_le_bytes(stl[80..84].try_into().unwrap()) as usize;
    assert_eq!(stl.len(), 84 + 50 * n);
    let (mut lo, mut hi) = ([f32::MAX; 3], [f32::MIN; 3]);
    for t in stl[84..].chunks_exact(50) {
        for v in 0..3 {
            for a in 0..3 {
                let o = 12 + v * 12 + a * 4;
                let x = f32::from_le_bytes(t[o..o + 4].try_into().unwrap());
                lo[a] = lo[a].min(x);
                hi[a] = hi[a].max(x);
            }
        }
    }
    for (a, (want_lo, want_hi)) in [(0.0, 15.0), (-10.0, 0.0), (0.0, 5.0)]
        .into_iter()
        .enumerate()
    {
        let slack = 0.1;
        assert!(
            (lo[a] - want_lo).abs() < slack && (hi[a] - want_hi).abs() < slack,
            "axis {a}: {lo:?} {hi:?}"
        );
    }
}

#[test]
fn counts_match_volumes_and_threads_do_not_change_bytes() {
    // At 0.1 mm the grid fits the bar exactly: 150 · 100 · 50 voxels, half
    // of the volume each material.
    let m = model(GRADED_BAR);
    let dir = tmp();
    let one = dir.path().join("one.gcvf");
    let two = dir.path().join("two.gcvf");
    let s = export(&m, &params(DVec3::splat(0.1), Some(1)), &one).unwrap();
    export(&m, &params(DVec3::splat(0.1), Some(2)), &two).unwrap();
    assert_eq!(std::fs::read(&one).unwrap(), std::fs::read(&two).unwrap());
    let half = 150.0 * 100.0 * 50.0 / 2.0;
    for (name, c) in &s.counts {
        assert!((*c as f64 - half).abs() < 0.01 * half, "{name}: {c}");
    }
    // The true resolution: 254 dpi, 100 000 nm.
    let mut z = zip::ZipArchive::new(Cursor::new(std::fs::read(&one).unwrap())).unwrap();
    let xml = String::from_utf8(entry(&mut z, "ConfigFile.xml")).unwrap();
    assert_eq!(field(&xml, "XDpi"), ["254"]);
    assert_eq!(field(&xml, "SliceThicknessNanoMeter"), ["100000"]);
    assert!(
        s.notes
            .iter()
            .any(|n| n.contains("not the J750's 600 × 300 dpi")),
        "{:?}",
        s.notes
    );
}

#[test]
fn refusals_name_the_fix_and_leave_nothing() {
    let dir = tmp();
    let dest = dir.path().join("bar.gcvf");
    let mut p = params(DVec3::splat(0.5), None);
    p.map.clear();
    let e = export(&model(GRADED_BAR), &p, &dest)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("\"red\" is not a J750 material") && e.contains("Tango+"),
        "{e}"
    );
    assert!(e.contains("--map blue="), "{e}");
    p.map = vec![
        ("red".into(), "VeroMagic".into()),
        ("green".into(), "VeroCyan".into()),
    ];
    let e = export(&model(GRADED_BAR), &p, &dest)
        .unwrap_err()
        .to_string();
    assert!(e.contains("\"VeroMagic\" is not a J750 material"), "{e}");
    assert!(e.contains("has no material \"green\""), "{e}");
    let seven = r#"let m = j750_materials();
Union(false, [Sphere(Vec3(0,0,0),1,m.id("VeroCyan")), Sphere(Vec3(3,0,0),1,m.id("VeroMgnt")), Sphere(Vec3(6,0,0),1,m.id("VeroYellow")), Sphere(Vec3(9,0,0),1,m.id("VeroBlack")), Sphere(Vec3(12,0,0),1,m.id("VeroPureWht")), Sphere(Vec3(15,0,0),1,m.id("VeroClear")), Sphere(Vec3(18,0,0),1,m.id("Agilus30Clr"))])"#;
    p.map.clear();
    let e = export(&model(seven), &p, &dest).unwrap_err().to_string();
    assert!(e.contains("7 resins") && e.contains("at most 6"), "{e}");
    assert_eq!(
        std::fs::read_dir(dir.path()).unwrap().count(),
        0,
        "nothing left"
    );
}

#[test]
fn liquid_keep_out_matches_pyvcad() {
    // A 10 × 10 × 4 mm VeroCyan block with a liquid channel (r 2.5 mm)
    // through it along z; keep-out 0.5 mm empties the channel's last
    // 0.5 mm at each end. pyvcad 2.3.4 at 0.1 mm (corner samples, 40
    // layers): M.Cleanser 78 280 voxels without keep-out, 56 753 with it
    // (29 of 40 layers: it keeps liquid only where the distance is below
    // −0.5), VeroCyan 321 720 both times. Ours samples voxel centres: 30
    // of 40 layers keep it, π · 2.5² · 3 mm = 58.9 mm³.
    let m = model(
        r#"let m = j750_materials();
Union(false, [Cylinder(Vec3(0,0,0), 2.5, 4, m.id("M.Cleanser")), RectPrism(Vec3(0,0,0), Vec3(10,10,4), m.id("VeroCyan"))])"#,
    );
    let dir = tmp();
    let mut p = params(DVec3::splat(0.1), None);
    p.map.clear();
    let full = export(&m, &p, &dir.path().join("full.gcvf")).unwrap();
    p.liquid_keep_out = Some(0.5);
    let kept = export(&m, &p, &dir.path().join("kept.gcvf")).unwrap();
    let count = |s: &Summary, name: &str| s.counts.iter().find(|c| c.0 == name).unwrap().1 as f64;
    let area = std::f64::consts::PI * 2.5 * 2.5;
    let per_mm3 = 1000.0;
    assert!((count(&full, "M.Cleanser") / (area * 4.0 * per_mm3) - 1.0).abs() < 0.01);
    assert!((count(&kept, "M.Cleanser") / (area * 3.0 * per_mm3) - 1.0).abs() < 0.01);
    // The rest of the channel is void, not VeroCyan.
    assert_eq!(count(&kept, "VeroCyan"), count(&full, "VeroCyan"));
    assert!((count(&full, "VeroCyan") / ((400.0 - area * 4.0) * per_mm3) - 1.0).abs() < 0.01);
    // A design of liquid alone, 1 mm deep at most, cannot keep 2 mm out.
    let drop = model(r#"let m = j750_materials(); Sphere(Vec3(0,0,0), 1, m.id("M.Cleanser"))"#);
    p.liquid_keep_out = Some(2.0);
    let e = export(&drop, &p, &dir.path().join("gone.gcvf"))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("--liquid-keep-out") && e.contains("removes the whole part"),
        "{e}"
    );
    p.liquid_keep_out = Some(0.5);
    let e = export(
        &model(GRADED_BAR),
        &params(DVec3::splat(0.5), None),
        &dir.path().join("x.gcvf"),
    )
    .map(|_| ())
    .and_then(|()| {
        export(
            &model(GRADED_BAR),
            &GcvfParams {
                liquid_keep_out: Some(0.5),
                ..params(DVec3::splat(0.5), None)
            },
            &dir.path().join("y.gcvf"),
        )
        .map(|_| ())
    })
    .unwrap_err()
    .to_string();
    assert!(e.contains("no liquid material"), "{e}");
    assert!(!dir.path().join("y.gcvf").exists());
}
