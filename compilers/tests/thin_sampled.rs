//! Thin features whose thickness the design does not state (a mesh, a
//! math-string `Function`), measured by sampling the distance, reach the
//! export's warnings and manifest as stated ones do.

mod common;

use std::sync::Arc;

use common::{mesh_design, mesh_stl, model, scratch};
use volcad_compilers::thin::thin_feature_notes;
use volcad_core::Model;

/// A gyroid sheet about 0.3 mm thick (|g| < 0.2, |grad g| up to about
/// 1.5), clipped to a 10 mm cube.
const GYROID: &str = r#"let m = default_materials();
Intersection(false, [
    Function("abs(sin(x)*cos(y) + sin(y)*cos(z) + sin(z)*cos(x)) - 0.2", m.id("gray")),
    RectPrism(Vec3(0, 0, 0), Vec3(10, 10, 10), m.id("gray")),
])"#;

fn warnings(notes: &[String]) -> Vec<&String> {
    notes.iter().filter(|n| n.starts_with("warning")).collect()
}

#[test]
fn a_thin_mesh_plate_warns_at_half_a_millimetre_and_not_at_a_tenth() {
    let m = mesh_design("plate_0.3mm.obj");
    let s = m.sampled_thinnest().expect("a bounded mesh");
    let f = s.feature.as_ref().expect("the plate's wall");
    assert!((f.thickness - 0.3).abs() < 0.01, "{f:?}");

    let (_t, dir) = scratch("mesh");
    let summary = mesh_stl(&m, 0.5, &dir);
    let w = warnings(&summary.notes);
    assert!(
        w.iter().any(|n| n.contains("a mesh about 0.3 mm across")
            && n.contains("measured by sampling")
            && n.contains("--voxel 0.15 resolves it")),
        "{w:?}"
    );
    let manifest = std::fs::read_to_string(dir.join("manifest.json")).expect("manifest");
    assert!(manifest.contains("--voxel 0.15 resolves it"), "{manifest}");

    let notes = thin_feature_notes(&m, 0.1, "--voxel");
    assert!(warnings(&notes).is_empty(), "{notes:?}");
    assert!(
        notes
            .iter()
            .any(|n| n.contains("measured by sampling every")),
        "{notes:?}"
    );
}

#[test]
fn a_thin_gyroid_sheet_warns_at_half_a_millimetre_and_not_at_a_tenth() {
    let m = model(GYROID);
    let f = m
        .sampled_thinnest()
        .and_then(|s| s.feature.clone())
        .expect("the sheet");
    assert!(f.thickness > 0.2 && f.thickness < 0.4, "{f:?}");
    let notes = thin_feature_notes(&m, 0.5, "--voxel");
    assert!(
        warnings(&notes)
            .iter()
            .any(|n| n.contains("a Function about") && n.contains("resolves it")),
        "{notes:?}"
    );
    let notes = thin_feature_notes(&m, 0.1, "--voxel");
    assert!(warnings(&notes).is_empty(), "{notes:?}");
}

#[test]
fn a_fat_mesh_sphere_does_not_warn() {
    let m = mesh_design("sphere_10mm.obj");
    let f = m
        .sampled_thinnest()
        .and_then(|s| s.feature.clone())
        .expect("the ball");
    assert!(f.thickness > 9.0, "{f:?}");
    let notes = thin_feature_notes(&m, 0.5, "--voxel");
    assert!(warnings(&notes).is_empty(), "{notes:?}");
}

#[test]
fn the_estimate_is_the_same_on_one_and_two_threads() {
    let on = |threads: usize, design: &dyn Fn() -> Arc<Model>| {
        let m = design();
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("a pool")
            .install(|| m.sampled_thinnest())
    };
    let gyroid = || model(GYROID);
    let plate = || mesh_design("plate_0.3mm.obj");
    for design in [&gyroid as &dyn Fn() -> Arc<Model>, &plate] {
        let one = on(1, design);
        assert!(one.as_ref().is_some_and(|s| s.feature.is_some()));
        assert_eq!(one, on(2, design));
    }
}

#[test]
fn designs_whose_thickness_is_stated_are_not_sampled() {
    let m = model(r#"Sphere(Vec3(0, 0, 0), 5, default_materials().id("gray"))"#);
    let notes = thin_feature_notes(&m, 0.5, "--voxel");
    assert!(notes.is_empty(), "{notes:?}");
}

#[test]
fn cells_no_larger_than_the_sampling_spacing_skip_the_sampling() {
    let m = mesh_design("sphere_10mm.obj");
    let h = m.thin_sampling_spacing().expect("a bounded design");
    let notes = thin_feature_notes(&m, h, "--voxel");
    assert!(warnings(&notes).is_empty(), "{notes:?}");
    assert!(
        notes.iter().any(|n| n.contains("were not sampled")),
        "{notes:?}"
    );
}

#[test]
fn sampling_only_as_deep_as_the_export_needs_finds_the_same_thin_plate() {
    // Half the plate is 0.15 mm deep: sampling to 0.5 mm finds it as the
    // full sampling does; sampling to 0.1 mm (features under 0.2 mm)
    // leaves it out, and a later full request samples again.
    let m = mesh_design("plate_0.3mm.obj");
    let full = m.sampled_thinnest().expect("a bounded mesh");
    let fresh = mesh_design("plate_0.3mm.obj");
    let capped = fresh.sampled_thinnest_below(1.0).expect("a bounded mesh");
    assert_eq!(capped, full);
    let shallow = mesh_design("plate_0.3mm.obj");
    let s = shallow.sampled_thinnest_below(0.2).expect("a bounded mesh");
    assert!(s.feature.is_none(), "{s:?}");
    let again = shallow.sampled_thinnest().expect("a bounded mesh");
    assert_eq!(again, full);
}
