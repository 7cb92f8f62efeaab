//! The studio's editor, headless (egui_kittest, see `common/`): typing
//! reruns the design, errors are listed by line, sliders, find and undo,
//! key order, the language reference, completion and parameter sets.

// A failed setup step (a scratch folder, a file read) fails the test.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use egui::accesskit::Role;
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use volcad_studio::studio::egui;
use volcad_studio::studio::{StudioApp, StudioOptions};

mod common;
use common::*;

#[test]
fn typing_changes_the_design() {
    let (_dir, mut h) = studio(BAR, "typing");
    wait_idle(&mut h);
    assert_eq!(bbox_x(h.state()), Some(15.0));
    h.get_by_label_contains("bbox 15.00 × 10.00 × 5.00 mm");
    // Legend lists the materials the design uses.
    h.get_by_label("red");
    h.get_by_label("blue");

    type_at_end(
        &mut h,
        r#"; let root = RectPrism(Vec3(0, 0, 0), Vec3(30, 10, 5), m.id("green"));"#,
    );
    assert!(
        h.state().text().ends_with("m.id(\"green\"));"),
        "{}",
        h.state().text()
    );
    wait_for(&mut h, "the new design", |a| bbox_x(a) == Some(30.0));
    wait_idle(&mut h);
    h.get_by_label_contains("bbox 30.00 × 10.00 × 5.00 mm");
    h.get_by_label("green");
    assert!(
        h.query_by_label("red").is_none(),
        "the legend follows the design"
    );
    assert!(h.state().is_dirty());
}

#[test]
fn syntax_error_is_listed_at_its_line_and_the_preview_is_kept() {
    let (_dir, mut h) = studio(BAR, "error");
    wait_idle(&mut h);
    let before = h.state().model().cloned().expect("a model");
    type_at_end(&mut h, "; let x = ;");
    wait_for(&mut h, "the error", |a| !a.problems().is_empty());
    let problems = h.state().problems();
    assert_eq!(problems[0].line, Some(4), "{problems:?}");
    h.get_by_label_contains("error  line 4");
    h.get_by_label_contains("Stale: the script has an error");
    let after = h
        .state()
        .model()
        .cloned()
        .expect("the last good model stays");
    assert!(std::sync::Arc::ptr_eq(&before, &after));
    h.get_by_label_contains("bbox 15.00 × 10.00 × 5.00 mm");

    // Clicking the problem puts the cursor on line 4.
    h.get_by_label_contains("error  line 4").click();
    h.run_steps(3);
    h.get_by_label("line 4");
    assert!(
        h.get_by_role(Role::MultilineTextInput).is_focused(),
        "the editor takes the focus"
    );

    // Fix it: the error goes and the stale marker with it.
    h.key_press_modifiers(egui::Modifiers::CTRL, egui::Key::End);
    h.key_press(egui::Key::Backspace);
    h.step();
    h.get_by_role(Role::MultilineTextInput)
        .type_text("1; graded");
    wait_for(&mut h, "the fix", |a| {
        a.problems().is_empty() && a.is_idle()
    });
    assert!(h.query_by_label_contains("Stale").is_none());
}

#[test]
fn parameter_slider_reruns_with_the_value() {
    let script = r#"let m = default_materials();
let w = param("width", 15.0, 5.0, 30.0);
RectPrism(Vec3(0, 0, 0), Vec3(w, 10, 5), m.id("gray"))"#;
    let (_dir, mut h) = studio(script, "param");
    wait_idle(&mut h);
    assert_eq!(bbox_x(h.state()), Some(15.0));
    h.get_by_role_and_label(Role::Slider, "width")
        .set_value_accesskit(22.0);
    wait_for(&mut h, "the new width", |a| {
        bbox_x(a).is_some_and(|x| (x - 22.0).abs() < 1e-9)
    });
    h.get_by_label_contains("bbox 22.00 × 10.00 × 5.00 mm");
    assert_eq!(h.state().text(), script, "the text is not edited");
    assert!(!h.state().is_dirty());
}

#[test]
fn find_tab_and_undo_in_the_editor() {
    let (_dir, mut h) = studio(BAR, "editor");
    wait_idle(&mut h);
    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::F);
    h.step();
    h.get_by_label("Find:");
    // The query field has the focus.
    h.event(egui::Event::Text("FGrade".into()));
    h.step();
    h.get_by_label("1 match");
    h.key_press(egui::Key::Enter);
    h.run_steps(3);
    h.get_by_label("line 3");

    // Tab indents with four spaces; Ctrl+Z takes it back.
    type_at_end(&mut h, "");
    h.key_press(egui::Key::Tab);
    h.step();
    assert!(
        h.state().text().ends_with("graded    "),
        "{:?}",
        h.state().text()
    );
    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    h.run_steps(2);
    assert_eq!(h.state().text(), BAR);
}

