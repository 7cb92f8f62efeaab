//! The studio's files, headless (egui_kittest, see `common/`): autosave
//! and recovery, closing with unsaved changes, opening another file, Save
//! As through the built-in browser.

// A failed setup step (a scratch folder, a file read) fails the test.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::time::{Duration, Instant};

use egui_kittest::kittest::Queryable;
use volcad_studio::studio::egui;
use volcad_studio::studio::{Modal, StudioOptions};

mod common;
use common::*;

#[test]
fn autosave_writes_the_recovery_file_and_restart_offers_it() {
    let (scratch, mut h) = studio(BAR, "recovery");
    let dir = scratch.path();
    wait_idle(&mut h);
    type_at_end(&mut h, " // unsaved edit");
    let rec = dir.join("data/recovery.rhai");
    let t = Instant::now();
    while std::fs::read_to_string(&rec).map_or(true, |s| !s.contains("unsaved edit")) {
        h.step();
        assert!(t.elapsed() < Duration::from_secs(20), "no recovery file");
        std::thread::sleep(Duration::from_millis(20));
    }
    drop(h);
    // A new session (same data folder) offers the text back.
    let mut h2 = harness(StudioOptions::for_tests(dir.join("data"), BAR));
    h2.step();
    assert!(matches!(h2.state().modal(), Some(Modal::Restore(_))));
    h2.get_by_label("Restore").click();
    h2.run_steps(2);
    assert!(h2.state().text().ends_with("// unsaved edit"));
}

#[test]
fn closing_with_unsaved_changes_asks_first() {
    let (_dir, mut h) = studio(BAR, "close");
    wait_idle(&mut h);
    type_at_end(&mut h, " ");
    if let Some(v) = h.input_mut().viewports.get_mut(&egui::ViewportId::ROOT) {
        v.events.push(egui::ViewportEvent::Close);
    }
    h.run_steps(2);
    assert!(
        matches!(h.state().modal(), Some(Modal::Unsaved(_))),
        "{:?}",
        h.state().modal()
    );
    h.get_by_label("Cancel").click();
    h.run_steps(2);
    assert!(h.state().modal().is_none());
}

/// Opening a different file frames its part, not the part that was on
/// screen before (the camera used to be fitted to the old model while the
/// new script was still running).
#[test]
fn opening_a_file_frames_the_new_design() {
    let (scratch, mut h) = studio(
        "Sphere(Vec3(0, 0, 0), 2.0, default_materials().id(\"red\"))",
        "frame",
    );
    wait_idle(&mut h);
    let small = h.state().viewport().settings.camera.distance;
    let big = scratch.path().join("big.rhai");
    std::fs::write(
        &big,
        "RectPrism(Vec3(100, 0, 0), Vec3(80, 60, 40), default_materials().id(\"blue\"))",
    )
    .expect("write big.rhai");
    let ctx = h.ctx.clone();
    h.state_mut().open_path(&ctx, big);
    wait_for(&mut h, "the big design", |a| {
        a.is_idle() && bbox_x(a).is_some_and(|x| (x - 80.0).abs() < 1e-6)
    });
    h.run_steps(3);
    let cam = h.state().viewport().settings.camera;
    assert!(
        (cam.target.x - 100.0).abs() < 1.0,
        "camera still aimed at the old part: {cam:?}"
    );
    assert!(
        cam.distance > 10.0 * small,
        "camera distance {} for a 108 mm part (was {small} for the sphere)",
        cam.distance
    );
}

/// Undoing back to the saved text, and then quitting, leaves no recovery
/// file: the next start must not offer "Restore unsaved work".
#[test]
fn a_clean_document_leaves_no_recovery_file() {
    let (scratch, mut h) = studio(BAR, "recovery-clean");
    let dir = scratch.path();
    wait_idle(&mut h);
    let saved = dir.join("bar.rhai");
    assert!(h.state_mut().save_to(saved.clone()));
    type_at_end(&mut h, " // edit");
    let rec = dir.join("data/recovery.rhai");
    let t = Instant::now();
    while !rec.exists() {
        h.step();
        assert!(t.elapsed() < Duration::from_secs(20), "no recovery file");
        std::thread::sleep(Duration::from_millis(20));
    }
    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    h.run_steps(3);
    assert_eq!(h.state().text(), BAR, "undo did not restore the saved text");
    assert!(!h.state().is_dirty());
    assert!(!rec.exists(), "recovery file kept for a clean document");
    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Q);
    h.run_steps(2);
    drop(h);
    let mut h2 = harness(StudioOptions::for_tests(dir.join("data"), BAR));
    h2.step();
    assert!(
        h2.state().modal().is_none(),
        "a clean exit offered: {:?}",
        h2.state().modal()
    );
}

/// With no desktop dialog (no xdg-desktop-portal, as here), Save As opens
/// the built-in file browser, and saving through it writes the file.
#[test]
fn save_as_falls_back_to_the_built_in_file_browser() {
    let (scratch, mut h) = studio(BAR, "dialog");
    let file = scratch.path().join("a.rhai");
    std::fs::write(&file, BAR).expect("write a.rhai");
    let ctx = h.ctx.clone();
    h.state_mut().open_path(&ctx, file.clone());
    wait_idle(&mut h);
    type_at_end(&mut h, " // saved by the built-in dialog");
    h.key_press_modifiers(
        egui::Modifiers::COMMAND | egui::Modifiers::SHIFT,
        egui::Key::S,
    );
    h.run_steps(3);
    assert!(
        h.query_by_label("Save design as").is_some(),
        "no built-in dialog; log:\n{}",
        h.state().log_lines().join("\n")
    );
    h.get_by_label("Save").click();
    h.run_steps(3);
    let saved = std::fs::read_to_string(&file).expect("read a.rhai");
    assert!(
        saved.ends_with("// saved by the built-in dialog"),
        "{saved}"
    );
    assert!(!h.state().is_dirty());
    let log = h.state().log_lines().join("\n");
    assert!(log.contains("built-in file browser"), "{log}");
}
