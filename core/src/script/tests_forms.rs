//! Script forms pyvcad users write (issue 34 item 2): names without `let`,
//! functions that read top-level values, the builder methods, node queries
//! and the BBox names; and reads inside the project (item 3).

use glam::DVec3;

use super::*;
use crate::Model;

fn run(src: &str) -> Result<Design, ScriptError> {
    run_script(src, "t.rhai", &ScriptOptions::default())
}

fn log(src: &str) -> Vec<String> {
    run(src).unwrap_or_else(|e| panic!("{e}")).log
}

#[test]
fn names_without_let_work_as_in_python() {
    let d = run("W = 10;\nroot = Sphere(Vec3(0, 0, 0), W / 4, 1);").unwrap();
    let m = Model::prepare(&d.root, d.materials).unwrap();
    assert_eq!(m.distance(DVec3::ZERO), -2.5);
    // A name first assigned inside a top-level loop or `if` is seen after
    // it, as in Python.
    assert_eq!(
        log(
            "for i in range(0, 3) { last = i; }\nif true { flag = \"on\"; }\nprint(last); print(flag);\nSphere(Vec3(0,0,0), 1, 1)"
        ),
        ["2", "on"]
    );
    // `let` inside a block keeps Rhai's meaning: local to the block.
    assert_eq!(
        log("x = 1;\nif true { let x = 2; print(x); }\nprint(x);\nSphere(Vec3(0,0,0), 1, 1)"),
        ["2", "1"]
    );
    // Top-level `let` and `const` still work, and re-assignment too.
    assert_eq!(
        log("let a = 1;\nconst K = 3;\na = a + K;\nprint(a);\nSphere(Vec3(0,0,0), 1, 1)"),
        ["4"]
    );
}

#[test]
fn functions_read_top_level_values_at_the_time_of_the_call() {
    let src = "\
W = 10;
let H = 4;
fn plate(t) { RectPrism(Vec3(0, 0, 0), Vec3(W, H, t), 1) }
fn width() { W }
print(width());
W = 20;
print(width());
root = plate(2);
";
    let d = run(src).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(d.log, ["10", "20"]);
    let m = Model::prepare(&d.root, d.materials).unwrap();
    assert_eq!(m.bbox().max.x - m.bbox().min.x, 20.0);
    // Through a function calling a function, and in closures.
    assert_eq!(
        log(
            "W = 2;\nfn inner() { W * 10 }\nfn outer() { inner() + W }\nprint(outer());\nprint([1, 2].map(|v| v * W));\nSphere(Vec3(0,0,0), 1, 1)"
        ),
        ["22", "[2, 4]"]
    );
    // A parameter or a local of the same name wins over the top level.
    assert_eq!(
        log(
            "W = 1;\nfn f(W) { W }\nfn g() { let W = 3; W }\nprint(f(2)); print(g());\nSphere(Vec3(0,0,0), 1, 1)"
        ),
        ["2", "3"]
    );
}

#[test]
fn what_functions_cannot_do_with_top_level_values_is_explained() {
    let e = run("fn f() { W }\nprint(f());\nW = 2;").unwrap_err();
    assert!(e.message.contains("before the top level assigns it"), "{e}");
    assert_eq!(e.line, Some(1), "{e}");
    let e = run("W = 1;\nfn f() { W = 3; }\nf();").unwrap_err();
    assert!(e.message.contains("`let W = ...`"), "{e}");
    assert!(e.message.contains("return the new value"), "{e}");
    let e = run("K = 1;\nfn f() { global::K }\nf()").unwrap_err();
    assert!(e.message.contains("write `K`"), "{e}");
    let e = run("fn f() { Q }\nf()").unwrap_err();
    assert!(e.message.contains("unknown name `Q`"), "{e}");
    // Read before any assignment at the top level: named, not a bare "()".
    let e = run("Sphere(Vec3(0,0,0), R, 1);\nR = 1;").unwrap_err();
    assert!(e.message.contains("`R`, which has no value yet"), "{e}");
    assert_eq!(
        log("print(R);\nR = 1;\nSphere(Vec3(0,0,0), R, 1)"),
        ["<R: no value yet>"]
    );
    let e = run("x = R + 1;\nR = 1;").unwrap_err();
    assert!(e.message.contains("no value yet"), "{e}");
}

#[test]
fn errors_keep_their_columns_after_let_is_removed() {
    let e = run("let m = default_materials();\nlet s = Sphere(Vec3(0,0,0), -1, m.id(\"red\"));")
        .unwrap_err();
    assert_eq!((e.line, e.column), (Some(2), Some(9)), "{e}");
    let e = run("let a = 1;\nlet b = ;").unwrap_err();
    assert_eq!(e.line, Some(2), "{e}");
}

