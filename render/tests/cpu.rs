//! CPU-side behaviour: bakes, the progressive baker, the pick, the camera.

mod common;

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::time::{Duration, Instant};

use common::*;
use glam::{Vec2, Vec3};
use volcad_render::{BakeError, Camera, CutPlane, ProgressiveBaker, StandardView, bake, pick};

#[test]
fn bake_covers_the_box_with_padding_and_colours() {
    let model = model(GRADED_BAR);
    let b = bake(&model, 32, &AtomicBool::new(false)).unwrap();
    assert_eq!(b.voxel_count(), b.distance.len());
    assert!((b.voxel_size_mm - 15.0 / 32.0).abs() < 1e-5);
    let (lo, hi) = b.grid_box();
    assert!(lo.x < -7.5 - b.voxel_size_mm && hi.x > 7.5 + b.voxel_size_mm);
    // Centre voxel: inside, half red half blue.
    let [nx, ny, nz] = b.dims;
    let c = b.index(nx / 2, ny / 2, nz / 2);
    assert!(b.distance_at(nx / 2, ny / 2, nz / 2) < 0.0);
    let col = b.color[c];
    assert!((col[0] as i32 - col[2] as i32).abs() < 30, "{col:?}");
    assert_eq!(b.channels, vec![0, 1]);
    // Corner voxel: outside (padding), dilated from the blue (-x) end.
    assert!(b.distance_at(0, 0, 0) > 0.0);
    let f = b.fractions[0];
    assert!(f[1] > 200 && f[0] < 30, "{f:?}");
    // Far outside voxels stay empty: bake a box with room around it.
    let far = bake(&common::model(SPHERE), 32, &AtomicBool::new(false)).unwrap();
    assert_eq!(
        far.fractions[0], [0; 4],
        "corner of a sphere's grid is empty"
    );
}

#[test]
fn a_bake_cancelled_before_it_starts_returns_cancelled() {
    let model = model(BCC_SPHERE);
    assert_eq!(
        bake(&model, 64, &AtomicBool::new(true)).unwrap_err(),
        BakeError::Cancelled
    );
}

#[test]
fn progressive_baker_sends_each_level_then_finishes() {
    let model = Arc::new(model(GRADED_BAR));
    let wakes = Arc::new(AtomicUsize::new(0));
    let w = wakes.clone();
    let baker = ProgressiveBaker::start(model, vec![16, 24], move || {
        w.fetch_add(1, Ordering::SeqCst);
    });
    let start = Instant::now();
    let mut first = None;
    while !baker.is_done() {
        if first.is_none() {
            first = baker.try_recv().map(|b| b.resolution);
        }
        assert!(start.elapsed() < Duration::from_secs(60), "baker stalled");
        std::thread::sleep(Duration::from_millis(2));
    }
    let last = baker.try_recv().map(|b| b.resolution).or(first);
    assert_eq!(last, Some(24), "finest level last (first seen: {first:?})");
    assert!(
        wakes.load(Ordering::SeqCst) >= 3,
        "wake after each level and at the end"
    );
    assert!(baker.error().is_none());
}

#[test]
fn progressive_baker_restart_replaces_the_model() {
    let big = Arc::new(model(BCC_SPHERE));
    let small = Arc::new(model(SPHERE));
    let mut baker = ProgressiveBaker::start(big, vec![256], || {});
    baker.restart(small);
    let start = Instant::now();
    while !baker.is_done() {
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "restart did not finish"
        );
        std::thread::sleep(Duration::from_millis(5));
    }
    let b = baker.try_recv().expect("a bake of the new model");
    assert_eq!(b.palette.len(), 1, "bake of the old model arrived");
}

