//! `.vcad` designs against the equivalent Rhai designs, against values
//! measured with pyvcad 2.3.4's `parse_vcad_text`, and their errors.

use glam::DVec3;

use super::*;
use crate::Model;

fn vcad(src: &str) -> Model {
    let d = match run_vcad(src, "t.vcad", &ScriptOptions::default()) {
        Ok(d) => d,
        Err(e) => panic!("{src}: {e}"),
    };
    Model::prepare(&d.root, d.materials).expect("prepare")
}

fn rhai(body: &str) -> Model {
    let src = format!("let m = default_materials();\n{body}");
    crate::script::model_of(&src, "t.rhai", &ScriptOptions::default()).expect("rhai")
}

fn error(src: &str) -> ScriptError {
    match run_vcad(src, "bad.vcad", &ScriptOptions::default()) {
        Ok(_) => panic!("{src} was accepted"),
        Err(e) => e,
    }
}

/// Points spread over ±3 mm (a fixed lattice, off the symmetry planes).
fn points() -> Vec<DVec3> {
    let mut out = Vec::new();
    for i in 0..7 {
        for j in 0..6 {
            for k in 0..5 {
                out.push(DVec3::new(
                    -3.0 + i as f64 * 0.93,
                    -2.9 + j as f64 * 1.07,
                    -2.7 + k as f64 * 1.31,
                ));
            }
        }
    }
    out
}

fn same(a: &Model, b: &Model, what: &str) {
    for p in points() {
        let (da, fa) = a.eval_point(p);
        let (db, fb) = b.eval_point(p);
        assert!((da - db).abs() < 1e-9, "{what} at {p}: {da} vs {db}");
        assert_eq!(fa.len(), fb.len(), "{what} at {p}: {fa:?} vs {fb:?}");
        for ((ia, xa), (ib, xb)) in fa.iter().zip(&fb) {
            assert_eq!(ia, ib, "{what} at {p}");
            assert!((xa - xb).abs() < 1e-9, "{what} at {p}: {fa:?} vs {fb:?}");
        }
    }
}

#[test]
fn every_construct_matches_its_rhai_design() {
    let cases = [
        (
            r#"union(){ sphere(2,"red"); }"#,
            r#"Union(false, [Sphere(Vec3(0,0,0), 2, m.id("red"))])"#,
        ),
        (
            r#"union(){ rectprism((2,3,4),"blue"); }"#,
            r#"Union(false, [RectPrism(Vec3(0,0,0), Vec3(2,3,4), m.id("blue"))])"#,
        ),
        (
            r#"union(){ cylinder(1,4,"red"); }"#,
            r#"Union(false, [Cylinder(Vec3(0,0,0), 1, 4, m.id("red"))])"#,
        ),
        (
            r#"union(){ strut((0,0,0),(1,1,1),0.5,"red"); }"#,
            r#"Union(false, [Strut(Vec3(0,0,0), Vec3(1,1,1), 0.5, m.id("red"))])"#,
        ),
        (
            r#"union(){ function((-2,-2,-2),(2,2,2),"x^2+y^2+z^2-4","green"); }"#,
            r#"Union(false, [Function("x^2+y^2+z^2-4", m.id("green"), Vec3(-2,-2,-2), Vec3(2,2,2))])"#,
        ),
        (
            r#"union(){ translate(1,-0.5,0.25){ sphere(1,"red"); } }"#,
            r#"Union(false, [Translate(1, -0.5, 0.25, Sphere(Vec3(0,0,0), 1, m.id("red")))])"#,
        ),
        (
            r#"union(){ rotate(10,20,30){ rectprism((4,1,1),"red"); } }"#,
            r#"Union(false, [Rotate(10, 20, 30, Vec3(0,0,0), RectPrism(Vec3(0,0,0), Vec3(4,1,1), m.id("red")))])"#,
        ),
        (
            r#"union(){ scale(2,1,0.5){ sphere(1,"red"); } }"#,
            r#"Union(false, [Scale(2, 1, 0.5, Sphere(Vec3(0,0,0), 1, m.id("red")))])"#,
        ),
        (
            r#"union(){ intersection(){ tile(1,1,1){ sphere(0.3,"red"); } rectprism((4,4,4),"blue"); } }"#,
            r#"Union(false, [Intersection(false, [Tile(1, 1, 1, Sphere(Vec3(0,0,0), 0.3, m.id("red"))), RectPrism(Vec3(0,0,0), Vec3(4,4,4), m.id("blue"))])])"#,
        ),
        (
            r#"union(){ difference(){ sphere(2,"red"); sphere(1,"blue"); } }"#,
            r#"Union(false, [Difference(Sphere(Vec3(0,0,0), 2, m.id("red")), Sphere(Vec3(0,0,0), 1, m.id("blue")))])"#,
        ),
        (
            r#"union(){ fgrade(["x/4+0.5","0.5-x/4"],["red","blue"],"prob"){ rectprism((4,2,2),"gray"); } }"#,
            r#"Union(false, [FGrade(["x/4+0.5","0.5-x/4"], [m.id("red"), m.id("blue")], true, RectPrism(Vec3(0,0,0), Vec3(4,2,2), m.id("gray")))])"#,
        ),
        (
            r#"union(){ fgrade(["d+1","-d"],["red","blue"],"thresh"){ sphere(2,"red"); } }"#,
            r#"Union(false, [FGrade(["d+1","-d"], [m.id("red"), m.id("blue")], false, Sphere(Vec3(0,0,0), 2, m.id("red")))])"#,
        ),
        (
            r#"union(){ blend(0.5){ union(){ translate(-1,0,0){ rectprism((2,2,2),"red"); } translate(1,0,0){ rectprism((2,2,2),"blue"); } } } }"#,
            r#"Union(false, [Blend(0.5, Union(false, [Translate(-1,0,0, RectPrism(Vec3(0,0,0), Vec3(2,2,2), m.id("red"))), Translate(1,0,0, RectPrism(Vec3(0,0,0), Vec3(2,2,2), m.id("blue")))]))])"#,
        ),
        (
            "/* block\n comment */ UNION(){ // line comment\n Sphere(1, \"red\"); translate(1,0,0){ sphere(1,\"blue\"); } }",
            r#"Union(false, [Sphere(Vec3(0,0,0), 1, m.id("red")), Translate(1,0,0, Sphere(Vec3(0,0,0), 1, m.id("blue")))])"#,
        ),
    ];
    for (v, r) in cases {
        same(&vcad(v), &rhai(r), v);
    }
}

