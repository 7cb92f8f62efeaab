//! Attribute rules on small designs with known answers.

use glam::DVec3;

use crate::Model;
use crate::aabb::Aabb;
use crate::model::Points;
use crate::script::{ScriptOptions, model_of};

pub(super) fn try_model(src: &str) -> Result<Model, String> {
    let src = format!("let m = default_materials();\n{src}");
    model_of(&src, "t.rhai", &ScriptOptions::default()).map_err(|e| e.to_string())
}

pub(super) fn model(src: &str) -> Model {
    try_model(src).unwrap_or_else(|e| panic!("{e}"))
}

/// Scalar attribute `name` at p.
fn at(m: &Model, name: &str, p: [f64; 3]) -> f64 {
    let i = m.attribute_index(name).expect("attribute");
    let mut o = [0.0];
    m.attribute_at(i, DVec3::from_array(p), &mut o).unwrap();
    o[0]
}

#[test]
fn constant_on_a_leaf_inside_only() {
    let m = model(
        "let s = Sphere(Vec3(0, 0, 0), 5.0, m.id(\"red\")); s.set_attribute(\"modulus\", 2850.0); s",
    );
    assert_eq!(m.attributes().len(), 1);
    assert_eq!(m.attributes()[0].name, "modulus");
    assert_eq!(at(&m, "modulus", [1.0, 0.0, 0.0]), 2850.0);
    assert!(at(&m, "modulus", [6.0, 0.0, 0.0]).is_nan());
}

#[test]
fn no_attributes_no_evaluator() {
    let m = model("Sphere(Vec3(0, 0, 0), 5.0, m.id(\"red\"))");
    assert!(m.attributes().is_empty());
    assert!(m.attrs.is_none());
    assert!(
        m.require_attribute("modulus")
            .unwrap_err()
            .message
            .contains("none")
    );
}

