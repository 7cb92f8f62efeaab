//! Every example in `assets/examples` runs, prepares, and shows what it
//! promises at a few points.

// A test crate: its helper functions stop on a failed setup as its tests do.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::PathBuf;

use glam::DVec3;
use volcad_core::Model;
use volcad_core::script::{ScriptOptions, run_script};

fn example(name: &str) -> Model {
    design("examples", name)
}

/// A design of `assets/<dir>` (`examples`, or `bench`: pyvcad's measured
/// designs, for like-for-like throughput).
fn design(dir: &str, name: &str) -> Model {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../assets")
        .join(dir)
        .join(name);
    let src = std::fs::read_to_string(&path).unwrap();
    let d =
        run_script(&src, name, &ScriptOptions::for_file(&path)).unwrap_or_else(|e| panic!("{e}"));
    Model::prepare(&d.root, d.materials.clone()).unwrap_or_else(|e| panic!("{name}: {e}"))
}

fn frac(m: &Model, p: DVec3, name: &str) -> f64 {
    let id = m.table().id(name).unwrap();
    let (_, f) = m.eval_point(p);
    f.iter().find(|(i, _)| *i == id).map_or(0.0, |x| x.1)
}

#[test]
fn every_example_is_tested() {
    let me = include_str!("examples.rs");
    for dir in ["examples", "bench"] {
        let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join("../assets")
            .join(dir);
        for e in std::fs::read_dir(dir).unwrap() {
            let name = e.unwrap().file_name().to_string_lossy().to_string();
            if name.ends_with(".rhai") {
                assert!(
                    me.contains(&format!("\"{name}\"")),
                    "{name} has no test here"
                );
            }
        }
    }
}

/// pyvcad's lattice (pyvcad 2.3.4's design d4; `d4_bcc_lattice_box` in the
/// model's tests checks this file against pyvcad's distances). Here: the
/// 10 mm box that makes pyvcad's 200³ grid 0.05 mm voxels, and the
/// lattice's material at a node.
#[test]
fn pyvcad_bcc_box() {
    let m = design("bench", "pyvcad_bcc_box.rhai");
    assert_eq!(m.bbox().size(), DVec3::splat(10.0));
    assert_eq!(frac(&m, DVec3::ONE, "red"), 1.0);
    assert_eq!(frac(&m, DVec3::ONE, "blue"), 0.0);
}

#[test]
fn pyvcad_sphere() {
    let m = design("bench", "pyvcad_sphere.rhai");
    assert_eq!(m.bbox().size(), DVec3::splat(20.0));
    assert!((m.distance(DVec3::ZERO) + 10.0).abs() < 1e-12);
    assert_eq!(frac(&m, DVec3::ZERO, "red"), 1.0);
}

#[test]
fn bunny_mesh_bench() {
    // The bunny body alone: its box is the mesh's, its centre inside it.
    let m = design("bench", "bunny_mesh.rhai");
    let b = m.bbox();
    assert!(b.size().min_element() > 10.0, "{b:?}");
    assert!(m.distance(b.center()) < 0.0);
    assert_eq!(frac(&m, b.center(), "clear"), 1.0);
}

#[test]
fn hello_cube() {
    let m = example("hello_cube.rhai");
    assert_eq!(m.bbox().size(), DVec3::splat(10.0));
    assert_eq!(frac(&m, DVec3::ZERO, "red"), 1.0);
}

/// The quartic-handle mug: the torus handle is solid red (its value is a
/// polynomial, not a distance: only its sign counts), its hole is empty,
/// and the cup is hollow above its 6 mm floor.
#[test]
fn mug() {
    let m = example("mug.rhai");
    assert!(!m.distance_is_bound());
    assert_eq!(frac(&m, DVec3::new(64.0, 0.0, 0.0), "red"), 1.0);
    assert_eq!(frac(&m, DVec3::new(42.0, 0.0, 22.0), "red"), 1.0);
    assert!(
        m.distance(DVec3::new(50.0, 0.0, 0.0)) > 0.0,
        "the handle's hole"
    );
    assert!(
        m.distance(DVec3::new(0.0, 0.0, 10.0)) > 0.0,
        "inside the cup"
    );
    assert_eq!(frac(&m, DVec3::new(38.0, 0.0, 0.0), "gray"), 1.0);
    assert_eq!(frac(&m, DVec3::new(0.0, 0.0, -42.0), "gray"), 1.0);
}

