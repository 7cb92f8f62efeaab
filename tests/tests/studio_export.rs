//! The studio's export panels and jobs, headless (egui_kittest, see
//! `common/`): cancel and completion with a manifest, warnings, the disk
//! check, default folders per design and kind, replacing a finished export.

// A failed setup step (a scratch folder, a file read) fails the test.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::Path;

use egui::accesskit::Role;
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use volcad_studio::studio::egui;
use volcad_studio::studio::{Modal, StudioApp};

mod common;
use common::*;

fn job_state(a: &StudioApp) -> Option<&'static str> {
    use volcad_studio::studio::jobs::JobState;
    a.jobs().list().last().map(|j| match &j.state {
        JobState::Running(None) => "starting",
        JobState::Running(Some(_)) => "running",
        JobState::Done(_) => "done",
        JobState::Cancelled => "cancelled",
        JobState::Failed(_) => "failed",
    })
}

/// Type `path` into the Output folder field (replacing what is there).
fn set_output_folder(h: &mut Harness<'static, StudioApp>, path: &Path) {
    h.get_by_label("Output folder").focus();
    h.step();
    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::A);
    h.step();
    h.get_by_label("Output folder")
        .type_text(&path.display().to_string());
    h.step();
}

fn set_png_voxel(h: &mut Harness<'static, StudioApp>, mm: f64) {
    for node in h.get_all_by_label("Voxel (mm)") {
        node.set_value_accesskit(mm);
    }
    h.run_steps(2);
}

#[test]
fn png_export_cancels_cleanly_and_completes_with_a_manifest() {
    let (scratch, mut h) = studio(BAR, "export");
    let dir = scratch.path();
    wait_idle(&mut h);

    // A long export (384 million voxels: a debug build takes about a
    // minute), cancelled once it reports progress; a shorter one could
    // finish while the harness renders the frames below.
    let cancelled = dir.join("cancelled");
    set_output_folder(&mut h, &cancelled);
    set_png_voxel(&mut h, 0.0125);
    let est = wait_label(&mut h, "Estimate:");
    assert!(est.contains("1200 × 800 × 400 voxels"), "{est}");
    h.get_by_label("Export PNG stack").click();
    wait_for(&mut h, "progress", |a| job_state(a) == Some("running"));
    h.get_by_role(Role::ProgressIndicator);
    // Closing the window while it runs asks first.
    if let Some(v) = h.input_mut().viewports.get_mut(&egui::ViewportId::ROOT) {
        v.events.push(egui::ViewportEvent::Close);
    }
    h.run_steps(2);
    assert_eq!(h.state().modal(), Some(&Modal::QuitWithJobs));
    h.get_by_label("Keep working").click();
    h.run_steps(2);
    assert!(h.state().modal().is_none());
    assert_eq!(job_state(h.state()), Some("running"));
    h.get_by_label("Cancel").click();
    wait_for(&mut h, "the cancel", |a| {
        job_state(a).is_some_and(|s| s != "running" && s != "starting")
    });
    assert_eq!(job_state(h.state()), Some("cancelled"));
    assert!(!cancelled.exists(), "a cancelled export leaves nothing");
    let leftovers: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .flatten()
        .filter(|e| e.file_name().to_string_lossy().contains("partial"))
        .collect();
    assert!(
        leftovers.is_empty(),
        "no staging folder left: {leftovers:?}"
    );
    h.get_by_label_contains("Cancelled; nothing was written");

    // A small one, run to the end.
    let out = dir.join("stack");
    set_output_folder(&mut h, &out);
    set_png_voxel(&mut h, 0.25);
    let est = wait_label(&mut h, "Estimate: 60 ×");
    assert!(est.contains("60 × 40 × 20 voxels"), "{est}");
    h.get_by_label("Export PNG stack").click();
    wait_for(&mut h, "the export", |a| {
        job_state(a) == Some("done") || job_state(a) == Some("failed")
    });
    assert_eq!(job_state(h.state()), Some("done"));
    h.get_by_label_contains("Done in");
    h.get_by_label("Open folder");
    let pngs = std::fs::read_dir(&out)
        .unwrap()
        .flatten()
        .filter(|e| e.path().extension().is_some_and(|x| x == "png"))
        .count();
    assert_eq!(pngs, 20, "one PNG per layer");
    let manifest: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("manifest.json")).unwrap()).unwrap();
    assert_eq!(manifest["kind"], "png");
}

/// Files in `dir` whose names end with `ext`.
fn count_ext(dir: &Path, ext: &str) -> usize {
    std::fs::read_dir(dir)
        .unwrap()
        .flatten()
        .filter(|e| e.file_name().to_string_lossy().ends_with(ext))
        .count()
}