/// Values printed by pyvcad 2.3.4: `pv.parse_vcad_text(text,
/// pv.default_materials_path)`, `prepare(Vec3(0.1,0.1,0.1), 1, 1)`, then
/// `evaluate` and `distribution` at each point.
#[test]
fn values_match_pyvcad() {
    type Case = (&'static str, [f64; 3], f64, &'static [(u8, f64)]);
    let cases: &[Case] = &[
        (
            r#"union(){ sphere(2,"red"); }"#,
            [1.0, 0.5, 0.2],
            -0.8642183308399454,
            &[(1, 1.0)],
        ),
        (
            r#"union(){ cylinder(1,4,"red"); }"#,
            [1.0, 0.5, 0.2],
            0.1180339887498949,
            &[],
        ),
        (
            r#"union(){ function((-2,-2,-2),(2,2,2),"x^2+y^2+z^2-4","red"); }"#,
            [-1.5, 0.3, 2.0],
            2.34,
            &[],
        ),
        (
            r#"union(){ function((-2,-2,-2),(2,2,2),"rho-1","red"); }"#,
            [1.5, 0.2, 0.3],
            0.5132745950421556,
            &[],
        ),
        (
            r#"union(){ translate(1,0,0){ sphere(1,"red"); } }"#,
            [2.0, 1.0, 0.0],
            0.41421356237309515,
            &[],
        ),
        (
            r#"union(){ scale(2,1,1){ sphere(1,"red"); } }"#,
            [1.0, 0.5, 0.2],
            -0.26515307716504655,
            &[(1, 1.0)],
        ),
        (
            r#"union(){ tile(2,2,2){ sphere(0.5,"red"); } }"#,
            [0.0, 0.0, 0.0],
            1.2320508075688772,
            &[],
        ),
        (
            r#"union(){ tile(1,1,1){ sphere(0.5,"red"); } }"#,
            [0.5, 0.2, 0.0],
            0.08309518795121318,
            &[],
        ),
        (
            r#"union(){ difference(){ sphere(2,"red"); sphere(1,"blue"); } }"#,
            [1.0, 0.5, 0.2],
            -0.13578166916005463,
            &[(1, 1.0)],
        ),
        (
            r#"union(){ sphere(1,"red"); translate(1,0,0){ sphere(1,"blue"); } }"#,
            [1.0, 0.5, 0.2],
            -0.4614835192865495,
            &[(3, 1.0)],
        ),
        (
            r#"union(){ rotate(0,90,0){ cylinder(0.5,4,"red"); } }"#,
            [1.5, 0.2, 0.3],
            -0.1394450096638274,
            &[(1, 1.0)],
        ),
        (
            r#"union(){ fgrade(["x/4+0.5","0.5-x/4"],["red","blue"],"prob"){ rectprism((4,2,2),"gray"); } }"#,
            [1.0, 0.5, 0.2],
            -0.5,
            &[(1, 0.75), (3, 0.25)],
        ),
        (
            r#"union(){ fgrade(["d+1","-d"],["red","blue"],"prob"){ sphere(2,"red"); } }"#,
            [1.5, 0.2, 0.3],
            -0.45727513794584906,
            &[(1, 0.5427248477935791), (3, 0.4572751522064209)],
        ),
    ];
    for (src, p, d, fracs) in cases {
        let (got, f) = vcad(src).eval_point(DVec3::from_array(*p));
        assert!(
            (got - d).abs() < 1e-6,
            "{src} at {p:?}: {got} vs pyvcad {d}"
        );
        let f: Vec<(u8, f64)> = f.into_iter().filter(|(_, x)| *x != 0.0).collect();
        assert_eq!(f.len(), fracs.len(), "{src}: {f:?} vs pyvcad {fracs:?}");
        for ((ia, xa), (ib, xb)) in f.iter().zip(fracs.iter()) {
            assert_eq!(ia, ib, "{src}");
            assert!((xa - xb).abs() < 1e-6, "{src}: {f:?} vs pyvcad {fracs:?}");
        }
    }
}