#[test]
fn graded_bar() {
    let m = example("graded_bar.rhai");
    assert!((frac(&m, DVec3::new(7.0, 0.0, 0.0), "red") - (7.0 / 15.0 + 0.5)).abs() < 1e-12);
    assert!((frac(&m, DVec3::new(-7.0, 0.0, 0.0), "blue") - (7.0 / 15.0 + 0.5)).abs() < 1e-12);
}

#[test]
fn color_sheet() {
    let m = example("color_sheet.rhai");
    assert_eq!(m.node_count(), 1 + 144 * 2);
    // Swatch i = 11 (+x edge) is pure cyan; i = 0, j = 0 is pure white.
    assert!((frac(&m, DVec3::new(137.5, 0.0, 0.0), "cyan") - 1.0).abs() < 1e-12);
    assert!((frac(&m, DVec3::new(-137.5, -137.5, 0.0), "white") - 1.0).abs() < 1e-12);
}

#[test]
fn bcc_sphere() {
    let m = example("bcc_sphere.rhai");
    // A strut passes through the cell centre (2.5, 2.5, 2.5); the gap between struts is empty.
    assert!(m.distance(DVec3::splat(2.5)) < 0.0);
    assert!(m.distance(DVec3::new(2.5, 0.0, 0.0)) > 0.0);
    assert!(m.distance(DVec3::splat(12.0)) > 0.0);
}

#[test]
fn lattice_grades() {
    let g = example("lattice_global_grade.rhai");
    assert!(g.distance(DVec3::new(2.5, 2.5, 7.5)) < 0.0);
    assert!(frac(&g, DVec3::new(2.5, 2.5, 7.5), "magenta") > 0.8);
    let c = example("lattice_per_cell.rhai");
    let a = frac(&c, DVec3::new(-7.5, -7.5, -10.0 + 0.01), "cyan");
    let b = frac(&c, DVec3::new(2.5, -7.5, -10.0 + 0.01), "cyan");
    assert!(b > a, "cells further along x are more cyan: {a} {b}");
    let s = example("lattice_per_strut.rhai");
    assert!(s.node_count() > 200);
    assert!(s.materials().len() == 2);
}

#[test]
fn gyroid() {
    let m = example("gyroid.rhai");
    assert!(m.bbox().is_finite());
    assert!(
        m.distance(DVec3::ZERO) <= 0.0,
        "the gyroid passes through the origin"
    );
}

#[test]
fn csg_tour() {
    let m = example("csg_tour.rhai");
    assert!(m.bbox().is_finite());
    assert!(m.materials().len() >= 4);
}

#[test]
fn bunny_examples() {
    let m = example("bunny_lattice.rhai");
    assert_eq!(m.node_count(), 1 + 3286 * 2 + 1);
    assert!(m.distance(DVec3::ZERO) < 0.0);
    let s = example("bunny_struts.rhai");
    assert_eq!(s.materials().len(), 2);
}

#[test]
fn bicycle_seat() {
    let m = example("bicycle_seat.rhai");
    let b = m.bbox();
    assert!((b.size().x - 260.3).abs() < 1.0, "{b:?}");
    // Near the unsupported rear wing the seat is mostly rigid; over the nose
    // rail (which barely moves) mostly soft.
    let wing = frac(&m, DVec3::new(88.7, 60.0, 15.0), "VeroCyan");
    let nose = frac(&m, DVec3::new(240.0, 0.0, 5.0), "VeroCyan");
    assert!(wing > 0.6 && nose < 0.1, "wing {wing}, nose {nose}");
}

#[test]
fn text_label() {
    let m = example("text_label.rhai");
    let b = m.bbox();
    assert!(
        (b.max.z - 0.8).abs() < 1e-12 && (b.min.z + 2.0).abs() < 1e-12,
        "{b:?}"
    );
    // Above the plate's top face: red letters along the first line, air
    // between the two lines; the plate itself is gray.
    let red = (0..400)
        .map(|i| DVec3::new(-20.0 + 0.1 * f64::from(i), 4.0, 0.5))
        .filter(|p| m.distance(*p) < 0.0)
        .inspect(|p| assert_eq!(frac(&m, *p, "red"), 1.0))
        .count();
    assert!(red > 40, "{red}");
    assert!(m.distance(DVec3::new(0.0, 0.0, 0.5)) > 0.0);
    assert_eq!(frac(&m, DVec3::new(-28.0, -10.0, -1.0), "gray"), 1.0);
}

