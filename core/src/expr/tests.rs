//! Language-level tests: values, precedence, errors, folding, interval containment.

use std::f64::consts::{E, PI};

use super::*;

/// Slots for `COORD_VARS` at x = 1.5, y = -2, z = 0.5, d = 0.25.
fn slots() -> [f64; 9] {
    let mut s = [1.5, -2.0, 0.5, 0.0, 0.0, 0.0, 0.0, 0.0, 0.25];
    fill_derived_coords(&mut s);
    s
}

fn compile(src: &str) -> Expr {
    Expr::compile(src, &COORD_VARS).unwrap_or_else(|e| panic!("{e}"))
}

fn ev(src: &str) -> f64 {
    compile(src).eval(&slots())
}

fn close(src: &str, want: f64) {
    let got = ev(src);
    let ok = (got.is_nan() && want.is_nan())
        || got == want
        || (got - want).abs() <= 1e-12 * want.abs().max(1.0);
    assert!(ok, "{src}: got {got}, want {want}");
}

fn err(src: &str) -> ExprError {
    match Expr::compile(src, &COORD_VARS) {
        Ok(e) => panic!("{src} compiled: {e:?}"),
        Err(e) => e,
    }
}

#[test]
fn numbers_and_constants() {
    close("1", 1.0);
    close("1.5", 1.5);
    close(".5", 0.5);
    close("1.5E2", 150.0);
    close("1e-3", 1e-3);
    close("pi", PI);
    close("PI", PI);
    close("e", E);
    close("epsilon", 1e-10);
    close("inf", f64::INFINITY);
    close("-inf", f64::NEG_INFINITY);
    close("true + TRUE", 2.0);
    close("false", 0.0);
}

#[test]
fn arithmetic_and_precedence() {
    close("1+2*3", 7.0);
    close("10-4-3", 3.0);
    close("8/4/2", 1.0);
    close("2^3^2", 512.0);
    close("-2^2", -4.0);
    close("2^-1", 0.5);
    close("(-2)^2", 4.0);
    close("-x^2", -2.25);
    close("2*-3", -6.0);
    close("--3", 3.0);
    close("+3", 3.0);
    close("7 % 3", 1.0);
    close("-7 % 3", -1.0);
    close("7.5 % -2", 1.5);
    close("2 + 3 % 2", 3.0);
    close("1/0", f64::INFINITY);
    close("0/0", f64::NAN);
    close("log(0)", f64::NEG_INFINITY);
    close("sqrt(-1)", f64::NAN);
    close(" ( 1 +\t2 ) *\n3 ", 9.0);
}

#[test]
fn comparisons_logic_and_ternary() {
    close("1 < 2", 1.0);
    close("2 < 1", 0.0);
    close("1 <= 1", 1.0);
    close("1 > 1", 0.0);
    close("1 >= 1", 1.0);
    close("1 == 1", 1.0);
    close("1 = 2", 0.0);
    close("1 != 2", 1.0);
    close("1 <> 1", 0.0);
    close("1 < 2 == 1", 1.0);
    close("3 > 2 > 1", 0.0); // (3 > 2) > 1 = 1 > 1
    close("1 + 1 == 2", 1.0);
    close("1 and 0", 0.0);
    close("1 and 2", 1.0);
    close("0 or 0", 0.0);
    close("0 or 3", 1.0);
    close("1 xor 1", 0.0);
    close("1 xor 0", 1.0);
    close("1 nand 1", 0.0);
    close("0 nor 0", 1.0);
    close("1 xnor 1", 1.0);
    close("1 & 0 | 1", 1.0);
    close("1 || 0 && 0", 1.0); // and binds tighter than or
    close("not 0", 1.0);
    close("NOT 5", 0.0);
    close("not 1 < 0", 1.0); // not (1 < 0)
    close("not 0 and 0", 0.0); // (not 0) and 0
    close("not (0) + 1", 0.0); // prefix operator: not ((0) + 1)
    close("0/0 and 1", 1.0); // NaN is truthy
    close("1 ? 2 : 3", 2.0);
    close("0 ? 2 : 3", 3.0);
    close("0 ? 1 : 0 ? 2 : 3", 3.0);
    close("1 ? 0 ? 5 : 6 : 7", 6.0);
    close("x > 1 ? x : -x", 1.5);
    close("1 < 2 ? 10 : 20", 10.0);
    close("1 ? 2 : 3 + 4", 2.0);
}

