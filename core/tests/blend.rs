//! `Blend` against pyvcad 2.3.4's measured stencil (docs/PYVCAD.md):
//! every value below was printed by pyvcad 2.3.4's `distribution(x, y, z)`
//! after `prepare(Vec3(0.1, 0.1, 0.1), 1, 1)` (its floats are single
//! precision, hence the 1e-6 tolerance).

// A test crate: its helper functions stop on a failed setup as its tests do.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use volcad_core::script::{ScriptOptions, run_script};
use volcad_core::{DVec3, Model};

fn model(src: &str) -> Model {
    let d =
        run_script(src, "blend.rhai", &ScriptOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    Model::prepare(&d.root, d.materials.clone()).unwrap_or_else(|e| panic!("{e}"))
}

/// The fraction of material `id` at `p` (0 when absent).
fn frac(m: &Model, p: [f64; 3], id: u8) -> f64 {
    let (_, f) = m.eval_point(DVec3::from_array(p));
    f.iter().find(|(k, _)| *k == id).map_or(0.0, |(_, v)| *v)
}

/// A red (1) / blue (3) step at x = 0 (x = 0 itself is red: the union's
/// first child holds it), blended with r = 5: six offsets per axis.
#[test]
fn red_blue_step_matches_pyvcad() {
    let m = model(
        "Blend(5.0, Union(false, [RectPrism(Vec3(-10,0,0), Vec3(20,20,20), 1), RectPrism(Vec3(10,0,0), Vec3(20,20,20), 3)]))",
    );
    // (x, blue fraction) from pyvcad 2.3.4 at (x, 0, 0).
    let measured = [
        (-7.0, 0.0),
        (-5.0, 0.0),
        (-4.75, 0.166667),
        (-3.0, 0.166667),
        (-2.75, 0.333333),
        (-1.0, 0.333333),
        (-0.75, 0.5),
        (0.0, 0.5),
        (1.0, 0.5),
        (1.25, 0.666667),
        (3.0, 0.666667),
        (3.25, 0.833333),
        (5.0, 0.833333),
        (5.25, 1.0),
        (7.0, 1.0),
    ];
    for (x, blue) in measured {
        let got = frac(&m, [x, 0.0, 0.0], 3);
        assert!(
            (got - blue).abs() < 1e-6,
            "x = {x}: ours {got}, pyvcad {blue}"
        );
        assert!((frac(&m, [x, 0.0, 0.0], 1) - (1.0 - blue)).abs() < 1e-6);
    }
}

/// Whether the stencil has 5 or 6 offsets per axis depends on r (the
/// step 0.4·r is single precision): pyvcad 2.3.4 at p = 0 with blue where
/// x > −1e-6 gives 0.5 (6 offsets, 3 positive) or 0.4 (5, 2 positive).
/// These radii of 0.05, 0.10, ..., 10.00 gave 0.4; the other 106 gave 0.5.
#[test]
fn stencil_size_follows_pyvcad_at_200_radii() {
    const FIVE: [f64; 94] = [
        0.25, 0.35, 0.45, 0.5, 0.7, 0.75, 0.85, 0.9, 1.0, 1.15, 1.35, 1.4, 1.5, 1.55, 1.65, 1.7,
        1.8, 1.85, 2.0, 2.15, 2.3, 2.45, 2.7, 2.75, 2.8, 3.0, 3.05, 3.1, 3.3, 3.35, 3.4, 3.6, 3.65,
        3.7, 3.95, 4.0, 4.05, 4.25, 4.3, 4.35, 4.55, 4.6, 4.65, 4.85, 4.9, 4.95, 5.35, 5.4, 5.45,
        5.5, 5.55, 5.6, 5.95, 6.0, 6.05, 6.1, 6.15, 6.2, 6.6, 6.65, 6.7, 6.75, 6.8, 6.85, 7.2,
        7.25, 7.3, 7.35, 7.4, 7.45, 7.85, 7.9, 7.95, 8.0, 8.05, 8.1, 8.45, 8.5, 8.55, 8.6, 8.65,
        8.7, 9.1, 9.15, 9.2, 9.25, 9.3, 9.35, 9.7, 9.75, 9.8, 9.85, 9.9, 9.95,
    ];
    for k in 1..=200 {
        let r: f64 = format!("{:.2}", k as f64 * 0.05).parse().unwrap();
        let m = model(&format!(
            "Blend({r:?}, FGrade([\"x>-0.000001\", \"x<=-0.000001\"], [3, 1], false, RectPrism(Vec3(0,0,0), Vec3(400,400,400), 1)))"
        ));
        let want = if FIVE.contains(&r) { 0.4 } else { 0.5 };
        let got = frac(&m, [0.0, 0.0, 0.0], 3);
        assert!(
            (got - want).abs() < 1e-12,
            "r = {r}: ours {got}, pyvcad {want}"
        );
    }
}

/// Near a sphere's surface only the stencil points inside count; a
/// diagonal interface checks the y and z offsets.
#[test]
fn sphere_and_oblique_interface_match_pyvcad() {
    let grade = "FGrade([\"x>0\", \"x<=0\"], [3, 1], false, Sphere(Vec3(0,0,0), 10.0, 1))";
    // (r, point, blue fraction) from pyvcad 2.3.4.
    // (Points outside the child, where pyvcad still reports fractions, are
    // left out: ours has fractions only inside the part.)
    let measured: [(f64, [f64; 3], f64); 10] = [
        (4.0, [0.0, 9.5, 0.0], 0.40541),
        (4.0, [-1.0, 9.7, 0.5], 0.21739),
        (4.0, [0.5, 0.0, 0.0], 0.4),
        (4.0, [3.0, -8.0, 4.5], 0.78182),
        (5.0, [-1.0, 9.7, 0.5], 0.35165),
        (5.0, [3.0, -8.0, 4.5], 0.58333),
        (2.35, [-1.0, 9.7, 0.5], 0.33962),
        (2.35, [0.5, 0.0, 0.0], 0.66667),
        (2.35, [9.5, 0.0, 0.0], 1.0),
        (2.35, [3.0, -8.0, 4.5], 1.0),
    ];
    for (r, p, blue) in measured {
        let m = model(&format!("Blend({r:?}, {grade})"));
        let got = frac(&m, p, 3);
        assert!(
            (got - blue).abs() < 1e-5,
            "r = {r} at {p:?}: ours {got}, pyvcad {blue}"
        );
    }
    let oblique = model(
        "Blend(5.0, FGrade([\"x+2*y-0.5*z>0\", \"x+2*y-0.5*z<=0\"], [3, 1], false, RectPrism(Vec3(0,0,0), Vec3(40,40,40), 1)))",
    );
    let measured = [
        ([-3.1, 1.2, 0.7], 0.4583333),
        ([0.3, -0.4, 2.2], 0.4166667),
        ([2.5, -1.0, -4.0], 0.5833333),
        ([-6.0, 2.0, 1.0], 0.375),
    ];
    for (p, blue) in measured {
        let got = frac(&oblique, p, 3);
        assert!(
            (got - blue).abs() < 1e-6,
            "{p:?}: ours {got}, pyvcad {blue}"
        );
    }
}
