//! Running exports: each is a `volcad_compilers::job` (its own thread,
//! progress channel, cancel, staging folder renamed on success). The list is
//! drained every frame with `try_recv`; a finished job is joined only once
//! `is_finished()` says it will not wait.

use std::path::PathBuf;
use std::time::Duration;

use volcad_compilers::job::{JobHandle, Progress, Summary};
use volcad_compilers::plan::Opt;

use super::files;

/// Where a job is.
#[derive(Debug)]
pub enum JobState {
    /// Working; the last progress report.
    Running(Option<Progress>),
    /// Done: what it wrote.
    Done(Summary),
    /// Cancelled by the user: nothing was written.
    Cancelled,
    /// Failed: why.
    Failed(String),
}

/// One export job in the list.
pub struct Job {
    /// "PNG stack", "Meshes", "FEA".
    pub title: String,
    /// The output folder.
    pub dest: PathBuf,
    /// Its state.
    pub state: JobState,
    handle: Option<JobHandle>,
    /// "Open folder" found no file manager: why, shown at the button.
    open_failed: Option<String>,
}

impl Job {
    /// True while the worker runs.
    pub fn is_running(&self) -> bool {
        matches!(self.state, JobState::Running(_))
    }
}

/// All jobs of this session.
#[derive(Default)]
pub struct Jobs {
    list: Vec<Job>,
}

impl Jobs {
    /// Track a started job.
    pub fn push(&mut self, title: &str, handle: JobHandle) {
        let dest = handle.destination().to_owned();
        self.list.push(Job {
            title: title.to_owned(),
            dest,
            state: JobState::Running(None),
            handle: Some(handle),
            open_failed: None,
        });
    }

    /// The jobs, oldest first.
    pub fn list(&self) -> &[Job] {
        &self.list
    }

    /// True when any job still runs (closing the window asks first).
    pub fn any_running(&self) -> bool {
        self.list.iter().any(Job::is_running)
    }

    /// Cancel every running job.
    pub fn cancel_all(&self) {
        for j in &self.list {
            if let Some(h) = &j.handle {
                h.cancel();
            }
        }
    }

    /// Drain progress and collect finished jobs (call every frame). Returns
    /// log lines for jobs that finished.
    pub fn poll(&mut self, ctx: &egui::Context) -> Vec<String> {
        let mut finished = Vec::new();
        for j in &mut self.list {
            let Some(h) = &j.handle else { continue };
            let mut last = None;
            while let Ok(p) = h.progress.try_recv() {
                last = Some(p);
            }
            if let (Some(p), JobState::Running(cur)) = (last, &mut j.state) {
                *cur = Some(p);
            }
            if h.is_finished()
                && let Some(h) = j.handle.take()
            {
                j.state = match h.join() {
                    Ok(s) => JobState::Done(s),
                    Err(volcad_compilers::ExportError::Cancelled) => JobState::Cancelled,
                    Err(e) => JobState::Failed(in_panel_words(&e.to_string())),
                };
                finished.push(match &j.state {
                    JobState::Done(s) => format!(
                        "{} done: {} in {:.1} s, {}",
                        j.title,
                        count(s.files.len(), "file"),
                        s.seconds,
                        j.dest.display()
                    ),
                    JobState::Cancelled => format!(
                        "{} cancelled; nothing written to {}",
                        j.title,
                        j.dest.display()
                    ),
                    JobState::Failed(e) => format!("{} failed: {e}", j.title),
                    JobState::Running(_) => String::new(),
                });
            }
        }
        if self.any_running() {
            // Job progress has no wake-up of its own: look again shortly.
            ctx.request_repaint_after(Duration::from_millis(100));
        }
        finished
    }

    /// Show the list: progress bars with time left and Cancel, summaries with
    /// "Open folder". Returns log lines (from "Open folder" failures).
    pub fn ui(&mut self, ui: &mut egui::Ui) -> Vec<String> {
        let mut notes = Vec::new();
        let mut remove = None;
        for (i, j) in self.list.iter_mut().enumerate().rev() {
            ui.push_id(("job", i), |ui| {
                ui.group(|ui| {
                    ui.horizontal(|ui| {
                        ui.label(egui::RichText::new(&j.title).strong());
                        ui.weak(j.dest.display().to_string());
                    });
                    match &j.state {
                        JobState::Running(p) => {
                            let (fraction, text) = progress_text(p.as_ref());
                            ui.add(egui::ProgressBar::new(fraction as f32).text(text));
                            if ui.button("Cancel").clicked()
                                && let Some(h) = &j.handle
                            {
                                h.cancel();
                            }
                        }
                        JobState::Done(s) => {
                            ui.label(summary_text(s));
                            for n in &s.notes {
                                // Warnings (an empty stack, say) stand out
                                // from the figures.
                                if n.starts_with("warning") {
                                    ui.colored_label(ui.visuals().warn_fg_color, n);
                                } else {
                                    ui.weak(n);
                                }
                            }
                            ui.horizontal(|ui| {
                                if ui.button("Open folder").clicked()
                                    && let Err(e) = files::open_folder(&j.dest)
                                {
                                    j.open_failed = Some(e.clone());
                                    notes.push(e);
                                }
                                if ui.small_button("Dismiss").clicked() {
                                    remove = Some(i);
                                }
                            });
                            if let Some(e) = &j.open_failed {
                                ui.colored_label(ui.visuals().warn_fg_color, e);
                                ui.horizontal(|ui| {
                                    let path = j.dest.display().to_string();
                                    ui.monospace(&path);
                                    if ui.small_button("Copy path").clicked() {
                                        ui.ctx().copy_text(path);
                                    }
                                });
                            }
                        }
                        JobState::Cancelled => {
                            ui.weak("Cancelled; nothing was written.");
                            if ui.small_button("Dismiss").clicked() {
                                remove = Some(i);
                            }
                        }
                        JobState::Failed(e) => {
                            ui.colored_label(ui.visuals().error_fg_color, e);
                            if ui.small_button("Dismiss").clicked() {
                                remove = Some(i);
                            }
                        }
                    }
                });
            });
        }
        if let Some(i) = remove {
            self.list.remove(i);
        }
        notes
    }
}