#[test]
fn every_function() {
    let cases: &[(&str, f64)] = &[
        ("abs(-2)", 2.0),
        ("avg(1, 2, 6)", 3.0),
        ("avg(5)", 5.0),
        ("ceil(1.2)", 2.0),
        ("floor(-1.2)", -2.0),
        ("round(2.5)", 3.0),
        ("round(-2.5)", -3.0),
        ("round(0.49999999999999994)", 0.0),
        ("roundn(1.23456, 2)", 1.23),
        ("roundn(-3.145, 2)", -3.15),
        ("trunc(-1.7)", -1.0),
        ("frac(-1.75)", -0.75),
        ("frac(2.25)", 0.25),
        ("sgn(-3)", -1.0),
        ("sgn(0)", 0.0),
        ("sgn(4)", 1.0),
        ("sqrt(16)", 4.0),
        ("root(27, 3)", 3.0),
        ("root(-8, 3)", -2.0),
        ("root(-16, 4)", f64::NAN),
        ("exp(1)", E),
        ("expm1(1e-10)", 1.00000000005e-10),
        ("log(e)", 1.0),
        ("log10(1000)", 3.0),
        ("log2(8)", 3.0),
        ("log1p(0)", 0.0),
        ("logn(81, 3)", 4.0),
        ("pow(2, 10)", 1024.0),
        ("hypot(3, 4)", 5.0),
        ("sin(pi/2)", 1.0),
        ("cos(0)", 1.0),
        ("tan(pi/4)", 1.0f64.atan().tan()),
        ("asin(1)", PI / 2.0),
        ("acos(1)", 0.0),
        ("atan(1)", PI / 4.0),
        ("atan2(1, 0)", PI / 2.0),
        ("atan2(0, -1)", PI),
        ("sinh(1)", 1f64.sinh()),
        ("cosh(1)", 1f64.cosh()),
        ("tanh(1)", 1f64.tanh()),
        ("asinh(1)", 1f64.asinh()),
        ("acosh(2)", 2f64.acosh()),
        ("atanh(0.5)", 0.5f64.atanh()),
        ("sec(0)", 1.0),
        ("csc(pi/2)", 1.0),
        ("cot(pi/4)", 1.0 / (PI / 4.0).tan()),
        ("sinc(0)", 1.0),
        ("sinc(pi)", PI.sin() / PI),
        ("deg2rad(180)", PI),
        ("rad2deg(pi)", 180.0),
        ("erf(0)", 0.0),
        ("erf(1)", 0.842_700_792_949_714_9),
        ("erfc(1)", 0.157_299_207_050_285_13),
        ("ncdf(0)", 0.5),
        ("ncdf(1.96)", 0.975_002_104_851_780_1),
        ("equal(1, 1 + 1e-12)", 1.0),
        ("equal(1, 1.001)", 0.0),
        ("equal(1e20, 1e20 + 1e9)", 1.0),
        ("min(3, 1, 2)", 1.0),
        ("max(3, 1, 2)", 3.0),
        ("min(7)", 7.0),
        ("sum(1, 2, 3, 4)", 10.0),
        ("mul(2, 3, 4)", 24.0),
        ("clamp(0, 1.5, 1)", 1.0),
        ("clamp(0, -1, 1)", 0.0),
        ("clamp(0, 0.25, 1)", 0.25),
        ("iclamp(0, 0.25, 1)", 0.0),
        ("iclamp(0, 0.75, 1)", 1.0),
        ("iclamp(0, 2, 1)", 2.0),
        ("inrange(0, 0.5, 1)", 1.0),
        ("inrange(0, 1, 1)", 1.0),
        ("inrange(0, 1.5, 1)", 0.0),
        ("if(1, 2, 3)", 2.0),
        ("if(0, 2, 3)", 3.0),
        ("If(x < 0, 2, 3)", 3.0),
    ];
    for &(src, want) in cases {
        close(src, want);
    }
    // Every function in the table is reachable by name.
    for f in functions::FUNCTIONS {
        let args = match f.arity() {
            Some(n) => vec!["0.5"; n].join(", "),
            None => "0.5, 0.25".into(),
        };
        let src = format!("{}({args})", f.name.to_uppercase());
        Expr::compile(&src, &COORD_VARS).unwrap_or_else(|e| panic!("{e}"));
    }
}

