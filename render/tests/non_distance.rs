//! A design whose value is not a distance: pyvcad's mug with a quartic
//! `Function` handle (`assets/examples/mug.rhai`). The viewport bake
//! redistances it, so the handle is drawn; the CPU pick, marching by sign,
//! finds the same surface. Runs on a real device (lavapipe where there is
//! no GPU), like `render.rs`.

mod common;

use common::*;
use glam::{DVec3, Vec3};
use volcad_render::{Camera, Offscreen, StandardView, ViewMode, ViewSettings, bake_blocking, pick};

const MUG: &str = include_str!("../../assets/examples/mug.rhai");
const SIZE: [u32; 2] = [320, 240];
const BG: [f32; 4] = [51.0 / 255.0, 77.0 / 255.0, 102.0 / 255.0, 1.0];

/// Handle ring centre on x, ring radius and tube radius (mm), as in mug.rhai.
const CX: f64 = 42.0;
const RING: f64 = 22.0;
const TUBE: f64 = 6.0;

/// Exact distance to the handle's torus (ring in the XZ plane).
fn torus_distance(p: DVec3) -> f64 {
    let q = p - DVec3::new(CX, 0.0, 0.0);
    let ring = (q.x * q.x + q.z * q.z).sqrt() - RING;
    (ring * ring + q.y * q.y).sqrt() - TUBE
}

#[test]
fn the_quartic_handle_is_drawn_and_picked() {
    let model = model(MUG);
    assert!(!model.distance_is_bound(), "a Function is not a distance");
    let bake = bake_blocking(&model, 128).expect("bake");
    assert!(
        bake.redistanced,
        "the quartic's bake was used as a distance"
    );
    let mut off = Offscreen::new(SIZE)
        .unwrap_or_else(|e| panic!("a GPU adapter is required for the render tests: {e}"));
    off.upload(&bake);
    let mut cam = Camera::fit(&model.bbox(), StandardView::Front);
    cam.orthographic = true;
    let img = off
        .render(&ViewSettings {
            mode: ViewMode::Solid,
            background: BG,
            ..ViewSettings::plain(cam)
        })
        .expect("render");
    save(&img, "mug_front.png");

    // The front of the handle's tube: outer arc, top and bottom arcs.
    let bg = bg_bytes(BG);
    for (x, z) in [(CX + RING, 0.0), (CX, RING), (CX, -RING)] {
        let (px, py) = project(&cam, Vec3::new(x as f32, -TUBE as f32, z as f32), SIZE);
        let c = mean3(&img, px, py);
        eprintln!("handle at x {x}, z {z}: pixel ({px}, {py}) {c:?}");
        assert!(
            c[0] > 80.0 && c[0] > 2.0 * c[1] && c[0] > 2.0 * c[2],
            "handle at x {x}, z {z} not drawn red: {c:?}"
        );
    }
    // Through the handle's hole: background.
    let (px, py) = project(&cam, Vec3::new((CX + 8.0) as f32, 0.0, 0.0), SIZE);
    assert!(!is_fg(&img, px, py, bg), "the handle's hole is filled");
    // The cup's body: grey.
    let (px, py) = project(&cam, Vec3::new(-20.0, -40.0, 0.0), SIZE);
    let c = mean3(&img, px, py);
    assert!(
        (c[0] - c[2]).abs() < 30.0 && c[0] > 40.0,
        "cup not grey: {c:?}"
    );

    // The CPU pick through the outer arc hits the torus's front, red.
    let aspect = SIZE[0] as f32 / SIZE[1] as f32;
    let (px, py) = project(&cam, Vec3::new((CX + RING) as f32, 0.0, 0.0), SIZE);
    let ndc = glam::Vec2::new(
        (px as f32 + 0.5) / SIZE[0] as f32 * 2.0 - 1.0,
        1.0 - (py as f32 + 0.5) / SIZE[1] as f32 * 2.0,
    );
    let hit = pick(&model, &cam, None, ndc, aspect).expect("pick hits the handle");
    let err = torus_distance(hit.point);
    eprintln!("pick: {:?}, torus distance {err:.2e}", hit.point);
    assert!(
        err.abs() < 1e-3,
        "pick hit {:?} off the torus by {err}",
        hit.point
    );
    assert!(hit.point.y < 0.0, "pick hit the back of the tube");
    let red = model.table().id("red").expect("red");
    assert_eq!(hit.fractions, vec![(red, 1.0)]);
}