#[test]
fn math_string_in_local_frame_and_other_attributes() {
    // The sphere is moved by 10 in x: x is the sphere's own frame.
    let m = model(
        "let s = Sphere(Vec3(0, 0, 0), 5.0, m.id(\"red\"));
         s.set_attribute(\"temperature\", \"20 + x\");
         s.set_attribute(\"infill_density\", \"temperature * 2\");
         Translate(10.0, 0.0, 0.0, s)",
    );
    assert_eq!(at(&m, "temperature", [12.0, 0.0, 0.0]), 22.0);
    assert_eq!(at(&m, "infill_density", [12.0, 0.0, 0.0]), 44.0);
    // d is the node's signed distance.
    let m = model(
        "let s = Sphere(Vec3(0, 0, 0), 5.0, m.id(\"red\")); s.set_attribute(\"depth\", \"-d\"); s",
    );
    assert!((at(&m, "depth", [1.0, 0.0, 0.0]) - 4.0).abs() < 1e-12);
}

#[test]
fn vectors_and_batch_equals_single() {
    let m = model(
        "let s = RectPrism(Vec3(0, 0, 0), Vec3(10, 10, 10), m.id(\"red\"));
         s.set_attribute(\"color\", [\"x/10 + 0.5\", 0.2, \"clamp(0, y/10 + 0.5, 1)\", 1.0]);
         s.set_attribute(\"dir\", Vec3(1, 2, 3));
         s",
    );
    let c = m.attribute_index("color").unwrap();
    let xs: Vec<f64> = (0..50).map(|i| -6.0 + 0.25 * i as f64).collect();
    let ys: Vec<f64> = xs.iter().map(|x| x * 0.5).collect();
    let zs = vec![0.0; xs.len()];
    let pts = Points {
        x: &xs,
        y: &ys,
        z: &zs,
    };
    let mut batch = vec![0.0; 4 * xs.len()];
    m.attribute_batch(c, pts, &mut batch).unwrap();
    for i in 0..xs.len() {
        let mut one = [0.0; 4];
        m.attribute_at(c, pts.get(i), &mut one).unwrap();
        for k in 0..4 {
            assert!(one[k] == batch[4 * i + k] || (one[k].is_nan() && batch[4 * i + k].is_nan()));
        }
    }
    let mut one = [0.0; 4];
    m.attribute_at(c, DVec3::new(2.0, 0.0, 0.0), &mut one)
        .unwrap();
    assert_eq!(one, [0.7, 0.2, 0.5, 1.0]);
    let d = m.attribute_index("dir").unwrap();
    let mut v = [0.0; 3];
    m.attribute_at(d, DVec3::ZERO, &mut v).unwrap();
    assert_eq!(v, [1.0, 2.0, 3.0]);
    // A buffer of the wrong length is an error, not a panic.
    assert!(m.attribute_at(d, DVec3::ZERO, &mut [0.0; 2]).is_err());
    assert!(m.attribute_at(9, DVec3::ZERO, &mut [0.0; 1]).is_err());
}

/// Two overlapping balls, a (modulus 10) at x = 0 and b (modulus 20) at
/// x = 6, radius 5: the overlap is 1 < x < 5.
const TWO: &str =
    "let a = Sphere(Vec3(0, 0, 0), 5.0, m.id(\"red\")); a.set_attribute(\"modulus\", 10.0);
     let b = Sphere(Vec3(6, 0, 0), 5.0, m.id(\"blue\")); b.set_attribute(\"modulus\", 20.0);";

#[test]
fn overlaps_first_child_wins_unless_a_resolver() {
    let m = model(&format!("{TWO} Union(false, [a, b])"));
    assert_eq!(at(&m, "modulus", [-2.0, 0.0, 0.0]), 10.0);
    assert_eq!(at(&m, "modulus", [3.0, 0.0, 0.0]), 10.0);
    assert_eq!(at(&m, "modulus", [8.0, 0.0, 0.0]), 20.0);
    let m = model(&format!("{TWO} Union(false, [b, a])"));
    assert_eq!(at(&m, "modulus", [3.0, 0.0, 0.0]), 20.0);
    for (r, want) in [
        ("average", 15.0),
        ("min", 10.0),
        ("max", 20.0),
        ("sum", 30.0),
        ("a*0.25+b", 22.5),
    ] {
        let m = model(&format!(
            "{TWO} let u = Union(false, [a, b]); u.set_attribute_conflict_resolver(\"modulus\", \"{r}\"); u"
        ));
        assert_eq!(at(&m, "modulus", [3.0, 0.0, 0.0]), want, "{r}");
        // Outside the overlap only one child holds the point.
        assert_eq!(at(&m, "modulus", [-2.0, 0.0, 0.0]), 10.0, "{r}");
    }
    // Intersection: every inside point is in both.
    let m = model(&format!("{TWO} let i = Intersection(false, [b, a]); i"));
    assert_eq!(at(&m, "modulus", [3.0, 0.0, 0.0]), 20.0);
}

#[test]
fn parent_overrides_and_children_inherit() {
    // The parent Union sets modulus: it overrides a's and b's. A third
    // ball without one inherits the parent's density; b's own density is
    // overridden too.
    let m = model(&format!(
        "{TWO} b.set_attribute(\"density\", 1.0);
         let c = Sphere(Vec3(0, 20, 0), 2.0, m.id(\"red\"));
         let u = Union(false, [a, b, c]);
         u.set_attribute(\"density\", 1.2);
         let top = Union(false, [u]); top.set_attribute(\"modulus\", 99.0); top"
    ));
    assert_eq!(at(&m, "modulus", [-2.0, 0.0, 0.0]), 99.0);
    assert_eq!(at(&m, "modulus", [0.0, 20.0, 0.0]), 99.0);
    assert_eq!(at(&m, "density", [0.0, 20.0, 0.0]), 1.2);
    assert_eq!(at(&m, "density", [8.0, 0.0, 0.0]), 1.2);
    // A part that sets nothing while its sibling does: NaN there.
    let m = model(&format!(
        "{TWO} let c = Sphere(Vec3(0, 20, 0), 2.0, m.id(\"red\")); Union(false, [a, c])"
    ));
    assert!(at(&m, "modulus", [0.0, 20.0, 0.0]).is_nan());
    // A Difference keeps the left side's attributes.
    let m = model(&format!("{TWO} Difference(a, b)"));
    assert_eq!(at(&m, "modulus", [-2.0, 0.0, 0.0]), 10.0);
    assert!(at(&m, "modulus", [3.0, 0.0, 0.0]).is_nan());
}

#[test]
fn smooth_union_blends_by_the_distance_weight() {
    let m = model(&format!("{TWO} Union(1.0, false, [a, b])"));
    // Midway both distances are equal: h = ½.
    assert!((at(&m, "modulus", [3.0, 0.0, 0.0]) - 15.0).abs() < 1e-12);
    // At x = 2.5: d_a = −2.5, d_b = −1.5, h = ½ + ½·1/4 = 0.625.
    let v = 0.625 * 10.0 + 0.375 * 20.0;
    assert!((at(&m, "modulus", [2.5, 0.0, 0.0]) - v).abs() < 1e-12);
    // Far from the seam (|d_a − d_b| ≥ 4k) a child's own value.
    assert_eq!(at(&m, "modulus", [-3.0, 0.0, 0.0]), 10.0);
}

#[test]
fn frames_follow_moves() {
    // Rotating by 90° about z: the child's x is the world's y.
    let m = model(
        "let s = RectPrism(Vec3(0, 0, 0), Vec3(10, 10, 10), m.id(\"red\"));
         s.set_attribute(\"temperature\", \"x\");
         let r = Rotate(0.0, 0.0, 90.0, Vec3(0, 0, 0), s);
         let i = Identity(r); i.set_attribute(\"world\", \"x\"); Union(false, [i])",
    );
    assert!((at(&m, "temperature", [0.0, 3.0, 0.0]) - 3.0).abs() < 1e-9);
    assert!((at(&m, "world", [2.0, 3.0, 0.0]) - 2.0).abs() < 1e-12);
    // Tile: every cell sees the child's own frame.
    let m = model(
        "let s = Sphere(Vec3(0, 0, 0), 2.0, m.id(\"red\")); s.set_attribute(\"temperature\", \"x\");
         Intersection(false, [Tile(10.0, 10.0, 10.0, s), RectPrism(Vec3(0, 0, 0), Vec3(40, 40, 40), m.id(\"red\"))])",
    );
    assert!((at(&m, "temperature", [16.0, 5.0, 5.0]) - 1.0).abs() < 1e-9);
}

#[test]
fn interval_contains_every_sample() {
    let designs = [
        "let s = Sphere(Vec3(1, 2, 0), 6.0, m.id(\"red\")); s.set_attribute(\"t\", \"x*x - 3*y + sin(z) + d\"); s",
        &format!(
            "{TWO} let u = Union(false, [a, b]); u.set_attribute_conflict_resolver(\"modulus\", \"a*0.3+b*b\"); u.set_attribute(\"w\", 1.0); Union(false, [Translate(1.0, 2.0, 3.0, u)])"
        ),
        &format!(
            "{TWO} b.set_attribute(\"modulus\", \"20 + abs(x*y)\"); Union(2.0, false, [a, Rotate(10.0, 20.0, 30.0, Vec3(1, 1, 1), b)])"
        ),
        "let s = RectPrism(Vec3(0, 0, 0), Vec3(8, 8, 8), m.id(\"red\")); s.set_attribute(\"p\", \"rho + theta\"); s.set_attribute(\"q\", \"p*2 - phis\"); s",
    ];
    let mut g = crate::xorshift::XorShift::new(7);
    let mut rng = |lo: f64, hi: f64| lo + (hi - lo) * g.next_f64();
    for src in designs {
        let m = model(src);
        for (idx, _) in m.attributes().iter().enumerate() {
            for _ in 0..60 {
                let c = DVec3::new(rng(-8.0, 10.0), rng(-8.0, 8.0), rng(-8.0, 8.0));
                let h = DVec3::new(rng(0.1, 4.0), rng(0.1, 4.0), rng(0.1, 4.0));
                let b = Aabb::new(c - h, c + h);
                let iv = m.attribute_interval(idx, &b);
                for _ in 0..40 {
                    let p = DVec3::new(
                        rng(b.min.x, b.max.x),
                        rng(b.min.y, b.max.y),
                        rng(b.min.z, b.max.z),
                    );
                    let mut o = [0.0];
                    m.attribute_at(idx, p, &mut o).unwrap();
                    if o[0].is_nan() {
                        continue;
                    }
                    let iv = iv.unwrap_or_else(|| panic!("{src}: no interval but {} at {p}", o[0]));
                    assert!(
                        iv.lo - 1e-9 <= o[0] && o[0] <= iv.hi + 1e-9,
                        "{src}: {} outside {iv:?} at {p}",
                        o[0]
                    );
                }
            }
        }
    }
}

#[test]
fn bad_input_is_refused_with_where_and_what() {
    // Type of a common name, at the line.
    let e = try_model(
        "let s = Sphere(Vec3(0, 0, 0), 5.0, m.id(\"red\")); s.set_attribute(\"color\", 3); s",
    )
    .unwrap_err();
    assert!(e.contains("t.rhai:2:") && e.contains("Vec4"), "{e}");
    // One name, two types.
    let e = try_model(
        "let a = Sphere(Vec3(0, 0, 0), 5.0, m.id(\"red\")); a.set_attribute(\"k\", 3);
         let b = Sphere(Vec3(9, 0, 0), 5.0, m.id(\"red\")); b.set_attribute(\"k\", Vec3(1, 2, 3));
         Union(false, [a, b])",
    )
    .unwrap_err();
    assert!(e.contains("one type") && e.contains("line 3"), "{e}");
    // A constant out of range at the call.
    let e = try_model("let s = Sphere(Vec3(0, 0, 0), 5.0, m.id(\"red\")); s.set_attribute(\"infill_density\", 120); s")
        .unwrap_err();
    assert!(e.contains("t.rhai:2:") && e.contains("0..100"), "{e}");
    // A cycle.
    let e = try_model(
        "let s = Sphere(Vec3(0, 0, 0), 5.0, m.id(\"red\")); s.set_attribute(\"p\", \"q+1\"); s.set_attribute(\"q\", \"p*2\"); s",
    )
    .unwrap_err();
    assert!(e.contains("cycle") && e.contains("p -> q -> p"), "{e}");
    // A resolver for a name nobody sets lists those present.
    let e = try_model(&format!(
        "{TWO} let u = Union(false, [a, b]); u.set_attribute_conflict_resolver(\"hardness\", \"max\"); u"
    ))
    .unwrap_err();
    assert!(e.contains("hardness") && e.contains("modulus"), "{e}");
    // A math string error names the call.
    let e = try_model(
        "let s = Sphere(Vec3(0, 0, 0), 5.0, m.id(\"red\")); s.set_attribute(\"t\", \"x +* 2\"); s",
    )
    .unwrap_err();
    assert!(e.contains("set_attribute at line 2"), "{e}");
    // Out of range at a sample: node, point and value.
    let m = model(
        "let s = Sphere(Vec3(0, 0, 0), 5.0, m.id(\"red\")); s.set_attribute(\"modulus\", \"x*100\"); s",
    );
    let mut o = [0.0];
    let e = m
        .attribute_at(0, DVec3::new(-1.0, 0.0, 0.0), &mut o)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("Sphere") && e.contains("-100") && e.contains("(-1, 0, 0)"),
        "{e}"
    );
}

#[test]
fn data_from_a_simulation_field_column() {
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path();
    std::fs::write(
        dir.join("t.inp"),
        "*NODE\n1, 0, 0, 0\n2, 10, 0, 0\n3, 0, 10, 0\n4, 0, 0, 10\n*ELEMENT, TYPE=C3D4\n1, 1, 2, 3, 4\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("t.csv"),
        "node_id,x,y,z,e\n1,0,0,0,100\n2,10,0,0,200\n3,0,10,0,100\n4,0,0,10,100\n",
    )
    .unwrap();
    let opts = ScriptOptions::for_file(&dir.join("t.rhai"));
    let src = "let m = default_materials(); let f = SimulationField(\"t.inp\", \"t.csv\", [\"1\"], [m.id(\"red\")]);
               let s = Sphere(Vec3(2, 2, 2), 1.5, m.id(\"red\")); s.set_attribute(\"modulus\", f, \"e\"); s";
    let m = model_of(src, "t.rhai", &opts).unwrap();
    assert!((at(&m, "modulus", [2.0, 2.0, 2.0]) - 120.0).abs() < 1e-9);
    let e = model_of(&src.replace("\"e\"", "\"E2\""), "t.rhai", &opts)
        .unwrap_err()
        .to_string();
    assert!(e.contains("no column \"E2\""), "{e}");
}

#[test]
fn convert_by_table_and_by_math_string() {
    let part = "let s = RectPrism(Vec3(0, 0, 0), Vec3(40, 4, 4), m.id(\"red\"));
                s.set_attribute(\"shore_hardness\", \"60 + x\");";
    let m = model(&format!(
        "{part} Convert(s, \"shore_hardness\", \"modulus\", [[30, 1.0], [50, 3.0], [70, 13.0]])"
    ));
    // x = −5: hardness 55, halfway from 50 to 70 is a quarter: 3 + 10/4.
    assert!((at(&m, "modulus", [-5.0, 0.0, 0.0]) - 5.5).abs() < 1e-12);
    assert!(m.attribute_warnings().is_empty());
    // x = 15: hardness 75, past the table's end: clamped, counted.
    assert_eq!(at(&m, "modulus", [15.0, 0.0, 0.0]), 13.0);
    assert_eq!(at(&m, "shore_hardness", [15.0, 0.0, 0.0]), 75.0);
    let w = m.attribute_warnings();
    assert!(
        w.len() == 1 && w[0].contains("1 samples") && w[0].contains("30..70"),
        "{w:?}"
    );
    let m = model(&format!(
        "{part} Convert(s, \"shore_hardness\", \"modulus\", \"exp(0.0235*shore_hardness - 0.6403)\")"
    ));
    let want = (0.0235f64 * 62.0 - 0.6403).exp();
    assert!((at(&m, "modulus", [2.0, 0.0, 0.0]) - want).abs() < 1e-12);
    // Its interval holds every sample.
    let i = m.attribute_index("modulus").unwrap();
    let iv = m
        .attribute_interval(i, &Aabb::new(DVec3::splat(-3.0), DVec3::splat(3.0)))
        .unwrap();
    assert!(iv.contains(at(&m, "modulus", [2.0, 0.0, 0.0])));
}

#[test]
fn convert_refusals() {
    let part = "let s = Sphere(Vec3(0, 0, 0), 5.0, m.id(\"red\")); s.set_attribute(\"shore_hardness\", 60);";
    let e = try_model(&format!(
        "{part} Convert(s, \"shore_hardness\", \"modulus\", [[30, 1.0], [20, 3.0]])"
    ))
    .unwrap_err();
    assert!(e.contains("must rise") && e.contains("t.rhai:2:"), "{e}");
    let e = try_model(&format!(
        "{part} Convert(s, \"hardness\", \"modulus\", [[30, 1.0], [50, 3.0]])"
    ))
    .unwrap_err();
    assert!(
        e.contains("no node sets") && e.contains("shore_hardness"),
        "{e}"
    );
    // A conversion reading an attribute its own node computes from it.
    let e = try_model(&format!(
        "{part} let c = Convert(s, \"shore_hardness\", \"k\", \"shore_hardness*2\"); c.set_attribute(\"shore_hardness\", \"k/2\"); c"
    ))
    .unwrap_err();
    assert!(e.contains("cycle"), "{e}");
}

#[test]
fn convert_fractions_by_voigt_and_reuss() {
    // Half red, half blue everywhere.
    let part = "let g = FGrade([\"0.5\", \"0.5\"], [m.id(\"red\"), m.id(\"blue\")], false, Sphere(Vec3(0, 0, 0), 5.0, m.id(\"red\")));";
    let m = model(&format!(
        "{part} Convert(g, \"fractions\", \"modulus\", \"voigt\", [[m.id(\"red\"), 2000.0], [m.id(\"blue\"), 1.0]])"
    ));
    assert!((at(&m, "modulus", [1.0, 0.0, 0.0]) - 1000.5).abs() < 1e-9);
    let m = model(&format!(
        "{part} Convert(g, \"fractions\", \"modulus\", \"reuss\", [[m.id(\"red\"), 2000.0], [m.id(\"blue\"), 1.0]])"
    ));
    // 1 / (0.5/2000 + 0.5/1).
    assert!((at(&m, "modulus", [1.0, 0.0, 0.0]) - 1.0 / (0.5 / 2000.0 + 0.5)).abs() < 1e-9);
    let e = try_model(&format!(
        "{part} Convert(g, \"fractions\", \"modulus\", \"reuss\", [[m.id(\"red\"), 0.0]])"
    ))
    .unwrap_err();
    assert!(e.contains("above 0"), "{e}");
}

#[test]
fn many_children_first_wins_and_resolvers_fold_the_near_ones() {
    // 40 overlapping spheres along x (radius 1, 1.5 apart), each with its
    // index: a union that large looks its children up in a grid.
    let spheres = "let u = Union(); for i in 0..40 { let s = Sphere(Vec3(1.5 * i, 0, 0), 1.0, m.id(\"red\")); s.set_attribute(\"temperature\", 1.0 * i); u.add_child(s); }";
    let first = model(&format!("{spheres} u"));
    let most = model(&format!(
        "{spheres} u.set_attribute_conflict_resolver(\"temperature\", \"max\"); u"
    ));
    let i = first.attribute_index("temperature").unwrap();
    for k in 0..=1200 {
        let x = -1.0 + 60.0 * f64::from(k) / 1200.0;
        let p = DVec3::new(x, 0.2, 0.0);
        let holds = |j: i32| (x - 1.5 * f64::from(j)).hypot(0.2) <= 1.0;
        let (lo, hi) = (
            (0..40).find(|j| holds(*j)),
            (0..40).rev().find(|j| holds(*j)),
        );
        let (mut a, mut b, mut c) = ([0.0], [0.0], [0.0]);
        first.attribute_at(i, p, &mut a).unwrap();
        most.attribute_at(i, p, &mut b).unwrap();
        match (lo, hi) {
            (Some(lo), Some(hi)) => {
                assert_eq!(a[0], f64::from(lo), "{x}");
                assert_eq!(b[0], f64::from(hi), "{x}");
                first.attribute_inside(i, p, &mut c).unwrap();
                assert_eq!(c[0], a[0]);
            }
            _ => assert!(a[0].is_nan() && b[0].is_nan(), "{x}"),
        }
    }
}
