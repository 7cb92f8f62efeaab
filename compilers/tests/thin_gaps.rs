//! Gaps between parts that the voxel cannot keep open: stated by the
//! design (two spheres, a slot), or measured by sampling (a mesh of two
//! plates), reach the export's warnings and manifest; the mesh's bodies
//! are compared with the design's parts; a concave corner is no gap.

mod common;

use common::{mesh_design, mesh_stl, model, scratch};
use volcad_compilers::thin::thin_feature_notes;

/// Two spheres of radius 1 mm, 0.2 mm apart.
const SPHERES: &str = r#"let m = default_materials();
Union(false, [Sphere(Vec3(0, 0, 0), 1, m.id("gray")), Sphere(Vec3(2.2, 0, 0), 1, m.id("gray"))])"#;

/// The voxel a note suggests: `--voxel V keeps it open`.
fn suggested(note: &str) -> Option<f64> {
    let (head, _) = note.rsplit_once(" keeps it open")?;
    head.rsplit_once("--voxel ")?.1.parse().ok()
}

fn warnings(notes: &[String]) -> Vec<&String> {
    notes.iter().filter(|n| n.starts_with("warning")).collect()
}

#[test]
fn two_spheres_a_fifth_of_a_millimetre_apart_warn_at_half_a_millimetre() {
    let m = model(SPHERES);
    let (_t, dir) = scratch("mesh");
    let s = mesh_stl(&m, 0.5, &dir);
    let w = warnings(&s.notes);
    let gap = "a gap between parts about 0.2 mm across (between a sphere and a sphere near (1.1, 0, 0) mm) is narrower than two cells of --voxel 0.5: it can close and join the parts on either side; --voxel 0.1 keeps it open";
    assert!(w.iter().any(|n| n.ends_with(gap)), "{w:?}");
    let manifest = std::fs::read_to_string(dir.join("manifest.json")).expect("manifest");
    assert!(manifest.contains(gap), "{manifest}");
}

#[test]
fn two_boxes_that_merge_at_half_a_millimetre_say_so() {
    let m = model(
        r#"let m = default_materials();
Union(false, [RectPrism(Vec3(0, 0, 0), Vec3(2, 2, 2), m.id("gray")), RectPrism(Vec3(2.1, 0, 0), Vec3(1.8, 2, 2), m.id("gray"))])"#,
    );
    // The box is 4 mm long, 8 voxels: their centres fall at 0.75 and
    // 1.25 mm, on either side of the gap from 1 to 1.2 mm.
    let (_t, dir) = scratch("mesh");
    let s = mesh_stl(&m, 0.5, &dir);
    assert!(
        s.notes
            .iter()
            .any(|n| n == "bodies: 1 (the design has 2 separate parts)"),
        "{:?}",
        s.notes
    );
    let merged = "warning: 2 parts of the design merged into 1 body: the gap between them, 0.2 mm, is narrower than two voxels of 0.5 mm; --voxel 0.1 keeps them apart";
    assert!(s.notes.iter().any(|n| n == merged), "{:?}", s.notes);
    let manifest = std::fs::read_to_string(dir.join("manifest.json")).expect("manifest");
    assert!(manifest.contains(merged), "{manifest}");
}

#[test]
fn two_spheres_a_fifth_of_a_millimetre_apart_stay_two_bodies_at_five_hundredths() {
    let m = model(SPHERES);
    let (_t, dir) = scratch("mesh");
    let s = mesh_stl(&m, 0.05, &dir);
    assert!(warnings(&s.notes).is_empty(), "{:?}", s.notes);
    assert!(
        s.notes
            .iter()
            .any(|n| n == "bodies: 2 (the design has 2 separate parts)"),
        "{:?}",
        s.notes
    );
}

#[test]
fn a_slot_cut_by_a_box_warns_until_the_voxel_keeps_it_open() {
    let m = model(
        r#"let m = default_materials();
Difference(RectPrism(Vec3(0, 0, 0), Vec3(10, 10, 2), m.id("gray")), RectPrism(Vec3(0, 0, 0), Vec3(0.3, 20, 4), m.id("gray")))"#,
    );
    let notes = thin_feature_notes(&m, 0.5, "--voxel");
    assert!(
        warnings(&notes).iter().any(|n| n
            .contains("about 0.3 mm across (a slot or hole cut by a box near (0, 0, 0) mm)")
            && n.ends_with("--voxel 0.15 keeps it open")),
        "{notes:?}"
    );
    assert!(thin_feature_notes(&m, 0.15, "--voxel").is_empty());
}

#[test]
fn a_mesh_of_two_plates_with_a_slot_warns_by_sampling() {
    let m = mesh_design("plates_0.3mm_slot.obj");
    let s = m.sampled_thinnest().expect("a bounded mesh");
    let g = s.gap.as_ref().expect("the slot");
    assert!((g.thickness - 0.3).abs() < 0.01, "{g:?}");
    assert!((g.at.x - 10.15).abs() < s.spacing, "{g:?}");
    let (_t, dir) = scratch("mesh");
    let summary = mesh_stl(&m, 0.5, &dir);
    let w = warnings(&summary.notes);
    assert!(
        w.iter().any(|n| n
            .starts_with("warning: a gap between parts about 0.3 mm across (near (10.1, ")
            && n.contains("measured by sampling every")
            && n.ends_with(" keeps it open")
            && suggested(n).is_some_and(|v| (0.14..=0.15).contains(&v))),
        "{w:?}"
    );
    let manifest = std::fs::read_to_string(dir.join("manifest.json")).expect("manifest");
    assert!(
        manifest.contains("a gap between parts about 0.3 mm across"),
        "{manifest}"
    );
    let notes = thin_feature_notes(&m, 0.1, "--voxel");
    assert!(warnings(&notes).is_empty(), "{notes:?}");
}

#[test]
fn a_concave_corner_is_no_gap() {
    // Stated: an L of two boxes that share a face.
    let m = model(
        r#"let m = default_materials();
Union(false, [RectPrism(Vec3(0, 0, 0), Vec3(10, 3, 3), m.id("gray")), RectPrism(Vec3(-3.5, 6.5, 0), Vec3(3, 10, 3), m.id("gray"))])"#,
    );
    assert_eq!(m.stated_gaps(10.0).narrowest, None);
    assert!(thin_feature_notes(&m, 1.0, "--voxel").is_empty());
    // Sampled: the same L as a mesh.
    let m = mesh_design("l_bracket.obj");
    let s = m.sampled_thinnest().expect("a bounded mesh");
    assert_eq!(s.gap, None, "{s:?}");
    for voxel in [0.5, 1.0] {
        let notes = thin_feature_notes(&m, voxel, "--voxel");
        assert!(warnings(&notes).is_empty(), "{voxel}: {notes:?}");
    }
}

#[test]
fn gaps_are_the_same_on_one_and_two_threads() {
    let on = |threads: usize| {
        let m = mesh_design("plates_0.3mm_slot.obj");
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("a pool")
            .install(|| (m.sampled_thinnest(), model(SPHERES).stated_gaps(1.0)))
    };
    let one = on(1);
    assert!(one.0.as_ref().is_some_and(|s| s.gap.is_some()));
    assert!(one.1.narrowest.is_some());
    assert_eq!(one, on(2));
}
