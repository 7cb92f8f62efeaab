//! The probe: what is under the cursor, read exactly from the model (not the
//! baked preview) by `volcad_render::pick`, on a worker thread so a big
//! design never stalls a frame. One probe runs at a time; while it runs, only
//! the newest request waits (hover requests replace each other; a click's
//! request is never replaced by a hover).

use std::sync::Arc;
use std::sync::mpsc::{Receiver, Sender, channel};

use egui::Pos2;
use volcad_core::Model;
use volcad_render::{PickHit, Vec2, ViewSettings};

/// One probe to run.
#[derive(Clone)]
pub struct ProbeRequest {
    /// The model on screen.
    pub model: Arc<Model>,
    /// The view at the time of the request: camera, cut plane, mode and
    /// hidden materials (the probe reads what the picture draws).
    pub view: ViewSettings,
    /// Cursor in normalized device coordinates (−1..1, y up).
    pub ndc: Vec2,
    /// Viewport width / height.
    pub aspect: f32,
    /// Cursor in screen points (to draw the marker).
    pub pos: Pos2,
}

/// A probe read-out.
#[derive(Clone, Debug, PartialEq)]
pub struct Probe {
    /// Where the cursor was (screen points).
    pub pos: Pos2,
    /// The hit: point, depth from the eye, fractions.
    pub hit: PickHit,
    /// The model's signed distance at the hit point (mm; ≤ 0 on the part).
    pub surface_distance: f64,
}

/// Run one probe (the worker's job; also handy in tests).
pub fn run(req: &ProbeRequest) -> Option<Probe> {
    let hit = volcad_render::pick_drawn(&req.model, &req.view, req.ndc, req.aspect)?;
    let surface_distance = req.model.distance(hit.point);
    Some(Probe {
        pos: req.pos,
        hit,
        surface_distance,
    })
}

type Answer = (Option<Probe>, bool);

/// Runs probes off the UI thread.
pub struct ProbeWorker {
    busy: bool,
    pending: Option<(ProbeRequest, bool)>,
    ctx: Option<egui::Context>,
    tx: Sender<Answer>,
    rx: Receiver<Answer>,
    pinned: Option<Option<Probe>>,
}

impl Default for ProbeWorker {
    fn default() -> Self {
        let (tx, rx) = channel();
        Self {
            busy: false,
            pending: None,
            ctx: None,
            tx,
            rx,
            pinned: None,
        }
    }
}

impl ProbeWorker {
    /// Ask for a probe; `pinned` marks a click (kept until the next click).
    pub fn request(&mut self, ctx: &egui::Context, req: ProbeRequest, pinned: bool) {
        self.ctx = Some(ctx.clone());
        if self.busy {
            if pinned || !self.pending.as_ref().is_some_and(|(_, p)| *p) {
                self.pending = Some((req, pinned));
            }
            return;
        }
        self.spawn(req, pinned);
    }

    fn spawn(&mut self, req: ProbeRequest, pinned: bool) {
        let tx = self.tx.clone();
        let ctx = self.ctx.clone();
        self.busy = true;
        let spawned = std::thread::Builder::new()
            .name("volcad-probe".into())
            .spawn(move || {
                let _ = tx.send((run(&req), pinned));
                if let Some(c) = ctx {
                    c.request_repaint();
                }
            });
        if spawned.is_err() {
            self.busy = false;
        }
    }

    /// The newest hover read-out, if one finished (`Some(None)`: a miss).
    pub fn poll(&mut self) -> Option<Option<Probe>> {
        let mut hover = None;
        while let Ok((probe, pinned)) = self.rx.try_recv() {
            self.busy = false;
            if pinned {
                self.pinned = Some(probe);
            } else {
                hover = Some(probe);
            }
        }
        if !self.busy
            && let Some((req, pinned)) = self.pending.take()
        {
            self.spawn(req, pinned);
        }
        hover
    }

