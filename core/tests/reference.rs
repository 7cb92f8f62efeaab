//! Agreement with pyvcad 2.3.4's own numbers (`tests/data/*.json`: points
//! from a fixed seed over each design's box and inside it, with pyvcad's
//! distance and fractions at each; each file names its generator).
//!
//! Rules:
//! * inside/outside agrees at every point farther than 1e-6 mm from the surface;
//! * fractions agree within 1e-5 wherever the point is inside;
//! * distances agree within 1e-4 mm wherever pyvcad's distance is exact.
//!
//! Where we differ on purpose the test checks our documented value instead
//! and names the fix (docs/PYVCAD.md):
//! * **exact box distance** — pyvcad's RectPrism is max-norm outside; ours is
//!   Euclidean, so outside a box ours ≥ pyvcad's and ≤ √3 × pyvcad's;
//! * **exact mesh distance** — pyvcad clamps the mesh SDF to its band and
//!   approximates it on a grid; ours is compared with the exact distance the
//!   harness computed (`exact_mesh_distance`).

// A test crate: its helper functions stop on a failed setup as its tests do.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::PathBuf;

use serde_json::Value;
use volcad_core::Model;
use volcad_core::script::{ScriptOptions, run_script};

fn data(name: &str) -> Value {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../tests/data")
        .join(name);
    let text = std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
    serde_json::from_str(&text).unwrap()
}

