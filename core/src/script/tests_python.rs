//! Python's number semantics in scripts (issue 34 item 1): every operator on
//! every pair of integer and float, the shapes that went silently wrong
//! with Rhai's integer division, and a ported pyvcad listing.

use glam::DVec3;

use super::*;
use crate::Model;

fn run(src: &str) -> Result<Design, ScriptError> {
    run_script(src, "t.rhai", &ScriptOptions::default())
}

/// The value of `expr` in a script: its type (`i64`, `f64`, `bool`) and
/// its printed text.
fn value(expr: &str) -> (String, String) {
    let src = format!("let v = {expr};\nprint(type_of(v));\nprint(v);\nSphere(Vec3(0,0,0), 1, 1)");
    let d = run(&src).unwrap_or_else(|e| panic!("{expr}: {e}"));
    (d.log[0].clone(), d.log[1].clone())
}

/// What Python 3 gives, as type and value.
#[derive(Debug)]
enum Py {
    Int(i64),
    Float(f64),
    Bool(bool),
}

fn check(expr: &str, want: Py) {
    let (ty, text) = value(expr);
    let ok = match want {
        Py::Int(i) => ty == "i64" && text.parse::<i64>() == Ok(i),
        Py::Float(f) => ty == "f64" && text.parse::<f64>().is_ok_and(|g| g == f),
        Py::Bool(b) => ty == "bool" && text.parse::<bool>() == Ok(b),
    };
    assert!(ok, "{expr}: got {ty} {text}, Python gives {want:?}");
}

#[test]
fn every_operator_on_every_pair_is_python_s() {
    use Py::*;
    // Python 3.12's results for the same expressions (`//` spelled
    // floor_div).
    let cases = [
        ("7 + 2", Int(9)),
        ("7 + 2.5", Float(9.5)),
        ("7.5 + 2", Float(9.5)),
        ("7 - 2", Int(5)),
        ("7 - 2.5", Float(4.5)),
        ("7.5 - 2", Float(5.5)),
        ("7 * 2", Int(14)),
        ("7 * 2.5", Float(17.5)),
        ("7.5 * 2", Float(15.0)),
        ("7 / 2", Float(3.5)),
        ("-7 / 2", Float(-3.5)),
        ("7 / 2.5", Float(2.8)),
        ("7.5 / 2", Float(3.75)),
        ("6 / 3", Float(2.0)),
        ("1 / 3", Float(1.0 / 3.0)),
        ("7 % 3", Int(1)),
        ("-7 % 3", Int(2)),
        ("7 % -3", Int(-2)),
        ("-7 % -3", Int(-1)),
        ("7.5 % 2", Float(1.5)),
        ("-7.5 % 2", Float(0.5)),
        ("7 % -2.5", Float(-0.5)),
        ("-7 % 2.5", Float(0.5)),
        ("6 % 3.0", Float(0.0)),
        ("2 ** 10", Int(1024)),
        ("2 ** -1", Float(0.5)),
        ("2 ** 0.5", Float(std::f64::consts::SQRT_2)),
        ("2.5 ** 2", Float(6.25)),
        ("(-8) ** 2", Int(64)),
        ("floor_div(7, 2)", Int(3)),
        ("floor_div(-7, 2)", Int(-4)),
        ("floor_div(7, -2)", Int(-4)),
        ("floor_div(-7.0, 2)", Float(-4.0)),
        ("floor_div(7.5, 2)", Float(3.0)),
        ("floor_div(7, 0.1)", Float(69.0)),
        ("2 < 2.5", Bool(true)),
        ("3 == 3.0", Bool(true)),
        ("2.5 >= 3", Bool(false)),
        ("3 != 3.0", Bool(false)),
        ("-1 <= -1.0", Bool(true)),
        ("5 / 2 == 2.5", Bool(true)),
        ("to_int(7 / 2)", Int(3)),
        ("to_int(-7 / 2)", Int(-3)),
        ("10 - 4 / 2", Float(8.0)),
        // math.sqrt(4), math.sin(0), max(2, 2.5) in Python.
        ("sqrt(4)", Float(2.0)),
        ("sin(0)", Float(0.0)),
        ("max(2, 2.5)", Float(2.5)),
    ];
    for (expr, want) in cases {
        check(expr, want);
    }
}