/// Clicks an export's Start button and steps until its job ends; it must
/// end done.
fn export_to_the_end(h: &mut Harness<'static, StudioApp>, button: &str) {
    h.get_by_label(button).click();
    wait_for(h, "the export", |a| {
        matches!(job_state(a), Some("done" | "failed" | "cancelled"))
    });
    assert_eq!(job_state(h.state()), Some("done"), "{button}");
}

#[test]
fn an_empty_slice_stack_is_reported_as_a_warning() {
    // A sphere minus a larger one: a box to slice, nothing inside it.
    let empty = "let m = default_materials();\nDifference(Sphere(Vec3(0,0,0), 5, m.id(\"red\")), Sphere(Vec3(0,0,0), 6, m.id(\"red\")))\n";
    let (scratch, mut h) = studio(empty, "empty");
    wait_idle(&mut h);
    let out = scratch.path().join("stack");
    set_output_folder(&mut h, &out);
    set_png_voxel(&mut h, 0.5);
    wait_label(&mut h, "Estimate:");
    export_to_the_end(&mut h, "Export PNG stack");
    h.get_by_label_contains("warning: no voxel centre is inside the design");
}

#[test]
fn a_gap_the_voxel_closes_is_named_in_the_panel_and_the_job_list() {
    // Two spheres 0.2 mm apart: 0.5 mm voxels can close the gap.
    let spheres = "let m = default_materials();\nUnion(false, [Sphere(Vec3(0,0,0), 1, m.id(\"red\")), Sphere(Vec3(2.2,0,0), 1, m.id(\"red\"))])\n";
    let (scratch, mut h) = studio(spheres, "gap");
    wait_idle(&mut h);
    let out = scratch.path().join("stack");
    set_output_folder(&mut h, &out);
    set_png_voxel(&mut h, 0.5);
    wait_label(&mut h, "Estimate:");
    let gap = "a gap between parts about 0.2 mm across";
    let before = h.get_all_by_label_contains(gap).count();
    assert!(before >= 1, "the panel's pre-flight warning");
    export_to_the_end(&mut h, "Export PNG stack");
    let after = h.get_all_by_label_contains(gap).count();
    assert!(after > before, "the job list names the gap too");
}

#[test]
fn mesh_and_fea_exports_run_from_their_panels() {
    let (scratch, mut h) = studio(BAR, "mesh-fea");
    let dir = scratch.path();
    wait_idle(&mut h);

    // Segmented meshes by dominant material (red and blue), every format.
    h.get_by_label("Mesh").click();
    h.run_steps(2);
    let meshes = dir.join("meshes");
    set_output_folder(&mut h, &meshes);
    let est = wait_label(&mut h, "Estimate:");
    assert!(
        est.contains("2 segments") && est.contains("triangles"),
        "{est}"
    );
    export_to_the_end(&mut h, "Export Meshes / 3MF");
    assert_eq!(count_ext(&meshes, ".stl"), 2);
    assert_eq!(count_ext(&meshes, ".obj"), 2);
    assert!(meshes.join("segments.3mf").is_file());
    let manifest: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(meshes.join("manifest.json")).unwrap())
            .unwrap();
    assert_eq!(manifest["kind"], "mesh");

    // An FEA deck of tetrahedra (the panel's default).
    h.get_by_label("FEA").click();
    h.run_steps(2);
    let fea = dir.join("fea");
    set_output_folder(&mut h, &fea);
    let est = wait_label(&mut h, "elements");
    assert!(est.contains(".inp"), "{est}");
    export_to_the_end(&mut h, "Export FEA (.inp)");
    assert_eq!(count_ext(&fea, ".inp"), 1);
    let manifest: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(fea.join("manifest.json")).unwrap()).unwrap();
    assert_eq!(manifest["kind"], "fea");
}

#[test]
fn an_export_larger_than_the_disk_is_not_started() {
    let (scratch, mut h) = studio(BAR, "disk");
    wait_idle(&mut h);
    // The bar at 1 µm: 7.5·10¹¹ voxels, some 500 GB of PNGs, more than
    // this disk holds; each layer still fits in memory.
    let out = scratch.path().join("huge");
    set_output_folder(&mut h, &out);
    set_png_voxel(&mut h, 0.001);
    let est = wait_label(&mut h, "Estimate: 15000 ×");
    assert!(est.contains("GiB on disk"), "{est}");
    h.get_by_label("Export PNG stack").click();
    h.run_steps(2);
    assert!(h.state().jobs().list().is_empty(), "no job starts");
    let log = h.state().log_lines().join("\n");
    assert!(
        log.contains("PNG stack export not started: \"Output folder\": the output needs about"),
        "{log}"
    );
    assert!(!out.exists());
}