#[test]
fn variables_case_and_implicit_multiplication() {
    let s = slots();
    close("x", 1.5);
    close("X + Y + Z", 0.0);
    close("SIN(X)", 1.5f64.sin());
    close("rho", (1.5f64 * 1.5 + 4.0).sqrt());
    close("phic", (-2f64).atan2(1.5));
    close("theta", s[6]);
    close("r", (1.5f64 * 1.5 + 4.0 + 0.25).sqrt());
    close("phis", (0.5 / s[5]).acos());
    close("d", 0.25);
    close("2x", 3.0);
    close("2 x", 3.0);
    close("2(x+1)", 5.0);
    close("2pi", 2.0 * PI);
    close("2e", 2.0 * E);
    close("2sin(x)", 2.0 * 1.5f64.sin());
    close("1/2x", 0.75);
    close("2x^2", 4.5);
    close("3 and 0", 0.0);
    let e = err("(x)(y)");
    assert_eq!(e.position, 4);
}

#[test]
fn pyvcad_expressions() {
    close("x/15+0.5", 1.5 / 15.0 + 0.5);
    close("-x/15+0.5", -1.5 / 15.0 + 0.5);
    close("clamp(0, x/10 + 0.5, 1)", 0.65);
    close("1 - clamp(0, -d, 1)", 1.0);
    let g = "sin(x)*cos(y)+sin(y)*cos(z)+sin(z)*cos(x)";
    let (x, y, z) = (1.5f64, -2.0f64, 0.5f64);
    close(g, x.sin() * y.cos() + y.sin() * z.cos() + z.sin() * x.cos());
    let expr = compile(g);
    assert_eq!(expr.used_vars(), 0b111);
    assert_eq!(expr.constant(), None);
    assert_eq!(expr.source(), g);
}

#[test]
fn folding_and_used_vars() {
    let e = compile("2*pi");
    assert_eq!(e.constant(), Some(2.0 * PI));
    assert_eq!(e.used_vars(), 0);
    assert_eq!(e.tape_len(), 0);
    assert_eq!(e.eval(&[]), 2.0 * PI);
    assert_eq!(e.eval_interval(&[]), Interval::point(2.0 * PI));
    let mut out = [0.0; 3];
    e.eval_batch(&[], &mut out);
    assert_eq!(out, [2.0 * PI; 3]);
    let mut out = [0.0; 2];
    compile("z - x").eval_batch(&[&[1.0, 2.0], &[], &[5.0, 7.0, 9.0]], &mut out);
    assert_eq!(out, [4.0, 5.0]);
    assert_eq!(
        compile("sqrt(2) * 3 + max(1, 2, 3)").constant(),
        Some(2f64.sqrt() * 3.0 + 3.0)
    );
    assert_eq!(compile("1 ? 5 : x").constant(), Some(5.0));
    let e = compile("x/15+0.5");
    assert_eq!(e.constant(), None);
    assert_eq!(e.used_vars(), 1);
    assert_eq!(e.tape_len(), 3);
    assert_eq!(compile("d + rho").used_vars(), (1 << 8) | (1 << 3));
    assert_eq!(compile("z * 1").tape_len(), 1);
    assert_eq!(compile("0 ? x : y").used_vars(), 0b10);
    // Debug shows the listing.
    let dbg = format!("{:?}", compile("x/15+0.5"));
    assert!(dbg.contains("r0 = div_rc r0, 15"), "{dbg}");
    assert!(format!("{:?}", compile("1+1")).contains("constant: Some(2.0)"));
}

