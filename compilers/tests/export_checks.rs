//! Exports that say when they cannot be trusted: features thinner than the
//! voxel (the BCC sphere of `assets/examples/bcc_sphere.rhai`, 0.7 mm
//! struts), parts that fall apart, end sets that poke a part at a few
//! points, and decks too large for the solving machine.

// A failed setup step (a scratch folder, a file read) fails the test.
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use std::path::Path;
use std::process::Command;
use std::sync::Arc;

use common::{mesh_stl, model, run, scratch};
use volcad_compilers::fea::{Element, EndSets, FeaParams, StepParams, export_fea, read_frd};
use volcad_compilers::{ExportError, Summary};
use volcad_core::Model;

fn bcc_sphere() -> Arc<Model> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/examples/bcc_sphere.rhai");
    model(&std::fs::read_to_string(path).expect("the example design"))
}

fn bricks(voxel: f64) -> FeaParams {
    FeaParams {
        element: Element::C3D8R,
        voxel,
        ..FeaParams::default()
    }
}

fn fea(m: &Arc<Model>, p: &FeaParams, dir: &Path) -> Result<Summary, ExportError> {
    let (m, p) = (m.clone(), p.clone());
    run(dir, move |ctx| export_fea(&m, &p, ctx))
}

fn warnings(s: &Summary) -> Vec<&String> {
    s.notes
        .iter()
        .filter(|n| n.starts_with("warning"))
        .collect()
}

#[test]
fn bcc_sphere_at_half_a_millimetre_warns_and_names_the_voxel_that_resolves_it() {
    let m = bcc_sphere();
    let (_t, dir) = scratch("mesh");
    let s = mesh_stl(&m, 0.5, &dir);
    let w = warnings(&s);
    assert!(
        w.iter()
            .any(|n| n.contains("strut radius 0.35") && n.contains("--voxel 0.35 resolves it")),
        "{w:?}"
    );
    let bodies: usize = s
        .notes
        .iter()
        .find_map(|n| n.strip_prefix("bodies: "))
        .expect("a body count")
        .parse()
        .expect("a number");
    assert!(bodies > 100, "{bodies}");
    assert!(w.iter().any(|n| n.contains("separate bodies")), "{w:?}");
    let manifest = std::fs::read_to_string(dir.join("manifest.json")).expect("manifest");
    assert!(manifest.contains("--voxel 0.35 resolves it"), "{manifest}");
    assert!(manifest.contains("separate bodies"), "{manifest}");
}

#[test]
fn bcc_sphere_at_a_quarter_millimetre_is_one_body_without_warnings() {
    let m = bcc_sphere();
    let (_t, dir) = scratch("mesh");
    let s = mesh_stl(&m, 0.25, &dir);
    assert!(s.notes.iter().any(|n| n == "bodies: 1"), "{:?}", s.notes);
    assert!(warnings(&s).is_empty(), "{:?}", s.notes);
    let shape = s
        .notes
        .iter()
        .find_map(|n| n.strip_prefix("triangle shape: smallest angle "))
        .expect("the triangle shape note");
    let angle: f64 = shape
        .split('°')
        .next()
        .and_then(|a| a.parse().ok())
        .expect("an angle");
    assert!(angle > 0.0 && angle < 60.0, "{shape}");
}

#[test]
fn a_deck_in_pieces_is_refused_unless_allowed() {
    let m = bcc_sphere();
    let (_t, dir) = scratch("fea");
    let e = fea(&m, &bricks(0.5), &dir).unwrap_err().to_string();
    assert!(
        e.contains("--voxel")
            && e.contains("pieces that share no face")
            && e.contains("--allow-pieces"),
        "{e}"
    );
    assert!(!dir.exists(), "a refused export leaves nothing");
    let p = FeaParams {
        allow_pieces: true,
        ..bricks(0.5)
    };
    let s = fea(&m, &p, &dir).expect("allowed");
    assert!(
        warnings(&s)
            .iter()
            .any(|n| n.contains("pieces") && n.contains("--allow-pieces")),
        "{:?}",
        s.notes
    );
}

/// `total force (fx,fy,fz) for set NBOTTOM` from a `.dat`.
fn reaction(dat: &Path) -> [f64; 3] {
    let text = std::fs::read_to_string(dat).expect("model.dat");
    let mut lines = text.lines().skip_while(|l| !l.contains("total force"));
    let row = lines
        .by_ref()
        .skip(1)
        .find(|l| !l.trim().is_empty())
        .expect("the totals row");
    let v: Vec<f64> = row
        .split_whitespace()
        .map(|t| t.parse().expect("a number"))
        .collect();
    [v[0], v[1], v[2]]
}

