//! FEA export end to end: the exported decks run in the real CalculiX
//! (`ccx`), and the results read back are plausible.
//!
//! `ccx` must be on PATH (Debian: `calculix-ccx`); a missing `ccx` fails the
//! test unless `VOLCAD_SKIP_CCX=1`.
//!
//! The graded bar: a 15 × 10 × 5 mm block (x ∈ [−7.5, 7.5]), VeroCyan at
//! +x, Agilus30 at −x, graded only in the middle third by
//! `clamp(0, (x+2.5)/5, 1)`. Its ends are pure (h = 1 → coarse elements)
//! and h falls to 0 at x = 0, so an adaptive mesh is fine only near the
//! middle plane. (The plain `x/15+0.5` bar has h < 1 everywhere, which
//! leaves little to coarsen.) E/ν from the J750 table: Vero 2850 MPa / 0.39,
//! Agilus30 0.383 MPa / 0.5 (written as 0.49).

// A failed setup step (a scratch folder, a file read) fails the test.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::Path;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;

mod common;

use common::{reaction, run_ccx, scratch};
use volcad_compilers::fea::*;
use volcad_compilers::job::{Summary, spawn};
use volcad_core::Model;
use volcad_core::script::{ScriptOptions, run_script};

const BAR: &str = r#"let m = j750_materials();
let g = "clamp(0, (x+2.5)/5, 1)";
FGrade([g, "1-" + g], [m.id("VeroCyan"), m.id("Agilus30")], true,
       RectPrism(Vec3(0,0,0), Vec3(15,10,5), m.id("VeroCyan")))"#;

/// The sizes the adaptive test uses: h = 1 ends at 5 mm (box edges at
/// 5/4 mm, see `tets::SHAPE_FLOOR`), the mixed middle at 0.5 mm.
const MIN_CELL: f64 = 0.5;
const MAX_CELL: f64 = 5.0;
const TOP_UZ: f64 = -0.1;

fn model(src: &str) -> Arc<Model> {
    let d = run_script(src, "t.rhai", &ScriptOptions::default()).unwrap();
    Arc::new(Model::prepare(&d.root, d.materials.clone()).unwrap())
}

fn export(model: &Arc<Model>, p: &FeaParams, dest: &Path) -> Summary {
    let (m, p2) = (model.clone(), p.clone());
    spawn(dest.to_path_buf(), "test".into(), move |ctx| {
        export_fea(&m, &p2, ctx)
    })
    .join()
    .unwrap()
}

/// Check a ccx result of the bar: finite, nonzero, bottom fixed, top at TOP_UZ.
fn check_bar_result(dir: &Path, what: &str) {
    let r = read_frd(&dir.join("model.frd")).unwrap();
    assert!(!r.displacements.is_empty());
    let z: Vec<f64> = r.nodes.iter().map(|(_, p)| p[2]).collect();
    let (zmin, zmax) = z
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(*v), b.max(*v))
        });
    let coords: std::collections::HashMap<u32, [f64; 3]> = r.nodes.iter().copied().collect();
    let (mut max_u, mut top, mut bottom) = (0.0f64, 0, 0);
    for (id, u) in &r.displacements {
        assert!(u.iter().all(|v| v.is_finite()), "node {id}: {u:?}");
        max_u = max_u.max((u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt());
        let pz = coords[id][2];
        if (pz - zmax).abs() < 1e-4 {
            assert!((u[2] - TOP_UZ).abs() < 1e-6, "top node {id}: uz {}", u[2]);
            top += 1;
        }
        if (pz - zmin).abs() < 1e-4 {
            assert!(u.iter().all(|v| v.abs() < 1e-12), "bottom node {id}: {u:?}");
            bottom += 1;
        }
    }
    assert!(max_u > 0.05, "max |u| {max_u}");
    assert!(top >= 3 && bottom >= 3, "top {top} bottom {bottom}");
    let rf = reaction(&dir.join("model.dat")).expect("reaction totals in model.dat");
    assert!(rf.iter().all(|v| v.is_finite()) && rf[2] > 0.0, "RF {rf:?}");
    eprintln!(
        "{what}: {} nodes with results, max |u| = {max_u:.5} mm, RF on NBOTTOM = ({:.4}, {:.4}, {:.4}) N",
        r.displacements.len(),
        rf[0],
        rf[1],
        rf[2]
    );
    // The CSV the CLI writes.
    let csv = dir.join("result.csv");
    let stats = write_result_csv(&r, Some(&dir.join("model.inp")), &csv).unwrap();
    assert_eq!(stats.rows, r.displacements.len());
    let text = std::fs::read_to_string(&csv).unwrap();
    assert!(text.starts_with("node_id,x,y,z,dx,dy,dz\n"));
    assert_eq!(text.lines().count(), stats.rows + 1);
}

