//! Scalar -> fractions through an inverted mix table, on small designs
//! with known answers.

use glam::DVec3;

use super::tests::{model, try_model};
use crate::Model;
use crate::model::Points;

/// The fraction of material `name` at p.
fn frac(m: &Model, name: &str, p: [f64; 3]) -> f64 {
    let id = m.table().id(name).unwrap();
    let (d, pairs) = m.eval_point(DVec3::from_array(p));
    assert!(d <= 0.0, "{p:?} is outside");
    pairs
        .iter()
        .find(|(i, _)| *i == id)
        .map_or(0.0, |(_, f)| *f)
}

/// A 20 mm bar along x (x in −10..10) whose hardness rises 30 + 4(x + 10)
/// from 30 to 110, converted by `table` to a red/blue mix.
fn bar(table: &str) -> String {
    format!(
        "let b = RectPrism(Vec3(0, 0, 0), Vec3(20, 4, 4), m.id(\"gray\"));
         b.set_attribute(\"hardness\", \"30 + 4 * (x + 10)\");
         Convert(b, \"hardness\", fractions([m.id(\"red\"), m.id(\"blue\")]), {table})"
    )
}

#[test]
fn two_rows_give_the_linear_mix() {
    let m = model(&bar("[[0.0, 30.0], [1.0, 90.0]]"));
    // Hardness 30 + 4·(x + 10): at x = −2.5 it is 60, half way.
    assert!((frac(&m, "blue", [-2.5, 0.0, 0.0]) - 0.5).abs() < 1e-12);
    assert!((frac(&m, "red", [-2.5, 0.0, 0.0]) - 0.5).abs() < 1e-12);
    // At x = −7 it is 42: share (42 − 30)/60 = 0.2.
    assert!((frac(&m, "blue", [-7.0, 0.0, 0.0]) - 0.2).abs() < 1e-12);
    // The child's own material is replaced.
    assert_eq!(frac(&m, "gray", [-7.0, 0.0, 0.0]), 0.0);
    assert!(m.attribute_warnings().is_empty());
}

#[test]
fn a_kink_and_clamping_with_its_count() {
    // Shares 0, 0.5, 1 measure 30, 50, 90.
    let m = model(&bar("[[0.0, 30.0], [0.5, 50.0], [1.0, 90.0]]"));
    // x = −7.5: hardness 40, a quarter of the way.
    assert!((frac(&m, "blue", [-7.5, 0.0, 0.0]) - 0.25).abs() < 1e-12);
    // x = 0: hardness 70, half way along the second segment.
    assert!((frac(&m, "blue", [0.0, 0.0, 0.0]) - 0.75).abs() < 1e-12);
    assert!(m.attribute_warnings().is_empty());
    // x = 6 and 9: hardness 94 and 106, above the table: pure blue, counted.
    assert_eq!(frac(&m, "blue", [6.0, 0.0, 0.0]), 1.0);
    assert_eq!(frac(&m, "blue", [9.0, 0.0, 0.0]), 1.0);
    let w = m.attribute_warnings();
    assert_eq!(w.len(), 1, "{w:?}");
    assert!(w[0].contains("2 samples of \"hardness\""), "{w:?}");
    assert!(w[0].contains("30..90"), "{w:?}");
}

#[test]
fn batch_equals_single_point() {
    let m = model(&bar("[[0.0, 30.0], [0.4, 50.0], [1.0, 90.0]]"));
    let xs: Vec<f64> = (0..41).map(|i| -10.5 + 0.5 * f64::from(i)).collect();
    let (ys, zs) = (vec![0.3; xs.len()], vec![-0.2; xs.len()]);
    let pts = Points {
        x: &xs,
        y: &ys,
        z: &zs,
    };
    let k = m.materials().len();
    let mut dist = vec![0.0; xs.len()];
    let mut fr = vec![0.0f32; xs.len() * k];
    m.eval_batch(pts, &mut dist, &mut fr);
    for (i, x) in xs.iter().enumerate() {
        let mut one = vec![0.0; k];
        let d = m.eval_into(DVec3::new(*x, 0.3, -0.2), &mut one);
        assert_eq!(d, dist[i]);
        for (a, b) in one.iter().zip(&fr[i * k..(i + 1) * k]) {
            assert_eq!(*a as f32, *b);
        }
    }
}

#[test]
fn the_outermost_fractions_win() {
    // The conversion replaces an FGrade below it...
    let m = model(
        "let b = FGrade([\"1\"], [m.id(\"green\")], true, RectPrism(Vec3(0, 0, 0), Vec3(20, 4, 4), m.id(\"gray\")));
         b.set_attribute(\"hardness\", 60.0);
         Convert(b, \"hardness\", fractions([m.id(\"red\"), m.id(\"blue\")]), [[0.0, 30.0], [1.0, 90.0]])",
    );
    assert!((frac(&m, "blue", [0.0, 0.0, 0.0]) - 0.5).abs() < 1e-12);
    assert_eq!(frac(&m, "green", [0.0, 0.0, 0.0]), 0.0);
    // ...and an FGrade over it replaces its mix.
    let m = model(&format!(
        "let c = {{ {} }}; FGrade([\"1\"], [m.id(\"green\")], true, c)",
        bar("[[0.0, 30.0], [1.0, 90.0]]")
    ));
    assert_eq!(frac(&m, "green", [0.0, 0.0, 0.0]), 1.0);
    assert_eq!(frac(&m, "blue", [0.0, 0.0, 0.0]), 0.0);
}

#[test]
fn where_the_attribute_is_missing_the_child_keeps_its_fractions() {
    let m = model(
        "let a = Sphere(Vec3(-5, 0, 0), 3.0, m.id(\"gray\"));
         a.set_attribute(\"hardness\", 90.0);
         let b = Sphere(Vec3(5, 0, 0), 3.0, m.id(\"green\"));
         Convert(Union(false, [a, b]), \"hardness\", fractions([m.id(\"red\"), m.id(\"blue\")]), [[0.0, 30.0], [1.0, 90.0]])",
    );
    assert_eq!(frac(&m, "blue", [-5.0, 0.0, 0.0]), 1.0);
    assert_eq!(frac(&m, "green", [5.0, 0.0, 0.0]), 1.0);
}

#[test]
fn a_table_that_turns_back_is_an_error_at_the_line() {
    let e = try_model(&bar("[[0.0, 30.0], [0.4, 60.0], [0.7, 55.0], [1.0, 90.0]]")).unwrap_err();
    assert!(e.contains("rows 2 and 3 (values 60 then 55)"), "{e}");
    assert!(e.contains("t.rhai:4:"), "{e}");
}

#[test]
fn bad_conversions_are_refused() {
    let e = try_model(
        "let b = RectPrism(Vec3(0, 0, 0), Vec3(20, 4, 4), m.id(\"gray\"));
         b.set_attribute(\"modulus\", 5.0);
         Convert(b, \"hardness\", fractions([m.id(\"red\"), m.id(\"blue\")]), [[0.0, 30.0], [1.0, 90.0]])",
    )
    .unwrap_err();
    assert!(e.contains("no node below it sets \"hardness\""), "{e}");
    assert!(e.contains("modulus"), "{e}");
    let e = try_model(
        "let b = RectPrism(Vec3(0, 0, 0), Vec3(20, 4, 4), m.id(\"gray\"));
         b.set_attribute(\"color\", Vec4(1, 0, 0, 1));
         Convert(b, \"color\", fractions([m.id(\"red\"), m.id(\"blue\")]), [[0.0, 30.0], [1.0, 90.0]])",
    )
    .unwrap_err();
    assert!(e.contains("a Vec4"), "{e}");
    let e = try_model(&bar("[[0.0, 30.0]]")).unwrap_err();
    assert!(e.contains("at least 2"), "{e}");
    let e = try_model("fractions([m.id(\"red\")])").unwrap_err();
    assert!(e.contains("mixes 2 to 16 materials, got 1"), "{e}");
    let e = try_model("fractions([m.id(\"red\"), m.id(\"blue\"), m.id(\"red\")])").unwrap_err();
    assert!(e.contains("named twice"), "{e}");
    let e = try_model(&bar("\"mix.txt\"")).unwrap_err();
    assert!(e.contains(".csv"), "{e}");
}

/// Random boxes over `m`: where the fraction bounds are given, every
/// inside sample lies within them, and where the fractions are called
/// constant, every inside sample has the same; returns how many boxes were
/// bounded and how many called constant.
fn bounds_hold(m: &Model, seed: u64) -> (usize, usize) {
    use crate::interval::Interval;
    let k = m.materials().len();
    let bb = m.bbox();
    let mut g = crate::xorshift::XorShift::new(seed);
    let mut r = || g.next_f64();
    let (mut bounded, mut constant) = (0, 0);
    let mut iv = vec![Interval::point(0.0); k];
    for n in 0..600 {
        let c = bb.min + bb.size() * DVec3::new(r(), r(), r());
        let h = DVec3::new(r(), r(), r()) * [0.05, 0.5, 3.0][n % 3];
        let b = crate::aabb::Aabb::new(c - h, c + h);
        let has = m.fraction_bounds(&b, &mut iv);
        let same = m.constant_fractions(&b);
        bounded += usize::from(has);
        constant += usize::from(same);
        let mut first: Option<Vec<f64>> = None;
        for _ in 0..40 {
            let p = b.min + b.size() * DVec3::new(r(), r(), r());
            let mut f = vec![0.0; k];
            if m.eval_into(p, &mut f) > 0.0 {
                continue;
            }
            if has {
                for (i, (b, v)) in iv.iter().zip(&f).enumerate() {
                    assert!(
                        b.lo - 1e-9 <= *v && *v <= b.hi + 1e-9,
                        "fraction {i} = {v} outside {b:?} at {p}"
                    );
                }
            }
            if same {
                let f0 = first.get_or_insert_with(|| f.clone());
                for (a, b) in f0.iter().zip(&f) {
                    assert!((a - b).abs() < 1e-12, "not constant at {p}: {f0:?} {f:?}");
                }
            }
        }
    }
    (bounded, constant)
}

#[test]
fn fraction_bounds_of_a_conversion_contain_every_sample() {
    let falling = "let b = Translate(3.0, 0.0, 1.0, Rotate(0.0, 30.0, 0.0, Vec3(0, 0, 0), RectPrism(Vec3(0, 0, 0), Vec3(20, 4, 4), m.id(\"gray\"))));
         b.set_attribute(\"shore_hardness\", \"60 + 20 * sin(x / 3)\");
         Convert(b, \"shore_hardness\", fractions([m.id(\"red\"), m.id(\"blue\")]), [[0.0, 85.0], [0.3, 70.0], [1.0, 45.0]])";
    let designs = [
        bar("[[0.0, 30.0], [1.0, 90.0]]"),
        bar("[[0.0, 30.0], [0.5, 50.0], [1.0, 90.0]]"),
        falling.to_owned(),
        // Only one child sets it: the other keeps its own material.
        "let a = Sphere(Vec3(-3, 0, 0), 4.0, m.id(\"gray\"));
         a.set_attribute(\"hardness\", \"50 + 5 * x\");
         let b = Sphere(Vec3(4, 0, 0), 4.0, m.id(\"green\"));
         Convert(Union(false, [a, b]), \"hardness\", fractions([m.id(\"red\"), m.id(\"blue\")]), [[0.0, 30.0], [1.0, 90.0]])".to_owned(),
        // NaN where x < 0 (sqrt): those points keep the child's fractions.
        "let b = RectPrism(Vec3(0, 0, 0), Vec3(20, 4, 4), m.id(\"gray\"));
         b.set_attribute(\"hardness\", \"30 + 10 * sqrt(x)\");
         Convert(b, \"hardness\", fractions([m.id(\"red\"), m.id(\"blue\")]), [[0.0, 30.0], [1.0, 90.0]])".to_owned(),
    ];
    for src in &designs {
        let m = model(src);
        let (bounded, _) = bounds_hold(&m, 11);
        assert!(bounded > 300, "{src}: {bounded} of 600 boxes bounded");
    }
    // A constant hardness: one mix everywhere, so boxes are constant.
    let m = model(&bar("[[0.0, 30.0], [1.0, 90.0]]").replace("\"30 + 4 * (x + 10)\"", "75.0"));
    let (bounded, constant) = bounds_hold(&m, 12);
    assert_eq!((bounded, constant), (600, 600));
}

#[test]
fn bounds_of_a_graded_conversion_decide_small_boxes() {
    // The bar's hardness 30 + 4(x + 10) over x in [−2.5, −2.4]: 60 to
    // 60.4, shares 0.5 to 0.50667 of blue.
    let m = model(&bar("[[0.0, 30.0], [1.0, 90.0]]"));
    let b = crate::aabb::Aabb::new(DVec3::new(-2.5, -1.0, -1.0), DVec3::new(-2.4, 1.0, 1.0));
    let k = m.materials().len();
    let mut iv = vec![crate::interval::Interval::point(0.0); k];
    assert!(m.fraction_bounds(&b, &mut iv));
    let blue = m
        .materials()
        .iter()
        .position(|&i| i == m.table().id("blue").unwrap())
        .unwrap();
    assert!((iv[blue].lo - 0.5).abs() < 1e-9, "{:?}", iv[blue]);
    assert!((iv[blue].hi - 30.4 / 60.0).abs() < 1e-9, "{:?}", iv[blue]);
    assert!(!m.constant_fractions(&b));
}

/// The bar of [`bar`] mixing red, green and blue along the path `table`.
fn bar3(table: &str) -> String {
    bar(table).replace(
        "fractions([m.id(\"red\"), m.id(\"blue\")])",
        "fractions([m.id(\"red\"), m.id(\"green\"), m.id(\"blue\")])",
    )
}

/// Red to green (30 to 60), then green to an even green-blue (60 to 90).
const PATH3: &str = "[[1, 0, 0, 30], [0, 1, 0, 60], [0, 0.5, 0.5, 90]]";

#[test]
fn three_materials_follow_the_path_of_the_rows() {
    let m = model(&bar3(PATH3));
    // Hardness 30 + 4(x + 10): x = −6.25 gives 45, half way to green.
    let at = |x: f64| ["red", "green", "blue"].map(|n| frac(&m, n, [x, 0.0, 0.0]));
    let close = |a: [f64; 3], b: [f64; 3]| a.iter().zip(&b).all(|(p, q)| (p - q).abs() < 1e-12);
    assert!(close(at(-6.25), [0.5, 0.5, 0.0]), "{:?}", at(-6.25));
    // x = 0: 70, a third of the way from green to the green-blue row.
    assert!(
        close(at(0.0), [0.0, 1.0 - 0.5 / 3.0, 0.5 / 3.0]),
        "{:?}",
        at(0.0)
    );
    // x = 9: 106, past the last row: its mix, counted (`at` evaluates
    // the point once per material).
    assert!(m.attribute_warnings().is_empty());
    assert!(close(at(9.0), [0.0, 0.5, 0.5]), "{:?}", at(9.0));
    let w = m.attribute_warnings();
    assert!(
        w[0].contains("3 samples") && w[0].contains("30..90"),
        "{w:?}"
    );
    let sum: f64 = at(-3.3).iter().sum();
    assert!((sum - 1.0).abs() < 1e-12);
    // A falling path is read the other way; a CSV gives the same rows.
    let f = model(&bar3("[[0, 0.5, 0.5, 90], [0, 1, 0, 60], [1, 0, 0, 30]]"));
    for x in [-9.0, -6.25, 0.0, 4.0] {
        let g = ["red", "green", "blue"].map(|n| frac(&f, n, [x, 0.0, 0.0]));
        assert!(close(g, at(x)), "{x}: {g:?} {:?}", at(x));
    }
    let t = super::MixTable::parse_csv_path(
        "# illustrative\nred,green,blue,shore\n1,0,0,30\n0,1,0,60\n0,0.5,0.5,90\n",
        3,
        "p.csv",
    )
    .unwrap();
    let mut mix = [0.0; 3];
    assert!(!t.mix(45.0, |i, v| mix[i] += v));
    assert_eq!(mix, [0.5, 0.5, 0.0]);
    assert_eq!(t.materials(), 3);
}

#[test]
fn three_material_bounds_contain_every_sample() {
    for src in [
        bar3(PATH3),
        bar3("[[0.2, 0.3, 0.5, 20], [1, 0, 0, 50], [0, 0, 1, 55], [0, 1, 0, 120]]"),
    ] {
        let m = model(&src);
        let (bounded, _) = bounds_hold(&m, 13);
        assert!(bounded > 300, "{src}: {bounded} of 600 boxes bounded");
    }
    let m = model(&bar3(PATH3).replace("\"30 + 4 * (x + 10)\"", "70.0"));
    assert_eq!(bounds_hold(&m, 14), (600, 600));
}

#[test]
fn bad_three_material_tables_are_refused() {
    for (table, says) in [
        ("[[1, 0, 0, 30], [0, 1, 0.2, 60]]", "add up to 1.2"),
        ("[[1, 0, 0, 30], [1.5, -0.5, 0, 60]]", "the fraction -0.5"),
        (
            "[[1, 0, 0, 30], [0, 1, 60]]",
            "table row 2 must be [the 3 materials' fractions, then the value]",
        ),
        (
            "[[1, 0, 0, 30], [0, 1, 0, 60], [0, 0, 1, 50]]",
            "rows 2 and 3 (values 60 then 50)",
        ),
        ("[[1, 0, 0, 30]]", "at least 2 rows"),
    ] {
        let e = try_model(&bar3(table)).unwrap_err();
        assert!(e.contains(says), "{table}: {e}");
        assert!(e.contains("t.rhai:4:"), "{e}");
    }
    let e = super::MixTable::parse_csv_path("a,b,c,v\n1,0,0,30\n0,1,0\n", 3, "p.csv").unwrap_err();
    assert!(e.contains("p.csv:3: expected 4 numbers"), "{e}");
}
