//! The studio's window as a picture, headless (egui_kittest, see
//! `common/`): the documentation screenshot, and frame times while a large
//! design bakes (a measurement, run on request).

// A failed setup step (a scratch folder, a file read) fails the test.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::time::{Duration, Instant};

use egui::accesskit::Role;
use egui_kittest::kittest::Queryable;
use volcad_studio::studio::StudioOptions;
use volcad_studio::studio::egui;

mod common;
use common::*;

/// Renders the studio with an example and saves `docs/images/studio.png`.
#[test]
fn screenshot_for_the_docs() {
    let scratch = temp_dir("docs-shot");
    let dir = scratch.path();
    let mut opts = StudioOptions::for_tests(dir.join("data"), "");
    opts.initial_text = None;
    opts.example = Some("lattice_per_strut".into());
    opts.bake_levels = vec![64, 128];
    let mut h = harness(opts);
    wait_idle(&mut h);
    // The language reference open over the editor, searched for lattices.
    h.key_press(egui::Key::F1);
    h.state_mut().reference.query = "lattice".into();
    h.run_steps(3);
    let img = h.render().expect("render");
    save_doc_image(&img, "studio.png");
    // The viewport shows the lattice: many strongly coloured (yellow or
    // magenta) pixels, which nothing else in the window has.
    let coloured = img
        .pixels()
        .filter(|p| {
            let [r, g, b, _] = p.0;
            r > 150 && (g < 90 || b < 90)
        })
        .count();
    assert!(coloured > 5_000, "only {coloured} lattice-coloured pixels");
}

fn percentile(v: &[f64], p: f64) -> f64 {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    s.get(((s.len() as f64 - 1.0) * p).round() as usize)
        .copied()
        .unwrap_or(0.0)
}

/// Frame times while the 3,286-strut bunny lattice runs and bakes (a
/// measurement, not a check): `cargo test --release -p volcad-tests --test
/// studio_view -- --ignored --nocapture frame_times`. Frames are stepped at
/// about 60 Hz (as a display would ask for them); every 30th is also
/// rendered, timing the GPU pass on whatever adapter runs the test.
#[test]
#[ignore = "measurement; run in release with --ignored --nocapture"]
fn frame_times_while_the_bunny_lattice_bakes() {
    let dir = temp_dir("bunny").keep();
    let opts = StudioOptions {
        example: Some("bunny_lattice".into()),
        initial_text: None,
        bake_levels: vec![64, 128, 256],
        ..StudioOptions::for_tests(dir.join("data"), "")
    };
    let t0 = Instant::now();
    let mut h = harness(opts);
    let (mut ui_ms, mut render_ms) = (Vec::new(), Vec::new());
    let mut model_at = None;
    let mut levels = Vec::new();
    let mut last_bakes = 0;
    // Once the design is on screen, a key every sixth frame (about ten a
    // second) for 40 keys, typed at the end of the script while it bakes.
    let mut typed = 0;
    let mut typing_ms = Vec::new();
    for frame in 0.. {
        let typing = model_at.is_some() && typed < 40 && frame % 6 == 0;
        if typing {
            if typed == 0 {
                h.get_by_role(Role::MultilineTextInput).focus();
                h.step();
                h.key_press_modifiers(egui::Modifiers::CTRL, egui::Key::End);
                h.step();
            }
            h.get_by_role(Role::MultilineTextInput).type_text(" ");
            typed += 1;
        }
        let t = Instant::now();
        h.step();
        ui_ms.push(t.elapsed().as_secs_f64() * 1e3);
        if typing {
            typing_ms.push(t.elapsed().as_secs_f64() * 1e3);
        }
        if frame % 30 == 0 {
            let t = Instant::now();
            h.render().expect("render");
            render_ms.push(t.elapsed().as_secs_f64() * 1e3);
        }
        let a = h.state();
        if model_at.is_none() && a.model().is_some() {
            model_at = Some(t0.elapsed());
        }
        if a.viewport().bakes_received() != last_bakes {
            last_bakes = a.viewport().bakes_received();
            let b = a.viewport().bake().expect("bake");
            levels.push((b.resolution, b.bake_seconds, t0.elapsed()));
        }
        if a.is_idle() && last_bakes >= 3 {
            break;
        }
        assert!(
            t0.elapsed() < Duration::from_secs(600),
            "the bunny did not bake in 10 minutes"
        );
        std::thread::sleep(Duration::from_millis(16).saturating_sub(t.elapsed()));
    }
    let stats = |v: &[f64]| {
        format!(
            "mean {:.1} ms, p50 {:.1}, p95 {:.1}, max {:.1} ({} frames)",
            v.iter().sum::<f64>() / v.len().max(1) as f64,
            percentile(v, 0.5),
            percentile(v, 0.95),
            percentile(v, 1.0),
            v.len()
        )
    };
    println!(
        "bunny lattice: model (script + prepare) on screen after {:.2} s",
        model_at.unwrap_or_default().as_secs_f64()
    );
    for (res, secs, at) in &levels {
        println!(
            "  bake {res}³: {secs:.2} s, shown at {:.2} s",
            at.as_secs_f64()
        );
    }
    println!(
        "  UI thread per frame (App::logic + App::ui + egui): {}",
        stats(&ui_ms)
    );
    println!(
        "  frames that took a key typed during the bake: {}",
        stats(&typing_ms)
    );
    println!(
        "  render of the 1280x800 window on this adapter: {}",
        stats(&render_ms)
    );
    let img = h.render().expect("render");
    img.save(dir.join("bunny.png")).expect("bunny.png");
    println!("  picture: {}", dir.join("bunny.png").display());
}
