//! Helpers shared by the studio's kittests: the harness, waiting for a
//! state, and the documentation pictures they render.
#![allow(dead_code)]

use std::path::Path;
use std::time::{Duration, Instant};

use egui_kittest::Harness;
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
