//! Helpers shared by the studio's kittests: the harness, waiting for a
//! state, typing, the documentation pictures they render, and the designs
//! they open.
//!
//! The tests drive the real `StudioApp` through eframe's creation path with
//! a wgpu renderer (Mesa's lavapipe where there is no GPU). Workers are real
//! threads, so tests step frames until a condition holds (with a generous
//! timeout), never sleep long. Mesa prints a harmless warning when
//! `XDG_RUNTIME_DIR` is unset; set it to any 0700 folder to silence it.
#![allow(dead_code)]
// A failed setup step (a scratch folder, a file write) fails the test.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::Path;
use std::time::{Duration, Instant};

use egui::accesskit::Role;
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use volcad_studio::studio::egui;
use volcad_studio::studio::{StudioApp, StudioOptions};

/// The studio in a 1280 × 800 window drawn by wgpu (lavapipe where there
/// is no GPU).
pub fn harness(opts: StudioOptions) -> Harness<'static, StudioApp> {
    Harness::builder()
        .with_size(egui::vec2(1280.0, 800.0))
        .wgpu()
        .build_eframe(move |cc| StudioApp::new(cc, opts))
}

/// Step frames until `cond` holds, for at most `limit`; the failure names
/// `what`, the editor's text, the problems and whether the studio is idle.
#[track_caller]
pub fn wait_within(
    h: &mut Harness<'static, StudioApp>,
    what: &str,
    limit: Duration,
    cond: impl Fn(&StudioApp) -> bool,
) {
    let t = Instant::now();
    loop {
        h.step();
        if cond(h.state()) {
            // One more frame so the UI shows the new state.
            h.step();
            return;
        }
        let a = h.state();
        assert!(
            t.elapsed() < limit,
            "timed out waiting for {what}; text:\n{}\nproblems: {:?}\nidle: {}",
            a.text(),
            a.problems(),
            a.is_idle()
        );
        std::thread::sleep(Duration::from_millis(5));
    }
}

/// Step until a widget whose label contains `text` shows (60 s at most);
/// returns its label (or value).
#[track_caller]
pub fn wait_label(h: &mut Harness<'static, StudioApp>, text: &str) -> String {
    use egui_kittest::kittest::{NodeT as _, Queryable};
    let t = Instant::now();
    loop {
        if let Some(n) = h.query_by_label_contains(text) {
            let node = n.accesskit_node();
            return node.label().or_else(|| node.value()).unwrap_or_default();
        }
        assert!(
            t.elapsed() < Duration::from_secs(60),
            "timed out waiting for a label with {text:?}"
        );
        h.step();
        std::thread::sleep(Duration::from_millis(5));
    }
}

/// Write a picture the README shows: `docs/images/<file>`.
pub fn save_doc_image(img: &image::RgbaImage, file: &str) {
    let out = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../docs/images")
        .join(file);
    std::fs::create_dir_all(out.parent().unwrap()).unwrap();
    img.save(&out)
        .unwrap_or_else(|e| panic!("writing {file}: {e}"));
}

/// The graded bar on 4 lines (errors are asserted by line).
pub const BAR: &str = r#"let m = default_materials();
let bar = RectPrism(Vec3(0, 0, 0), Vec3(15, 10, 5), m.id("gray"));
let graded = FGrade(["x/15+0.5", "-x/15+0.5"], [m.id("red"), m.id("blue")], true, bar);
graded"#;

/// A scratch folder for one test, removed when the test ends (passed or
/// failed).
pub fn temp_dir(name: &str) -> tempfile::TempDir {
    tempfile::Builder::new()
        .prefix(&format!("volcad-studio-ui-{name}-"))
        .tempdir()
        .expect("temp dir")
}

/// The scratch folder comes first: bound as `let (dir, h)`, the studio is
/// dropped first (waiting for its autosave), then the folder is removed.
pub fn studio(text: &str, name: &str) -> (tempfile::TempDir, Harness<'static, StudioApp>) {
    let dir = temp_dir(name);
    let h = harness(StudioOptions::for_tests(dir.path().join("data"), text));
    (dir, h)
}

/// Step frames until `cond` holds (60 s at most).
#[track_caller]
pub fn wait_for(
    h: &mut Harness<'static, StudioApp>,
    what: &str,
    cond: impl Fn(&StudioApp) -> bool,
) {
    wait_within(h, what, Duration::from_secs(60), cond);
}

pub fn wait_idle(h: &mut Harness<'static, StudioApp>) {
    wait_for(h, "the script and the bake", |a| {
        a.is_idle() && a.viewport().bake().is_some() || a.is_idle() && !a.problems().is_empty()
    });
}

pub fn bbox_x(a: &StudioApp) -> Option<f64> {
    a.model().map(|m| m.bbox().size().x)
}

/// Type at the end of the editor's text.
pub fn type_at_end(h: &mut Harness<'static, StudioApp>, text: &str) {
    let editor = h.get_by_role(Role::MultilineTextInput);
    editor.focus();
    h.step();
    h.key_press_modifiers(egui::Modifiers::CTRL, egui::Key::End);
    h.step();
    h.get_by_role(Role::MultilineTextInput).type_text(text);
    h.step();
}

/// A studio with `text` saved as `dir/name` and opened from there.
pub fn studio_with_file(
    dir: &Path,
    name: &str,
    text: &str,
) -> (std::path::PathBuf, Harness<'static, StudioApp>) {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    let mut opts = StudioOptions::for_tests(dir.join("data"), text);
    opts.script = Some(path.clone());
    (path, harness(opts))
}

pub const SPHERE: &str = "let m = default_materials();\nSphere(Vec3(0, 0, 0), 5, m.id(\"red\"))\n";
