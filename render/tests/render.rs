//! Offscreen renders on a real device (Mesa lavapipe where there is no GPU).
//! Without an adapter these tests fail: `Offscreen::new` returns
//! `RenderError::NoAdapter` and the tests unwrap it.

mod common;

use common::*;
use glam::Vec3;
use volcad_render::{
    Camera, CutPlane, Offscreen, StandardView, ViewMode, ViewSettings, bake_blocking,
};

const SIZE: [u32; 2] = [256, 192];
/// Exactly representable in 8 bits (51, 77, 102).
const BG: [f32; 4] = [51.0 / 255.0, 77.0 / 255.0, 102.0 / 255.0, 1.0];

fn device() -> Offscreen {
    Offscreen::new(SIZE)
        .unwrap_or_else(|e| panic!("a GPU adapter is required for the render tests: {e}"))
}

fn settings(cam: Camera, mode: ViewMode) -> ViewSettings {
    ViewSettings {
        mode,
        background: BG,
        ..ViewSettings::plain(cam)
    }
}

#[test]
fn graded_bar_front_view_runs_blue_to_red() {
    let model = model(GRADED_BAR);
    let mut off = device();
    eprintln!("adapter: {}", off.adapter());
    let bake = bake_blocking(&model, 64).unwrap();
    off.upload(&bake);
    let cam = Camera::fit(&model.bbox(), StandardView::Front);
    let img = off.render(&settings(cam, ViewMode::Solid)).unwrap();
    save(&img, "graded_bar_front.png");

    let at = |x: f32| {
        let (px, py) = project(&cam, Vec3::new(x, -5.0, 0.0), SIZE);
        mean3(&img, px, py)
    };
    let (red_end, mid, blue_end) = (at(6.5), at(0.0), at(-6.5));
    eprintln!("red end {red_end:?}, middle {mid:?}, blue end {blue_end:?}");
    assert!(
        red_end[0] > 100.0 && red_end[0] > 3.0 * red_end[2],
        "+x end not red: {red_end:?}"
    );
    assert!(
        blue_end[2] > 100.0 && blue_end[2] > 3.0 * blue_end[0],
        "-x end not blue: {blue_end:?}"
    );
    assert!(
        mid[0] > 50.0 && mid[2] > 50.0,
        "middle not a blend: {mid:?}"
    );
    assert!(
        (mid[0] - mid[2]).abs() < 0.35 * mid[0].max(mid[2]),
        "middle not an even blend: {mid:?}"
    );
    assert!(
        red_end[1] < 40.0 && blue_end[1] < 40.0,
        "green where there is none"
    );

    let bg = bg_bytes(BG);
    for (x, y) in [
        (0, 0),
        (SIZE[0] - 1, 0),
        (0, SIZE[1] - 1),
        (SIZE[0] - 1, SIZE[1] - 1),
        (SIZE[0] / 2, 2),
    ] {
        assert_eq!(&img.get_pixel(x, y).0[..3], &bg, "background at ({x}, {y})");
    }
}

#[test]
fn calibration_sheet_cut_shows_swatch_colours() {
    let model = model(&calibration_sheet());
    let mut off = device();
    let bake = bake_blocking(&model, 128).unwrap();
    off.upload(&bake);
    let mut cam = Camera::fit(&model.bbox(), StandardView::Top);
    cam.orthographic = true;
    let mut s = settings(cam, ViewMode::Solid);
    s.cut = Some(CutPlane {
        axis: 2,
        offset: 0.0,
        keep_below: true,
    });
    let img = off.render(&s).unwrap();
    save(&img, "calibration_cut_top.png");

    let mut worst = 0.0f32;
    for i in 0..12 {
        for j in 0..12 {
            let (c, mg, _) = swatch_fractions(i, j);
            let p = Vec3::new((i as f32 - 5.5) * 25.0, (j as f32 - 5.5) * 25.0, 0.0);
            let (px, py) = project(&cam, p, SIZE);
            let rgb = mean3(&img, px, py);
            // Expected colour c·cyan + mg·magenta + w·white = (1−c, 1−mg, 1)·255,
            // times the lighting: compare ratios to blue.
            assert!(rgb[2] > 150.0, "swatch ({i}, {j}) too dark: {rgb:?}");
            let (r, g) = (rgb[0] / rgb[2], rgb[1] / rgb[2]);
            let err = (r - (1.0 - c as f32))
                .abs()
                .max((g - (1.0 - mg as f32)).abs());
            worst = worst.max(err);
            assert!(
                err < 0.1,
                "swatch ({i}, {j}) c={c:.2} mg={mg:.2}: got {rgb:?} (r/b {r:.2}, g/b {g:.2})"
            );
        }
    }
    eprintln!("worst swatch ratio error {worst:.3}");
    // The c = 1 swatch is cyan, the w = 1 swatch white.
    let cyan = {
        let (x, y) = project(&cam, Vec3::new(5.5 * 25.0, 0.0, 0.0), SIZE);
        mean3(&img, x, y)
    };
    let white = {
        let (x, y) = project(&cam, Vec3::new(-5.5 * 25.0, -5.5 * 25.0, 0.0), SIZE);
        mean3(&img, x, y)
    };
    assert!(
        cyan[0] < 40.0 && cyan[1] > 150.0 && cyan[2] > 150.0,
        "c = 1 swatch not cyan: {cyan:?}"
    );
    assert!(
        white.iter().all(|v| *v > 150.0),
        "w = 1 swatch not white: {white:?}"
    );
}

