//! Node semantics: one test per node, pyvcad's cross-check designs
//! (measured on pyvcad 2.3.4), every deliberate fix (docs/PYVCAD.md), and the
//! soundness of interval bounds and of the large-union index.

use glam::DVec3;

use crate::Model;
use crate::aabb::Aabb;
use crate::script::{ScriptOptions, model_of, run_script};

/// `src` after `let m = default_materials();`, run and prepared (shared by
/// the model's test modules).
pub(crate) fn model(src: &str) -> Model {
    let src = format!("let m = default_materials();\n{src}");
    model_of(&src, "t.rhai", &ScriptOptions::default()).unwrap_or_else(|e| panic!("{e}"))
}

fn d(m: &Model, x: f64, y: f64, z: f64) -> f64 {
    m.distance(DVec3::new(x, y, z))
}

/// Fractions at p by material id (0 for absent).
fn frac(m: &Model, p: [f64; 3], id: u8) -> f64 {
    let (_, f) = m.eval_point(DVec3::from_array(p));
    f.iter().find(|(i, _)| *i == id).map_or(0.0, |x| x.1)
}

fn close(a: f64, b: f64, tol: f64) {
    assert!((a - b).abs() <= tol, "{a} vs {b}");
}

// ---- pyvcad 2.3.4's own values ----

#[test]
fn d1_csg_priority() {
    let m = model(
        "let u = Union(false, [Sphere(Vec3(0,0,0), 5, 1), RectPrism(Vec3(4,0,0), Vec3(6,4,4), 3)]);
         Difference(u, Cylinder(Vec3(0,0,0), 1.5, 20, 2))",
    );
    close(d(&m, 0.0, 0.0, 0.0), 1.5, 1e-12);
    close(d(&m, 3.0, 0.0, 0.0), -1.5, 1e-12);
    close(d(&m, 6.5, 1.0, 1.0), -0.5, 1e-12);
    assert_eq!(frac(&m, [3.0, 0.0, 0.0], 1), 1.0);
    assert_eq!(frac(&m, [6.5, 1.0, 1.0], 3), 1.0);
    assert_eq!(
        m.materials(),
        &[1, 2, 3],
        "pyvcad's material_list includes the subtracted green"
    );
}

