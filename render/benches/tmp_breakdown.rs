#[path = "../tests/common/mod.rs"]
mod common;
use common::*;
use volcad_render::{Camera, Offscreen, StandardView, ViewMode, ViewSettings, bake_blocking};
fn med(off: &mut Offscreen, s: &ViewSettings) -> f64 {
    off.draw_timed(s).unwrap();
    let mut v: Vec<f64> = (0..3).map(|_| off.draw_timed(s).unwrap() * 1e3).collect();
    v.sort_by(|a, b| a.total_cmp(b));
    v[1]
}
fn main() {
    let mut off = Offscreen::new([1280, 800]).unwrap();
    let m = model(SPHERE);
    let cam = Camera::fit(&m.bbox(), StandardView::Iso);
    let plain = ViewSettings::plain(cam);
    let full = ViewSettings { camera: cam, ..Default::default() };
    println!("no volume plain {:.1} ms, overlays {:.1} ms", med(&mut off, &plain), med(&mut off, &full));
    for (name, src) in [("sphere", SPHERE.to_string()), ("bar", GRADED_BAR.to_string()), ("bcc", BCC_SPHERE.to_string())] {
        let m = model(&src);
        let cam = Camera::fit(&m.bbox(), StandardView::Iso);
        for res in [64, 128] {
            off.upload(&bake_blocking(&m, res).unwrap());
            let plain = ViewSettings::plain(cam);
            let full = ViewSettings { camera: cam, ..Default::default() };
            let half = ViewSettings { render_scale: 0.5, ..full.clone() };
            let vol = ViewSettings { mode: ViewMode::Volume, ..full.clone() };
            let iso = ViewSettings { mode: ViewMode::Iso { material_index: 0, level: 0.5 }, ..full.clone() };
            println!("{name} {res}: plain {:.1} overlays {:.1} half {:.1} volume {:.1} iso {:.1}", med(&mut off, &plain), med(&mut off, &full), med(&mut off, &half), med(&mut off, &vol), med(&mut off, &iso));
        }
    }
}