#[test]
fn pick_hits_the_front_face_with_fractions() {
    let model = model(GRADED_BAR);
    let cam = Camera::fit(&model.bbox(), StandardView::Front);
    let hit = pick(&model, &cam, None, Vec2::ZERO, 1.5).expect("centre ray hits the bar");
    assert!((hit.point.y + 5.0).abs() < 1e-3, "{:?}", hit.point);
    let total: f64 = hit.fractions.iter().map(|f| f.1).sum();
    assert!((total - 1.0).abs() < 1e-6);
    assert!(
        hit.fractions.iter().all(|f| (f.1 - 0.5).abs() < 0.01),
        "{:?}",
        hit.fractions
    );
    assert!(pick(&model, &cam, None, Vec2::new(0.99, 0.99), 1.5).is_none());
    // A cut at y = 0 keeping y >= 0 moves the hit to the cut face.
    let cut = CutPlane {
        axis: 1,
        offset: 0.0,
        keep_below: false,
    };
    let hit = pick(&model, &cam, Some(&cut), Vec2::ZERO, 1.5).expect("hits the cut face");
    assert!(hit.point.y.abs() < 1e-3, "{:?}", hit.point);
}

#[test]
fn camera_rays_agree_with_view_proj() {
    let bbox = model(GRADED_BAR).bbox();
    for view in [
        StandardView::Iso,
        StandardView::Top,
        StandardView::Front,
        StandardView::Side,
        StandardView::Bottom,
    ] {
        for ortho in [false, true] {
            let mut cam = Camera::fit(&bbox, view);
            cam.orthographic = ortho;
            let ndc = Vec2::new(0.3, -0.4);
            let (o, d) = cam.ray(ndc, 1.6);
            let p = o + d * cam.distance * 0.9;
            let c = cam.view_proj(1.6) * p.extend(1.0);
            let got = Vec2::new(c.x / c.w, c.y / c.w);
            assert!(
                (got - ndc).length() < 1e-3,
                "{view:?} ortho={ortho}: {got:?}"
            );
            assert!(c.z / c.w > 0.0 && c.z / c.w < 1.0);
        }
    }
    // Top: x right, y up. Front: x right, z up.
    let top = Camera::fit(&bbox, StandardView::Top);
    let (r, u, _) = top.basis();
    assert!((r - Vec3::X).length() < 1e-5 && (u - Vec3::Y).length() < 1e-5);
    let front = Camera::fit(&bbox, StandardView::Front);
    let (r, u, _) = front.basis();
    assert!((r - Vec3::X).length() < 1e-5 && (u - Vec3::Z).length() < 1e-5);
}

#[test]
fn zoom_keeps_the_point_under_the_cursor() {
    let mut cam = Camera::fit(&model(SPHERE).bbox(), StandardView::Iso);
    let ndc = Vec2::new(0.5, 0.2);
    let (r, u, _) = cam.basis();
    let h = cam.half_height_at_target();
    let before = cam.target + r * (ndc.x * h * 1.5) + u * (ndc.y * h);
    cam.zoom_to(0.5, ndc, 1.5);
    let h = cam.half_height_at_target();
    let after = cam.target + r * (ndc.x * h * 1.5) + u * (ndc.y * h);
    assert!((before - after).length() < 1e-4);
    assert!(
        (cam.distance - Camera::fit(&model(SPHERE).bbox(), StandardView::Iso).distance * 0.5).abs()
            < 1e-3
    );
}

#[test]
fn more_than_four_materials_keep_four_fraction_channels() {
    let model = model(
        r#"let m = default_materials();
        Union(false, [Sphere(Vec3(0,0,0), 2, m.id("red")), Sphere(Vec3(5,0,0), 2, m.id("green")),
                      Sphere(Vec3(10,0,0), 2, m.id("blue")), Sphere(Vec3(15,0,0), 2, m.id("yellow")),
                      Sphere(Vec3(20,0,0), 2, m.id("cyan"))])"#,
    );
    let b = bake(&model, 48, &AtomicBool::new(false)).unwrap();
    assert_eq!(b.materials.len(), 5);
    assert_eq!(b.channels, vec![0, 1, 2, 3]);
    assert_eq!(b.channel_of(4), None);
    // The fifth material is in the colour volume.
    let v = (
        ((20.0 - b.origin.x) / b.voxel.x) as u32,
        ((0.0 - b.origin.y) / b.voxel.y) as u32,
        ((0.0 - b.origin.z) / b.voxel.z) as u32,
    );
    let c = b.color[b.index(v.0, v.1, v.2)];
    assert!(
        c[0] < 10 && c[1] > 245 && c[2] > 245,
        "cyan sphere colour {c:?}"
    );
    assert_eq!(b.fractions[b.index(v.0, v.1, v.2)], [0; 4]);
}

