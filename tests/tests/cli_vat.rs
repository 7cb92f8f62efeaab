//! `volcad export vat` end to end: multi-vat folders, gray from an
//! attribute, and the refusals (build area, unknown attribute, options of
//! another export) that leave nothing behind.

mod cli_common;

use cli_common::{example, fails, ok, tmp, volcad};

/// Mean gray of the lit pixels of a PNG.
fn mean_lit(path: &std::path::Path) -> f64 {
    let img = image::open(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .to_luma8();
    let lit: Vec<f64> = img
        .pixels()
        .filter(|p| p[0] > 0)
        .map(|p| f64::from(p[0]))
        .collect();
    lit.iter().sum::<f64>() / lit.len() as f64
}

#[test]
fn two_vats_and_gray_from_an_attribute() {
    let d = tmp("vat");
    let bar = example("graded_bar.rhai");
    let out = d.path().join("bar");
    let o = ok(&volcad(&[
        "export",
        "vat",
        &bar,
        "--out",
        out.to_str().unwrap(),
        "--pixel",
        "250",
        "--screen",
        "80x60",
        "--layer",
        "250",
        "--vats",
        "2",
        "--vat-materials",
        "red,blue",
    ]));
    assert!(o.contains("vat1 (red)") && o.contains("vat2 (blue)"), "{o}");
    for v in ["vat1", "vat2"] {
        let n = std::fs::read_dir(out.join(v)).unwrap().count();
        assert_eq!(n, 20, "{v}: 5 mm at 0.25 mm layers");
        let img = image::open(out.join(v).join("slice_00000.png")).unwrap();
        assert_eq!((img.width(), img.height()), (80, 60));
    }
    // The modulus beam (6 × 6 × 60 mm, 500 MPa at the base to 2850 at the
    // top): mapped over 500..2850, layer z is 255 (z + 0.5) / 60 bright.
    let beam = example("modulus_beam.rhai");
    let out = d.path().join("beam");
    ok(&volcad(&[
        "export",
        "vat",
        &beam,
        "--out",
        out.to_str().unwrap(),
        "--pixel",
        "500",
        "--screen",
        "20x20",
        "--layer",
        "1000",
        "--intensity",
        "modulus",
        "--range",
        "500,2850",
    ]));
    for z in [0usize, 30, 59] {
        let got = mean_lit(&out.join(format!("slice_{z:05}.png")));
        let want = 255.0 * (z as f64 + 0.5) / 60.0;
        assert!((got - want).abs() < 1.0, "layer {z}: {got} vs {want}");
    }
}

#[test]
fn refusals_come_before_any_work() {
    let d = tmp("vat");
    let out = d.path().join("out");
    let o = out.to_str().unwrap();
    let bar = example("graded_bar.rhai");
    let e = fails(&volcad(&[
        "export", "vat", &bar, "--out", o, "--pixel", "100", "--screen", "100x200", "--layer",
        "100",
    ]));
    assert!(
        e.contains("150 × 100 px (15.00 × 10.00 mm)")
            && e.contains("100 × 200 px (10.00 × 20.00 mm)"),
        "{e}"
    );
    let beam = example("modulus_beam.rhai");
    let e = fails(&volcad(&[
        "export",
        "vat",
        &beam,
        "--out",
        o,
        "--preset",
        "saturn-4-ultra",
        "--intensity",
        "dose",
    ]));
    assert!(e.contains("it has density, modulus, poissons_ratio"), "{e}");
    let e = fails(&volcad(&[
        "export", "vat", &bar, "--out", o, "--voxel", "0.1",
    ]));
    assert!(e.contains("--voxel does not apply to vat"), "{e}");
    let e = fails(&volcad(&["export", "vat", &bar, "--out", o]));
    assert!(e.contains("--preset saturn-4-ultra"), "{e}");
    let e = fails(&volcad(&[
        "export", "png", &bar, "--out", o, "--voxel", "1", "--vats", "2",
    ]));
    assert!(
        e.contains("--vats does not apply to `volcad export png`"),
        "{e}"
    );
    assert!(!out.exists());
    assert_eq!(std::fs::read_dir(d.path()).unwrap().count(), 0);
}