#[test]
fn assignment_forms_follow_the_operators() {
    use Py::*;
    check("{ let x = 5; x /= 2; x }", Float(2.5));
    check("{ let x = -7; x %= 3; x }", Int(2));
    check("{ let x = 2; x **= -2; x }", Float(0.25));
    check("{ let x = 1; x += 0.5; x }", Float(1.5));
    let d = run("let v = Vec3(2, 4, 6);\nv /= 2;\nprint(v.z);\nprint((Vec3(1, 1, 1) / 4).x);\nSphere(v, 1, 1)").unwrap();
    assert_eq!(d.log, ["3.0", "0.25"]);
}

#[test]
fn what_python_refuses_is_an_error_at_its_line() {
    for (expr, says) in [
        ("1 / 0", "division by zero"),
        ("1.5 / 0", "division by zero"),
        ("1 % 0", "modulo by zero"),
        ("floor_div(1, 0)", "division by zero"),
        ("0 ** -1", "negative power"),
        ("(-8) ** (1 / 3)", "complex"),
        ("2 ** 64", "does not fit"),
    ] {
        let e = run(&format!("let a = 1;\nlet b = {expr};\nb")).unwrap_err();
        assert!(e.message.contains(says), "{expr}: {e}");
        assert_eq!(e.line, Some(2), "{expr}: {e}");
    }
}

/// The nine shapes that moved parts with Rhai's integer division, each
/// with integer/integer, integer/float and float/integer operands: the
/// model must hold Python's numbers.
#[test]
fn the_nine_failure_shapes_give_python_s_numbers() {
    let sphere_at = |src: &str| {
        let d = run(src).unwrap_or_else(|e| panic!("{src}: {e}"));
        let m = Model::prepare(&d.root, d.materials).unwrap();
        let b = m.bbox();
        (b.min, b.max)
    };
    // Centres `-r/2`: a sphere of radius 1 centred at x = -r/2.
    for (r, want) in [("5", -2.5), ("5.0", -2.5), ("5", -2.5)] {
        for den in ["2", "2.0"] {
            let (lo, hi) = sphere_at(&format!("r = {r};\nSphere(Vec3(-r/{den}, 0, 0), 1, 1)"));
            assert_eq!((lo.x + hi.x) / 2.0, want, "r = {r}, /{den}");
        }
    }
    // Loop fractions `i/(n-1)`: spheres at x = 10 i/(n-1) for n = 4.
    for n in ["4", "4.0"] {
        let src = format!(
            "n = {n};\nparts = [];\nfor i in range(0, 4) {{ t = i/(n-1); parts.push(Sphere(Vec3(10*t, 0, 0), 0.1, 1)); }}\nprint(t);\nUnion(false, parts)"
        );
        let d = run(&src).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(d.log, ["1.0"], "n = {n}");
        let m = Model::prepare(&d.root, d.materials).unwrap();
        for i in 0..4 {
            let x = 10.0 * i as f64 / 3.0;
            assert!(
                (m.distance(DVec3::new(x, 0.0, 0.0)) + 0.1).abs() < 1e-12,
                "i = {i}"
            );
        }
    }
    // Sizes `w/count`: a box of width w/count.
    for (w, count) in [("10", "4"), ("10", "4.0"), ("10.0", "4")] {
        let (lo, hi) = sphere_at(&format!(
            "w = {w};\ncount = {count};\nRectPrism(Vec3(0,0,0), Vec3(w/count, 1, 1), 1)"
        ));
        assert_eq!(hi.x - lo.x, 2.5, "w = {w}, count = {count}");
    }
}