#[test]
fn pyvcad_blend_kernel_is_taken_with_a_warning() {
    let d = run_vcad(
        r#"union(){ blend(1,2,1){ sphere(1,"red"); } }"#,
        "k.vcad",
        &ScriptOptions::default(),
    )
    .expect("blend(x,y,z)");
    assert_eq!(d.warnings.len(), 1, "{:?}", d.warnings);
    assert!(
        d.warnings[0].starts_with("1:10: blend(1, 2, 1)"),
        "{:?}",
        d.warnings
    );
    let NodeKindRef::Union(kids) = kind(&d.root) else {
        panic!("root is not a union");
    };
    match kids[0].kind() {
        crate::NodeKind::Blend { radius, .. } => assert_eq!(*radius, 1.0),
        other => panic!("{other:?}"),
    }
}

enum NodeKindRef<'a> {
    Union(&'a [crate::Node]),
    Other,
}

fn kind(n: &crate::Node) -> NodeKindRef<'_> {
    match n.kind() {
        crate::NodeKind::Union { children, .. } => NodeKindRef::Union(children),
        _ => NodeKindRef::Other,
    }
}

#[test]
fn errors_name_line_column_and_construct() {
    let cases: &[(&str, usize, usize, &str)] = &[
        (
            "union(){\n  sphere(1,\"red\")\n}",
            3,
            1,
            "expected `;` to end `sphere(...)`",
        ),
        (
            "union(){\n  shell(-1){ sphere(1,\"red\"); }\n}",
            2,
            3,
            "construct `shell` is not taken",
        ),
        (
            "union(){\n  sphre(1,\"red\");\n}",
            2,
            3,
            "did you mean `sphere(radius, \"material\");`",
        ),
        ("union(){ sphere(1,\"rde\"); }", 1, 19, "material \"rde\""),
        ("union(){ sphere(1,2); }", 1, 19, "materials are named"),
        ("union(){ sphere(-1,\"red\"); }", 1, 17, "a number above 0"),
        (
            "union(){ sphere(1); }",
            1,
            17,
            "write `sphere(radius, \"material\");`",
        ),
        ("union(){ rectprism((1,2),\"red\"); }", 1, 20, "(x, y, z)"),
        (
            "union(){\n function((-1,-1,-1),(1,1,1),\"x^2+q\",\"red\"); }",
            2,
            35,
            "`function` expression \"x^2+q\"",
        ),
        (
            "union(){ translate(1,0,0){ sphere(1,\"red\"); sphere(1,\"blue\"); } }",
            1,
            10,
            "exactly one part",
        ),
        (
            "union(){ difference(){ sphere(1,\"red\"); } }",
            1,
            10,
            "exactly two parts",
        ),
        (
            "union(){ fgrade([\"x\"],[\"red\",\"blue\"],\"prob\"){ sphere(1,\"red\"); } }",
            1,
            23,
            "one material per expression",
        ),
        (
            "union(){ fgrade([\"x\"],[\"red\"],\"maybe\"){ sphere(1,\"red\"); } }",
            1,
            31,
            "write \"prob\" or \"thresh\"",
        ),
        (
            "union(true){ sphere(1,\"red\"); }",
            1,
            7,
            "takes no arguments",
        ),
        ("sphere(1,\"red\");", 1, 1, "must be `union(){ ... }`"),
        (
            "union(){ sphere(1,\"red\"); }\nunion(){ }",
            2,
            1,
            "one top-level union",
        ),
        ("union(){ sphere(1,\"red\"); ", 1, 1, "never closed"),
        ("union(){ }", 1, 1, "nothing inside"),
        ("union(){ sphere(r,\"red\"); }", 1, 17, "no variables"),
        (
            "union(){ sphere(1,\"red); }",
            1,
            19,
            "string is never closed",
        ),
        ("/* open", 1, 1, "never closed"),
        ("", 1, 1, "holds no design"),
        (
            "union(){ sphere(1,\"red\") { sphere(1,\"red\"); } }",
            1,
            28,
            "takes no `{ }` body",
        ),
        (
            "union(){ sphere(1 # 2,\"red\"); }",
            1,
            19,
            "unexpected character `#`",
        ),
        (
            "union(){ mesh(\"part.stl\",\"red\"); }",
            1,
            15,
            "save the design first",
        ),
        (
            "union(){ root((0,0,0),(1,1,1),(1,1,1)){ sphere(1,\"red\"); } }",
            1,
            10,
            "`root((min),(max),(voxel))",
        ),
    ];
    let mut wrong = Vec::new();
    for (src, line, column, want) in cases {
        let e = error(src);
        if (e.line, e.column) != (Some(*line), Some(*column)) {
            wrong.push(format!("{src}: {e}"));
        }
        assert!(e.message.contains(want), "{src}: {e}");
        assert!(e.to_string().starts_with("bad.vcad:"), "{e}");
    }
    assert!(wrong.is_empty(), "wrong positions:\n{}", wrong.join("\n"));
}

