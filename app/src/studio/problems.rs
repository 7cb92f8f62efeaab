//! The bottom panel: problems (script errors and warnings, click to jump to
//! the line) and the log (what scripts printed, bakes, exports, files).

use std::time::SystemTime;

/// How bad a problem is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Severity {
    /// The script did not run; the preview is stale.
    Error,
    /// The script ran but something deserves a look.
    Warning,
}

/// One entry of the problems list.
#[derive(Clone, Debug, PartialEq)]
pub struct Problem {
    /// Error or warning.
    pub severity: Severity,
    /// 1-based line, if known.
    pub line: Option<usize>,
    /// 1-based column, if known.
    pub column: Option<usize>,
    /// The message.
    pub message: String,
}

impl Problem {
    /// The list entry's text: `error  line 3:9  message`.
    pub fn label(&self) -> String {
        let kind = match self.severity {
            Severity::Error => "error",
            Severity::Warning => "warning",
        };
        let at = match (self.line, self.column) {
            (Some(l), Some(c)) => format!("  line {l}:{c}"),
            (Some(l), None) => format!("  line {l}"),
            _ => String::new(),
        };
        format!("{kind}{at}  {}", self.message)
    }
}

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
enum Tab {
    #[default]
    Problems,
    Log,
}

/// The log and the bottom panel's tab.
#[derive(Default)]
pub struct BottomPanel {
    tab: Tab,
    log: Vec<String>,
}

/// Most log lines kept.
const MAX_LOG: usize = 2000;

impl BottomPanel {
    /// Add a line to the log, stamped with the time of day (UTC).
    pub fn log(&mut self, line: impl Into<String>) {
        let secs = SystemTime::now()
            .duration_since(SystemTime::UNIX_EPOCH)
            .map_or(0, |d| d.as_secs());
        let (h, m, s) = ((secs / 3600) % 24, (secs / 60) % 60, secs % 60);
        self.log
            .push(format!("{h:02}:{m:02}:{s:02}  {}", line.into()));
        if self.log.len() > MAX_LOG {
            self.log.drain(..self.log.len() - MAX_LOG);
        }
    }

    /// The log lines (tests).
    pub fn log_lines(&self) -> &[String] {
        &self.log
    }

    /// Show the problems list as the current tab (after an error).
    pub fn show_problems(&mut self) {
        self.tab = Tab::Problems;
    }

    /// Show the panel; returns the (line, column) of a clicked problem.
    pub fn ui(
        &mut self,
        ui: &mut egui::Ui,
        problems: &[Problem],
    ) -> Option<(usize, Option<usize>)> {
        let mut jump = None;
        ui.horizontal(|ui| {
            let errors = problems
                .iter()
                .filter(|p| p.severity == Severity::Error)
                .count();
            let warnings = problems.len() - errors;
            let title = format!("Problems ({errors} errors, {warnings} warnings)");
            ui.selectable_value(&mut self.tab, Tab::Problems, title);
            ui.selectable_value(&mut self.tab, Tab::Log, format!("Log ({})", self.log.len()));
            if self.tab == Tab::Log && ui.small_button("Clear").clicked() {
                self.log.clear();
            }
        });
        ui.separator();
        // One scroll state per tab: the log's starts at its newest entry
        // (stuck to the end) instead of inheriting the problem list's top.
        egui::ScrollArea::vertical()
            .id_salt(("bottom-scroll", self.tab == Tab::Log))
            .auto_shrink([false, false])
            .stick_to_bottom(self.tab == Tab::Log)
            .show(ui, |ui| match self.tab {
                Tab::Problems => {
                    if problems.is_empty() {
                        ui.weak("No problems.");
                    }
                    for p in problems {
                        let color = match p.severity {
                            Severity::Error => ui.visuals().error_fg_color,
                            Severity::Warning => ui.visuals().warn_fg_color,
                        };
                        let text = egui::RichText::new(p.label()).monospace().color(color);
                        let resp = ui.add(egui::Button::new(text).frame(false));
                        if let Some(line) = p.line
                            && resp.on_hover_text("Go to this line").clicked()
                        {
                            jump = Some((line, p.column));
                        }
                    }
                }
                Tab::Log => {
                    for l in &self.log {
                        ui.label(egui::RichText::new(l).monospace());
                    }
                }
            });
        jump
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn labels_name_the_line() {
        let p = Problem {
            severity: Severity::Error,
            line: Some(3),
            column: Some(9),
            message: "boom".into(),
        };
        assert_eq!(p.label(), "error  line 3:9  boom");
        let w = Problem {
            severity: Severity::Warning,
            line: None,
            column: None,
            message: "hm".into(),
        };
        assert_eq!(w.label(), "warning  hm");
    }

    #[test]
    fn log_is_bounded() {
        let mut b = BottomPanel::default();
        for i in 0..(MAX_LOG + 10) {
            b.log(format!("{i}"));
        }
        assert_eq!(b.log_lines().len(), MAX_LOG);
        assert!(b.log_lines()[0].ends_with("  10"));
    }
}