/// Attribute mode: the colour volume follows the attribute through the
/// colour map over the automatic range (the baked values' extremes), a
/// fixed range clamps, vec4 values are their own colour, and errors stop
/// the bake with their message.
#[test]
fn attribute_bake_maps_values_through_viridis() {
    use volcad_render::attribute_bake::{AttributeEval, UNDEFINED};
    use volcad_render::{AttributeShading, ColorMap, bake_shaded};
    let model = model(GRADED_BAR);
    let no = AtomicBool::new(false);
    // The attribute is x (mm) on the 15 mm bar; NaN for x > 5 ("undefined").
    let x_eval = |p: volcad_core::Points<'_>, out: &mut [f64]| {
        for (o, x) in out.iter_mut().zip(p.x) {
            *o = if *x > 5.0 { f64::NAN } else { *x };
        }
        Ok(())
    };
    let eval: &AttributeEval<'_> = &x_eval;
    let mut s = AttributeShading {
        index: 0,
        width: 1,
        range: None,
        map: ColorMap::Viridis,
    };
    let b = bake_shaded(&model, 32, Some((&s, eval)), &no).unwrap();
    let [lo, hi] = b.attribute_range.unwrap();
    assert!(lo > -7.5 && lo < -7.0, "{lo}");
    assert!(hi > 4.5 && hi <= 5.0, "{hi}");
    let [nx, ny, nz] = b.dims;
    let centre = |i: u32| b.color[b.index(i, ny / 2, nz / 2)];
    // Voxel centre x of column i.
    let x_of = |i: u32| b.origin.x + (i as f32 + 0.5) * b.voxel.x;
    let i0 = (0..nx).find(|i| x_of(*i) > -7.0).unwrap();
    let i1 = (0..nx).find(|i| x_of(*i) > 0.0).unwrap();
    assert_eq!(
        centre(i1),
        ColorMap::Viridis.color_in(x_of(i1) as f64, lo, hi)
    );
    assert_eq!(
        centre(i0),
        ColorMap::Viridis.color_in(x_of(i0) as f64, lo, hi)
    );
    let i2 = (0..nx).find(|i| x_of(*i) > 6.0).unwrap();
    assert_eq!(centre(i2), UNDEFINED);
    // A fixed range: x = 0 is its top, so the top colour.
    s.range = Some([-10.0, 0.0]);
    let f = bake_shaded(&model, 32, Some((&s, eval)), &no).unwrap();
    assert_eq!(f.attribute_range, Some([-10.0, 0.0]));
    assert_eq!(
        f.color[f.index(i1, ny / 2, nz / 2)],
        ColorMap::Viridis.color(1.0)
    );
    // Colours as they are.
    let red = |_p: volcad_core::Points<'_>, out: &mut [f64]| {
        for c in out.chunks_mut(4) {
            c.copy_from_slice(&[1.0, 0.0, 0.0, 1.0]);
        }
        Ok(())
    };
    s.width = 4;
    let c = bake_shaded(&model, 32, Some((&s, &red)), &no).unwrap();
    assert_eq!(c.color[c.index(i1, ny / 2, nz / 2)], [255, 0, 0, 255]);
    assert_eq!(c.attribute_range, None);
    // An evaluation error is the bake's error.
    let bad = |_p: volcad_core::Points<'_>, _o: &mut [f64]| Err("modulus -3 < 0".to_string());
    assert_eq!(
        bake_shaded(&model, 32, Some((&s, &bad)), &no).unwrap_err(),
        BakeError::Attribute("modulus -3 < 0".into())
    );
}
