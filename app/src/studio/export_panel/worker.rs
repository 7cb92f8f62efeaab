//! The export panel's estimate worker: one thread, newest request first.
//!
//! A mesh estimate samples a few layers at the export's voxel size (tens of
//! milliseconds, more on large designs), and dragging a value asks for one
//! per frame. Requests that a newer one overtook while the worker was busy
//! are dropped unanswered, so at most one estimate runs at a time.

use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::mpsc::{Receiver, Sender, channel};

use volcad_compilers::plan::{Assessment, ExportParams};
use volcad_core::Model;

use crate::studio::jobs::in_panel_words;

/// The newest estimate asked for and its answer.
#[derive(Default)]
pub(super) struct EstimateWorker {
    key: Option<(usize, ExportParams)>,
    /// Number of the newest request; only its answer is shown.
    seq: u64,
    /// The answer to the newest request (messages in the panel's words,
    /// except the verdicts', which the panel words when it shows them).
    pub(super) answer: Option<Result<Assessment, String>>,
    link: Option<WorkerLink>,
}

/// One request to the worker.
struct EstimateRequest {
    seq: u64,
    model: Arc<Model>,
    params: ExportParams,
    ctx: egui::Context,
}

/// The worker's two channels (the worker ends when `jobs` is dropped).
struct WorkerLink {
    jobs: Sender<EstimateRequest>,
    answers: Receiver<(u64, Result<Assessment, String>)>,
    /// Estimates computed (read by tests).
    #[cfg_attr(not(test), allow(dead_code))]
    computed: Arc<AtomicUsize>,
}

impl WorkerLink {
    fn start() -> Option<WorkerLink> {
        let (jobs, inbox) = channel::<EstimateRequest>();
        let (outbox, answers) = channel();
        let computed = Arc::new(AtomicUsize::new(0));
        let count = computed.clone();
        std::thread::Builder::new()
            .name("volcad-estimate".into())
            .spawn(move || {
                while let Ok(mut req) = inbox.recv() {
                    // Skip to the newest request waiting.
                    while let Ok(newer) = inbox.try_recv() {
                        req = newer;
                    }
                    let answer = req
                        .params
                        .assess(&req.model)
                        .map_err(|e| in_panel_words(&e.to_string()));
                    count.fetch_add(1, Ordering::Relaxed);
                    if outbox.send((req.seq, answer)).is_err() {
                        break;
                    }
                    req.ctx.request_repaint();
                }
            })
            .ok()?;
        Some(WorkerLink {
            jobs,
            answers,
            computed,
        })
    }
}

impl EstimateWorker {
    /// Ask for the estimate of `params` on `model` unless it is the one
    /// asked for last, and take the worker's answers.
    pub(super) fn update(
        &mut self,
        ctx: &egui::Context,
        model: &Arc<Model>,
        params: &ExportParams,
    ) {
        let key = (Arc::as_ptr(model) as usize, params.clone());
        if self.key.as_ref() != Some(&key) {
            self.key = Some(key);
            self.answer = None;
            self.seq += 1;
            if self.link.is_none() {
                self.link = WorkerLink::start();
            }
            let sent = self.link.as_ref().is_some_and(|l| {
                l.jobs
                    .send(EstimateRequest {
                        seq: self.seq,
                        model: model.clone(),
                        params: params.clone(),
                        ctx: ctx.clone(),
                    })
                    .is_ok()
            });
            if !sent {
                self.link = None;
                self.answer = Some(Err("the estimate could not be started".into()));
            }
        }
        if let Some(link) = &self.link {
            for (seq, answer) in link.answers.try_iter() {
                if seq == self.seq {
                    self.answer = Some(answer);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;
    use volcad_compilers::mesh::MeshParams;

    #[test]
    fn a_burst_of_requests_gets_the_newest_answer_from_few_estimates() {
        let d = volcad_core::script::run_script(
            "let m = default_materials(); Sphere(Vec3(0,0,0), 10, m.id(\"red\"))",
            "t.rhai",
            &Default::default(),
        )
        .unwrap();
        let model = Arc::new(Model::prepare(&d.root, d.materials).unwrap());
        let ctx = egui::Context::default();
        let mut w = EstimateWorker::default();
        let mesh = |voxel: f64| {
            ExportParams::Mesh(MeshParams {
                voxel: DVec3::splat(voxel),
                ..MeshParams::default()
            })
        };
        // Twenty values in a row, as a drag gives them, the last 0.2 mm.
        for i in 0..20 {
            w.update(&ctx, &model, &mesh(0.2 + 0.01 * f64::from(19 - i)));
        }
        let deadline = std::time::Instant::now() + std::time::Duration::from_secs(60);
        while w.answer.is_none() && std::time::Instant::now() < deadline {
            std::thread::sleep(std::time::Duration::from_millis(5));
            w.update(&ctx, &model, &mesh(0.2));
        }
        let text = w
            .answer
            .clone()
            .expect("an answer")
            .expect("an estimate")
            .text;
        // 20 mm at 0.2 mm, padded by a voxel on every side.
        assert!(text.starts_with("102 × 102 × 102 voxels"), "{text}");
        let computed = w.link.as_ref().unwrap().computed.load(Ordering::Relaxed);
        assert!(
            (1..=3).contains(&computed),
            "{computed} estimates for 20 requests"
        );
    }
}