#[test]
fn error_positions_and_messages() {
    let e = err("x/");
    assert_eq!(e.position, 3);
    assert_eq!(
        e.message,
        "expected a number, variable, function or '(' after '/', but the expression ended"
    );
    assert_eq!(
        e.to_string(),
        "in expression \"x/\": at character 3: expected a number, variable, function or '(' after '/', but the expression ended"
    );

    let e = err("(x+1");
    assert_eq!(e.position, 5);
    assert_eq!(
        e.message,
        "expected ')' to close '(' at character 1, but the expression ended"
    );

    let e = err("foo(x)");
    assert_eq!(e.position, 1);
    assert!(
        e.message
            .starts_with("unknown function 'foo' (available: abs, "),
        "{}",
        e.message
    );

    let e = err("2 * ln(x)");
    assert_eq!(e.position, 5);
    assert_eq!(e.message, "unknown function 'ln' (did you mean 'log'?)");
    assert!(err("rand()").message.contains("deterministic"));
    assert!(err("noise(x)").message.contains("deterministic"));
    assert!(err("sinn(x)").message.contains("did you mean 'sin'?"));

    let e = err("q+1");
    assert_eq!(e.position, 1);
    assert_eq!(
        e.message,
        "unknown variable 'q' (known: x, y, z, rho, phic, r, theta, phis, d; constants: pi, e, epsilon, inf, true, false)"
    );

    let e = err("1e309");
    assert_eq!(e.position, 1);
    assert!(e.message.contains("too large"), "{}", e.message);

    let e = err("x ++");
    assert_eq!(e.position, 5);
    assert!(
        e.message.contains("after '+', but the expression ended"),
        "{}",
        e.message
    );

    let e = err("min()");
    assert_eq!(e.position, 1);
    assert_eq!(
        e.message,
        "function 'min' expects at least 1 argument, got 0"
    );

    let e = err("clamp(1,2)");
    assert_eq!(e.position, 1);
    assert_eq!(
        e.message,
        "function 'clamp' expects 3 arguments (lo, x, hi), got 2"
    );
    assert_eq!(
        err("sin(1, 2)").message,
        "function 'sin' expects 1 argument (x), got 2"
    );

    let e = err("x 2");
    assert_eq!(e.position, 3);
    assert_eq!(
        e.message,
        "unexpected '2'; expected an operator or end of expression"
    );
    let e = err("(x+1))");
    assert_eq!(e.position, 6);

    // Positions count characters, not bytes.
    let e = err("\"é\" + q");
    assert_eq!(e.position, 1);
    let e = Expr::compile("é + q", &["é"]).unwrap_err();
    assert_eq!(e.position, 5);

    assert_eq!(err("").message, "the expression is empty");
    assert_eq!(err("   ").position, 1);
    assert!(
        err("1 ? 2")
            .message
            .starts_with("expected ':' to complete the '?' at character 3")
    );
    assert!(
        err("min(1 2)")
            .message
            .starts_with("expected ',' or ')' in the call to 'min' opened at character 4")
    );
    assert!(
        err("sin + 1")
            .message
            .contains("must be called with arguments")
    );
    assert!(err("x(2)").message.contains("'x' is not a function"));
    assert!(err("*3").message.contains("found '*'"));
    assert!(err("1 + !x").message.contains("not x"));
}

#[test]
fn depth_limits() {
    let deep = format!("{}x{}", "(".repeat(5000), ")".repeat(5000));
    assert!(err(&deep).message.contains("nested too deeply"));
    let long = vec!["x"; 5000].join("+");
    assert!(err(&long).message.contains("nested too deeply"));
    let neg = format!("{}x", "-".repeat(5000));
    assert!(err(&neg).message.contains("nested too deeply"));
    // The largest accepted shapes compile (also in unoptimised builds, on a 2 MiB
    // test-thread stack).
    let sum = vec!["sin(x)"; 250].join("+");
    compile(&sum);
    let parens = format!("{}x{}", "(1+".repeat(95), ")".repeat(95));
    compile(&parens);
    let ternaries = format!("{}0", "x < 1 ? 1 : ".repeat(95));
    compile(&ternaries);
    let calls = format!("{}x{}", "max(1, ".repeat(95), ")".repeat(95));
    compile(&calls);
}

#[test]
fn expr_is_send_sync_clone() {
    fn check<T: Send + Sync + Clone>() {}
    check::<Expr>();
    let e = compile("x + 1");
    let f = e.clone();
    assert_eq!(f.eval(&[2.0]), 3.0);
}

