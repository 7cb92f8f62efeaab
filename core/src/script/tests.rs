use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use glam::DVec3;

use super::*;
use crate::Model;

fn run(src: &str) -> Result<Design, ScriptError> {
    run_script(src, "t.rhai", &ScriptOptions::default())
}

fn model(src: &str) -> Model {
    let d = run(src).unwrap_or_else(|e| panic!("{e}"));
    Model::prepare(&d.root, d.materials.clone()).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn paper_forms_work_as_written() {
    let m = model(
        r#"
        let materials = default_materials();
        let bar = RectPrism(Vec3(0,0,0), Vec3(15,10,5), materials.id("gray"));
        let g = FGrade(["x/15+0.5", "-x/15+0.5"], [materials.id("red"), materials.id("blue")], true, bar);
        let u = Union();
        u.add_child(g);
        u.add_child(Sphere(Vec3(0, 0, 0), 10, materials.id("green")));
        let a = Strut(Vec3(0,0,0), Vec3(1,1,1), 0.5, materials.id("red"));
        let b = Union(false, [a, Translate(5, 0, 0, a)]);
        let c = Intersection(false, [Tile(GraphLattice(LatticeType::BodyCenteredCubic, Vec3(5,5,5), 0.175, materials.id("red"))), Sphere(Vec3(0,0,0), 10, 3)]);
        let d = Difference(b, c);
        Union(false, [u, d])
        "#,
    );
    let (d, f) = m.eval_point(DVec3::new(7.5, 0.0, 0.0));
    assert!(d <= 0.0);
    // FGrade at x = 7.5: red 1.0, blue 0.0.
    assert_eq!(f.iter().find(|(id, _)| *id == 1).unwrap().1, 1.0);
}

#[test]
fn root_variable_is_the_design() {
    let d = run("let root = Sphere(Vec3(0,0,0), 1, 1); let x = 3;").unwrap();
    assert_eq!(d.root.kind().type_name(), "Sphere");
}

#[test]
fn wrong_argument_types_are_named_in_the_script_s_words() {
    let m = "let m = default_materials();\nlet a = Sphere(Vec3(0,0,0), 1, m.id(\"red\"));\n";
    for (call, got) in [
        ("Intersection(a, a)", "write Intersection(false, [a, b])"),
        ("Union(a, [a])", "write Union(false, [a, b])"),
        ("Difference(a, 2)", "got an integer"),
        ("Sphere(Vec3(0,0,0), \"big\", 1)", "got a string"),
        ("Sphere(1, 1, 1)", "got an integer"),
        ("Union(false, [a, Vec3(1,1,1)])", "got a Vec3"),
        ("Union(false, [a, m])", "got a MaterialDefs"),
        ("Union(1.5, [a])", "got an array"),
    ] {
        let e = run(&format!("{m}{call}")).unwrap_err();
        assert!(e.message.contains(got), "{call}: {e}");
        assert!(!e.message.contains("::"), "{call}: {e}");
    }
}

#[test]
fn errors_carry_line_and_column() {
    let e = run("let m = default_materials();\nlet s = Sphere(Vec3(0,0,0), -1, m.id(\"red\"));\ns")
        .unwrap_err();
    assert_eq!(e.line, Some(2), "{e}");
    assert!(e.message.contains("radius must be > 0"), "{e}");
    assert!(e.to_string().starts_with("t.rhai:2:"), "{e}");
}

#[test]
fn wrong_arguments_and_unknown_functions_read_as_script_words() {
    let e = run(
        "let m = default_materials();\nTile(Sphere(Vec3(0,0,0), 1, m.id(\"red\")), Vec3(3,3,3))",
    )
    .unwrap_err();
    assert_eq!(e.line, Some(2), "{e}");
    assert!(
        e.message.contains("no form of `Tile` takes (Node, Vec3)"),
        "{e}"
    );
    assert!(!e.message.contains("volcad_core"), "{e}");
    let e = run("let m = default_materials();\nSpher(Vec3(0,0,0), 1, m.id(\"red\"))").unwrap_err();
    assert!(
        e.message
            .contains("unknown function `Spher`; did you mean `Sphere`?"),
        "{e}"
    );
    let e = run("Frobnicate(1.0)").unwrap_err();
    assert_eq!(e.message, "unknown function `Frobnicate`", "{e}");
}

#[test]
fn unknown_material_suggests() {
    let e = run("let m = default_materials();\nSphere(Vec3(0,0,0), 1, m.id(\"rde\"))").unwrap_err();
    assert_eq!(e.line, Some(2));
    assert!(e.message.contains("\"red\""), "{e}");
}

#[test]
fn expression_error_points_at_fgrade() {
    let e = run("let b = Sphere(Vec3(0,0,0), 1, 1);\n\nFGrade([\"x/\", \"1\"], [1, 3], true, b)")
        .unwrap_err();
    assert_eq!(e.line, Some(3), "{e}");
    assert!(e.message.contains("FGrade: expression 1"), "{e}");
}

#[test]
fn syntax_error_has_position() {
    let e = run("let x = ;").unwrap_err();
    assert_eq!(e.line, Some(1));
    assert!(e.column.is_some());
}

#[test]
fn runaway_script_stops() {
    let opts = ScriptOptions {
        max_operations: 100_000,
        ..ScriptOptions::default()
    };
    let e = run_script("loop { }", "t.rhai", &opts).unwrap_err();
    assert!(e.message.contains("too many operations"), "{e}");
    let cancel = Arc::new(AtomicBool::new(true));
    let opts = ScriptOptions {
        cancel: Some(cancel),
        ..ScriptOptions::default()
    };
    let e = run_script("loop { }", "t.rhai", &opts).unwrap_err();
    assert!(e.message.contains("cancelled"), "{e}");
}

#[test]
fn bulk_allocations_are_checked_and_keep_rhai_semantics() {
    let opts = ScriptOptions {
        max_heap: 64 << 20,
        ..ScriptOptions::default()
    };
    let design = |body: &str| {
        format!("let m = default_materials();\n{body}\nSphere(Vec3(0,0,0), 1, m.id(\"red\"))")
    };
    for (call, what) in [
        (
            "let a = []; a.pad(100000000000, 0);",
            "pad: 100000000000 would need 1.5 TiB",
        ),
        (
            "let s = \"\"; s.pad(100000000000, \"x\");",
            "pad: 100000000000 would need",
        ),
        (
            "let s = \"\"; s.pad(100000000000, 'x');",
            "pad: 100000000000 would need 93 GiB",
        ),
        (
            "let b = blob(100000000000);",
            "blob: 100000000000 would need 93 GiB",
        ),
    ] {
        let e = run_script(&design(call), "t.rhai", &opts).unwrap_err();
        assert!(e.message.contains(what), "{call}: {e}");
        assert!(e.message.contains("budget of 64 MiB"), "{e}");
        assert_eq!(e.line, Some(2), "{e}");
    }
    // Within the budget: what Rhai's own functions give.
    let checks = r#"
        let a = [1]; a.pad(3, 7); if a != [1, 7, 7] { throw "array " + a; }
        a.pad(2, 0); if a.len() != 3 { throw "array shrank"; }
        let s = "ab"; s.pad(5, '-'); if s != "ab---" { throw "char " + s; }
        let t = "é"; t.pad(6, "xyz"); if t != "éxyzxy" { throw "string " + t; }
        let b = blob(3, 0x1ff); if b.len() != 3 || b[0] != 0xff { throw "blob"; }
        b.pad(4, 2); if b[3] != 2 { throw "blob pad"; }
        if blob(-1).len() != 0 { throw "negative"; }
    "#;
    run_script(&design(checks), "t.rhai", &opts).expect("same semantics as Rhai");
}

#[test]
fn no_design_is_an_error() {
    let e = run("let x = 1;").unwrap_err();
    assert!(e.message.contains("built no design"), "{e}");
}

#[test]
fn params_default_and_override() {
    let src = "let r = param(\"radius\", 2.0, 1.0, 5.0); Sphere(Vec3(0,0,0), r, 1)";
    let d = run(src).unwrap();
    assert_eq!(d.params[0].value, 2.0);
    let mut opts = ScriptOptions::default();
    opts.params.insert("radius".into(), 9.0);
    let d = run_script(src, "t", &opts).unwrap();
    assert_eq!(d.params[0].value, 5.0, "clamped to max");
}

#[test]
fn files_need_a_folder_and_stay_inside_it() {
    let e = run("read_csv(\"a.csv\")").unwrap_err();
    assert!(e.message.contains("save the script first"), "{e}");
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path();
    std::fs::create_dir_all(dir.join("sub")).unwrap();
    std::fs::write(dir.join("sub/s.csv"), "x1,y1,name\n1,2,a\n3.5,4,b\n").unwrap();
    let opts = ScriptOptions {
        base_dir: Some(dir.join("sub")),
        ..ScriptOptions::default()
    };
    let d = run_script(
        "let t = 0.0; for r in read_csv(\"s.csv\") { t += r.x1; } Sphere(Vec3(0,0,0), t, 1)",
        "t",
        &opts,
    )
    .unwrap();
    let m = Model::prepare(&d.root, d.materials).unwrap();
    assert!((m.distance(DVec3::ZERO) + 4.5).abs() < 1e-12);
    std::fs::write(dir.join("secret.csv"), "a\n1\n").unwrap();
    let e = run_script("read_csv(\"../secret.csv\")", "t", &opts).unwrap_err();
    assert!(e.message.contains("outside the project folder"), "{e}");
}

#[test]
fn len_without_displacement_columns_says_which_are_missing() {
    // Abaqus-style columns (u1, u2, u3) instead of dx, dy, dz: `len` does
    // not exist, and the error says why.
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path();
    std::fs::write(
        dir.join("t.inp"),
        "*NODE\n1, 0, 0, 0\n2, 1, 0, 0\n3, 0, 1, 0\n4, 0, 0, 1\n*ELEMENT, TYPE=C3D4\n1, 1, 2, 3, 4\n",
    )
    .unwrap();
    let rows = "1,0,0,0,0,0,0\n2,1,0,0,0,0,0\n3,0,1,0,0,0,0\n4,0,0,1,0,0,0\n";
    let opts = ScriptOptions::for_file(&dir.join("t.rhai"));
    let field = |header: &str| {
        std::fs::write(dir.join("t.csv"), format!("{header}\n{rows}")).unwrap();
        run_script(
            "SimulationField(\"t.inp\", \"t.csv\", [\"len\"], [1])",
            "t",
            &opts,
        )
    };
    let e = field("node_id,x,y,z,u1,u2,dz").unwrap_err();
    assert!(
        e.message.contains("unknown variable 'len'")
            && e.message.contains("`len` is the length of (dx, dy, dz)")
            && e.message.contains("t.csv has no columns dx, dy"),
        "{e}"
    );
    // With the columns there, `len` is known.
    field("node_id,x,y,z,dx,dy,dz").unwrap_or_else(|e| panic!("{e}"));
}

#[test]
fn material_id_not_in_table() {
    let e = run("let m = j750_materials();\nSphere(Vec3(0,0,0), 1, 40)").unwrap_err();
    assert_eq!(e.line, Some(2), "{e}");
    assert!(e.message.contains("unknown material id 40"), "{e}");
}

#[test]
fn print_goes_to_the_log() {
    let d = run("print(\"hello\"); Sphere()").unwrap();
    assert_eq!(d.log, vec!["hello".to_string()]);
}

#[test]
fn prepare_errors_name_the_node() {
    let d = run("let t = Translate(1, 2, 3);\nt").unwrap();
    let e = Model::prepare(&d.root, d.materials).unwrap_err();
    assert!(e.to_string().contains("Translate (made at line 1:"), "{e}");
}