/// Text and Enter arriving in one frame (a fast typist) keep their order:
/// `bbbb⏎cccc` with each pair of keys in one frame gives two lines.
#[test]
fn keys_in_one_frame_keep_their_order() {
    let (_dir, mut h) = studio("", "key-order");
    wait_idle(&mut h);
    let editor = h.get_by_role(Role::MultilineTextInput);
    editor.focus();
    h.step();
    let enter = |pressed| egui::Event::Key {
        key: egui::Key::Enter,
        physical_key: None,
        pressed,
        repeat: false,
        modifiers: egui::Modifiers::NONE,
    };
    let frames: Vec<Vec<egui::Event>> = vec![
        vec![egui::Event::Text("b".into()), egui::Event::Text("b".into())],
        vec![egui::Event::Text("b".into()), egui::Event::Text("b".into())],
        vec![egui::Event::Text("b".into()), enter(true), enter(false)],
        vec![
            egui::Event::Text("c".into()),
            enter(true),
            egui::Event::Text("c".into()),
            enter(true),
        ],
        vec![egui::Event::Text("c".into()), egui::Event::Text("c".into())],
    ];
    for events in frames {
        h.input_mut().events.extend(events);
        h.step();
    }
    h.run_steps(4);
    assert_eq!(h.state().text(), "bbbbb\nc\nc\ncc");
}

/// F1 opens the language reference; its search filters the entries.
#[test]
fn the_language_reference_opens_and_searches() {
    let (_dir, mut h) = studio(BAR, "reference");
    wait_idle(&mut h);
    h.key_press(egui::Key::F1);
    h.run_steps(2);
    assert!(h.state().reference.open);
    assert!(h.query_by_label("GraphLattice").is_some());
    assert!(h.query_by_label("Sphere").is_some());
    h.state_mut().reference.query = "lattice".into();
    h.run_steps(2);
    assert!(h.query_by_label("GraphLattice").is_some());
    assert!(
        h.query_by_label("Sphere").is_none(),
        "search did not filter"
    );
}

/// The labels the editor's completion list offers now.
fn completion_labels(h: &Harness<'static, StudioApp>) -> Vec<String> {
    h.state()
        .editor_completion()
        .iter()
        .map(|i| i.label.clone())
        .collect()
}

/// Typing two letters of a node name lists it; Enter inserts the
/// skeleton. Inside `id("…")` the design's material names are offered.
#[test]
fn completion_inserts_node_skeletons_and_material_names() {
    let (_dir, mut h) = studio(BAR, "completion");
    wait_idle(&mut h);
    type_at_end(&mut h, ";\nlet s = Sph");
    h.run_steps(2);
    let items = completion_labels(&h);
    assert_eq!(
        items.first().map(String::as_str),
        Some("Sphere"),
        "{items:?}"
    );
    h.key_press(egui::Key::Enter);
    h.run_steps(2);
    assert!(
        h.state()
            .text()
            .ends_with("let s = Sphere(Vec3(0, 0, 0), 5.0, m.id(\"red\"))"),
        "{}",
        h.state().text()
    );
    type_at_end(&mut h, ";\nm.id(\"bl");
    h.run_steps(2);
    let items = completion_labels(&h);
    assert!(items.iter().any(|i| i == "blue"), "{items:?}");
}

/// Slider values saved as a named set beside the design come back when the
/// design is opened again, and the command line can use the same file.
#[test]
fn parameter_sets_are_saved_beside_the_design_and_restored() {
    let script = r#"let m = default_materials();
let w = param("width", 15.0, 5.0, 30.0);
RectPrism(Vec3(0, 0, 0), Vec3(w, 10, 5), m.id("gray"))"#;
    let (scratch, mut h) = studio(BAR, "param-sets");
    let file = scratch.path().join("plate.rhai");
    std::fs::write(&file, script).expect("write plate.rhai");
    let ctx = h.ctx.clone();
    h.state_mut().open_path(&ctx, file.clone());
    wait_for(&mut h, "the plate", |a| {
        a.is_idle() && bbox_x(a) == Some(15.0)
    });
    h.get_by_role_and_label(Role::Slider, "width")
        .set_value_accesskit(22.0);
    wait_for(&mut h, "the new width", |a| {
        bbox_x(a).is_some_and(|x| (x - 22.0).abs() < 1e-9)
    });
    h.get_by_label("Set name").focus();
    h.step();
    h.get_by_label("Set name").type_text("wide");
    h.step();
    h.get_by_label("Save set").click();
    h.run_steps(2);
    let sets = scratch.path().join("plate.params.json");
    let text = std::fs::read_to_string(&sets).expect("plate.params.json written");
    assert!(
        text.contains("\"wide\"") && text.contains("\"22\""),
        "{text}"
    );
    drop(h);
    // Opened again in a new studio: the sliders come back as saved.
    let mut h2 = harness(StudioOptions::for_tests(scratch.path().join("data2"), BAR));
    let ctx = h2.ctx.clone();
    h2.state_mut().open_path(&ctx, file);
    wait_for(&mut h2, "the saved width", |a| {
        a.is_idle() && bbox_x(a).is_some_and(|x| (x - 22.0).abs() < 1e-9)
    });
}