fn model(src: &str) -> Model {
    let opts = ScriptOptions {
        base_dir: Some(PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../assets/examples/data")),
        ..ScriptOptions::default()
    };
    let d = run_script(src, "reference.rhai", &opts).unwrap_or_else(|e| panic!("{e}"));
    Model::prepare(&d.root, d.materials.clone()).unwrap_or_else(|e| panic!("{e}"))
}

/// How a design's distances may differ from pyvcad's.
#[derive(Clone, Copy, PartialEq)]
enum DistanceRule {
    /// Equal within 1e-4 everywhere.
    Exact,
    /// Equal inside; outside, ours is the Euclidean box distance.
    EuclideanBoxes,
    /// Compare with the harness's exact mesh distance where the mesh is nearer.
    ExactMesh,
}

struct Outcome {
    checked_inside: usize,
    checked_fractions: usize,
    checked_distance: usize,
}

fn check(file: &str, src: &str, rule: DistanceRule) -> Outcome {
    let r = data(file);
    let m = model(src);
    // For the mesh rule: the same design without its last child (the mesh).
    let struts_only =
        (rule == DistanceRule::ExactMesh).then(|| model(&src.replace("u.add_child(Mesh(", "// (")));
    let names: Vec<String> = m
        .materials()
        .iter()
        .map(|id| m.table().name(*id).to_owned())
        .collect();
    let points = r["points"].as_array().unwrap();
    let dist = r["distance"].as_array().unwrap();
    let fracs = r["fractions"].as_array().unwrap();
    let exact_mesh = r.get("exact_mesh_distance").and_then(|v| v.as_array());
    let mut out = Outcome {
        checked_inside: 0,
        checked_fractions: 0,
        checked_distance: 0,
    };
    let mut f = vec![0.0; names.len()];
    for (i, p) in points.iter().enumerate() {
        let p = p.as_array().unwrap();
        let p = glam::DVec3::new(
            p[0].as_f64().unwrap(),
            p[1].as_f64().unwrap(),
            p[2].as_f64().unwrap(),
        );
        let theirs = dist[i].as_f64().unwrap();
        let ours = m.eval_into(p, &mut f);
        // The surface distance that decides whether the sign must agree.
        let surface = match (rule, exact_mesh) {
            (DistanceRule::ExactMesh, Some(e)) => ours
                .abs()
                .min(e[i].as_f64().unwrap().abs())
                .min(theirs.abs()),
            _ => theirs.abs().min(ours.abs()),
        };
        if surface > 1e-6 {
            assert_eq!(
                ours <= 0.0,
                theirs <= 0.0,
                "{file} point {i} {p}: inside/outside differs: ours {ours}, pyvcad {theirs}"
            );
            out.checked_inside += 1;
        }
        // Fractions where both say inside.
        if ours <= 0.0 && theirs <= 0.0 && surface > 1e-6 {
            let want = fracs[i].as_object().unwrap();
            for (j, name) in names.iter().enumerate() {
                let w = want.get(name).and_then(|v| v.as_f64()).unwrap_or(0.0);
                assert!(
                    (f[j] - w).abs() <= 1e-5,
                    "{file} point {i} {p}: fraction of {name}: ours {}, pyvcad {w}",
                    f[j]
                );
            }
            for name in want.keys() {
                assert!(
                    names.contains(name),
                    "{file} point {i}: pyvcad has material {name} we do not"
                );
            }
            out.checked_fractions += 1;
        }
        match rule {
            DistanceRule::Exact => {
                assert!(
                    (ours - theirs).abs() <= 1e-4,
                    "{file} point {i} {p}: distance ours {ours}, pyvcad {theirs}"
                );
                out.checked_distance += 1;
            }
            DistanceRule::EuclideanBoxes => {
                if theirs <= 0.0 {
                    assert!(
                        (ours - theirs).abs() <= 1e-4,
                        "{file} point {i} {p}: inside distance ours {ours}, pyvcad {theirs}"
                    );
                } else {
                    // Fix: exact Euclidean box distance ≥ pyvcad's max-norm value.
                    assert!(
                        ours >= theirs - 1e-4 && ours <= theirs * 3f64.sqrt() + 1e-4,
                        "{file} point {i} {p}: outside distance ours {ours}, pyvcad (max-norm) {theirs}"
                    );
                }
                out.checked_distance += 1;
            }
            DistanceRule::ExactMesh => {
                // pyvcad = min(exact struts, approximate mesh clamped to its
                // ±10 mm band). Ours must be min(exact struts, exact mesh);
                // the struts-only model gives the first term independently.
                let e = exact_mesh.unwrap()[i].as_f64().unwrap();
                let band = r["prepare"]["exterior_bandwidth"].as_f64().unwrap();
                let struts = struts_only.as_ref().unwrap().distance(p);
                let want = struts.min(e);
                assert!(
                    (ours - want).abs() <= 1e-4,
                    "{file} point {i} {p}: ours {ours}, min(struts {struts}, exact mesh {e})"
                );
                // Where pyvcad's value clearly came from the struts, it agrees.
                if struts < e.clamp(-band, band) - 0.2 {
                    assert!(
                        (ours - theirs).abs() <= 1e-4,
                        "{file} point {i} {p}: strut distance ours {ours}, pyvcad {theirs}"
                    );
                }
                out.checked_distance += 1;
            }
        }
    }
    assert!(
        out.checked_inside > points.len() / 2,
        "{file}: too few points checked"
    );
    out
}

#[test]
fn cube() {
    let o = check(
        "cube.json",
        r#"let m = default_materials(); RectPrism(Vec3(0,0,0), Vec3(10,10,10), m.id("red"))"#,
        DistanceRule::EuclideanBoxes,
    );
    assert!(o.checked_fractions > 100);
}

#[test]
fn graded_bar() {
    let o = check(
        "graded_bar.json",
        r#"let m = default_materials();
           let bar = RectPrism(Vec3(0,0,0), Vec3(15,10,5), m.id("gray"));
           FGrade(["x/15+0.5", "-x/15+0.5"], [m.id("red"), m.id("blue")], true, bar)"#,
        DistanceRule::EuclideanBoxes,
    );
    assert!(o.checked_fractions > 100);
}

#[test]
fn color_sheet() {
    let o = check(
        "color_sheet.json",
        r#"let m = default_materials();
           let u = Union();
           for i in 0..12 { for j in 0..12 {
               let c = i / 11.0;
               let mg = (1.0 - c) * j / 11.0;
               let w = 1.0 - c - mg;
               let sw = RectPrism(Vec3((i - 5.5) * 25.0, (j - 5.5) * 25.0, 0), Vec3(25, 25, 10), m.id("white"));
               u.add_child(FGrade([`${c}`, `${mg}`, `${w}`], [m.id("cyan"), m.id("magenta"), m.id("white")], true, sw));
           }}
           u"#,
        DistanceRule::EuclideanBoxes,
    );
    assert!(o.checked_fractions > 100);
}

#[test]
fn bcc_sphere() {
    let o = check(
        "bcc_sphere.json",
        r#"let m = default_materials();
           let cell = GraphLattice(LatticeType::BodyCenteredCubic, Vec3(5,5,5), 0.175, m.id("red"));
           Intersection(false, [Tile(cell), Sphere(Vec3(0,0,0), 10, m.id("blue"))])"#,
        DistanceRule::Exact,
    );
    assert!(o.checked_fractions > 100 && o.checked_distance == 2500);
}

#[test]
fn bunny_lattice_300() {
    let o = check(
        "bunny_lattice_300.json",
        r#"let m = default_materials();
           let u = Union();
           for r in read_csv("bunny_struts_300ish.csv") {
               let f = r.fraction_magenta;
               let s = Strut(Vec3(r.x1, r.y1, r.z1), Vec3(r.x2, r.y2, r.z2), 0.5, m.id("yellow"));
               u.add_child(FGrade([`${1.0 - f}`, `${f}`], [m.id("yellow"), m.id("magenta")], true, s));
           }
           u.add_child(Mesh("bunny.obj", m.id("clear")));
           u"#,
        DistanceRule::ExactMesh,
    );
    assert!(
        o.checked_fractions > 100 && o.checked_distance > 500,
        "{} {}",
        o.checked_fractions,
        o.checked_distance
    );
}
