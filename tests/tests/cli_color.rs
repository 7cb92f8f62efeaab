//! `volcad export png --full-color` and `--bitmap-format bmp` from the
//! command line: what they write, and the option combinations refused
//! before any work.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed step fails the test

mod cli_common;

use cli_common::{example, fails, ok, tmp, volcad};

/// A 2 × 2 × 0.1 mm plate of a default material, coloured orange.
const PLATE: &str = r#"let m = default_materials();
let b = RectPrism(Vec3(0, 0, 0), Vec3(2, 2, 0.1), m.id("red"));
b.set_attribute("color", Vec4(1, 0.5, 0, 1));
b
"#;

#[test]
fn full_color_writes_resin_slices_and_counts() {
    let scratch = tmp("color");
    let d = scratch.path();
    let out = d.join("wheel");
    let wheel = example("color_wheel.rhai");
    let text = ok(&volcad(&[
        "export",
        "png",
        &wheel,
        "--out",
        out.to_str().unwrap(),
        "--voxel",
        "0.5",
        "--full-color",
    ]));
    for resin in volcad_compilers::color::J750_COLOR_RESINS {
        assert!(text.contains(resin), "{text}");
    }
    assert!(out.join("slice_00003.png").is_file());
    let manifest = std::fs::read_to_string(out.join("manifest.json")).unwrap();
    assert!(
        manifest.contains("\"full_color\"") && manifest.contains("OKLab"),
        "{manifest}"
    );
    // A design on default materials with the J750 preset: the resins are
    // the J750's whatever the materials, so nothing to map.
    let plate = d.join("plate.rhai");
    std::fs::write(&plate, PLATE).unwrap();
    let plate = plate.to_str().unwrap();
    let out = d.join("plate_png");
    let text = ok(&volcad(&[
        "export",
        "png",
        plate,
        "--out",
        out.to_str().unwrap(),
        "--preset",
        "j750",
        "--full-color",
    ]));
    assert!(
        text.contains("VeroYellow") && text.contains("VeroMgnt"),
        "{text}"
    );
    // The same plate as 1-bit BMPs, Myerson's width.
    let out = d.join("plate_bmp");
    ok(&volcad(&[
        "export",
        "png",
        plate,
        "--out",
        out.to_str().unwrap(),
        "--voxel",
        "0.1",
        "--bitmaps",
        "--bitmap-format",
        "bmp",
        "--bitmap-width",
        "880",
    ]));
    let bmp = std::fs::read(out.join("red/100000_100000_red.bmp")).unwrap();
    assert_eq!(&bmp[..2], b"BM");
    assert_eq!(
        bmp.len(),
        62 + 112 * 20,
        "880 px = 110 bytes, padded to 112, 20 rows"
    );
}

#[test]
fn option_combinations_that_would_do_nothing_are_refused() {
    let scratch = tmp("color-refused");
    let d = scratch.path();
    let plate = d.join("plate.rhai");
    std::fs::write(&plate, PLATE).unwrap();
    let plate = plate.to_str().unwrap();
    let out = d.join("out");
    let o = out.to_str().unwrap();
    let base = ["export", "png", plate, "--out", o, "--voxel", "0.5"];
    let cases: [(&[&str], &str); 6] = [
        (
            &["--full-color", "--dither", "diffusion"],
            "--dither diffusion: a full-colour stack",
        ),
        (
            &["--full-color", "--map", "red=VeroMgnt"],
            "--map red=VeroMgnt: a full-colour stack",
        ),
        (
            &["--bitmap-format", "bmp"],
            "--bitmap-format: chooses the format of the 1-bit bitmaps; add --bitmaps",
        ),
        (
            &["--bitmaps", "--bitmap-format", "tiff"],
            "\"tiff\": expected png or bmp",
        ),
        (
            &["--bitmaps", "--bitmap-width", "880"],
            "--bitmap-width: sets the width of BMP bitmaps",
        ),
        (
            &["--color-profile", "p.csv"],
            "--color-profile: gives the resins' colours for --full-color",
        ),
    ];
    for (extra, want) in cases {
        let args: Vec<&str> = base.iter().chain(extra).copied().collect();
        let err = fails(&volcad(&args));
        assert!(err.contains(want), "{extra:?}: {err}");
        assert!(!out.exists(), "{extra:?} wrote output");
    }
    let err = fails(&volcad(&[
        "export",
        "mesh",
        plate,
        "--out",
        o,
        "--voxel",
        "0.5",
        "--full-color",
    ]));
    assert!(
        err.contains("--full-color does not apply to `volcad export mesh`"),
        "{err}"
    );
}

/// A part larger than the J750's tray (490 × 390 × 200 mm) is refused with
/// both sizes by every J750 export, before any work and leaving nothing.
#[test]
fn a_part_larger_than_the_j750_tray_is_refused_with_both_sizes() {
    let d = tmp("tray");
    let design = d.path().join("slab.rhai");
    std::fs::write(
        &design,
        r#"let m = j750_materials();
RectPrism(Vec3(0, 0, 0), Vec3(500, 100, 1), m.id("VeroCyan"))"#,
    )
    .unwrap();
    let design = design.to_str().unwrap();
    let png = d.path().join("png");
    let gcvf = d.path().join("slab.gcvf");
    let runs: [Vec<&str>; 3] = [
        vec![
            "export", "png", design, "--preset", "j750", "--layers", "0..1",
        ],
        vec!["export", "png", design, "--preset", "j750", "--full-color"],
        vec!["export", "gcvf", design],
    ];
    for (args, out) in runs.iter().zip([&png, &png, &gcvf]) {
        let mut args = args.clone();
        args.extend(["--out", out.to_str().unwrap()]);
        let err = fails(&volcad(&args));
        assert!(
            err.contains("500.0 × 100.0 × 1.0 mm") && err.contains("490 × 390 × 200 mm"),
            "{args:?}: {err}"
        );
        assert!(!out.exists(), "{args:?} left {}", out.display());
    }
    assert_eq!(
        std::fs::read_dir(d.path()).unwrap().count(),
        1,
        "only the design"
    );
}