/// Format rules: flat deck, no comma-led line, ≤ 16 ids per set line,
/// node ids 1..N and element ids 1..M in order.
fn check_deck(inp: &Path) -> (usize, usize) {
    let text = std::fs::read_to_string(inp).unwrap();
    assert!(
        !text.to_ascii_uppercase().contains("*PART")
            && !text.to_ascii_uppercase().contains("*ASSEMBLY")
    );
    let (mut block, mut nodes, mut elems) = (String::new(), 0usize, 0usize);
    for line in text.lines() {
        assert!(
            !line.trim_start().starts_with(','),
            "comma-led line: {line}"
        );
        assert!(line.len() <= 132, "line too long for ccx: {line}");
        if line.starts_with('*') {
            block = line.to_ascii_uppercase();
            continue;
        }
        let first: Option<usize> = line.split(',').next().and_then(|t| t.trim().parse().ok());
        if block.starts_with("*NODE,") {
            nodes += 1;
            assert_eq!(first, Some(nodes));
        } else if block.starts_with("*ELEMENT") {
            elems += 1;
            assert_eq!(first, Some(elems));
        } else if block.starts_with("*NSET") || block.starts_with("*ELSET") {
            assert!(line.split(',').count() <= 16, "{line}");
        }
    }
    (nodes, elems)
}

#[test]
fn bricks_of_the_graded_bar_run_in_calculix() {
    let m = model(BAR);
    let p = FeaParams {
        element: Element::C3D8R,
        voxel: 1.0,
        seed: 3,
        step: Some(StepParams {
            top_displacement: TOP_UZ,
        }),
        ..FeaParams::default()
    };
    let (_scratch, dir) = scratch("bricks");
    let s = export(&m, &p, &dir);
    assert_eq!(s.units, 750, "{s:?}");
    let counts: std::collections::HashMap<_, _> = s.counts.iter().cloned().collect();
    assert_eq!(counts.len(), 2);
    // x > 2.5 is pure VeroCyan: 5 of 15 columns; x < −2.5 pure Agilus30.
    assert!(
        counts["VeroCyan"] > 250 && counts["Agilus30Clr"] > 250,
        "{counts:?}"
    );
    let (nodes, elems) = check_deck(&dir.join("model.inp"));
    assert_eq!((nodes, elems), (16 * 11 * 6, 750));
    let est = estimate_fea(&m, &p).unwrap();
    assert!(est.elements.abs_diff(750) < 100, "{est:?}");
    if run_ccx(&dir, "model") {
        check_bar_result(&dir, "C3D8R bar");
    }
}

#[test]
fn adaptive_tets_of_the_graded_bar_run_in_calculix() {
    let m = model(BAR);
    let p = FeaParams {
        element: Element::C3D4,
        min_cell: MIN_CELL,
        max_cell: MAX_CELL,
        seed: 11,
        step: Some(StepParams {
            top_displacement: TOP_UZ,
        }),
        ..FeaParams::default()
    };
    let (_scratch, dir) = scratch("tets");
    let s = export(&m, &p, &dir);
    let (_, elems) = check_deck(&dir.join("model.inp"));
    assert_eq!(elems as u64, s.units);
    assert!((1000..20_000).contains(&elems), "{elems}");
    let q = s
        .notes
        .iter()
        .find(|n| n.starts_with("tet quality"))
        .expect("quality note");
    eprintln!("C3D4 bar: {elems} elements; {q}");
    // Adaptive vs uniform at min_cell: at least 5× fewer.
    let uniform = build_mesh(
        &m,
        &FeaParams {
            max_cell: MIN_CELL,
            ..p.clone()
        },
        &AtomicBool::new(false),
        &|_, _, _, _| {},
    )
    .unwrap();
    eprintln!(
        "C3D4 bar: adaptive {elems} vs uniform {} elements ({:.1}×)",
        uniform.len(),
        uniform.len() as f64 / elems as f64
    );
    assert!(
        uniform.len() >= 5 * elems,
        "adaptive {elems}, uniform {}",
        uniform.len()
    );
    // Elements near the graded middle are smaller than at the pure ends.
    let mesh = build_mesh(&m, &p, &AtomicBool::new(false), &|_, _, _, _| {}).unwrap();
    let (mut mid, mut ends) = ((0.0, 0usize), (0.0, 0usize));
    for e in 0..mesh.len() {
        let c: Vec<_> = mesh
            .element_nodes(e)
            .iter()
            .map(|i| mesh.nodes[*i as usize])
            .collect();
        let v = signed_volume(&[c[0], c[1], c[2], c[3]]);
        let x = (c[0].x + c[1].x + c[2].x + c[3].x) / 4.0;
        let bin = if x.abs() < 1.0 {
            &mut mid
        } else if x.abs() > 5.0 {
            &mut ends
        } else {
            continue;
        };
        bin.0 += v;
        bin.1 += 1;
    }
    let (vm, ve) = (mid.0 / mid.1 as f64, ends.0 / ends.1 as f64);
    assert!(ve > 10.0 * vm, "mean volume middle {vm}, ends {ve}");
    let est = estimate_fea(&m, &p).unwrap();
    assert!(
        est.elements as f64 > 0.4 * elems as f64 && (est.elements as f64) < 2.5 * elems as f64,
        "{est:?} vs {elems}"
    );
    if run_ccx(&dir, "model") {
        check_bar_result(&dir, "C3D4 bar");
    }
}