/// Fraction of the sphere's projected disk covered by the lattice.
fn coverage(img: &image::RgbaImage, cam: &Camera, radius: f32) -> f32 {
    let (cx, cy) = project(cam, Vec3::ZERO, SIZE);
    let (ex, _) = project(cam, cam.basis().0 * radius, SIZE);
    let rpx = (ex as f32 - cx as f32).abs();
    let bg = bg_bytes(BG);
    let (mut inside, mut hit) = (0u32, 0u32);
    for y in 0..SIZE[1] {
        for x in 0..SIZE[0] {
            let d = ((x as f32 - cx as f32).powi(2) + (y as f32 - cy as f32).powi(2)).sqrt();
            if d < rpx * 0.95 {
                inside += 1;
                hit += is_fg(img, x, y, bg) as u32;
            }
        }
    }
    hit as f32 / inside.max(1) as f32
}

#[test]
fn bcc_sphere_shows_struts() {
    let model = model(BCC_SPHERE);
    let mut off = device();
    for res in [64, 128] {
        let bake = bake_blocking(&model, res).unwrap();
        eprintln!(
            "bake {res}: voxel {:.3} mm, {:.2} s",
            bake.voxel_size_mm, bake.bake_seconds
        );
        off.upload(&bake);
        let mut cam = Camera::fit(&model.bbox(), StandardView::Front);
        cam.orthographic = true;
        let img = off.render(&settings(cam, ViewMode::Solid)).unwrap();
        save(&img, &format!("bcc_sphere_{res}.png"));
        let iso = off
            .render(&settings(
                Camera::fit(&model.bbox(), StandardView::Iso),
                ViewMode::Solid,
            ))
            .unwrap();
        save(&iso, &format!("bcc_sphere_{res}_iso.png"));
        let cov = coverage(&img, &cam, 10.0);
        eprintln!(
            "bcc {res}: coverage of the sphere's disk {:.1} %",
            cov * 100.0
        );
        assert!(cov > 0.05, "struts vanished at {res}: coverage {cov}");
        if res == 64 {
            // The thin-feature bias is what keeps the struts whole at 64³.
            off.renderer_mut().set_thin_bias_voxels(0.0);
            let plain = off.render(&settings(cam, ViewMode::Solid)).unwrap();
            off.renderer_mut()
                .set_thin_bias_voxels(volcad_render::THIN_BIAS_VOXELS);
            save(&plain, "bcc_sphere_64_no_bias.png");
            let cov0 = coverage(&plain, &cam, 10.0);
            eprintln!("bcc 64 without the bias: coverage {:.1} %", cov0 * 100.0);
            assert!(cov >= cov0);
        }
        assert!(cov < 0.6, "solid disk at {res}: coverage {cov}");
    }
}

#[test]
fn iso_volume_and_hidden_material_modes() {
    let model = model(GRADED_BAR);
    let mut off = device();
    off.upload(&bake_blocking(&model, 64).unwrap());
    let cam = Camera::fit(&model.bbox(), StandardView::Front);
    let bg = bg_bytes(BG);
    let px = |x: f32| project(&cam, Vec3::new(x, -5.0, 0.0), SIZE);

    // Iso: red fraction ≥ 0.5 is the +x half.
    let img = off
        .render(&settings(
            cam,
            ViewMode::Iso {
                material_index: 0,
                level: 0.5,
            },
        ))
        .unwrap();
    save(&img, "graded_bar_iso_red_half.png");
    let (a, b) = (px(5.0), px(-5.0));
    assert!(is_fg(&img, a.0, a.1, bg), "iso: +x half missing");
    assert!(!is_fg(&img, b.0, b.1, bg), "iso: -x half drawn");

    // Hidden red: the blue-dominant half remains.
    let mut s = settings(cam, ViewMode::Solid);
    s.material_opacity = vec![0.0, 1.0];
    let img = off.render(&s).unwrap();
    save(&img, "graded_bar_red_hidden.png");
    assert!(!is_fg(&img, a.0, a.1, bg), "hidden red still drawn");
    assert!(is_fg(&img, b.0, b.1, bg), "blue half missing");
    let blue = mean3(&img, b.0, b.1);
    assert!(blue[2] > 2.0 * blue[0], "visible half not blue: {blue:?}");

    // Volume: translucent, still red at +x and blue at −x.
    let img = off.render(&settings(cam, ViewMode::Volume)).unwrap();
    save(&img, "graded_bar_volume.png");
    let (r, l) = (mean3(&img, a.0, a.1), mean3(&img, b.0, b.1));
    assert!(r[0] > r[2] + 30.0, "volume +x not red: {r:?}");
    assert!(l[2] > l[0] + 30.0, "volume -x not blue: {l:?}");
}