#[test]
fn where_an_integer_is_needed_the_error_says_floor_div_or_to_int() {
    for (src, col) in [
        ("n = 6;\na = [1, 2, 3, 4];\na[n/2]", 4),
        ("n = 6;\nfor i in 0..n/2 { }", 11),
        ("n = 6;\nfor i in range(0, n/2) { }", 10),
        ("n = 6;\n\"abcdef\".sub_string(n/3)", 10),
    ] {
        let e = run(src).unwrap_err();
        assert!(
            e.message.contains("floor_div(a, b)") && e.message.contains("to_int(x)"),
            "{src}: {e}"
        );
        assert_eq!(
            (e.line, e.column),
            (Some(if src.contains("a = [") { 3 } else { 2 }), Some(col)),
            "{src}: {e}"
        );
    }
    // Written as the message says, they run.
    let d = run("n = 6;\na = [1, 2, 3, 4];\nprint(a[floor_div(n, 2)]);\nfor i in 0..to_int(n/2) { print(i); }\nSphere(Vec3(0,0,0), 1, 1)").unwrap();
    assert_eq!(d.log, ["4", "0", "1", "2"]);
}

/// A pyvcad listing with integer literals, ported line by line (Python's
/// `//` as floor_div, statements ending in `;`), compared with the values pyvcad 2.3.4 printed for the Python
/// listing at the same points (`root.evaluate(x, y, z)` after `prepare`).
#[test]
fn a_ported_pyvcad_listing_agrees_with_pyvcad() {
    let src = "\
radius = 5;
count = 4;
w = 10;
n = 5;
h = 7;
parts = [Sphere(Vec3(-radius/2, 0, 0), radius/2, 1)];
for i in range(n) {
    t = i/(n-1);
    parts.push(Sphere(Vec3(t*w, 0, h/2), w/count/3, 2));
}
parts.push(RectPrism(Vec3(w/2, -w/count, -h/2), Vec3(w/count, w/3, h/2), 1));
parts.push(Translate(-w % 3, floor_div(7, 2), 2**-1, Sphere(Vec3(0,0,0), 1/2, 2)));
root = Union(false, parts);
root.prepare(Vec3(0.1, 0.1, 0.1), 0.001, 0.001);
print(root.evaluate(6.2, 0.9, -3.2));
";
    let d = run(src).unwrap_or_else(|e| panic!("{e}"));
    let m = Model::prepare(&d.root, d.materials).unwrap();
    // pyvcad 2.3.4: root.evaluate at these points.
    let pyvcad = [
        ([-2.5, 0.0, 0.0], -2.5),
        ([0.0, 0.0, 0.0], 0.0),
        ([-4.9, 0.3, 0.1], -0.07925631261795907),
        ([2.5, 0.0, 3.5], -0.8333333333333334),
        ([3.3, 0.0, 3.5], -0.03333333333333355),
        ([5.0, -2.5, -3.5], -1.25),
        ([6.2, 0.9, -3.2], 1.733333373069763),
        ([2.0, 3.0, 0.5], -0.5),
        ([-1.0, 0.1, 0.2], -0.9834249111896898),
        ([7.5, 0.0, 3.6], -0.7333333333333333),
        ([10.7, 0.0, 3.5], -0.13333333333333408),
        ([4.1, -3.4, -5.2], -0.04999999999999982),
    ];
    for (p, want) in pyvcad {
        let got = m.distance(DVec3::from_array(p));
        // pyvcad keeps some sizes in single precision (1.7333333731).
        assert!((got - want).abs() < 1e-6, "{p:?}: {got} vs pyvcad {want}");
    }
    let printed: f64 = d.log[0].parse().unwrap();
    assert!((printed - 1.733333373069763).abs() < 1e-6, "{printed}");
    // pyvcad 2.3.4: root.bounding_box().
    let b = m.bbox();
    let want = [
        -5.0,
        -4.166666507720947,
        -5.25,
        10.833333015441895,
        3.5,
        4.333333492279053,
    ];
    let got = [b.min.x, b.min.y, b.min.z, b.max.x, b.max.y, b.max.z];
    for (g, w) in got.iter().zip(want) {
        assert!((g - w).abs() < 1e-6, "bbox {got:?} vs pyvcad {want:?}");
    }
}
