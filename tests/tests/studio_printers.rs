//! The studio's printer exports, headless (egui_kittest, wgpu on lavapipe
//! where there is no GPU): a GrabCAD package written from its panel, the
//! J750 resin table refusing a `default_materials()` design with the
//! nearest J750 resins until mapped, and a vat stack from its panel (a
//! layer range, an offset, and the shard-or-layers refusal in its words).

use std::path::Path;
use std::time::Duration;

use egui_kittest::Harness;
use egui_kittest::kittest::{NodeT as _, Queryable};
use volcad_studio::studio::egui;
use volcad_studio::studio::{StudioApp, StudioOptions};

mod common;
use common::{harness, wait_label, wait_within};

/// The graded bar (15 × 10 × 5 mm, red and blue from default_materials()).
const BAR: &str = r#"let m = default_materials();
let bar = RectPrism(Vec3(0, 0, 0), Vec3(15, 10, 5), m.id("gray"));
FGrade(["x/15+0.5", "-x/15+0.5"], [m.id("red"), m.id("blue")], true, bar)"#;

fn studio(name: &str) -> (tempfile::TempDir, Harness<'static, StudioApp>) {
    let dir = tempfile::Builder::new()
        .prefix(&format!("volcad-studio-printers-{name}-"))
        .tempdir()
        .unwrap_or_else(|e| panic!("temp dir: {e}"));
    let mut h = harness(StudioOptions::for_tests(dir.path().join("data"), BAR));
    wait_within(&mut h, "the design", Duration::from_secs(60), |a| {
        a.is_idle() && a.model().is_some()
    });
    (dir, h)
}

/// Replace the text of the field labelled `label` with `text`.
fn set_field(h: &mut Harness<'static, StudioApp>, label: &str, text: &str) {
    h.get_by_label(label).focus();
    h.step();
    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::A);
    h.step();
    h.get_by_label(label).type_text(text);
    h.run_steps(2);
}

/// Click `button` and step until the last job ends; it must end done.
fn export_to_the_end(h: &mut Harness<'static, StudioApp>, button: &str) {
    use volcad_studio::studio::jobs::JobState;
    // Through accesskit: with a custom screen's rows the button sits below
    // the side panel's fold (the panel scrolls), where a pointer click at
    // its centre lands on the log panel.
    h.get_by_label(button).click_accesskit();
    h.run_steps(2);
    assert!(
        !h.state().jobs().list().is_empty(),
        "{button}: no job started; modal {:?}; log:\n{}",
        h.state().modal(),
        h.state().log_lines().join("\n")
    );
    let end = |a: &StudioApp| {
        a.jobs()
            .list()
            .last()
            .map(|j| !matches!(j.state, JobState::Running(_)))
    };
    wait_within(h, "the export", Duration::from_secs(240), |a| {
        end(a) == Some(true)
    });
    let state = h
        .state()
        .jobs()
        .list()
        .last()
        .map(|j| format!("{:?}", j.state));
    assert!(
        state.as_deref().is_some_and(|s| s.starts_with("Done")),
        "{state:?}"
    );
}

#[test]
fn j750_refuses_default_materials_until_mapped_and_writes_a_gcvf() {
    let (dir, mut h) = studio("gcvf");
    h.get_by_label("GCVF").click();
    h.run_steps(2);
    // red and blue are not J750 resins: refused with the nearest ones.
    let e = wait_label(&mut h, "is not a J750 material");
    assert!(e.contains("\"red\"") && e.contains("VeroMgnt"), "{e}");
    assert!(e.contains("\"Resin map\""), "in the panel's words: {e}");
    let out = dir.path().join("bar.gcvf");
    set_field(&mut h, "Output file", &out.display().to_string());
    set_field(&mut h, "Resin map", "red=VeroMgnt,blue=VeroCyan");
    let est = wait_label(&mut h, "Estimate:");
    assert!(
        est.contains("355 × 119 × 186 voxels") && est.contains("VeroMgnt"),
        "{est}"
    );
    export_to_the_end(&mut h, "Export GCVF (.gcvf)");
    // A zip (local header signature) naming pyvcad's entries (zip stores
    // entry names as plain text).
    let bytes = std::fs::read(&out).expect("the package");
    assert!(bytes.starts_with(b"PK\x03\x04"));
    let has = |name: &str| bytes.windows(name.len()).any(|w| w == name.as_bytes());
    assert!(has("ConfigFile.xml") && has("gcvf_export_185.png") && !has("gcvf_export_186.png"));
    let others: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n != "data" && n != "bar.gcvf")
        .collect();
    assert!(others.is_empty(), "nothing but the package: {others:?}");
    // A second export asks before replacing the file.
    h.get_by_label("Export GCVF (.gcvf)").click();
    h.run_steps(2);
    assert!(h.state().modal().is_some(), "asks before replacing");
}