#[test]
fn export_folders_default_to_the_design_and_kind() {
    let scratch = temp_dir("folders");
    let dir = scratch.path();
    let (_, mut h) = studio_with_file(dir, "bar.rhai", BAR);
    wait_idle(&mut h);
    assert_eq!(h.state().export_dir(), Some(dir.join("bar_png")));
    h.get_by_label("Mesh").click();
    h.run_steps(2);
    assert_eq!(h.state().export_dir(), Some(dir.join("bar_mesh")));
    h.get_by_label("FEA").click();
    h.run_steps(2);
    assert_eq!(h.state().export_dir(), Some(dir.join("bar_fea")));
    // A folder typed for one kind stays with it.
    set_output_folder(&mut h, &dir.join("deck"));
    h.get_by_label("PNG").click();
    h.run_steps(2);
    assert_eq!(h.state().export_dir(), Some(dir.join("bar_png")));
    h.get_by_label("FEA").click();
    h.run_steps(2);
    assert_eq!(h.state().export_dir(), Some(dir.join("deck")));
    drop(h);
    // An untitled design's go to the documents folder.
    let (data, mut h) = studio(BAR, "untitled-folders");
    wait_idle(&mut h);
    let docs = data.path().join("data/documents");
    assert_eq!(h.state().export_dir(), Some(docs.join("untitled_png")));
}

#[test]
fn the_spheres_fea_deck_does_not_land_in_the_bars_folder() {
    let scratch = temp_dir("two-decks");
    let dir = scratch.path();
    let (_, mut h) = studio_with_file(dir, "bar.rhai", BAR);
    wait_idle(&mut h);
    h.get_by_label("FEA").click();
    h.run_steps(2);
    wait_label(&mut h, "Estimate: about");
    export_to_the_end(&mut h, "Export FEA (.inp)");
    let sphere = dir.join("sphere.rhai");
    std::fs::write(&sphere, SPHERE).unwrap();
    let ctx = h.ctx.clone();
    h.state_mut().open_path(&ctx, sphere);
    wait_for(&mut h, "the sphere", |a| {
        bbox_x(a).is_some_and(|x| (x - 10.0).abs() < 0.01)
    });
    wait_idle(&mut h);
    assert_eq!(h.state().export_dir(), Some(dir.join("sphere_fea")));
    wait_label(&mut h, "Estimate: about");
    export_to_the_end(&mut h, "Export FEA (.inp)");
    let design = |folder: &str| -> serde_json::Value {
        let m = std::fs::read_to_string(dir.join(folder).join("manifest.json")).unwrap();
        serde_json::from_str::<serde_json::Value>(&m).unwrap()["design"].clone()
    };
    assert_eq!(design("bar_fea"), "bar.rhai");
    assert_eq!(design("sphere_fea"), "sphere.rhai");
    assert!(dir.join("bar_fea/model.inp").is_file());
}

#[test]
fn replacing_a_finished_export_asks_and_names_what_is_in_it() {
    let scratch = temp_dir("replace");
    let dir = scratch.path();
    let (_, mut h) = studio_with_file(dir, "bar.rhai", BAR);
    wait_idle(&mut h);
    set_png_voxel(&mut h, 0.5);
    wait_label(&mut h, "Estimate: 30 ×");
    export_to_the_end(&mut h, "Export PNG stack");
    let out = dir.join("bar_png");
    let files = || std::fs::read_dir(&out).unwrap().count();
    assert_eq!(files(), 11, "ten layers and the manifest");
    // Escape and Enter both keep the folder; replacing takes a click.
    for key in [egui::Key::Escape, egui::Key::Enter] {
        h.get_by_label("Export PNG stack").click();
        h.run_steps(2);
        assert!(
            matches!(h.state().modal(), Some(Modal::ConfirmExport(_))),
            "{:?}",
            h.state().modal()
        );
        h.get_by_label_contains("holds a finished export: a png export of bar.rhai (11 files,");
        h.get_by_label_contains("written 20");
        h.key_press(key);
        h.run_steps(2);
        assert!(h.state().modal().is_none(), "{key:?}");
        assert_eq!(h.state().jobs().list().len(), 1, "{key:?}: no new job");
        assert_eq!(files(), 11);
    }
    h.get_by_label("Export PNG stack").click();
    h.run_steps(2);
    h.get_by_label("Replace").click();
    wait_for(&mut h, "the second export", |a| {
        a.jobs().list().len() == 2 && !a.jobs().any_running()
    });
    assert_eq!(job_state(h.state()), Some("done"));
    assert_eq!(files(), 11);
    // A folder of other files is refused, naming them.
    let mine = dir.join("mine");
    std::fs::create_dir(&mine).unwrap();
    std::fs::write(mine.join("notes.txt"), "x").unwrap();
    set_output_folder(&mut h, &mine);
    h.get_by_label("Export PNG stack").click();
    h.run_steps(2);
    assert!(h.state().modal().is_none());
    assert_eq!(h.state().jobs().list().len(), 2, "no job starts");
    let log = h.state().log_lines().join("\n");
    assert!(
        log.contains("PNG stack export not started: \"Output folder\" ")
            && log.contains("holds other files (notes.txt) and no export manifest"),
        "{log}"
    );
}