#[test]
fn d2_fgrade_sees_local_coordinates() {
    let m = model(
        "let bar = RectPrism(Vec3(0,0,0), Vec3(10,4,2), 4);
         let g = FGrade([\"clamp(0, x/10 + 0.5, 1)\", \"1 - clamp(0, x/10 + 0.5, 1)\"], [1, 3], false, bar);
         Translate(5, 0, 0, g)",
    );
    close(d(&m, 5.0, 0.0, 0.0), -1.0, 1e-12);
    close(frac(&m, [5.0, 0.0, 0.0], 1), 0.5, 1e-12);
    close(frac(&m, [7.5, 1.0, 0.5], 1), 0.75, 1e-12);
    close(frac(&m, [7.5, 1.0, 0.5], 3), 0.25, 1e-12);
    close(d(&m, 11.0, 0.0, 0.0), 1.0, 1e-12);
}

#[test]
fn d3_smooth_union() {
    let m = model("Union(2.0, false, [Sphere(Vec3(-3,0,0), 3, 1), Sphere(Vec3(3,0,0), 3, 2)])");
    close(d(&m, 0.0, 0.0, 0.0), -2.0, 1e-12);
    close(d(&m, 0.0, 2.5, 0.0), -1.0948751620466721, 1e-12);
    close(d(&m, -5.0, 0.0, 0.0), -1.125, 1e-12);
    // In the fillet no child contains the point: the nearest (first on ties) wins.
    assert_eq!(frac(&m, [0.0, 2.5, 0.0], 1), 1.0);
    let b = m.bbox();
    assert_eq!(
        (b.min, b.max),
        (DVec3::new(-8.0, -5.0, -5.0), DVec3::new(8.0, 5.0, 5.0))
    );
}

/// The design lives in `assets/bench/pyvcad_bcc_box.rhai` (ids 1 and 3 are
/// red and blue), which the like-for-like throughput bench exports: one
/// text, checked here against pyvcad's values.
#[test]
fn d4_bcc_lattice_box() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../assets/bench/pyvcad_bcc_box.rhai");
    let m = crate::script::model_of_file(&path).unwrap_or_else(|e| panic!("{e}"));
    close(d(&m, 1.0, 1.0, 1.0), -0.2, 1e-7);
    close(d(&m, 0.5, 0.5, 0.5), -0.2, 1e-7);
    close(d(&m, 1.3, 1.0, 0.7), 0.044948965311050415, 1e-7);
    assert_eq!(frac(&m, [1.0, 1.0, 1.0], 1), 1.0);
}

#[test]
fn d5_shell_grade_scale() {
    let m = model(
        "let shell = Shell(-1.0, Cylinder(Vec3(0,0,0), 5, 10, 1));
         let g = FGrade([\"clamp(0, -d, 1)\", \"1 - clamp(0, -d, 1)\"], [1, 3], false, shell);
         Scale(1, 1, 2, g)",
    );
    close(d(&m, 4.5, 0.0, 0.0), -0.5, 1e-12);
    close(frac(&m, [4.5, 0.0, 0.0], 1), 0.5, 1e-12);
    // pyvcad: -0.2 with fractions 0.2 / 0.8; ours is scaled by min|s| = 1.
    close(d(&m, 0.0, 4.8, 5.0), -0.2, 1e-12);
    close(frac(&m, [0.0, 4.8, 5.0], 1), 0.2, 1e-7);
    close(d(&m, 2.0, 0.0, 0.0), 2.0, 1e-12);
}

// ---- deliberate fixes (docs/PYVCAD.md) ----

#[test]
fn rotate_geometry_and_box_agree() {
    let m = model(
        "Rotate(0, 0, 90, Vec3(0,0,0), Translate(5, 0, 0, RectPrism(Vec3(0,0,0), Vec3(10,4,2), 1)))",
    );
    let b = m.bbox();
    assert!(
        (b.min - DVec3::new(-2.0, 0.0, -1.0)).length() < 1e-9,
        "{b:?}"
    );
    assert!(
        (b.max - DVec3::new(2.0, 10.0, 1.0)).length() < 1e-9,
        "{b:?}"
    );
    // The geometry is where the box is (pyvcad puts it at -y).
    close(d(&m, 0.0, 5.0, 0.0), -1.0, 1e-9);
    assert!(d(&m, 0.0, -5.0, 0.0) > 4.0);
}

#[test]
fn scale_keeps_distances_metric() {
    let m = model("Scale(2, 2, 2, Sphere(Vec3(0,0,0), 1, 1))");
    close(d(&m, 3.0, 0.0, 0.0), 1.0, 1e-12);
    let m = model("Scale(1, 1, 3, Sphere(Vec3(0,0,0), 1, 1))");
    // A lower bound of the true distance (0.5 along x) with the right sign.
    let v = d(&m, 1.5, 0.0, 0.0);
    assert!(v > 0.0 && v <= 0.5 + 1e-12, "{v}");
    assert!(d(&m, 0.0, 0.0, 2.9) < 0.0);
}

#[test]
fn offset_and_shell_accept_both_signs() {
    let grow = model("Offset(1.0, Sphere(Vec3(0,0,0), 2, 1))");
    close(d(&grow, 3.0, 0.0, 0.0), 0.0, 1e-12);
    let shrink = model("Offset(-1.0, Sphere(Vec3(0,0,0), 2, 1))");
    close(d(&shrink, 1.0, 0.0, 0.0), 0.0, 1e-12);
    assert_eq!(shrink.bbox().max.x, 1.0);
    for t in ["-0.5", "0.5"] {
        let s = model(&format!("Shell({t}, Sphere(Vec3(0,0,0), 2, 1))"));
        assert!(d(&s, 1.75, 0.0, 0.0) < 0.0);
        assert!(d(&s, 1.0, 0.0, 0.0) > 0.0, "hollow inside");
        close(d(&s, 0.0, 0.0, 0.0), 1.5, 1e-12);
    }
}

#[test]
fn intersection_box_is_tight() {
    let m = model(
        "Intersection(false, [Sphere(Vec3(0,0,0), 5, 1), RectPrism(Vec3(4,0,0), Vec3(2,2,2), 1)])",
    );
    let b = m.bbox();
    assert_eq!((b.min.x, b.max.x), (3.0, 5.0));
    let m = model("Difference(Sphere(Vec3(0,0,0), 5, 1), Sphere(Vec3(20,0,0), 5, 1))");
    assert_eq!(m.bbox().max.x, 5.0);
}

#[test]
fn function_is_clipped_to_its_box() {
    let m = model("Function(\"x*x + y*y + z*z - 100\", 1, Vec3(-2,-2,-2), Vec3(2,2,2))");
    assert!(d(&m, 0.0, 0.0, 0.0) < 0.0);
    assert!(
        d(&m, 3.0, 0.0, 0.0) > 0.0,
        "outside the box, although f < 0"
    );
}

#[test]
fn fgrade_clamps_negative_fractions() {
    let m = model("FGrade([\"-3\", \"1\"], [1, 3], true, Sphere(Vec3(0,0,0), 1, 1))");
    assert_eq!(frac(&m, [0.0, 0.0, 0.0], 1), 0.0);
    assert_eq!(frac(&m, [0.0, 0.0, 0.0], 3), 1.0);
    let m = model("FGrade([\"0.2\", \"0.3\"], [1, 3], true, Sphere(Vec3(0,0,0), 1, 1))");
    close(frac(&m, [0.0, 0.0, 0.0], 1), 0.4, 1e-12);
}

// ---- one test per remaining node ----

#[test]
fn sphere_rectprism_cylinder_strut() {
    close(
        d(&model("Sphere(1, 2, 3, 4, 1)"), 1.0, 2.0, 8.0),
        1.0,
        1e-12,
    );
    close(
        d(
            &model("RectPrism(Vec3(0,0,0), Vec3(2,4,6), 1)"),
            2.0,
            3.0,
            4.0,
        ),
        3f64.sqrt(),
        1e-12,
    );
    close(
        d(&model("Cylinder(Vec3(0,0,0), 1, 4, 1)"), 2.0, 0.0, 3.0),
        2f64.sqrt(),
        1e-12,
    );
    let s = model("Strut(Vec3(0,0,0), Vec3(10,0,0), 0.5, 1)");
    close(d(&s, 5.0, 1.0, 0.0), 0.5, 1e-12);
    close(d(&s, -1.0, 0.0, 0.0), 0.5, 1e-12);
}

#[test]
fn polygon_extrude() {
    let m = model(
        "PolygonExtrude([Vec3(0,0,0), Vec3(4,0,0), Vec3(4,2,0), Vec3(0,2,0)], 3.0, false, 1)",
    );
    close(d(&m, 2.0, 1.0, 1.5), -1.0, 1e-12);
    close(d(&m, 2.0, 1.0, 4.0), 1.0, 1e-12);
    close(d(&m, 6.0, 1.0, 1.0), 2.0, 1e-12);
    // Clockwise in XY extrudes toward -Z; symmetric centres it.
    let cw = model(
        "PolygonExtrude([Vec3(0,0,0), Vec3(0,2,0), Vec3(4,2,0), Vec3(4,0,0)], 3.0, false, 1)",
    );
    assert!(d(&cw, 2.0, 1.0, -1.5) < 0.0 && d(&cw, 2.0, 1.0, 1.5) > 0.0);
    let sym =
        model("PolygonExtrude([Vec3(0,0,0), Vec3(4,0,0), Vec3(4,2,0), Vec3(0,2,0)], 3.0, true, 1)");
    assert!(d(&sym, 2.0, 1.0, -1.4) < 0.0 && d(&sym, 2.0, 1.0, 1.4) < 0.0);
}

#[test]
fn function_node() {
    let m = model("Function(\"x*x + y*y + z*z - 4\", 1)");
    close(d(&m, 1.0, 0.0, 0.0), -3.0, 1e-12);
    assert!(d(&m, 3.0, 0.0, 0.0) > 0.0);
}

#[test]
fn translate_and_rotate_about_a_point() {
    close(
        d(
            &model("Translate(5, 0, 0, Sphere(Vec3(0,0,0), 1, 1))"),
            5.0,
            0.0,
            0.0,
        ),
        -1.0,
        1e-12,
    );
    let r = model("Rotate(0, 0, 90, Vec3(5,0,0), Sphere(Vec3(6,0,0), 0.5, 1))");
    assert!(d(&r, 5.0, 1.0, 0.0) < -0.49);
}

#[test]
fn unions_blend_materials_on_request() {
    let m = model("Union(true, [Sphere(Vec3(0,0,0), 2, 1), Sphere(Vec3(1,0,0), 2, 3)])");
    close(frac(&m, [0.5, 0.0, 0.0], 1), 0.5, 1e-12);
    close(frac(&m, [0.5, 0.0, 0.0], 3), 0.5, 1e-12);
    let m = model("Intersection(true, [Sphere(Vec3(0,0,0), 2, 1), Sphere(Vec3(1,0,0), 2, 3)])");
    close(frac(&m, [0.5, 0.0, 0.0], 3), 0.5, 1e-12);
}

#[test]
fn smooth_intersection_and_difference() {
    let i =
        model("Intersection(1.0, false, [Sphere(Vec3(0,0,0), 2, 1), Sphere(Vec3(1,0,0), 2, 1)])");
    assert!(d(&i, 0.5, 0.0, 0.0) < 0.0);
    let df = model("Difference(0.5, Sphere(Vec3(0,0,0), 2, 1), Sphere(Vec3(2,0,0), 1, 1))");
    assert!(d(&df, -1.0, 0.0, 0.0) < 0.0 && d(&df, 1.5, 0.0, 0.0) > 0.0);
}

#[test]
fn tile_replicates_at_cell_centres() {
    let m = model(
        "Intersection(false, [Tile(4, 4, 4, Sphere(Vec3(0,0,0), 1, 1)), RectPrism(Vec3(0,0,0), Vec3(20,20,20), 1)])",
    );
    // Copies at (k + 1/2) * 4: 2, 6, -2, ...
    close(d(&m, 2.0, 2.0, 2.0), -1.0, 1e-12);
    close(d(&m, 6.0, -2.0, 2.0), -1.0, 1e-12);
    assert!(d(&m, 0.0, 0.0, 0.0) > 0.0);
    assert!(!model("Tile(Sphere(Vec3(0,0,0), 1, 1))").bbox().is_finite());
}

#[test]
fn blend_averages_neighbourhood() {
    let m = model(
        "Blend(1.0, Union(false, [RectPrism(Vec3(-5,0,0), Vec3(10,10,10), 1), RectPrism(Vec3(5,0,0), Vec3(10,10,10), 3)]))",
    );
    let f1 = frac(&m, [0.0, 0.0, 0.0], 1);
    assert!(f1 > 0.2 && f1 < 0.8, "{f1}");
    assert_eq!(frac(&m, [-4.0, 0.0, 0.0], 1), 1.0);
}

#[test]
fn graph_lattices() {
    for t in [
        "BodyCenteredCubic",
        "FaceCenteredCubic",
        "Cubic",
        "KelvinCell",
        "Octet",
    ] {
        let m = model(&format!(
            "GraphLattice(LatticeType::{t}, Vec3(4,4,4), 0.3, 1)"
        ));
        let b = m.bbox();
        assert_eq!(b.max, DVec3::splat(2.0), "{t}");
        assert!(d(&m, 3.0, 0.0, 0.0) > 0.0, "{t}: clipped to the cell");
    }
    let c = model("GraphLattice([[Vec3(0,0,0), Vec3(5,0,0)], [Vec3(0,0,0), Vec3(0,5,0)]], 0.5, 1)");
    close(d(&c, 2.5, 0.0, 1.0), 0.5, 1e-12);
    assert_eq!(c.bbox().min, DVec3::splat(-0.5), "box grown by the radius");
}

#[test]
fn tpms_sheets() {
    for t in ["Gyroid", "SchwarzP", "Diamond"] {
        let m = model(&format!(
            "Intersection(false, [{t}(5.0, 0.5, 1), Sphere(Vec3(0,0,0), 10, 1)])"
        ));
        let mut inside = 0;
        for i in 0..1000 {
            let p =
                DVec3::new((i % 10) as f64, ((i / 10) % 10) as f64, (i / 100) as f64) * 0.7 - 3.0;
            if m.distance(p) <= 0.0 {
                inside += 1;
            }
        }
        // A 0.5 mm sheet with a 5 mm cell fills a modest share of the volume.
        assert!(inside > 30 && inside < 500, "{t}: {inside}");
    }
}

// ---- soundness of bounds and of the union index ----

const DESIGNS: [&str; 6] = [
    "Union(false, [Sphere(Vec3(0,0,0), 5, 1), RectPrism(Vec3(4,0,0), Vec3(6,4,4), 3)])",
    "Intersection(false, [Tile(GraphLattice(LatticeType::BodyCenteredCubic, Vec3(5,5,5), 0.175, 1)), Sphere(Vec3(0,0,0), 10, 3)])",
    "FGrade([\"x/15+0.5\", \"-x/15+0.5\"], [1, 3], true, RectPrism(Vec3(0,0,0), Vec3(15,10,5), 11))",
    "Rotate(20, 30, 40, Vec3(1,2,3), Scale(1, 2, 0.5, Shell(-1.0, Cylinder(Vec3(0,0,0), 5, 10, 1))))",
    "Intersection(false, [Gyroid(Vec3(6,6,6), 0.6, 1), Difference(1.0, Sphere(Vec3(0,0,0), 8, 1), Function(\"x*x+y*y-9\", 1, Vec3(-10,-10,-10), Vec3(10,10,10)))])",
    "let u = Union(); for i in 0..40 { u.add_child(Strut(Vec3(i % 7, i % 5, i % 3) * 2.0, Vec3(i % 3, i % 7, i % 5) * 2.0, 0.3, 1 + i % 2)); } u",
];

/// Deterministic pseudo-random numbers in [0, 1).
fn rng(seed: u64) -> impl FnMut() -> f64 {
    let mut s = seed | 1;
    move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64
    }
}

#[test]
fn intervals_contain_every_sample() {
    for (n, src) in DESIGNS.iter().enumerate() {
        let m = model(src);
        let b = m
            .bbox()
            .intersection(&Aabb::new(DVec3::splat(-12.0), DVec3::splat(12.0)));
        let mut r = rng(n as u64 + 1);
        for _ in 0..200 {
            let c = b.min + DVec3::new(r(), r(), r()) * b.size();
            let size = DVec3::new(r(), r(), r()) * 3.0;
            let bx = Aabb::from_center_size(c, size);
            let iv = m.interval(&bx);
            for _ in 0..20 {
                let p = bx.min + DVec3::new(r(), r(), r()) * bx.size();
                let v = m.distance(p);
                assert!(
                    iv.lo <= v + 1e-9 && v <= iv.hi + 1e-9,
                    "design {n}: {v} not in {iv:?} over {bx:?}"
                );
            }
        }
    }
}

#[test]
fn primitive_intervals_are_exact_and_sound() {
    // Sphere, box and cylinder: the interval's ends are the distances at
    // the box's nearest and farthest points (per-axis offsets from the
    // centre), and no sample, corners and faces included, falls outside
    // (no tolerance: the samplers' settled tiles rely on the exact sign).
    let srcs = [
        "Sphere(Vec3(0.3, -0.2, 0.1), 4, m.id(\"red\"))",
        "RectPrism(Vec3(0.3, -0.2, 0.1), Vec3(15, 10, 5), m.id(\"red\"))",
        "Cylinder(Vec3(0.3, -0.2, 0.1), 4, 6, m.id(\"red\"))",
    ];
    let mut r = rng(77);
    let mut tighter = 0;
    for src in srcs {
        let m = model(src);
        for _ in 0..2_000 {
            let c = DVec3::new(r() - 0.5, r() - 0.5, r() - 0.5) * 20.0;
            let bx = Aabb::from_center_size(c, DVec3::new(r(), r(), r()) * 3.0);
            let iv = m.interval(&bx);
            let (lo, hi) = (bx.min, bx.max);
            let corner = |k: usize| {
                DVec3::new(
                    if k & 1 == 0 { lo.x } else { hi.x },
                    if k & 2 == 0 { lo.y } else { hi.y },
                    if k & 4 == 0 { lo.z } else { hi.z },
                )
            };
            let mut max_seen = f64::NEG_INFINITY;
            for k in 0..8 {
                let v = m.distance(corner(k));
                assert!(iv.lo <= v && v <= iv.hi, "{src}: corner {v} not in {iv:?}");
                max_seen = max_seen.max(v);
            }
            for _ in 0..30 {
                // Inside, and on a face.
                let mut p = lo + DVec3::new(r(), r(), r()) * bx.size();
                if r() < 0.3 {
                    p.x = if r() < 0.5 { lo.x } else { hi.x };
                }
                let v = m.distance(p);
                assert!(
                    iv.lo <= v && v <= iv.hi,
                    "{src}: {v} not in {iv:?} over {bx:?}"
                );
            }
            // The far end is a corner's distance (the farthest point of a
            // box from any centre is a corner).
            assert_eq!(iv.hi, max_seen, "{src}: far end over {bx:?}");
            let dc = m.distance(bx.center());
            let half = bx.half_diagonal();
            assert!(iv.lo >= dc - half - 1e-12 && iv.hi <= dc + half + 1e-12);
            if iv.hi < dc + half - 1e-3 {
                tighter += 1;
            }
        }
    }
    assert!(
        tighter > 3_000,
        "{tighter} of 6000 tighter than the Lipschitz bound"
    );
}

#[test]
fn constant_fractions_are_constant() {
    for (n, src) in DESIGNS.iter().enumerate() {
        let m = model(src);
        let b = m
            .bbox()
            .intersection(&Aabb::new(DVec3::splat(-12.0), DVec3::splat(12.0)));
        let mut r = rng(100 + n as u64);
        for _ in 0..300 {
            let c = b.min + DVec3::new(r(), r(), r()) * b.size();
            let bx = Aabb::from_center_size(c, DVec3::new(r(), r(), r()) * 2.0);
            if !m.constant_fractions(&bx) {
                continue;
            }
            let mut first: Option<Vec<(u8, f64)>> = None;
            for _ in 0..20 {
                let p = bx.min + DVec3::new(r(), r(), r()) * bx.size();
                let (dist, f) = m.eval_point(p);
                if dist > 0.0 {
                    continue;
                }
                match &first {
                    None => first = Some(f),
                    Some(g) => {
                        for ((_, a), (_, b)) in g.iter().zip(&f) {
                            assert!((a - b).abs() < 1e-9, "design {n}: fractions vary in {bx:?}");
                        }
                    }
                }
            }
        }
    }
}

#[test]
fn indexed_union_matches_brute_force() {
    // 60 struts: indexed. Compare with the min over single-strut models.
    let mut src = String::from("let u = Union();\n");
    let mut singles = Vec::new();
    let mut struts = Vec::new();
    let mut r = rng(9);
    for i in 0..60 {
        let a = DVec3::new(r(), r(), r()) * 20.0 - 10.0;
        let b = a + DVec3::new(r(), r(), r()) * 6.0 - 3.0;
        struts.push((a, b));
        let s = format!(
            "Strut(Vec3({},{},{}), Vec3({},{},{}), 0.4, {})",
            a.x,
            a.y,
            a.z,
            b.x,
            b.y,
            b.z,
            1 + i % 3
        );
        src.push_str(&format!("u.add_child({s});\n"));
        singles.push(model(&s));
    }
    src.push('u');
    let m = model(&src);
    for k in 0..6000 {
        // Half uniform, half within 1 mm of a random strut (where the
        // candidate lists and their per-point slack decide).
        let p = if k % 2 == 0 {
            DVec3::new(r(), r(), r()) * 30.0 - 15.0
        } else {
            let (a, b) = struts[(r() * 59.99) as usize];
            a + (b - a) * r() + (DVec3::new(r(), r(), r()) - 0.5) * 2.0
        };
        let (d_eval, _) = m.eval_point(p);
        let want = singles
            .iter()
            .map(|s| s.distance(p))
            .fold(f64::INFINITY, f64::min);
        close(m.distance(p), want, 1e-12);
        close(d_eval, want, 1e-12);
        if want <= 0.0 {
            // First containing strut wins.
            let first = singles.iter().position(|s| s.distance(p) <= 0.0).unwrap();
            let id = 1 + (first % 3) as u8;
            assert_eq!(frac(&m, p.to_array(), id), 1.0);
        }
    }
}

#[test]
fn prepare_errors() {
    let d = run_script("Union()", "t", &ScriptOptions::default()).unwrap();
    let e = Model::prepare(&d.root, d.materials)
        .unwrap_err()
        .to_string();
    assert!(e.contains("Union") && e.contains("no children"), "{e}");
    let d = run_script(
        "Difference(Sphere(), Sphere())",
        "t",
        &ScriptOptions::default(),
    )
    .unwrap();
    assert!(Model::prepare(&d.root, d.materials).is_ok());
    let e = run_script(
        "PolygonExtrude([Vec3(0,0,0), Vec3(1,0,0), Vec3(2,0,0)], 1.0)",
        "t",
        &ScriptOptions::default(),
    )
    .map(|d| {
        Model::prepare(&d.root, d.materials)
            .map(|_| ())
            .unwrap_err()
            .to_string()
    })
    .unwrap();
    assert!(e.contains("collinear"), "{e}");
    // More expressions than a grade's scratch array holds (one material
    // listed 65 times): an error naming the node, not a panic when sampled.
    let exprs = vec!["`0.5`"; 65].join(", ");
    let mats = vec!["1"; 65].join(", ");
    let src = format!("FGrade([{exprs}], [{mats}], true, Sphere())");
    let d = run_script(&src, "t", &ScriptOptions::default()).unwrap();
    let e = Model::prepare(&d.root, d.materials)
        .map(|_| ())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("FGrade") && e.contains("65 expressions; at most 64"),
        "{e}"
    );
    let exprs = vec!["`0.5`"; 64].join(", ");
    let mats = vec!["1"; 64].join(", ");
    let src = format!("FGrade([{exprs}], [{mats}], true, Sphere())");
    let d = run_script(&src, "t", &ScriptOptions::default()).unwrap();
    let m = Model::prepare(&d.root, d.materials).unwrap();
    let mut f = vec![0.0; m.materials().len()];
    assert!(m.eval_into(DVec3::ZERO, &mut f) < 0.0);
    assert!((f.iter().sum::<f64>() - 1.0).abs() < 1e-12, "{f:?}");
}

#[test]
fn mesh_intervals_contain_every_sample() {
    let dir = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../assets/examples/data");
    let opts = ScriptOptions {
        base_dir: Some(dir),
        ..ScriptOptions::default()
    };
    let src = "Union(false, [Mesh(\"bunny.obj\", 1), Strut(Vec3(0,0,0), Vec3(40,0,0), 2, 3)])";
    let d = run_script(src, "t", &opts).unwrap();
    let m = Model::prepare(&d.root, d.materials.clone()).unwrap();
    let b = m.bbox().expand(5.0);
    let mut r = rng(77);
    for _ in 0..300 {
        let c = b.min + DVec3::new(r(), r(), r()) * b.size();
        let bx = Aabb::from_center_size(c, DVec3::new(r(), r(), r()) * 6.0);
        let iv = m.interval(&bx);
        for _ in 0..10 {
            let p = bx.min + DVec3::new(r(), r(), r()) * bx.size();
            let v = m.distance(p);
            assert!(
                iv.lo <= v + 1e-9 && v <= iv.hi + 1e-9,
                "{v} not in {iv:?} over {bx:?}"
            );
        }
    }
}

#[test]
fn batch_calls_match_single_points() {
    let m = model(DESIGNS[2]);
    let xs: Vec<f64> = (0..50).map(|i| i as f64 * 0.4 - 10.0).collect();
    let ys = vec![0.5; 50];
    let zs = vec![-0.5; 50];
    let pts = crate::Points {
        x: &xs,
        y: &ys,
        z: &zs,
    };
    let k = m.materials().len();
    let (mut d, mut f, mut d2) = (vec![0.0; 50], vec![0.0f32; 50 * k], vec![0.0; 50]);
    m.eval_batch(pts, &mut d, &mut f);
    m.distance_batch(pts, &mut d2);
    for i in 0..50 {
        let (di, fi) = m.eval_point(pts.get(i));
        assert_eq!(d[i], di);
        assert_eq!(d2[i], di);
        for (j, id) in m.materials().iter().enumerate() {
            let want = fi.iter().find(|(m, _)| m == id).map_or(0.0, |x| x.1) as f32;
            assert_eq!(f[i * k + j], want, "point {i} material {id}");
        }
    }
}

/// A tiled lattice folded into one octant and clipped to its cell is
/// 1-Lipschitz across the cell faces (`Model::distance_is_bound`): random
/// pairs of nearby points, many across a face, never differ by more than
/// their distance. A tiled `Function` is not claimed to be.
#[test]
fn a_tiled_symmetric_lattice_is_lipschitz_across_cell_faces() {
    let m = model("Tile(GraphLattice(LatticeType::BodyCenteredCubic, Vec3(2, 2, 2), 0.3, 1))");
    assert!(m.distance_is_bound());
    let mut rng = crate::bench::XorShift::new(3);
    let mut r = || rng.next_f64() * 2.0 - 1.0;
    for _ in 0..50_000 {
        // Near the cell faces at ±1 (and their corners).
        let a = DVec3::new(1.0 + 0.2 * r(), 1.0 + 0.2 * r(), 3.0 * r());
        let b = a + DVec3::new(r(), r(), r()) * 0.15;
        let (da, db) = (m.distance(a), m.distance(b));
        assert!(
            (da - db).abs() <= a.distance(b) * (1.0 + 1e-12) + 1e-12,
            "{a} {b}: {da} {db}"
        );
    }
    let f = model(r#"Tile(2, 2, 2, Function("x*x + y*y + z*z - 0.5", 1))"#);
    assert!(!f.distance_is_bound());
}
