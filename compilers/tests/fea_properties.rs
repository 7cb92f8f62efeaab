//! FEA from property fields: a bar whose `modulus` rises along its axis,
//! exported as elastic sets (`property_bins`) and solved by CalculiX,
//! against the 1-D series-spring estimate.
//!
//! A bar of section A and length L with modulus E(z) under an axial force F
//! shortens by δ = F/A ∫ dz/E(z) (springs in series). With
//! E(z) = E₀(1 + 3 s), s = (z − z₀)/L, ∫ dz/E = L ln 4 / (3 E₀), so under
//! the same force it shortens ln 4 / 3 ≈ 0.462 times as much as a uniform
//! bar of E₀. The deck's step prescribes the top's displacement instead;
//! the solver's reaction force F then gives the displacement per unit force
//! u/F, whose ratio is the same. ccx must be on PATH (see `fea.rs`).

// A failed setup step (a scratch folder, a file read) fails the test.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::Path;

mod common;

use common::{model, reaction, run, run_ccx, scratch};
use volcad_compilers::fea::*;

/// A 4 × 4 × 40 mm bar along z (z ∈ [−20, 20]); `{E}` is its modulus.
const BAR: &str = r#"let m = j750_materials();
let b = RectPrism(Vec3(0,0,0), Vec3(4,4,40), m.id("VeroCyan"));
b.set_attribute("modulus", {E});
b.set_attribute("poissons_ratio", 0.3);
b"#;

const TOP_UZ: f64 = -0.1;

fn params(bins: Option<usize>) -> FeaParams {
    FeaParams {
        element: Element::C3D8R,
        voxel: 1.0,
        property_bins: bins,
        step: Some(StepParams {
            top_displacement: TOP_UZ,
        }),
        ..FeaParams::default()
    }
}

/// The bar's `*MATERIAL` count and its `*ELASTIC` moduli, from the deck.
fn moduli(inp: &Path) -> Vec<f64> {
    let text = std::fs::read_to_string(inp).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    lines
        .windows(2)
        .filter(|w| w[0] == "*ELASTIC")
        .map(|w| w[1].split(',').next().unwrap().trim().parse().unwrap())
        .collect()
}

/// Export and solve `modulus` (a number or a math string); the reaction
/// force (N) on the clamped end, or `None` when ccx is skipped.
fn solve(modulus: &str, bins: Option<usize>, name: &str) -> (Vec<f64>, Option<f64>) {
    let m = model(&BAR.replace("{E}", modulus));
    let (_scratch, dir) = scratch(name);
    let p = params(bins);
    let s = run(&dir, move |ctx| export_fea(&m, &p, ctx)).unwrap();
    assert_eq!(s.units, 4 * 4 * 40, "{s:?}");
    let e = moduli(&dir.join("model.inp"));
    if !run_ccx(&dir, "model") {
        return (e, None);
    }
    let rf = reaction(&dir.join("model.dat")).expect("reaction force in model.dat");
    (e, Some(rf[2].abs()))
}

#[test]
fn graded_modulus_bar_is_stiffer_by_the_series_spring_estimate() {
    // The uniform bar: one set of 100 MPa, whatever the material table says.
    let (e_soft, f_soft) = solve("100.0", None, "soft");
    assert_eq!(e_soft, vec![100.0]);
    // Modulus 100 → 400 MPa from the bottom to the top, 16 bins.
    let (e_graded, f_graded) = solve("\"100 * (1 + 3 * (z + 20) / 40)\"", Some(16), "graded");
    assert_eq!(e_graded.len(), 16, "{e_graded:?}");
    assert!(e_graded.windows(2).all(|w| w[0] < w[1]), "{e_graded:?}");
    assert!(e_graded[0] > 100.0 && e_graded[0] < 120.0, "{e_graded:?}");
    assert!(e_graded[15] > 380.0 && e_graded[15] < 400.0, "{e_graded:?}");
    let (Some(f_soft), Some(f_graded)) = (f_soft, f_graded) else {
        return;
    };
    // Displacement per unit force, graded over uniform.
    let measured = (TOP_UZ.abs() / f_graded) / (TOP_UZ.abs() / f_soft);
    let predicted = 4f64.ln() / 3.0;
    let err = (measured / predicted - 1.0).abs();
    eprintln!(
        "uniform 100 MPa: RF {f_soft:.4} N; graded 100-400 MPa: RF {f_graded:.4} N; displacement ratio {measured:.4} vs series-spring {predicted:.4} ({:.2} %)",
        100.0 * err
    );
    assert!(err < 0.10, "measured {measured}, predicted {predicted}");
    // The uniform bar against its own 1-D estimate, F = E A u / L.
    let f_1d = 100.0 * 16.0 * TOP_UZ.abs() / 40.0;
    assert!((f_soft / f_1d - 1.0).abs() < 0.10, "{f_soft} vs {f_1d}");
}

#[test]
fn property_bins_refuse_a_design_without_modulus() {
    let m = model(
        r#"let m = j750_materials(); let b = RectPrism(Vec3(0,0,0), Vec3(4,4,4), m.id("VeroCyan")); b.set_attribute("density", 1.1); b"#,
    );
    let (_scratch, dir) = scratch("nomod");
    let p = params(Some(8));
    let e = run(&dir, move |ctx| export_fea(&m, &p, ctx))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("--property-bins") && e.contains("modulus") && e.contains("density"),
        "{e}"
    );
    assert!(!dir.join("model.inp").exists());
}

/// The example column (`assets/examples/modulus_beam.rhai`) exports with
/// its modulus, Poisson ratio and density and solves in CalculiX; its
/// reaction force matches the series-spring estimate
/// F = u A / ∫ dz/E(z), E = 500 + 2350 s, ∫ = L ln(2850/500) / 2350.
#[test]
fn modulus_beam_example_solves_in_calculix() {
    let path = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../assets/examples/modulus_beam.rhai");
    let m = model(&std::fs::read_to_string(path).unwrap());
    let (_scratch, dir) = scratch("beam");
    let p = params(None);
    let s = run(&dir, move |ctx| export_fea(&m, &p, ctx)).unwrap();
    assert_eq!(s.units, 6 * 6 * 60, "{s:?}");
    let deck = std::fs::read_to_string(dir.join("model.inp")).unwrap();
    assert_eq!(deck.matches("*DENSITY\n0.00000000117\n").count(), 16);
    assert_eq!(moduli(&dir.join("model.inp")).len(), 16);
    if !run_ccx(&dir, "model") {
        return;
    }
    let f = reaction(&dir.join("model.dat")).unwrap()[2].abs();
    let f_1d = TOP_UZ.abs() * 36.0 / (60.0 * (2850.0f64 / 500.0).ln() / 2350.0);
    assert!((f / f_1d - 1.0).abs() < 0.10, "{f} vs {f_1d}");
}