/// Scalar attribute `name` of `m` at `p` (NaN where it is not set).
fn attr(m: &Model, name: &str, p: DVec3) -> f64 {
    let i = m
        .attribute_index(name)
        .unwrap_or_else(|| panic!("no {name}"));
    let mut out = [f64::NAN];
    m.attribute_at(i, p, &mut out).unwrap();
    out[0]
}

/// Hardness by intent: Shore A 85 in the middle, 40 at the ends; the resin
/// mix inverts the example's (illustrative) mix table at the same target,
/// and the modulus follows Gent's relation tabulated in the file.
#[test]
fn shore_grip() {
    let m = example("shore_grip.rhai");
    let names: Vec<&str> = m.attributes().iter().map(|a| a.name.as_str()).collect();
    assert_eq!(names, ["modulus", "shore_hardness"]);
    let mid = DVec3::new(0.0, 0.0, 0.0);
    let end = DVec3::new(0.0, 0.0, -49.0);
    assert!((attr(&m, "shore_hardness", mid) - 85.0).abs() < 1e-9);
    let s_end = 85.0 - 45.0 * (49.0f64 / 50.0).powi(2);
    assert!((attr(&m, "shore_hardness", end) - s_end).abs() < 1e-9);
    // Between the table's rows 80 (9.351) and 90 (20.844) MPa.
    let e_mid = attr(&m, "modulus", mid);
    assert!(
        (e_mid - (9.351 + 0.5 * (20.844 - 9.351))).abs() < 1e-9,
        "{e_mid}"
    );
    assert!(attr(&m, "modulus", end) < 2.0);
    // The mix inverts assets/examples/data/shore_mix.csv (VeroClear share
    // -> Shore A: 0.5 -> 57, 0.75 -> 75, 1 -> 95). Shore A 85 in the middle
    // lies half way from 75 to 95: share 0.875.
    assert!((frac(&m, mid, "VeroClear") - 0.875).abs() < 1e-12);
    assert!((frac(&m, mid, "Agilus30Clr") - 0.125).abs() < 1e-12);
    // At z = 30, Shore A 85 − 45·0.36 = 68.8: 11.8 of the 18 from 57 to 75.
    let at30 = DVec3::new(0.0, 0.0, 30.0);
    let share30 = 0.5 + 0.25 * (68.8 - 57.0) / 18.0;
    assert!((frac(&m, at30, "VeroClear") - share30).abs() < 1e-12);
    assert!(frac(&m, end, "Agilus30Clr") > 0.75);
    assert!(m.attribute_warnings().is_empty());
    assert!(attr(&m, "modulus", DVec3::new(0.0, 0.0, 60.0)).is_nan());
}

/// The CalculiX column: modulus 500 → 2850 MPa along z, ν and density
/// constant (`compilers/tests/fea_properties.rs` solves it).
#[test]
fn modulus_beam() {
    let m = example("modulus_beam.rhai");
    assert_eq!(attr(&m, "modulus", DVec3::new(0.0, 0.0, -30.0)), 500.0);
    assert_eq!(attr(&m, "modulus", DVec3::new(1.0, 2.0, 30.0)), 2850.0);
    assert_eq!(attr(&m, "poissons_ratio", DVec3::ZERO), 0.35);
    assert_eq!(attr(&m, "density", DVec3::ZERO), 1.17);
}

/// The colour-graded ball: red at −x, blue at +x, green rising with z.
#[test]
fn color_gradient() {
    let m = example("color_gradient.rhai");
    let i = m.attribute_index("color").unwrap();
    let mut c = [0.0; 4];
    let near = |a: [f64; 4], b: [f64; 4]| a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-12);
    m.attribute_at(i, DVec3::new(-19.0, 0.0, 0.0), &mut c)
        .unwrap();
    assert!(near(c, [0.975, 0.5, 0.025, 1.0]), "{c:?}");
    m.attribute_at(i, DVec3::new(0.0, 0.0, 19.0), &mut c)
        .unwrap();
    assert!(near(c, [0.5, 0.975, 0.5, 1.0]), "{c:?}");
}