/// Random expression trees over x, y, z: the compiled expression's interval bounds
/// must contain its value at random points of random boxes.
#[test]
fn interval_containment_end_to_end() {
    struct Rng(crate::xorshift::XorShift);
    impl Rng {
        fn unit(&mut self) -> f64 {
            self.0.next_f64()
        }
        fn below(&mut self, n: usize) -> usize {
            ((self.unit() * n as f64) as usize).min(n - 1)
        }
    }
    fn random_expr(rng: &mut Rng, depth: u32) -> String {
        const LEAVES: [&str; 8] = ["x", "y", "z", "1", "0.5", "2", "pi", "-3"];
        const UNARY: [&str; 14] = [
            "sin", "cos", "sqrt", "abs", "exp", "log", "atan", "tanh", "floor", "sgn", "frac",
            "erf", "cosh", "sinc",
        ];
        const BINARY: [&str; 14] = [
            "+", "-", "*", "/", "^", "%", "<", ">=", "==", " and ", " or ", "min", "max", "atan2",
        ];
        if depth == 0 || rng.unit() < 0.25 {
            return LEAVES[rng.below(LEAVES.len())].to_string();
        }
        match rng.below(4) {
            0 => format!(
                "{}({})",
                UNARY[rng.below(UNARY.len())],
                random_expr(rng, depth - 1)
            ),
            1 => {
                let op = BINARY[rng.below(BINARY.len())];
                let (a, b) = (random_expr(rng, depth - 1), random_expr(rng, depth - 1));
                if op.chars().all(char::is_alphanumeric) {
                    format!("{op}({a}, {b})")
                } else {
                    format!("({a}){op}({b})")
                }
            }
            2 => format!(
                "({}) ? ({}) : ({})",
                random_expr(rng, depth - 1),
                random_expr(rng, depth - 1),
                random_expr(rng, depth - 1)
            ),
            _ => format!(
                "clamp({}, {}, {})",
                random_expr(rng, depth - 1),
                random_expr(rng, depth - 1),
                random_expr(rng, depth - 1)
            ),
        }
    }
    let mut rng = Rng(crate::xorshift::XorShift::new(0xD1B5_4A32_D192_ED03));
    for _ in 0..400 {
        let src = random_expr(&mut rng, 4);
        let expr = Expr::compile(&src, &["x", "y", "z"]).unwrap_or_else(|e| panic!("{e}"));
        for _ in 0..8 {
            let mut boxes = [Interval::EVERYTHING; 3];
            for b in &mut boxes {
                let c = (rng.unit() - 0.5) * 10.0;
                let w = rng.unit() * [0.01, 1.0, 10.0][rng.below(3)];
                *b = Interval::new(c, c + w);
            }
            let bounds = expr.eval_interval(&boxes);
            // Batch evaluation agrees with point evaluation (100 points: one full
            // chunk and a partial one for every register-file size).
            let cols: Vec<Vec<f64>> = boxes
                .iter()
                .map(|b| {
                    (0..100)
                        .map(|k| b.lo + (b.hi - b.lo) * f64::from(k) / 99.0)
                        .collect()
                })
                .collect();
            let col_refs: Vec<&[f64]> = cols.iter().map(Vec::as_slice).collect();
            let mut out = vec![0.0; 100];
            expr.eval_batch(&col_refs, &mut out);
            for (k, &got) in out.iter().enumerate() {
                let want = expr.eval(&[cols[0][k], cols[1][k], cols[2][k]]);
                assert!(
                    got.to_bits() == want.to_bits() || (got.is_nan() && want.is_nan()),
                    "{src}: batch {got} != {want}"
                );
            }
            for _ in 0..8 {
                let p: Vec<f64> = boxes
                    .iter()
                    .map(|b| (b.lo + rng.unit() * (b.hi - b.lo)).clamp(b.lo, b.hi))
                    .collect();
                let v = expr.eval(&p);
                let ok = if v.is_nan() {
                    bounds.is_everything()
                } else {
                    bounds.contains(v)
                };
                assert!(
                    ok,
                    "{src}\n  at {p:?}: {v} not in {bounds:?} (boxes {boxes:?})\n  {expr:?}"
                );
            }
        }
    }
}

#[test]
fn derived_coordinate_intervals_contain_points() {
    let boxes = [
        [
            Interval::new(1.0, 2.0),
            Interval::new(-1.0, 0.5),
            Interval::new(0.0, 3.0),
        ],
        [
            Interval::new(-2.0, -1.0),
            Interval::new(-0.5, 0.5),
            Interval::new(-1.0, 1.0),
        ],
        [
            Interval::new(-1.0, 1.0),
            Interval::new(-1.0, 1.0),
            Interval::new(-1.0, 1.0),
        ],
    ];
    for b in boxes {
        let mut iv = [Interval::EVERYTHING; 9];
        iv[..3].copy_from_slice(&b);
        fill_derived_coord_intervals(&mut iv);
        for i in 0..=10 {
            for j in 0..=10 {
                for k in 0..=10 {
                    let t = |iv: Interval, n: i32| iv.lo + (iv.hi - iv.lo) * f64::from(n) / 10.0;
                    let mut s = [
                        t(b[0], i),
                        t(b[1], j),
                        t(b[2], k),
                        0.0,
                        0.0,
                        0.0,
                        0.0,
                        0.0,
                        0.0,
                    ];
                    fill_derived_coords(&mut s);
                    for slot in 3..8 {
                        let ok = if s[slot].is_nan() {
                            iv[slot].is_everything()
                        } else {
                            iv[slot].contains(s[slot])
                        };
                        assert!(
                            ok,
                            "slot {slot}: {} not in {:?} at {:?}",
                            s[slot],
                            iv[slot],
                            &s[..3]
                        );
                    }
                }
            }
        }
    }
}