    /// A finished click probe, once.
    pub fn take_pinned(&mut self) -> Option<Option<Probe>> {
        self.pinned.take()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use volcad_core::script::{ScriptOptions, run_script};

    #[test]
    fn probe_reads_fractions_at_the_surface() {
        let d = run_script(
            r#"let m = default_materials();
               let bar = RectPrism(Vec3(0, 0, 0), Vec3(15, 10, 5), m.id("gray"));
               FGrade(["x/15+0.5", "-x/15+0.5"], [m.id("red"), m.id("blue")], true, bar)"#,
            "t.rhai",
            &ScriptOptions::default(),
        )
        .unwrap();
        let model = Arc::new(Model::prepare(&d.root, d.materials.clone()).unwrap());
        let camera = volcad_render::Camera::fit(&model.bbox(), volcad_render::StandardView::Top);
        let req = ProbeRequest {
            model,
            view: ViewSettings::plain(camera),
            ndc: Vec2::ZERO,
            aspect: 1.0,
            pos: Pos2::ZERO,
        };
        let p = run(&req).expect("the centre ray hits the bar");
        assert!(
            p.surface_distance <= 0.0 && p.surface_distance > -0.01,
            "{}",
            p.surface_distance
        );
        assert!(
            (p.hit.point.z - 2.5).abs() < 0.01,
            "top face: {:?}",
            p.hit.point
        );
        let sum: f64 = p.hit.fractions.iter().map(|(_, f)| f).sum();
        assert!((sum - 1.0).abs() < 1e-6, "{:?}", p.hit.fractions);

        let ctx = egui::Context::default();
        let mut w = ProbeWorker::default();
        w.request(&ctx, req.clone(), false);
        w.request(&ctx, req, true);
        let t = std::time::Instant::now();
        let (mut hover, mut pinned) = (None, None);
        while (hover.is_none() || pinned.is_none()) && t.elapsed().as_secs() < 10 {
            hover = hover.or(w.poll());
            pinned = pinned.or(w.take_pinned());
            std::thread::sleep(std::time::Duration::from_millis(5));
        }
        assert!(hover.flatten().is_some() && pinned.flatten().is_some());
    }

    /// A red core inside a blue skin, probed from the top through the
    /// centre.
    fn core_and_skin(view: impl FnOnce(&Model) -> ViewSettings) -> Probe {
        let d = run_script(
            r#"let m = default_materials();
               Union(false, [Sphere(Vec3(0, 0, 0), 5.0, m.id("red")),
                             Sphere(Vec3(0, 0, 0), 10.0, m.id("blue"))])"#,
            "t.rhai",
            &ScriptOptions::default(),
        )
        .unwrap();
        let model = Arc::new(Model::prepare(&d.root, d.materials.clone()).unwrap());
        let req = ProbeRequest {
            view: view(&model),
            model,
            ndc: Vec2::ZERO,
            aspect: 1.0,
            pos: Pos2::ZERO,
        };
        run(&req).expect("the centre ray hits the part")
    }

    fn top(model: &Model) -> ViewSettings {
        ViewSettings::plain(volcad_render::Camera::fit(
            &model.bbox(),
            volcad_render::StandardView::Top,
        ))
    }

    #[test]
    fn probe_looks_through_hidden_materials() {
        let shown = core_and_skin(top);
        assert!((shown.hit.point.z - 10.0).abs() < 0.01, "{:?}", shown.hit);
        assert_eq!(shown.hit.surface, volcad_render::HitSurface::Part);
        let hidden = core_and_skin(|m| {
            let blue = m
                .materials()
                .iter()
                .position(|&id| m.table().name(id) == "blue")
                .unwrap();
            let mut v = top(m);
            v.material_opacity = vec![1.0; m.materials().len()];
            v.material_opacity[blue] = 0.0;
            v
        });
        assert!((hidden.hit.point.z - 5.0).abs() < 0.02, "{:?}", hidden.hit);
        assert_eq!(hidden.hit.surface, volcad_render::HitSurface::Region);
        assert_eq!(hidden.hit.fractions.len(), 1);
        assert!(
            hidden.surface_distance < -4.9,
            "{}",
            hidden.surface_distance
        );
    }

    #[test]
    fn probe_stops_on_the_cut_face_and_at_the_iso_level() {
        let cut = core_and_skin(|m| {
            let mut v = top(m);
            v.cut = Some(volcad_render::CutPlane {
                axis: 2,
                offset: 0.0,
                keep_below: true,
            });
            v
        });
        assert!(cut.hit.point.z.abs() < 0.01, "{:?}", cut.hit);
        assert_eq!(cut.hit.surface, volcad_render::HitSurface::Cut);
        let iso = core_and_skin(|m| {
            let red = m
                .materials()
                .iter()
                .position(|&id| m.table().name(id) == "red")
                .unwrap();
            let mut v = top(m);
            v.mode = volcad_render::ViewMode::Iso {
                material_index: red,
                level: 0.5,
            };
            v
        });
        assert!((iso.hit.point.z - 5.0).abs() < 0.02, "{:?}", iso.hit);
    }
}
