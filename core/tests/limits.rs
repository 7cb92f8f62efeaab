//! Pathological scripts end quickly with an error that names the line, or
//! prepare in bounded time and memory: endless loops, nodes added to
//! themselves, thousands of coincident children, sizes of 1e308.

// A test crate: its helper functions stop on a failed setup as its tests do.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::sync::Arc;
use std::time::{Duration, Instant};

use volcad_core::script::{DEFAULT_MAX_OPERATIONS, ScriptOptions, run_script};
use volcad_core::{DVec3, MaterialTable, Model, Node, NodeKind};

fn prepare(src: &str) -> Result<Model, String> {
    let d = run_script(src, "t.rhai", &ScriptOptions::default()).map_err(|e| e.to_string())?;
    Model::prepare(&d.root, d.materials).map_err(|e| e.to_string())
}

#[test]
fn an_endless_loop_stops_on_the_default_operation_limit() {
    // 500 million operations took 25 to 51 s to stop; scripts run 10 to 20
    // million a second.
    const { assert!(DEFAULT_MAX_OPERATIONS <= 50_000_000) };
    let src = "let i = 0;\nwhile true { i += 1; }";
    let start = Instant::now();
    let e = run_script(src, "loop.rhai", &ScriptOptions::default()).expect_err("stops");
    assert!(e.message.contains("too many operations"), "{e}");
    assert_eq!(e.line, Some(2), "{e}");
    eprintln!("the endless loop stopped after {:?}", start.elapsed());
}

#[test]
fn every_example_runs_within_a_tenth_of_the_operation_limit() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/examples");
    let mut ran = 0;
    for entry in std::fs::read_dir(&dir).expect("examples") {
        let path = entry.expect("entry").path();
        if path.extension().is_none_or(|e| e != "rhai") {
            continue;
        }
        let src = std::fs::read_to_string(&path).expect("read");
        let opts = ScriptOptions {
            max_operations: DEFAULT_MAX_OPERATIONS / 10,
            ..ScriptOptions::for_file(&path)
        };
        if let Err(e) = run_script(&src, &path.display().to_string(), &opts) {
            panic!("{}: {e}", path.display());
        }
        ran += 1;
    }
    assert!(ran >= 10, "ran {ran} examples");
}

#[test]
fn a_union_added_to_itself_prepares_in_linear_time() {
    // A DAG of 26 nodes that a tree walk expands to 2^25 paths.
    let src = "let m = default_materials();\n\
               let a = Union(false, [Sphere(Vec3(0,0,0), 1, m.id(\"red\"))]);\n\
               for i in 0..25 { a.add_child(a); }\n\
               a";
    let start = Instant::now();
    let m = prepare(src).expect("prepares");
    assert!(
        start.elapsed() < Duration::from_secs(5),
        "{:?}",
        start.elapsed()
    );
    assert!((m.distance(DVec3::new(3.0, 0.0, 0.0)) - 2.0).abs() < 1e-12);

    // A smooth union cannot be read flat: refused with the count.
    let smooth = src.replace("Union(false,", "Union(0.5, false,");
    let e = prepare(&smooth).expect_err("refused");
    assert!(
        e.contains("expands to") && e.contains("a.add_child(a)"),
        "{e}"
    );
}

fn sphere(c: DVec3, r: f64) -> Node {
    Node::new(NodeKind::Sphere {
        center: c,
        radius: r,
        material: 1,
    })
}

#[test]
fn five_thousand_coincident_spheres_prepare_in_bounded_time() {
    let table = Arc::new(MaterialTable::default_table());
    // Identical ones (listed once) and ones that differ in the radius (the
    // union index's lists stay within their budget).
    for step in [0.0, 1e-6] {
        let children = (0..5000)
            .map(|i| sphere(DVec3::ZERO, 1.0 + step * i as f64))
            .collect();
        let root = Node::new(NodeKind::Union {
            smooth: 0.0,
            blend: false,
            children,
        });
        let start = Instant::now();
        let m = Model::prepare(&root, table.clone()).expect("prepares");
        assert!(
            start.elapsed() < Duration::from_secs(20),
            "{:?}",
            start.elapsed()
        );
        let want = -1.0 - step * 4999.0;
        assert!((m.distance(DVec3::ZERO) - want).abs() < 1e-9);
        assert!((m.distance(DVec3::new(3.0, 0.0, 0.0)) - (2.0 + want + 1.0)).abs() < 1e-9);
    }
}

#[test]
fn sizes_beyond_1e9_mm_are_refused_where_they_are_given() {
    for (line3, what) in [
        (
            "Sphere(Vec3(0,0,0), 1e308, m.id(\"red\"))",
            "Sphere: radius",
        ),
        (
            "Sphere(Vec3(1,0,0) * 1e308, 1, m.id(\"red\"))",
            "Sphere: center",
        ),
        (
            "RectPrism(Vec3(0,0,0), Vec3(1, 1, 2e9), m.id(\"red\"))",
            "Vec3: z",
        ),
        (
            "Translate(0, 1e300, 0, Sphere(Vec3(0,0,0), 1, m.id(\"red\")))",
            "Translate: y",
        ),
        (
            "Scale(1, 1e-300, 1, Sphere(Vec3(0,0,0), 1, m.id(\"red\")))",
            "Scale: factors",
        ),
    ] {
        let src = format!("let m = default_materials();\n\n{line3}");
        let e = run_script(&src, "big.rhai", &ScriptOptions::default()).expect_err(what);
        assert_eq!(e.line, Some(3), "{e}");
        assert!(e.message.contains(what), "{e}");
        assert!(
            e.message.contains("1e9") || e.message.contains("1e-9"),
            "{e}"
        );
    }
}

#[test]
fn scripts_that_nest_their_design_in_a_loop_prepare_and_evaluate() {
    // The fuzzing run's reproducers: each overflowed the stack of `volcad
    // info`, `eval` and `export`.
    let cases = [
        (
            "for i in 0..10000 { n = Union(false, [n, Sphere(Vec3(i, 0, 0), 1, red)]); }",
            DVec3::new(9999.0, 0.0, 0.0),
            -1.0,
        ),
        (
            "for i in 0..3000 { n = Union(false, [n]); }",
            DVec3::ZERO,
            -1.0,
        ),
        (
            "for i in 0..200000 { n = Translate(0.00001, 0, 0, n); }",
            DVec3::new(2.0, 0.0, 0.0),
            -1.0,
        ),
    ];
    for (body, p, want) in cases {
        let src = format!(
            "let m = default_materials();\nlet red = m.id(\"red\");\n\
             let n = Sphere(Vec3(0,0,0), 1, red);\n{body}\nn"
        );
        let handle = std::thread::Builder::new()
            .stack_size(2 << 20)
            .spawn(move || {
                let m = prepare(&src).expect("prepares");
                let d = m.distance(p);
                let (d2, fracs) = m.eval_point(p);
                assert_eq!(d, d2);
                assert!(!fracs.is_empty());
                d
            })
            .expect("spawn");
        let d = handle.join().expect("no panic");
        assert!((d - want).abs() < 1e-6, "{body}: {d}");
    }
}