/// Expressions whose shared subterms stay live long enough to need the 32- and
/// 128-register files: point, batch and interval evaluation must agree.
#[test]
fn large_register_files() {
    for n in [6usize, 20, 45] {
        let terms: Vec<String> = (1..=n).map(|i| format!("sin(x + {i})")).collect();
        let src = format!("{} + {}", terms.join(" + "), terms.join(" * "));
        let e = compile(&src);
        let dbg = format!("{e:?}");
        let regs: usize = dbg
            .split("registers: ")
            .nth(1)
            .and_then(|s| s.split(',').next())
            .and_then(|s| s.parse().ok())
            .unwrap();
        assert!(regs > n, "{n} terms: only {regs} registers");
        let x = 0.3f64;
        let s: Vec<f64> = (1..=n).map(|i| (x + i as f64).sin()).collect();
        let want = s.iter().fold(0.0, |a, v| a + v) + s.iter().skip(1).fold(s[0], |a, v| a * v);
        let got = e.eval(&[x]);
        assert!((got - want).abs() < 1e-12, "{got} vs {want}");
        let xs: Vec<f64> = (0..70).map(|k| f64::from(k) * 0.1).collect();
        let mut out = vec![0.0; 70];
        e.eval_batch(&[&xs], &mut out);
        for (k, &v) in out.iter().enumerate() {
            assert_eq!(v.to_bits(), e.eval(&[xs[k]]).to_bits());
        }
        let b = e.eval_interval(&[Interval::new(0.25, 0.35)]);
        assert!(b.contains(got), "{got} not in {b:?}");
    }
}

/// Affine gradings take their interval from the affine form: it must hold
/// every point value (including the box corners, where it is attained).
#[test]
fn affine_intervals_contain_points_and_reach_the_corners() {
    let vars = ["x", "y", "z"];
    for src in ["x/15+0.5", "-x/15+0.5", "0.3 - 2*y + z/7", "(x - y)/3 - z"] {
        let e = Expr::compile(src, &vars).unwrap();
        assert!(e.is_affine(), "{src}");
        let mut rng = crate::trimesh::tests::Rng::new(5);
        let mut unit = || rng.f64();
        for _ in 0..200 {
            let lo: Vec<f64> = (0..3).map(|_| unit() * 20.0 - 10.0).collect();
            let hi: Vec<f64> = lo.iter().map(|l| l + unit() * 3.0).collect();
            let iv: Vec<Interval> = (0..3).map(|i| Interval::new(lo[i], hi[i])).collect();
            let b = e.eval_interval(&iv);
            let mut reached = (false, false);
            for c in 0..8 {
                let p: Vec<f64> = (0..3)
                    .map(|i| if c >> i & 1 == 0 { lo[i] } else { hi[i] })
                    .collect();
                let v = e.eval(&p);
                assert!(b.lo <= v && v <= b.hi, "{src}: {v} outside {b:?}");
                reached.0 |= v == b.lo;
                reached.1 |= v == b.hi;
            }
            assert!(reached.0 && reached.1, "{src}: {b:?} not attained");
            for _ in 0..20 {
                let p: Vec<f64> = (0..3).map(|i| lo[i] + unit() * (hi[i] - lo[i])).collect();
                let v = e.eval(&p);
                assert!(b.lo <= v && v <= b.hi, "{src}: {v} outside {b:?}");
            }
        }
    }
}

#[test]
fn derived_coords_fill_what_is_used_with_the_same_bits() {
    for p in [
        [1.0, 2.0, 3.0],
        [-0.3, 0.0, -7.5],
        [0.0, 0.0, 0.0],
        [5.0, -1e-9, 2.0],
    ] {
        let mut all = [0.0; 9];
        all[..3].copy_from_slice(&p);
        fill_derived_coords(&mut all);
        for slot in 3..8 {
            let mut s = [f64::INFINITY; 9];
            s[..3].copy_from_slice(&p);
            fill_derived_coords_used(&mut s, 1 << slot);
            assert_eq!(
                s[slot].to_bits(),
                all[slot].to_bits(),
                "slot {slot} at {p:?}"
            );
        }
        // Nothing derived asked: nothing computed.
        let mut s = [f64::INFINITY; 9];
        s[..3].copy_from_slice(&p);
        fill_derived_coords_used(&mut s, 0b111);
        assert!(s[3..8].iter().all(|v| *v == f64::INFINITY));
    }
}