/// Progress bar fraction and text: "sampling 42% · 1,234 of 5,000 layers · 12 s left".
pub fn progress_text(p: Option<&Progress>) -> (f64, String) {
    let Some(p) = p else {
        return (0.0, "starting…".into());
    };
    let mut s = format!("{} {:.0}%", p.stage, p.fraction * 100.0);
    if p.total > 0 {
        s += &format!(" · {} of {} {}", p.done, p.total, p.unit);
    }
    if let Some(eta) = p.eta {
        s += &format!(" · {} left", duration_text(eta));
    }
    (p.fraction, s)
}

/// "1 h 02 min", "3 min 05 s", "12 s".
pub fn duration_text(d: Duration) -> String {
    let s = d.as_secs();
    if s >= 3600 {
        format!("{} h {:02} min", s / 3600, (s / 60) % 60)
    } else if s >= 60 {
        format!("{} min {:02} s", s / 60, s % 60)
    } else {
        format!("{s} s")
    }
}

/// The export panel's name for the option `o` (its field, in quotes).
pub fn field(o: Opt) -> &'static str {
    match o {
        Opt::MinCell => "\"Cell min\"",
        Opt::MaxCell => "\"Cell max\"",
        Opt::Sizing => "\"Size of h\"",
        Opt::Voxel => "\"Voxel (mm)\"",
        Opt::Out => "\"Output folder\"",
        Opt::Infill => "\"3MF infill\"",
        Opt::Segments => "\"Segments\"",
        Opt::By => "\"Split by\"",
        Opt::Formats => "\"Formats\"",
        Opt::Threads => "the thread count",
        Opt::Layers => "the layer range",
        Opt::Step => "\"Static step\"",
        Opt::PropertyBins => "\"Property bins\"",
        Opt::Shard => "the shard",
        Opt::Force => "\"Export anyway\"",
        Opt::FullColor => "\"Full colour\"",
        Opt::ColorProfile => "\"Colour profile\"",
        Opt::BitmapFormat => "\"Bitmap format\"",
        Opt::BitmapWidth => "\"Bitmap width\"",
        Opt::Preset => "\"Printer\"",
        Opt::Map => "\"Resin map\"",
        Opt::Intensity => "\"Intensity\"",
        Opt::Range => "\"Range\"",
        Opt::Vats => "\"Vats\"",
        Opt::VatMaterials => "\"Vat materials\"",
        Opt::Offset => "\"Offset (mm)\"",
        Opt::Design => "design",
    }
}

/// A compiler's message in the panel's words: its command-line option
/// names become the fields that set them (`--voxel` → "Voxel (mm)").
pub fn in_panel_words(message: &str) -> String {
    let mut m = message.to_owned();
    for o in Opt::ALL.into_iter().filter(|o| *o != Opt::Design) {
        m = m.replace(o.flag(), field(o));
    }
    // Older spellings some messages still use.
    m.replace("--material", field(Opt::By))
        .replace("--format", field(Opt::Formats))
}

/// "1 file", "2 files".
pub fn count(n: usize, noun: &str) -> String {
    if n == 1 {
        format!("1 {noun}")
    } else {
        format!("{n} {noun}s")
    }
}

fn summary_text(s: &Summary) -> String {
    let mut t = format!(
        "Done in {}: {}",
        duration_text(Duration::from_secs_f64(s.seconds)),
        count(s.files.len(), "file")
    );
    if s.units > 0 {
        t += &format!(", {} {}", s.units, s.unit);
    }
    if !s.counts.is_empty() {
        let counts: Vec<String> = s.counts.iter().map(|(n, c)| format!("{n} {c}")).collect();
        t += &format!("\n{}", counts.join(", "));
    }
    t
}

#[cfg(test)]
mod tests {

    #[test]
    fn messages_name_panel_fields_not_flags() {
        assert_eq!(
            in_panel_words("--voxel: one layer needs 3 GiB; use a larger --voxel"),
            "\"Voxel (mm)\": one layer needs 3 GiB; use a larger \"Voxel (mm)\""
        );
        assert_eq!(count(1, "file"), "1 file");
        assert_eq!(count(2, "file"), "2 files");
    }

    use super::*;

    #[test]
    fn durations_read_well() {
        assert_eq!(duration_text(Duration::from_secs(12)), "12 s");
        assert_eq!(duration_text(Duration::from_secs(185)), "3 min 05 s");
        assert_eq!(duration_text(Duration::from_secs(3720)), "1 h 02 min");
    }

    #[test]
    fn progress_text_has_stage_units_and_eta() {
        let p = Progress {
            stage: "sampling".into(),
            fraction: 0.5,
            done: 5,
            total: 10,
            unit: "layers",
            elapsed: Duration::from_secs(3),
            eta: Some(Duration::from_secs(3)),
        };
        assert_eq!(
            progress_text(Some(&p)).1,
            "sampling 50% · 5 of 10 layers · 3 s left"
        );
    }
}