#[test]
fn the_png_printer_choice_j750_brings_its_resin_table() {
    let (_dir, mut h) = studio("png-j750");
    // Generic: the design's own materials.
    wait_label(&mut h, "Estimate:");
    h.get_by_label("Printer").click();
    h.run_steps(2);
    h.get_by_label("j750").click();
    h.run_steps(2);
    let e = wait_label(&mut h, "is not a J750 material");
    assert!(e.contains("\"blue\"") && e.contains("VeroBlue"), "{e}");
    assert!(
        h.query_by_label("Export PNG stack")
            .is_some_and(|b| b.accesskit_node().is_disabled()),
        "refused before any work"
    );
    set_field(&mut h, "Resin map", "red=VeroMgnt,blue=VeroCyan");
    let est = wait_label(&mut h, "Estimate:");
    assert!(
        est.contains("355 × 119 × 186 voxels"),
        "the J750 grid: {est}"
    );
    // A map onto a name the J750 lacks is refused with its nearest resins.
    set_field(&mut h, "Resin map", "red=Crimson,blue=VeroCyan");
    let e = wait_label(&mut h, "is not a J750 material");
    assert!(e.contains("Crimson") && e.contains("VeroMgnt"), "{e}");
    // Full colour is made of the J750's colour resins whatever the
    // design's materials: no resin map is asked for (as on the CLI).
    h.get_by_label("Resin map").focus();
    h.step();
    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::A);
    h.key_press(egui::Key::Backspace);
    h.run_steps(2);
    wait_label(&mut h, "is not a J750 material");
    h.get_by_label("Full colour").click();
    h.run_steps(2);
    let est = wait_label(&mut h, "Estimate:");
    assert!(est.contains("355 × 119 × 186 voxels"), "{est}");
    assert!(
        h.query_by_label_contains("is not a J750 material")
            .is_none(),
        "no resin refusal with full colour"
    );
}

#[test]
fn a_vat_stack_from_its_panel() {
    let (dir, mut h) = studio("vat");
    h.get_by_label("Vat").click();
    h.run_steps(2);
    h.get_by_label("Vat printer").click();
    h.run_steps(2);
    h.get_by_label("Custom screen").click();
    h.run_steps(2);
    for node in h.get_all_by_label("Pixel (µm)") {
        node.set_value_accesskit(250.0);
    }
    for (node, v) in h.get_all_by_label("Screen (px)").zip([80.0, 60.0]) {
        node.set_value_accesskit(v);
    }
    h.get_by_label("Layer (µm)").set_value_accesskit(500.0);
    h.run_steps(2);
    let out = dir.path().join("vat");
    set_field(&mut h, "Output folder", &out.display().to_string());
    set_field(&mut h, "Vat materials", "red,blue");
    // The command line's --layers, --shard and --offset, read the same way.
    set_field(&mut h, "Layers", "2..5");
    set_field(&mut h, "Shard", "1/2");
    let refusal = wait_label(&mut h, "both choose layers");
    assert!(
        refusal.contains("the shard: 1/2 and the layer range both choose layers"),
        "{refusal}"
    );
    h.get_by_label("Shard").focus();
    h.step();
    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::A);
    h.step();
    h.key_press(egui::Key::Backspace);
    h.run_steps(2);
    set_field(&mut h, "Offset (mm)", "1,0");
    let est = wait_label(&mut h, "Estimate:");
    assert!(
        est.contains("part 60 × 40 px of a 80 × 60 px screen")
            && est.contains("2 vat(s)")
            && est.contains("layers 2 to 4 included (3 of 10)"),
        "{est}"
    );
    export_to_the_end(&mut h, "Export Vat stack");
    let mut cols = (usize::MAX, 0);
    for v in ["vat1", "vat2"] {
        let mut names: Vec<String> = std::fs::read_dir(out.join(v))
            .map(|d| {
                d.filter_map(Result::ok)
                    .map(|e| e.file_name().to_string_lossy().into_owned())
                    .collect()
            })
            .unwrap_or_default();
        names.sort();
        assert_eq!(
            names,
            ["slice_00002.png", "slice_00003.png", "slice_00004.png"],
            "{v}"
        );
        let img = image::open(out.join(v).join("slice_00003.png"))
            .unwrap_or_else(|e| panic!("{v}: {e}"))
            .to_luma8();
        for (x, _, p) in img.enumerate_pixels() {
            if p[0] > 0 {
                cols = (cols.0.min(x as usize), cols.1.max(x as usize));
            }
        }
    }
    // The 60 px bar centred on 80 px spans columns 10..70; 1 mm = 4 px right.
    assert_eq!(cols, (14, 73));
    assert!(Path::new(&out.join("manifest.json")).is_file());
}