#[test]
fn bcc_sphere_at_a_quarter_millimetre_solves_in_calculix() {
    let m = bcc_sphere();
    let (_t, dir) = scratch("fea");
    let uz = -0.1;
    let p = FeaParams {
        step: Some(StepParams {
            top_displacement: uz,
        }),
        ends: EndSets {
            fix: Some("z<-8".into()),
            load: Some("z>8".into()),
            band: None,
        },
        ..bricks(0.25)
    };
    let s = fea(&m, &p, &dir).expect("one piece");
    assert!(
        s.notes.iter().any(|n| n.starts_with("pieces: 1")),
        "{:?}",
        s.notes
    );
    assert!(warnings(&s).is_empty(), "{:?}", s.notes);
    let out = Command::new("ccx")
        .args(["-i", "model"])
        .current_dir(&dir)
        .env("OMP_NUM_THREADS", "1")
        .output();
    let out = match out {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            if std::env::var("VOLCAD_SKIP_CCX").as_deref() == Ok("1") {
                return;
            }
            panic!(
                "ccx (CalculiX) is not installed: install calculix-ccx, or set VOLCAD_SKIP_CCX=1 to skip"
            );
        }
        other => other.expect("ccx runs"),
    };
    let log = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success() && !log.contains("*ERROR"), "{log}");
    let r = read_frd(&dir.join("model.frd")).expect("results");
    assert!(
        r.displacements
            .iter()
            .all(|(_, u)| u.iter().all(|v| v.is_finite()))
    );
    // No arrangement of the mesh's material volume V over the height H is
    // stiffer than a straight column: F ≤ E V |u| / H² (Voigt bound).
    let volume: f64 = s
        .notes
        .iter()
        .find_map(|n| n.split("mesh volume ").nth(1))
        .and_then(|v| v.split_whitespace().next())
        .expect("the mesh volume")
        .parse()
        .expect("a number");
    let bound = 2850.0 * volume * uz.abs() / (20.0 * 20.0);
    let f = reaction(&dir.join("model.dat"));
    assert!(f[2] > 0.0 && f[2] < bound, "RF {f:?}, bound {bound}");
    assert!(
        f[0].abs() < 1e-6 * f[2] && f[1].abs() < 1e-6 * f[2],
        "RF {f:?}"
    );
}

const BOX: &str = r#"let m = j750_materials();
RectPrism(Vec3(0,0,0), Vec3(6,4,3), m.id("VeroCyan"))"#;

#[test]
fn end_sets_report_nodes_and_areas_and_follow_the_band() {
    let m = model(BOX);
    let (_t, dir) = scratch("fea");
    let s = fea(&m, &bricks(0.5), &dir).expect("box");
    let line = |name: &str| -> String {
        s.notes
            .iter()
            .find(|n| n.starts_with(&format!("{name}: ")))
            .cloned()
            .unwrap_or_else(|| panic!("no {name} line in {:?}", s.notes))
    };
    // 12 × 8 bricks a layer: 13 × 9 nodes and 24 mm² at each end.
    for name in ["NBOTTOM", "NTOP"] {
        let l = line(name);
        assert!(
            l.contains(": 117 nodes") && l.contains("24.0000 mm² of surface"),
            "{l}"
        );
        // The footprint is counted on a raster of 512 cells across.
        assert!(l.contains("100 % of the part's 23.9"), "{l}");
    }
    assert!(warnings(&s).is_empty(), "{:?}", s.notes);
    let (_t2, dir2) = scratch("fea");
    let p = FeaParams {
        ends: EndSets {
            band: Some(1.0),
            ..EndSets::default()
        },
        ..bricks(0.5)
    };
    let s = fea(&m, &p, &dir2).expect("box");
    assert!(
        s.notes
            .iter()
            .any(|n| n.starts_with("NBOTTOM: 234 nodes within 1 mm")),
        "{:?}",
        s.notes
    );
}

#[test]
fn a_sphere_warns_that_its_ends_are_points_and_a_condition_selects_more() {
    let m = model(r#"Sphere(Vec3(0,0,0), 5, j750_materials().id("VeroCyan"))"#);
    let (_t, dir) = scratch("fea");
    let s = fea(&m, &bricks(0.5), &dir).expect("sphere");
    let w = warnings(&s);
    assert!(
        w.iter()
            .any(|n| n.starts_with("warning: NBOTTOM covers only") && n.contains(r#"--fix "z<"#)),
        "{w:?}"
    );
    let (_t2, dir2) = scratch("fea");
    let p = FeaParams {
        ends: EndSets {
            fix: Some("z < -3".into()),
            load: Some("z > 3".into()),
            band: None,
        },
        ..bricks(0.5)
    };
    let s = fea(&m, &p, &dir2).expect("sphere");
    assert!(warnings(&s).is_empty(), "{:?}", s.notes);
    let e = fea(
        &m,
        &FeaParams {
            ends: EndSets {
                fix: Some("z < -30".into()),
                ..EndSets::default()
            },
            ..bricks(0.5)
        },
        &scratch("fea").1,
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("--fix") && e.contains("selects no node"), "{e}");
}

#[test]
fn a_deck_beyond_the_solving_machine_is_refused_with_sizes_that_fit() {
    let m = model(BOX);
    let (_t, dir) = scratch("fea");
    let p = FeaParams {
        solver_memory: Some(1 << 20),
        ..bricks(0.25)
    };
    let e = fea(&m, &p, &dir).unwrap_err().to_string();
    assert!(
        e.contains("CalculiX") && e.contains("--voxel") && e.contains("--force"),
        "{e}"
    );
    assert!(!dir.exists());
    let s = fea(&m, &FeaParams { force: true, ..p }, &dir).expect("forced");
    assert!(
        warnings(&s).iter().any(|n| n.contains("--force")),
        "{:?}",
        s.notes
    );
}