/// The photo tile: at the centre of each pixel of the picture (256 px
/// over 40 mm, the top row at +y) the colour is that pixel's, through the
/// whole thickness (pixels inside the rounded corners); between centres a
/// mix of the neighbours.
#[test]
fn photo_tile() {
    let m = example("photo_tile.rhai");
    let i = m.attribute_index("color").unwrap();
    let path =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../assets/examples/data/astronaut.png");
    let img = image::open(path).unwrap().to_rgba8();
    assert_eq!(img.dimensions(), (256, 256));
    let pitch = 40.0 / 256.0;
    let mut c = [0.0; 4];
    for (col, row) in [(3, 3), (128, 40), (70, 200), (252, 252), (200, 17)] {
        let want = img.get_pixel(col, row).0.map(|v| f64::from(v) / 255.0);
        let x = -20.0 + (f64::from(col) + 0.5) * pitch;
        let y = 20.0 - (f64::from(row) + 0.5) * pitch;
        for z in [-1.4, 0.0, 1.4] {
            m.attribute_at(i, DVec3::new(x, y, z), &mut c).unwrap();
            assert!(
                c.iter().zip(want).all(|(a, b)| (a - b).abs() < 1e-12),
                "pixel {col}, {row} at z {z}: {c:?} vs {want:?}"
            );
        }
    }
    // Half way between two centres along a row: their mean.
    let (a, b) = (img.get_pixel(100, 50).0, img.get_pixel(101, 50).0);
    let x = -20.0 + 101.0 * pitch;
    let y = 20.0 - 50.5 * pitch;
    m.attribute_at(i, DVec3::new(x, y, 0.0), &mut c).unwrap();
    for k in 0..3 {
        let mean = (f64::from(a[k]) + f64::from(b[k])) / 510.0;
        assert!((c[k] - mean).abs() < 1e-12, "{c:?}");
    }
}

/// The colour wheel: white at the centre, the pure hue at the rim (red
/// at +x, green at 120°, blue at 240°).
#[test]
fn color_wheel() {
    let m = example("color_wheel.rhai");
    let i = m.attribute_index("color").unwrap();
    let mut c = [0.0; 4];
    let near = |a: [f64; 4], b: [f64; 4]| a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-9);
    m.attribute_at(i, DVec3::ZERO, &mut c).unwrap();
    assert!(near(c, [1.0, 1.0, 1.0, 1.0]), "{c:?}");
    let at = |deg: f64| {
        DVec3::new(
            19.9 * deg.to_radians().cos(),
            19.9 * deg.to_radians().sin(),
            0.0,
        )
    };
    m.attribute_at(i, at(0.0), &mut c).unwrap();
    assert!(near(c, [1.0, 0.005, 0.005, 1.0]), "{c:?}");
    m.attribute_at(i, at(120.0), &mut c).unwrap();
    assert!(near(c, [0.005, 1.0, 0.005, 1.0]), "{c:?}");
    m.attribute_at(i, at(240.0), &mut c).unwrap();
    assert!(near(c, [0.005, 0.005, 1.0, 1.0]), "{c:?}");
    // Half way out at 60°: yellow at half saturation.
    m.attribute_at(i, at(60.0) * 0.5, &mut c).unwrap();
    assert!(
        (c[0] - 1.0).abs() < 1e-9 && (c[1] - 1.0).abs() < 1e-6 && (c[2] - 0.5025).abs() < 1e-9,
        "{c:?}"
    );
}

#[test]
fn thermal_plate() {
    let m = example("thermal_plate.rhai");
    let names: Vec<&str> = m.attributes().iter().map(|a| a.name.as_str()).collect();
    assert_eq!(names, ["modulus", "temperature"]);
    // At a thermocouple the reading itself (assets/examples/data/
    // plate_temperatures.csv: 88 °C at the centre of the top face).
    let hot = DVec3::new(0.0, 0.0, 1.5);
    assert!((attr(&m, "temperature", hot) - 88.0).abs() < 1e-9);
    assert!((attr(&m, "modulus", hot) - (2850.0 - 20.0 * 68.0)).abs() < 1e-6);
    // Between readings, a weighted mean of them: inside their range, and
    // nearer the closer one.
    let between = DVec3::new(-15.0, 0.0, 1.5);
    let t = attr(&m, "temperature", between);
    assert!(t > 47.0 && t < 88.0, "{t}");
    let near_edge = attr(&m, "temperature", DVec3::new(-27.0, 0.0, 1.5));
    assert!(
        (near_edge - 47.0).abs() < (t - 47.0).abs(),
        "{near_edge} {t}"
    );
}