#[test]
fn deep_nesting_is_an_error_not_a_crash() {
    let n = 100_000;
    let src = format!("{}{}", "union(){".repeat(n), "}".repeat(n));
    let e = error(&src);
    assert!(e.message.contains("nested more than"), "{e}");
}

#[test]
fn prepare_errors_point_into_the_vcad() {
    let d = run_vcad(
        "union(){\n  sphere(1,\"red\");\n}",
        "o.vcad",
        &ScriptOptions::default(),
    )
    .expect("run");
    let NodeKindRef::Union(kids) = kind(&d.root) else {
        panic!("root is not a union");
    };
    assert_eq!(kids[0].origin().map(|o| (o.line, o.column)), Some((2, 3)));
}

#[test]
fn the_example_file_runs() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../assets/examples/legacy.vcad"
    );
    let m = crate::script::model_of_file(std::path::Path::new(path)).expect("legacy.vcad");
    // The plate, graded red (x/40 + 0.5) to blue (0.5 − x/40), at x = −5.
    let used = |p: DVec3| -> Vec<(u8, f64)> {
        m.eval_point(p)
            .1
            .into_iter()
            .filter(|(_, f)| *f > 0.0)
            .collect()
    };
    assert!(m.distance(DVec3::new(-5.0, 0.0, 0.0)) < 0.0);
    assert_eq!(
        used(DVec3::new(-5.0, 0.0, 0.0)),
        vec![(1, 0.375), (3, 0.625)]
    );
    // The hole through it at x = 3, the magenta ball above it at z = 12.
    assert!(m.distance(DVec3::new(3.0, 0.0, 0.0)) > 0.0);
    assert_eq!(used(DVec3::new(12.0, 0.0, 12.0)), vec![(7, 1.0)]);
}

#[test]
fn meshes_resolve_beside_the_design() {
    let dir = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../assets/examples/legacy.vcad"
    );
    let opts = ScriptOptions::for_file(std::path::Path::new(dir));
    let e = run_vcad(
        r#"union(){ mesh("../../../etc/passwd","red"); }"#,
        "m.vcad",
        &opts,
    )
    .expect_err("outside");
    assert_eq!((e.line, e.column), (Some(1), Some(15)), "{e}");
    let e =
        run_vcad(r#"union(){ mesh("no_such.stl","red"); }"#, "m.vcad", &opts).expect_err("missing");
    assert!(e.message.contains("no_such.stl"), "{e}");
}

#[test]
fn a_mesh_beside_the_design_is_read() {
    let dir = tempfile::tempdir().expect("temp dir");
    // A 2 mm cube centred at the origin, 12 outward-facing triangles.
    let obj = "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n\
               f 1 3 2\nf 1 4 3\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\n\
               f 2 3 7\nf 2 7 6\nf 3 4 8\nf 3 8 7\nf 4 1 5\nf 4 5 8\n";
    std::fs::write(dir.path().join("cube.obj"), obj).expect("write");
    let opts = ScriptOptions::for_file(&dir.path().join("part.vcad"));
    let d = run_vcad(
        r#"union(){ translate(1,0,0){ mesh("cube.obj","blue"); } }"#,
        "part.vcad",
        &opts,
    )
    .expect("mesh");
    let m = Model::prepare(&d.root, d.materials).expect("prepare");
    let (dist, fr) = m.eval_point(DVec3::new(1.5, 0.2, 0.0));
    assert!((dist + 0.5).abs() < 1e-9, "{dist}");
    assert_eq!(fr, vec![(3, 1.0)]);
    assert!((m.distance(DVec3::new(3.0, 0.0, 0.0)) - 1.0).abs() < 1e-9);
}