#[test]
fn overlays_draw_without_a_volume_and_with_one() {
    let model = model(SPHERE);
    let mut off = device();
    let cam = Camera::fit(&model.bbox(), StandardView::Iso);
    let s = ViewSettings {
        background: BG,
        ..ViewSettings {
            camera: cam,
            ..Default::default()
        }
    };
    // Nothing uploaded yet: background and the axis triad only.
    let img = off.render(&s).unwrap();
    let bg = bg_bytes(BG);
    assert_eq!(&img.get_pixel(SIZE[0] / 2, SIZE[1] / 2).0[..3], &bg);
    off.upload(&bake_blocking(&model, 64).unwrap());
    let img = off.render(&s).unwrap();
    save(&img, "sphere_overlays.png");
    assert!(is_fg(&img, SIZE[0] / 2, SIZE[1] / 2, bg), "sphere missing");
}

#[test]
fn reduced_render_scale_upscales_the_same_picture() {
    let model = model(GRADED_BAR);
    let mut off = device();
    off.upload(&bake_blocking(&model, 64).unwrap());
    let cam = Camera::fit(&model.bbox(), StandardView::Front);
    let full = off.render(&settings(cam, ViewMode::Solid)).unwrap();
    let half = off
        .render(&ViewSettings {
            render_scale: 0.5,
            ..settings(cam, ViewMode::Solid)
        })
        .unwrap();
    save(&half, "graded_bar_front_half_scale.png");
    let (x, y) = project(&cam, Vec3::new(6.0, -5.0, 0.0), SIZE);
    let (a, b) = (mean3(&full, x, y), mean3(&half, x, y));
    assert!(
        (0..3).all(|c| (a[c] - b[c]).abs() < 20.0),
        "full {a:?} vs half {b:?}"
    );
    assert_eq!(&half.get_pixel(0, 0).0[..3], &bg_bytes(BG));
}

#[test]
fn cut_plane_shows_the_inside_fractions() {
    // Red core grading to a blue skin.
    let model = model(
        r#"let m = default_materials();
        FGrade(["1 - sqrt(x*x+y*y+z*z)/10", "sqrt(x*x+y*y+z*z)/10"], [m.id("red"), m.id("blue")], true,
               Sphere(Vec3(0,0,0), 10, m.id("gray")))"#,
    );
    let mut off = device();
    off.upload(&bake_blocking(&model, 64).unwrap());
    let cam = Camera::fit(&model.bbox(), StandardView::Iso);
    let whole = off.render(&settings(cam, ViewMode::Solid)).unwrap();
    save(&whole, "radial_sphere.png");
    let mut s = settings(cam, ViewMode::Solid);
    s.cut = Some(CutPlane {
        axis: 0,
        offset: 0.0,
        keep_below: true,
    });
    let img = off.render(&s).unwrap();
    save(&img, "radial_sphere_cut_x.png");
    let at = |p: Vec3, img: &image::RgbaImage| {
        let (x, y) = project(&cam, p, SIZE);
        mean3(img, x, y)
    };
    let core = at(Vec3::ZERO, &img);
    let rim = at(Vec3::new(0.0, -8.5, 0.0), &img);
    assert!(core[0] > 2.0 * core[2], "cut face centre not red: {core:?}");
    assert!(rim[2] > 2.0 * rim[0], "cut face rim not blue: {rim:?}");
    let outside = at(Vec3::ZERO, &whole);
    assert!(
        outside[2] > 2.0 * outside[0],
        "uncut sphere not blue outside: {outside:?}"
    );
}

#[test]
fn five_materials_use_the_colour_volume() {
    let model = model(
        r#"let m = default_materials();
        Union(false, [Sphere(Vec3(0,0,0), 2, m.id("red")), Sphere(Vec3(5,0,0), 2, m.id("green")),
                      Sphere(Vec3(10,0,0), 2, m.id("blue")), Sphere(Vec3(15,0,0), 2, m.id("yellow")),
                      Sphere(Vec3(20,0,0), 2, m.id("cyan"))])"#,
    );
    let mut off = device();
    off.upload(&bake_blocking(&model, 64).unwrap());
    let cam = Camera::fit(&model.bbox(), StandardView::Front);
    let img = off.render(&settings(cam, ViewMode::Solid)).unwrap();
    save(&img, "five_materials.png");
    let at = |x: f32| {
        let (px, py) = project(&cam, Vec3::new(x, -2.0, 0.0), SIZE);
        mean3(&img, px, py)
    };
    let (red, cyan) = (at(0.0), at(20.0));
    assert!(
        red[0] > 100.0 && red[1] < 40.0 && red[2] < 40.0,
        "red sphere {red:?}"
    );
    assert!(
        cyan[0] < 40.0 && cyan[1] > 100.0 && cyan[2] > 100.0,
        "cyan sphere {cyan:?}"
    );
}
