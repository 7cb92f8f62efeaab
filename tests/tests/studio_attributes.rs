//! The viewport's attribute mode, driven through the real studio UI
//! (egui_kittest with a wgpu renderer; lavapipe where there is no GPU):
//! pick an attribute in the toolbar's Colour menu, the bake's colours follow
//! it, the legend shows its name, unit and range, and the probe lists every
//! attribute under the cursor. Also renders `docs/images/attribute_mode.png`.

use std::time::Duration;

use egui::accesskit::Role;
use egui_kittest::Harness;
use egui_kittest::kittest::{NodeT as _, Queryable};
use volcad_studio::studio::egui;
use volcad_studio::studio::{StudioApp, StudioOptions};

mod common;
use common::{harness, save_doc_image, wait_within};

/// Step frames until `cond` holds (90 s at most).
#[track_caller]
fn wait_for(h: &mut Harness<'static, StudioApp>, what: &str, cond: impl Fn(&StudioApp) -> bool) {
    wait_within(h, what, Duration::from_secs(90), cond);
}

/// True once every bake level of the current shading has arrived.
fn baked(a: &StudioApp) -> bool {
    a.is_idle() && !a.viewport().is_baking() && a.viewport().bake().is_some()
}

#[test]
fn attribute_mode_shades_by_shore_hardness_with_legend_and_probe() {
    let scratch = tempfile::Builder::new()
        .prefix("volcad-studio-attrs-")
        .tempdir()
        .expect("temp dir");
    let mut opts = StudioOptions::for_tests(scratch.path().join("data"), "");
    opts.initial_text = None;
    opts.example = Some("shore_grip".into());
    opts.bake_levels = vec![48, 96];
    let mut h = harness(opts);
    wait_for(&mut h, "the grip's bake", baked);
    assert_eq!(h.state().viewport().bake().unwrap().attribute_range, None);

    // Colour: Materials -> shore_hardness.
    let combo = h
        .get_all_by_role(Role::ComboBox)
        .find(|n| {
            let n = n.accesskit_node();
            n.value().as_deref() == Some("Materials") || n.label().as_deref() == Some("Materials")
        })
        .expect("the Colour menu showing Materials");
    combo.click();
    h.run_steps(2);
    h.get_by_label("shore_hardness").click();
    h.run_steps(2);
    wait_for(&mut h, "the shore_hardness bake", |a| {
        baked(a) && a.viewport().bake().unwrap().attribute_range.is_some()
    });
    let [lo, hi] = h
        .state()
        .viewport()
        .bake()
        .unwrap()
        .attribute_range
        .unwrap();
    // Shore A 85 in the middle, 40 at the ends: the voxel centres lie a
    // little inside both.
    assert!(hi <= 85.0 && hi > 84.0, "{hi}");
    assert!((40.0..45.0).contains(&lo), "{lo}");
    // The legend: name with unit, the automatic range.
    h.get_by_label("shore_hardness (Shore)");
    h.get_by_label(&format!(
        "max {}",
        volcad_studio::studio::attribute_view::fmt(hi)
    ));
    h.get_by_label(&format!(
        "min {}",
        volcad_studio::studio::attribute_view::fmt(lo)
    ));

    // The probe under the cursor (the middle of the picture is on the grip).
    h.hover_at(egui::pos2(700.0, 340.0));
    wait_for(&mut h, "a probe read-out", |a| {
        a.viewport().hovered.is_some()
    });
    let probe = h.state().viewport().hovered.clone().unwrap();
    let names: Vec<&str> = probe.attributes.iter().map(|a| a.name.as_str()).collect();
    assert_eq!(names, ["modulus", "shore_hardness"]);
    for a in &probe.attributes {
        let v = a.value.as_ref().expect("a value")[0];
        assert!(v.is_finite(), "{a:?}");
        h.get_by_label(&a.text());
    }
    assert!(probe.attributes[1].text().ends_with(" Shore"));

    let img = h.render().expect("render");
    save_doc_image(&img, "attribute_mode.png");
    // Viridis' yellow-green top end (the firm middle) fills the picture
    // (x 440-965, y 80-615 of the window); the grip's clear resins would
    // draw it white.
    let viridis_top = img
        .enumerate_pixels()
        .filter(|(x, y, p)| {
            let [r, g, b, _] = p.0.map(i32::from);
            (440..965).contains(x) && (80..615).contains(y) && g > 110 && g > b + 40 && g + 10 > r
        })
        .count();
    assert!(
        viridis_top > 5_000,
        "only {viridis_top} yellow-green pixels"
    );
}