#[test]
fn builder_methods_fill_the_slots() {
    let src = "\
d = Difference();
d.set_left(Sphere(Vec3(0, 0, 0), 2, 1));
d.set_right(Sphere(Vec3(2, 0, 0), 1, 1));
t = Translate(0, 0, 5);
t.set_child(d);
u = Union();
u.add_child(t);
u.add_child(Sphere(Vec3(0, 0, -5), 1, 1));
print(t.evaluate(1.5, 0, 5));
print(t.evaluate(-1, 0, 5));
u
";
    let d = run(src).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(d.log, ["0.5", "-1.0"]);
    for (call, says) in [
        (
            "Sphere(Vec3(0,0,0), 1, 1).set_left(Sphere(Vec3(0,0,0), 1, 1))",
            "set_left is for Difference",
        ),
        (
            "Union().set_child(Sphere(Vec3(0,0,0), 1, 1))",
            "set_child is for single-child nodes",
        ),
        (
            "Translate(1, 0, 0).add_child(Sphere(Vec3(0,0,0), 1, 1))",
            "use set_child",
        ),
    ] {
        let e = run(call).unwrap_err();
        assert!(e.message.contains(says), "{call}: {e}");
    }
}

#[test]
fn node_queries_answer_as_pyvcad() {
    let src = "\
s = Sphere(Vec3(0, 0, 0), 5, 1);
s.prepare(Vec3(0.1, 0.1, 0.1), 0.001, 0.001);
print(s.evaluate(1, 2, 3));
print(s.evaluate(10, 0, 0));
b = s.bounding_box();
print(b[0].x); print(b[1].z);
g = FGrade([\"x/10+0.5\", \"0.5-x/10\"], [1, 2], false, RectPrism(Vec3(0,0,0), Vec3(10,10,10), 2));
f = g.distribution(1, 0, 0);
print(f[1]); print(f[2]); print(f.len());
print(g.distribution(20, 0, 0)[1]);
g
";
    let d = run(src).unwrap_or_else(|e| panic!("{e}"));
    let v: Vec<f64> = d.log.iter().map(|s| s.parse().unwrap()).collect();
    // pyvcad 2.3.4: s.evaluate(1, 2, 3) = -1.2583426132260591,
    // s.evaluate(10, 0, 0) = 5.0, bounding box (-5,-5,-5)..(5,5,5),
    // g.distribution(1, 0, 0) = {2: 0.40000000596, 1: 0.60000002384}
    // (single precision), and {} outside.
    assert!((v[0] + 1.2583426132260591).abs() < 1e-12, "{v:?}");
    assert_eq!(v[1], 5.0);
    assert_eq!((v[2], v[3]), (-5.0, 5.0));
    assert!(
        (v[4] - 0.6).abs() < 1e-6 && (v[5] - 0.4).abs() < 1e-6,
        "{v:?}"
    );
    // One entry per material id of the default table.
    assert_eq!(v[6] as usize, MaterialTable::default_table().len());
    assert_eq!(v[7], 0.0);
    let e = run("Sphere(Vec3(0,0,0), 1, 1).evaluate(0, \"a\", 0)").unwrap_err();
    assert!(e.message.contains("evaluate: y must be a number"), "{e}");
    let e = run("Union().evaluate(0, 0, 0)").unwrap_err();
    assert!(e.message.starts_with("evaluate:"), "{e}");
}

#[test]
fn bbox_names_are_union_and_intersection() {
    let d = run("a = Sphere(Vec3(0,0,0), 2, 1);\nb = Sphere(Vec3(3,0,0), 2, 1);\nprint(BBoxUnion([a, b]).evaluate(4, 0, 0));\nprint(BBoxIntersection([a, b]).evaluate(1.5, 0, 0));\nu = BBoxUnion();\nu.add_child(a);\nu").unwrap();
    assert_eq!(d.log, ["-1.0", "-0.5"]);
    assert_eq!(d.root.kind().type_name(), "Union");
}

#[test]
fn scripts_read_inside_their_project_and_allowed_folders() {
    let t = tempfile::tempdir().unwrap();
    let r = t.path().canonicalize().unwrap();
    for d in ["p/.git", "p/examples", "p/data/3d_models", "elsewhere"] {
        std::fs::create_dir_all(r.join(d)).unwrap();
    }
    std::fs::write(r.join("p/data/3d_models/t.csv"), "v\n2\n").unwrap();
    std::fs::write(r.join("elsewhere/t.csv"), "v\n3\n").unwrap();
    let src = |path: &str| format!("r = read_csv(\"{path}\")[0].v;\nSphere(Vec3(0,0,0), r, 1)");
    let mut opts = ScriptOptions {
        base_dir: Some(r.join("p/examples")),
        home: None,
        ..ScriptOptions::default()
    };
    run_script(&src("../data/3d_models/t.csv"), "t.rhai", &opts).unwrap_or_else(|e| panic!("{e}"));
    let e = run_script(&src("../../elsewhere/t.csv"), "t.rhai", &opts).unwrap_err();
    assert!(
        e.message.contains(&format!(
            "outside the project folder {}",
            r.join("p").display()
        )),
        "{e}"
    );
    assert!(
        e.message
            .contains(&format!("--allow-read {}", r.join("elsewhere").display())),
        "{e}"
    );
    assert_eq!(e.line, Some(1));
    opts.allow_read.push(r.join("elsewhere"));
    run_script(&src("../../elsewhere/t.csv"), "t.rhai", &opts).unwrap_or_else(|e| panic!("{e}"));
}
