//! The nodes of issue 34 item 6 (Cone, Torus, PolygonRevolve, tapered
//! Strut, Mirror, Identity, Sum): distances against a brute force (the
//! nearest of a dense sampling of the surface, the sign from a membership
//! test written from the shape's definition), the interval property over
//! random boxes, and pyvcad 2.3.4's values for `Sum`.

// A test crate: its helper functions stop on a failed setup as its tests do.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::f64::consts::{PI, TAU};

use volcad_core::bench::XorShift;
use volcad_core::script::{ScriptOptions, run_script};
use volcad_core::{Aabb, DVec3, Model};

fn model(src: &str) -> Model {
    let d =
        run_script(src, "nodes.rhai", &ScriptOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    Model::prepare(&d.root, d.materials.clone()).unwrap_or_else(|e| panic!("{e}"))
}

fn script_error(src: &str) -> String {
    match run_script(src, "nodes.rhai", &ScriptOptions::default()) {
        Err(e) => e.to_string(),
        Ok(d) => match Model::prepare(&d.root, d.materials.clone()) {
            Err(e) => e.to_string(),
            Ok(_) => panic!("{src} was accepted"),
        },
    }
}

/// A shape as the brute force sees it: surface samples (spacing `h`) and
/// an inside test.
struct Brute {
    surface: Vec<DVec3>,
    inside: Box<dyn Fn(DVec3) -> bool>,
    h: f64,
}

impl Brute {
    fn unsigned(&self, p: DVec3) -> f64 {
        self.surface
            .iter()
            .map(|s| (*s - p).length_squared())
            .fold(f64::INFINITY, f64::min)
            .sqrt()
    }
}

/// Random points in `b`, deterministic.
fn points(b: Aabb, n: usize, seed: u64) -> Vec<DVec3> {
    let mut r = XorShift::new(seed);
    (0..n)
        .map(|_| {
            let t = DVec3::new(r.next_f64(), r.next_f64(), r.next_f64());
            b.min + (b.max - b.min) * t
        })
        .collect()
}

/// Exact distances: equal to the brute force within its sampling error.
fn check_exact(m: &Model, brute: &Brute, seed: u64) {
    let b = m.bbox().expand(1.0);
    let mut inside = 0;
    for p in points(b, 300, seed) {
        let d = m.distance(p);
        let want = brute.unsigned(p);
        let is_in = (brute.inside)(p);
        inside += usize::from(is_in);
        if want > brute.h {
            assert_eq!(d <= 0.0, is_in, "sign at {p}: ours {d}, brute {want}");
        }
        assert!(
            (d.abs() - want).abs() <= brute.h,
            "at {p}: ours {d}, brute force {want} (± {})",
            brute.h
        );
    }
    assert!(
        inside > 10,
        "only {inside} points inside: test the inside too"
    );
}

/// A design whose distance is exact: brute force and intervals.
fn check_shape(src: &str, brute: &Brute, seed: u64) -> Model {
    let m = model(src);
    check_exact(&m, brute, seed);
    check_intervals(&m, seed + 1);
    m
}

/// Every sample of a box lies in the model's interval over that box.
fn check_intervals(m: &Model, seed: u64) {
    let outer = m.bbox().expand(2.0);
    let mut r = XorShift::new(seed);
    for corner in points(outer, 60, seed) {
        let size = DVec3::new(r.next_f64(), r.next_f64(), r.next_f64()) * 3.0 + 0.01;
        let b = Aabb::new(corner, corner + size);
        let i = m.interval(&b);
        for p in points(b, 40, seed + 1) {
            let d = m.distance(p);
            assert!(
                i.lo <= d && d <= i.hi,
                "{d} at {p} outside {i:?} over {b:?}"
            );
        }
    }
}

/// `f(u, t)` for `nu` angles u in [0, 2π) and `nt + 1` values t in [0, 1].
fn around(nu: usize, nt: usize, mut f: impl FnMut(f64, f64)) {
    for i in 0..nu {
        for k in 0..=nt {
            f(TAU * i as f64 / nu as f64, k as f64 / nt as f64);
        }
    }
}

fn torus_brute(big: f64, small: f64) -> Brute {
    let (nu, nv) = (720, 240);
    let mut surface = Vec::new();
    for i in 0..nu {
        for j in 0..nv {
            let (u, v) = (TAU * i as f64 / nu as f64, TAU * j as f64 / nv as f64);
            let rr = big + small * v.cos();
            surface.push(DVec3::new(rr * u.cos(), rr * u.sin(), small * v.sin()));
        }
    }
    Brute {
        surface,
        inside: Box::new(move |p| {
            let rho = (p.x * p.x + p.y * p.y).sqrt();
            (rho - big).powi(2) + p.z * p.z <= small * small
        }),
        h: TAU * (big + small) / nu as f64,
    }
}

#[test]
fn torus_matches_brute_force_and_bounds() {
    check_shape("Torus(4.0, 1.5)", &torus_brute(4.0, 1.5), 1);
    let d = model("Torus()");
    // pyvcad's default torus: major 2, minor 1; the tube centre is 1 deep.
    assert!((d.distance(DVec3::new(2.0, 0.0, 0.0)) + 1.0).abs() < 1e-12);
}

fn cone_brute(angle: f64, h: f64) -> Brute {
    let r = h * angle.tan();
    let mut surface = Vec::new();
    let (nu, nt) = (720, 240);
    around(nu, nt, |u, t| {
        // Side (apex to rim) and base disc.
        surface.push(DVec3::new(r * t * u.cos(), r * t * u.sin(), -h * t));
        surface.push(DVec3::new(r * t * u.cos(), r * t * u.sin(), -h));
    });
    let tan = angle.tan();
    Brute {
        surface,
        inside: Box::new(move |p| {
            let rho = (p.x * p.x + p.y * p.y).sqrt();
            p.z <= 0.0 && p.z >= -h && rho <= -p.z * tan
        }),
        h: (TAU * r / nu as f64).max(h.hypot(r) / nt as f64),
    }
}

#[test]
fn cone_matches_brute_force_and_bounds() {
    check_shape("Cone(0.5, 6.0)", &cone_brute(0.5, 6.0), 3);
    let e = script_error("Cone(30, 5)");
    assert!(e.contains("radians") && e.contains("nodes.rhai:1:"), "{e}");
}

/// The vase of pyvcad's revolve example: (radial, axial) profile about Z.
const VASE: [(f64, f64); 5] = [
    (0.0, -8.0),
    (7.0, -8.0),
    (10.0, -2.0),
    (6.0, 6.0),
    (0.0, 6.0),
];

fn in_polygon(q: (f64, f64), v: &[(f64, f64)]) -> bool {
    let mut inside = false;
    let mut j = v.len() - 1;
    for i in 0..v.len() {
        let (a, b) = (v[i], v[j]);
        if (a.1 > q.1) != (b.1 > q.1) && q.0 < (b.0 - a.0) * (q.1 - a.1) / (b.1 - a.1) + a.0 {
            inside = !inside;
        }
        j = i;
    }
    inside
}

fn revolve_brute(sweep: f64) -> Brute {
    let (nu, ne) = (720, 200);
    let mut surface = Vec::new();
    let frac = sweep / TAU;
    for i in 0..=nu {
        let u = sweep * i as f64 / nu as f64;
        for e in 0..VASE.len() {
            let (a, b) = (VASE[e], VASE[(e + 1) % VASE.len()]);
            if a.0 == 0.0 && b.0 == 0.0 {
                continue; // on the axis: inside a full revolution
            }
            for k in 0..=ne {
                let t = k as f64 / ne as f64;
                let (x, z) = (a.0 + (b.0 - a.0) * t, a.1 + (b.1 - a.1) * t);
                surface.push(DVec3::new(x * u.cos(), x * u.sin(), z));
            }
        }
    }
    if sweep < TAU {
        // The two end faces: the filled profile at angles 0 and sweep.
        for u in [0.0, sweep] {
            for i in 0..=200 {
                for k in 0..=280 {
                    let (x, z) = (10.0 * i as f64 / 200.0, -8.0 + 14.0 * k as f64 / 280.0);
                    if in_polygon((x, z), &VASE) {
                        surface.push(DVec3::new(x * u.cos(), x * u.sin(), z));
                    }
                }
            }
        }
    }
    Brute {
        surface,
        inside: Box::new(move |p| {
            let phi = p.y.atan2(p.x).rem_euclid(TAU);
            let rho = (p.x * p.x + p.y * p.y).sqrt();
            phi <= sweep && in_polygon((rho, p.z), &VASE)
        }),
        h: (TAU * frac * 10.0 / nu as f64).max(0.06),
    }
}

fn revolve_script(sweep: f64) -> String {
    let v: Vec<String> = VASE
        .iter()
        .map(|(x, z)| format!("Vec3({x:.1}, 0.0, {z:.1})"))
        .collect();
    format!(
        "PolygonRevolve([{}], Vec3(0.0, 0.0, -8.0), Vec3(0.0, 0.0, 6.0), {sweep:.1})",
        v.join(", ")
    )
}

#[test]
fn full_revolve_matches_brute_force_and_bounds() {
    check_shape(&revolve_script(360.0), &revolve_brute(TAU), 5);
}

#[test]
fn partial_revolve_matches_brute_force_and_bounds() {
    let m = check_shape(&revolve_script(270.0), &revolve_brute(1.5 * PI), 7);
    // The cut-away quarter (x > 0, y < 0) is empty; the opposite one full.
    assert!(m.distance(DVec3::new(4.0, -4.0, 0.0)) > 0.0);
    assert!(m.distance(DVec3::new(-4.0, 4.0, 0.0)) < 0.0);
}

#[test]
fn revolve_refuses_bad_profiles_at_the_call() {
    let e = script_error(
        "PolygonRevolve([Vec3(1.0,0.0,0.0), Vec3(2.0,0.0,0.0), Vec3(-1.0,0.0,1.0)], Vec3(0,0,0), Vec3(0,0,1), 360.0)",
    );
    assert!(
        e.contains("other side of the axis") && e.contains("nodes.rhai:1:"),
        "{e}"
    );
    let e = script_error(
        "PolygonRevolve([Vec3(1.0,0.0,0.0), Vec3(2.0,0.0,0.0), Vec3(2.0,1.0,1.0)], Vec3(0,0,0), Vec3(0,0,1), 360.0)",
    );
    assert!(e.contains("off the plane"), "{e}");
    let e = script_error(
        "PolygonRevolve([Vec3(1.0,0.0,0.0), Vec3(2.0,0.0,0.0), Vec3(2.0,0.0,1.0)], Vec3(0,0,0), Vec3(0,0,1), 400.0)",
    );
    assert!(e.contains("(0, 360]"), "{e}");
}

/// A frustum from the origin along +X, length `len`, radii `ra`, `rb`, with
/// a full sphere at the start and a flat end.
fn beam_brute(len: f64, ra: f64, rb: f64) -> Brute {
    let in_frustum = move |p: DVec3| {
        let rho = (p.y * p.y + p.z * p.z).sqrt();
        (0.0..=len).contains(&p.x) && rho <= ra + (rb - ra) * p.x / len
    };
    let in_ball = move |p: DVec3| p.length() <= ra;
    let mut surface = Vec::new();
    let (nu, nt) = (360, 300);
    for i in 0..nu {
        let u = TAU * i as f64 / nu as f64;
        for k in 0..=nt {
            let t = k as f64 / nt as f64;
            let r = ra + (rb - ra) * t;
            surface.push(DVec3::new(len * t, r * u.cos(), r * u.sin()));
            surface.push(DVec3::new(len, rb * t * u.cos(), rb * t * u.sin()));
            let v = PI * t;
            surface.push(DVec3::new(
                ra * v.cos(),
                ra * v.sin() * u.cos(),
                ra * v.sin() * u.sin(),
            ));
        }
    }
    // The union's surface: each part's surface outside the other part.
    surface.retain(|s| {
        let grow = |f: &dyn Fn(DVec3) -> bool| f(*s) && !f(*s * 1.0001 + DVec3::X * 1e-4);
        !(in_frustum(*s) && in_ball(*s)) || grow(&in_frustum) || grow(&in_ball)
    });
    Brute {
        surface,
        inside: Box::new(move |p| in_frustum(p) || in_ball(p)),
        h: TAU * rb.max(ra) / nu as f64 + len / nt as f64,
    }
}

#[test]
fn tapered_strut_matches_brute_force_outside_and_bounds() {
    let m = model("Strut(Vec3(0,0,0), Vec3(10,0,0), 1.0, 3.0, CapMode::Sphere, CapMode::Butt)");
    let brute = beam_brute(10.0, 1.0, 3.0);
    for p in points(m.bbox().expand(1.5), 300, 9) {
        let d = m.distance(p);
        let want = brute.unsigned(p);
        let is_in = (brute.inside)(p);
        if want > brute.h {
            assert_eq!(d <= 0.0, is_in, "sign at {p}: ours {d}, brute {want}");
        }
        if is_in {
            // Inside, the union of exact parts is a bound: never deeper.
            assert!(-d <= want + brute.h, "at {p}: ours {d}, brute {want}");
        } else {
            assert!(
                (d - want).abs() <= brute.h,
                "at {p}: ours {d}, brute {want}"
            );
        }
    }
    check_intervals(&m, 10);
    // Equal radii with round ends is the capsule, exactly.
    let cap =
        model("Strut(Vec3(0,0,0), Vec3(10,0,0), 2.0, 2.0, CapMode::HemiSphere, CapMode::Sphere)");
    let old = model("Strut(Vec3(0,0,0), Vec3(10,0,0), 2.0)");
    for p in points(old.bbox().expand(1.0), 100, 11) {
        assert_eq!(cap.distance(p), old.distance(p));
    }
    // A hemisphere cap reaches r beyond the end; a butt end stops at it.
    let hemi =
        model("Strut(Vec3(0,0,0), Vec3(10,0,0), 1.0, 2.0, CapMode::Butt, CapMode::HemiSphere, 1)");
    assert!((hemi.distance(DVec3::new(12.5, 0.0, 0.0)) - 0.5).abs() < 1e-12);
    assert!((hemi.distance(DVec3::new(-0.5, 0.0, 0.0)) - 0.5).abs() < 1e-12);
    // pyvcad 2's Strut(start, end, radius, material) keeps its meaning.
    let two = model("Strut(Vec3(0,0,0), Vec3(10,0,0), 1.0, 3)");
    assert_eq!(two.materials(), &[3]);
    let e = script_error("Strut(Vec3(0,0,0), Vec3(10,0,0), 1.0, 2.0, \"flat\")");
    assert!(e.contains("CapMode::Butt") && e.contains("a string"), "{e}");
}

#[test]
fn mirror_reflects_across_every_plane_form() {
    let pairs = [
        (
            "Mirror(\"x\", RectPrism(Vec3(5.0,-8.0,0.0), Vec3(2.0,3.0,3.0)))",
            "RectPrism(Vec3(-5.0,-8.0,0.0), Vec3(2.0,3.0,3.0))",
        ),
        (
            "Mirror(\"X\", 6.0, RectPrism(Vec3(10.0,0.0,0.0), Vec3(2.0,3.0,3.0)))",
            "RectPrism(Vec3(2.0,0.0,0.0), Vec3(2.0,3.0,3.0))",
        ),
        (
            "Mirror(Vec3(0,0,0), Vec3(1.0,-1.0,0.0), Sphere(Vec3(8.0,4.0,0.0), 1.5))",
            "Sphere(Vec3(4.0,8.0,0.0), 1.5)",
        ),
        (
            "Mirror(Vec3(0,0,2), Vec3(1,0,2), Vec3(0,1,2), Sphere(Vec3(1.0,2.0,5.0), 1.5))",
            "Sphere(Vec3(1.0,2.0,-1.0), 1.5)",
        ),
        (
            "let m = Mirror(\"z\"); m.set_child(Torus(3.0, 1.0)); m",
            "Torus(3.0, 1.0)",
        ),
    ];
    for (mirrored, direct) in pairs {
        let (a, b) = (model(mirrored), model(direct));
        for p in points(b.bbox().expand(2.0), 200, 12) {
            assert!(
                (a.distance(p) - b.distance(p)).abs() < 1e-9,
                "{mirrored} at {p}"
            );
        }
        assert!((a.bbox().min - b.bbox().min).length() < 1e-9, "{mirrored}");
        check_intervals(&a, 13);
    }
    let e = script_error("Mirror(\"w\", Sphere())");
    assert!(e.contains("\"x\", \"y\" or \"z\""), "{e}");
    let e = script_error("Mirror(Vec3(0,0,0), Vec3(1,1,1), Vec3(2,2,2))");
    assert!(e.contains("collinear"), "{e}");
}

#[test]
fn identity_changes_nothing() {
    let inner = "FGrade([\"x/4+0.5\", \"0.5-x/4\"], [1, 3], false, Sphere(Vec3(1,0,0), 2.0))";
    let a = model(&format!("Translate(1.0, 0.0, 0.0, Identity({inner}))"));
    let b = model(&format!("Translate(1.0, 0.0, 0.0, {inner})"));
    for p in points(b.bbox(), 100, 14) {
        assert_eq!(a.eval_point(p), b.eval_point(p));
    }
    assert!(script_error("Identity()").contains("has no child"));
}

/// pyvcad 2.3.4: `Sum(-1.0, [Sphere(Vec3(-3,0,0), 2, 1), Sphere(Vec3(3,0,0), 2, 3)])`
/// after `prepare(Vec3(0.1,0.1,0.1), 1, 1)`: `evaluate` and `distribution`.
#[test]
fn sum_matches_pyvcad() {
    let m = model("Sum(-1.0, [Sphere(Vec3(-3,0,0), 2.0, 1), Sphere(Vec3(3,0,0), 2.0, 3)])");
    let cases: [([f64; 3], f64, Option<u8>); 7] = [
        ([0.0, 0.0, 0.0], 1.0, None),
        ([-3.0, 0.0, 0.0], 1.0, Some(1)),
        ([3.0, 0.0, 0.0], 1.0, Some(3)),
        ([-1.5, 0.0, 0.0], 1.0, Some(1)),
        ([0.0, 1.0, 0.0], 1.324555320336759, None),
        ([0.0, 3.0, 1.0], 3.717797887081346, None),
        ([10.0, 0.0, 0.0], 15.0, None),
    ];
    for (p, d, _) in cases {
        let got = m.distance(DVec3::from_array(p));
        assert!((got - d).abs() < 1e-12, "{p:?}: {got} vs pyvcad {d}");
    }
    // Inside the sum: the first child holding the point gives the
    // fractions, none when no child holds it (pyvcad returns {}).
    let inside = model("Sum(-9.0, [Sphere(Vec3(-3,0,0), 2.0, 1), Sphere(Vec3(3,0,0), 2.0, 3)])");
    for (p, _, mat) in cases.iter().take(4) {
        let (d, f) = inside.eval_point(DVec3::from_array(*p));
        assert!(d <= 0.0);
        let on: Vec<u8> = f
            .iter()
            .filter(|(_, v)| *v > 0.0)
            .map(|(m, _)| *m)
            .collect();
        assert_eq!(on, mat.iter().copied().collect::<Vec<_>>(), "{p:?}");
    }
    check_intervals(&m, 15);
    check_intervals(&inside, 16);
    // Outside every child's box the sum needs −iso of room: the box grows.
    assert!(inside.bbox().max.x >= 5.0 + 9.0);
    // pyvcad 2.3.4: Sum(0.5) with one sphere of radius 2 gives -1.5 at its centre.
    let one = model("let s = Sum(0.5); s.add_child(Sphere(Vec3(0,0,0), 2.0)); s");
    assert!((one.distance(DVec3::ZERO) + 1.5).abs() < 1e-12);
    assert!(script_error("Sum(1.0)").contains("has no children"));
}
