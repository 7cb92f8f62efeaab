//! Every example in `assets/examples` runs, prepares, and shows what it
//! promises at a few points.

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