#[test]
fn read_frd_of_the_uniaxial_brick_reference() {
    // Eight bricks of two materials in uniaxial compression, written by
    // hand; its heading gives the exact answer checked below.
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/bricks_c3d8r_uniaxial.inp");
    let (_scratch, dir) = scratch("uniaxial");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::copy(&src, dir.join("uni.inp")).unwrap();
    if !run_ccx(&dir, "uni") {
        return;
    }
    let r = read_frd(&dir.join("uni.frd")).unwrap();
    assert_eq!(r.nodes.len(), 27);
    assert_eq!(r.displacements.len(), 27);
    for (id, u) in &r.displacements {
        let z = r.nodes.iter().find(|(n, _)| n == id).unwrap().1[2];
        let want = if z == 0.0 {
            0.0
        } else if z == 10.0 {
            -0.9090909
        } else {
            -1.0
        };
        assert!((u[2] - want).abs() < 1e-5, "node {id} z {z}: uz {}", u[2]);
    }
    let rf = reaction(&dir.join("uni.dat")).unwrap();
    assert!((rf[2] - 72.72727).abs() < 1e-3, "{rf:?}");
    let stats = write_result_csv(&r, Some(&dir.join("uni.inp")), &dir.join("u.csv")).unwrap();
    assert_eq!(stats.rows, 27);
    assert!((stats.max_displacement - 1.0).abs() < 1e-6);
    let csv = std::fs::read_to_string(dir.join("u.csv")).unwrap();
    assert!(
        csv.lines().nth(14).unwrap().starts_with("14,10,10,10,"),
        "{csv}"
    );
}

/// The paper's loop with our own tools at every step but the solver:
/// export the graded bar as tets, solve it in CalculiX, convert the `.frd`
/// to CSV, and import the result as a SimulationField that grades a new
/// design by the simulated displacement.
#[test]
fn round_trip_through_calculix_into_a_simulation_field() {
    let (_scratch, dir) = scratch("roundtrip");
    let m = model(BAR);
    let p = FeaParams {
        element: Element::C3D4,
        min_cell: 1.0,
        max_cell: 4.0,
        step: Some(StepParams {
            top_displacement: TOP_UZ,
        }),
        ..FeaParams::default()
    };
    export(&m, &p, &dir);
    if !run_ccx(&dir, "model") {
        return;
    }
    let frd = read_frd(&dir.join("model.frd")).unwrap();
    let csv = dir.join("result.csv");
    write_result_csv(&frd, Some(&dir.join("model.inp")), &csv).unwrap();
    let header = std::fs::read_to_string(&csv).unwrap();
    assert!(
        header.starts_with("node_id,x,y,z,dx,dy,dz"),
        "{}",
        &header[..60]
    );

    // Import: the displacement magnitude drives a two-material grade.
    let script = r#"let m = default_materials();
        SimulationField("model.inp", "result.csv", ["clamp(0, len/0.1, 1)", "1 - clamp(0, len/0.1, 1)"],
                        [m.id("red"), m.id("blue")])"#;
    let d = run_script(
        script,
        "roundtrip.rhai",
        &ScriptOptions::for_file(&dir.join("roundtrip.rhai")),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let field = Model::prepare(&d.root, d.materials.clone()).unwrap();
    let red = |z: f64| {
        let (dist, f) = field.eval_point(glam::DVec3::new(5.0, 0.0, z));
        assert!(dist <= 0.0, "inside the bar at z = {z}");
        f.iter().find(|(id, _)| *id == 1).map_or(0.0, |x| x.1)
    };
    // Bottom fixed (|u| ≈ 0: blue), top moved 0.1 mm (|u| ≈ 0.1: red).
    let (bottom, top) = (red(-2.45), red(2.45));
    assert!(bottom < 0.2 && top > 0.8, "bottom {bottom}, top {top}");
}
