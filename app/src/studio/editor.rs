//! The code editor: an egui `TextEdit` with Rhai highlighting, a line-number
//! gutter, error lines tinted with their message beside them, a find bar,
//! Tab/Shift+Tab indenting with spaces, auto-indent on Enter, undo/redo and
//! cursor jumps (from the problems list).
//!
//! Painting order: a placeholder shape is added before the `TextEdit` and
//! filled afterwards (error tint, find matches), so the tints lie under the
//! text; gutter numbers and messages are painted after, from the galley's
//! rows.

use std::ops::Range;
use std::sync::Arc;

use egui::text::{CCursor, CCursorRange};
use egui::{Color32, FontId, Id, Key, KeyboardShortcut, Modifiers, Rect, Shape, TextEdit};
use egui_extras::syntax_highlighting::SyntectSettings;

use super::completion::{Completion, Vocabulary};
use super::highlight;
use super::textops::{self, Edit};

/// Ctrl+F: open the find bar.
pub const FIND: KeyboardShortcut = KeyboardShortcut::new(Modifiers::COMMAND, Key::F);

/// A line to mark: an error (or warning) and its message.
#[derive(Clone, Debug, PartialEq)]
pub struct LineMark {
    /// 1-based line.
    pub line: usize,
    /// 1-based column, if known.
    pub column: Option<usize>,
    /// The message shown beside the line.
    pub message: String,
}

#[derive(Default)]
struct FindBar {
    open: bool,
    query: String,
    focus_query: bool,
    /// Byte range of the match last jumped to.
    current: Option<Range<usize>>,
}

/// The editor's state.
pub struct Editor {
    /// The script text.
    pub text: String,
    id: Id,
    find: FindBar,
    /// A selection (char indices) to apply on the next frame, then scroll
    /// to; the flag says whether the editor takes the focus.
    jump: Option<(Range<usize>, bool)>,
    /// Lines to tint (errors).
    pub marks: Vec<LineMark>,
    /// Input events held back to the next frame so that a key the editor
    /// handles itself (Tab, Enter) is applied after the text typed before
    /// it in the same frame (see [`Editor::order_keys`]).
    deferred: Vec<egui::Event>,
    /// The completion list.
    pub completion: Completion,
    /// Material and parameter names of the last good design.
    pub vocabulary: Vocabulary,
}

/// What happened in the editor this frame.
#[derive(Default)]
pub struct EditorOutput {
    /// The text changed.
    pub changed: bool,
}

impl Editor {
    /// An editor holding `text`.
    pub fn new(text: String) -> Self {
        Self {
            text,
            id: Id::unique("volcad-editor"),
            find: FindBar::default(),
            jump: None,
            marks: Vec::new(),
            deferred: Vec::new(),
            completion: Completion::default(),
            vocabulary: Vocabulary::default(),
        }
    }

    /// The `TextEdit`'s id (tests and focus).
    pub fn id(&self) -> Id {
        self.id
    }

    /// Replace the whole text (open, new, example): clears undo history and
    /// puts the cursor at the start.
    pub fn set_text(&mut self, ctx: &egui::Context, text: String) {
        self.text = text;
        self.marks.clear();
        self.find.current = None;
        let mut state = TextEdit::load_state(ctx, self.id).unwrap_or_default();
        state.clear_undoer();
        state
            .cursor
            .set_char_range(Some(CCursorRange::one(CCursor::new(0))));
        TextEdit::store_state(ctx, self.id, state);
    }

    /// Put the cursor at `line` (1-based) and `column`, focus the editor and
    /// scroll there on the next frame.
    pub fn goto(&mut self, line: usize, column: Option<usize>) {
        let c = textops::line_col_to_char(&self.text, line, column);
        self.jump = Some((c..c, true));
    }

    /// The 1-based line the cursor is on.
    pub fn cursor_line(&self, ctx: &egui::Context) -> usize {
        let c = self.selection(ctx).start;
        textops::line_of_char(&self.text, c)
    }

    /// Open the find bar with its field focused.
    pub fn open_find(&mut self) {
        self.find.open = true;
        self.find.focus_query = true;
    }

    /// Undo the last edit (menu; Ctrl+Z in the editor does the same).
    pub fn undo(&mut self, ctx: &egui::Context) -> bool {
        self.history_step(ctx, true)
    }

    /// Redo (menu; Ctrl+Shift+Z or Ctrl+Y in the editor).
    pub fn redo(&mut self, ctx: &egui::Context) -> bool {
        self.history_step(ctx, false)
    }

    fn history_step(&mut self, ctx: &egui::Context, undo: bool) -> bool {
        let Some(mut state) = TextEdit::load_state(ctx, self.id) else {
            return false;
        };
        let range = state.cursor.char_range().unwrap_or_default();
        let current = (range, self.text.clone());
        let mut undoer = state.undoer();
        let target = if undo {
            undoer.undo(&current)
        } else {
            undoer.redo(&current)
        }
        .cloned();
        let Some((cursor, text)) = target else {
            return false;
        };
        self.text = text;
        state.set_undoer(undoer);
        state.cursor.set_char_range(Some(cursor));
        TextEdit::store_state(ctx, self.id, state);
        true
    }

    fn selection(&self, ctx: &egui::Context) -> Range<usize> {
        TextEdit::load_state(ctx, self.id)
            .and_then(|s| s.cursor.char_range())
            .map(|r| {
                let [a, b] = r.sorted_cursors();
                a.index.0..b.index.0
            })
            .unwrap_or(0..0)
    }

    fn apply(&mut self, ctx: &egui::Context, edit: Edit) {
        self.text = edit.text;
        let mut state = TextEdit::load_state(ctx, self.id).unwrap_or_default();
        let sel = edit.selection;
        state.cursor.set_char_range(Some(CCursorRange::two(
            CCursor::new(sel.start),
            CCursor::new(sel.end),
        )));
        TextEdit::store_state(ctx, self.id, state);
    }

    /// Keys the editor handles itself while focused (before the `TextEdit`
    /// sees them): Tab, Shift+Tab, Enter.
    fn handle_keys(&mut self, ui: &egui::Ui) -> bool {
        let ctx = ui.ctx();
        if !ctx.memory(|m| m.has_focus(self.id)) {
            self.deferred.clear();
            return false;
        }
        self.order_keys(ctx);
        let sel = self.selection(ctx);
        let edit = if ctx.input_mut(|i| i.consume_key(Modifiers::SHIFT, Key::Tab)) {
            Some(textops::dedent(&self.text, sel))
        } else if ctx.input_mut(|i| i.consume_key(Modifiers::NONE, Key::Tab)) {
            Some(textops::indent(&self.text, sel))
        } else if ctx.input_mut(|i| i.consume_key(Modifiers::NONE, Key::Enter)) {
            Some(textops::newline_with_indent(&self.text, sel))
        } else {
            None
        };
        match edit {
            Some(e) => {
                self.apply(ctx, e);
                true
            }
            None => false,
        }
    }

    /// Keep the frame's input in typing order. The editor takes Tab and
    /// Enter before the `TextEdit` sees the frame's events, so when a fast
    /// typist's `b` and Enter arrive in one frame the newline would land
    /// before the `b`. Events held back last frame go first; then, if an
    /// editing event (text, paste, another key) comes before this frame's
    /// first Tab or Enter, that key and everything after it wait for the
    /// next frame, and the `TextEdit` applies the earlier ones now; so does
    /// a second Tab or Enter (one is handled a frame).
    fn order_keys(&mut self, ctx: &egui::Context) {
        let held = std::mem::take(&mut self.deferred);
        let own_key = |e: &egui::Event| {
            matches!(
                e,
                egui::Event::Key {
                    key: Key::Tab | Key::Enter,
                    pressed: true,
                    ..
                }
            )
        };
        let editing = |e: &egui::Event| {
            matches!(
                e,
                egui::Event::Text(_)
                    | egui::Event::Paste(_)
                    | egui::Event::Key { pressed: true, .. }
            )
        };
        ctx.input_mut(|i| {
            if !held.is_empty() {
                i.events.splice(0..0, held);
            }
            let Some(k) = i.events.iter().position(own_key) else {
                return;
            };
            // The editor handles one own key a frame: a second one waits too.
            let cut = if i.events[..k].iter().any(editing) {
                Some(k)
            } else {
                i.events[k + 1..]
                    .iter()
                    .position(own_key)
                    .map(|j| k + 1 + j)
            };
            if let Some(c) = cut {
                self.deferred = i.events.split_off(c);
            }
        });
        if !self.deferred.is_empty() {
            ctx.request_repaint();
        }
    }

    /// Show the editor (find bar on top when open) filling `ui`.
    /// `label` names the editor for accessibility (the file name above it).
    pub fn ui(
        &mut self,
        ui: &mut egui::Ui,
        settings: &Arc<SyntectSettings>,
        font_size: f32,
        label: Id,
    ) -> EditorOutput {
        let mut out = EditorOutput::default();
        if ui.input_mut(|i| i.consume_shortcut(&FIND)) {
            self.open_find();
        }
        if self.find.open {
            self.find_bar_ui(ui);
        }
        let focused = ui.ctx().memory(|m| m.has_focus(self.id));
        if focused && let Some(choice) = self.completion.keys(ui.ctx()) {
            let edit = choice.edit(&self.text);
            self.apply(ui.ctx(), edit);
            out.changed = true;
        }
        let forced = focused && ui.input_mut(|i| i.consume_key(Modifiers::COMMAND, Key::Space));
        out.changed |= self.handle_keys(ui);

        // A jump that takes the focus waits out a frame with a click (the
        // click elsewhere would take the focus away again in this frame).
        let defer = matches!(self.jump, Some((_, true))) && ui.input(|i| i.pointer.any_click());
        if defer {
            ui.ctx().request_repaint();
        }
        if let Some((sel, focus)) = self.jump.clone().filter(|_| !defer) {
            let mut state = TextEdit::load_state(ui.ctx(), self.id).unwrap_or_default();
            state.cursor.set_char_range(Some(CCursorRange::two(
                CCursor::new(sel.start),
                CCursor::new(sel.end),
            )));
            TextEdit::store_state(ui.ctx(), self.id, state);
            if focus {
                ui.memory_mut(|m| m.request_focus(self.id));
            }
        }

        let font = FontId::monospace(font_size);
        let matches = if self.find.open {
            textops::find_all(&self.text, &self.find.query)
        } else {
            Vec::new()
        };
        egui::ScrollArea::both()
            .id_salt("editor-scroll")
            .auto_shrink([false, false])
            .show(ui, |ui| {
                ui.horizontal_top(|ui| {
                    let digits = self.text.lines().count().max(1).to_string().len().max(3);
                    let char_w = ui.fonts_mut(|f| f.glyph_width(&font, '0'));
                    let gutter_w = char_w * digits as f32 + 12.0;
                    let (gutter, _) =
                        ui.allocate_exact_size(egui::vec2(gutter_w, 1.0), egui::Sense::hover());
                    let under_text = ui.painter().add(Shape::Noop);
                    let mut layouter = |ui: &egui::Ui, buf: &dyn egui::TextBuffer, _wrap: f32| {
                        let mut job = highlight::layout_job(
                            ui.ctx(),
                            ui.style(),
                            settings,
                            buf.as_str(),
                            font_size,
                        );
                        job.wrap.max_width = f32::INFINITY;
                        ui.fonts_mut(|f| f.layout_job(job))
                    };
                    let rows = (ui.available_height() / ui.fonts_mut(|f| f.row_height(&font)))
                        .max(4.0) as usize;
                    let output = TextEdit::multiline(&mut self.text)
                        .id(self.id)
                        .code_editor()
                        .font(font.clone())
                        .frame(egui::Frame::NONE)
                        .desired_width(f32::INFINITY)
                        .desired_rows(rows)
                        .layouter(&mut layouter)
                        .show(ui);
                    out.changed |= output.response.changed();
                    let response = output.response.response.clone().labelled_by(label);
                    self.complete_and_explain(ui, &output, &response, forced);
                    let lines = line_rects(&output.galley, output.galley_pos);
                    let right = ui.clip_rect().right().max(output.response.rect.right());
                    let tints = self.tints(
                        ui.visuals(),
                        &output,
                        &lines,
                        gutter.left()..=right,
                        &matches,
                    );
                    ui.painter().set(under_text, Shape::Vec(tints));
                    self.paint_gutter_and_messages(ui, gutter, &lines, &font);
                    if !defer
                        && self.jump.take().is_some()
                        && let Some(range) = output.cursor_range
                    {
                        let r = output
                            .galley
                            .pos_from_cursor(range.primary)
                            .translate(output.galley_pos.to_vec2());
                        ui.scroll_to_rect(r.expand(font_size * 2.0), Some(egui::Align::Center));
                    }
                });
            });
        out
    }

    /// What is drawn under the text: the marked lines across `x` (the gutter
    /// to the right edge), and the find bar's `matches` (the current one
    /// brighter).
    fn tints(
        &self,
        visuals: &egui::Visuals,
        output: &egui::text_edit::TextEditOutput,
        lines: &[Rect],
        x: std::ops::RangeInclusive<f32>,
        matches: &[Range<usize>],
    ) -> Vec<Shape> {
        let mut tints = Vec::new();
        for mark in &self.marks {
            if let Some(r) = lines.get(mark.line.saturating_sub(1)) {
                let full = Rect::from_x_y_ranges(x.clone(), r.y_range());
                tints.push(Shape::rect_filled(
                    full,
                    0.0,
                    visuals.error_fg_color.gamma_multiply(0.18),
                ));
            }
        }
        for m in matches {
            let current = self.find.current.as_ref() == Some(m);
            let at = |byte: usize| {
                output
                    .galley
                    .pos_from_cursor(CCursor::new(textops::byte_to_char(&self.text, byte)))
            };
            let (a, b) = (at(m.start), at(m.end));
            let rect = Rect::from_min_max(a.min, egui::pos2(b.max.x, a.max.y))
                .translate(output.galley_pos.to_vec2());
            let color = if current {
                Color32::from_rgb(255, 170, 0)
            } else {
                visuals.warn_fg_color
            };
            tints.push(Shape::rect_filled(
                rect,
                2.0,
                color.gamma_multiply(if current { 0.55 } else { 0.3 }),
            ));
        }
        tints
    }

    /// After the text was laid out: update and draw the completion list
    /// at the cursor, and explain the name under the mouse.
    fn complete_and_explain(
        &mut self,
        ui: &egui::Ui,
        output: &egui::text_edit::TextEditOutput,
        response: &egui::Response,
        forced: bool,
    ) {
        let focused = ui.ctx().memory(|m| m.has_focus(self.id));
        match output.cursor_range.filter(|_| focused) {
            Some(range) => {
                let cursor = range.primary.index.0;
                let typed = output.response.changed();
                if typed || forced || self.completion.is_open() {
                    self.completion
                        .update(&self.text, cursor, typed, forced, &self.vocabulary);
                }
                let at = output
                    .galley
                    .pos_from_cursor(range.primary)
                    .translate(output.galley_pos.to_vec2());
                self.completion.ui(ui.ctx(), at.left_bottom());
            }
            None => self.completion.close(),
        }
        if let Some(p) = response.hover_pos() {
            let c = output.galley.cursor_from_pos(p - output.galley_pos);
            let word = textops::word_at(&self.text, c.index.0);
            if let Some(f) = volcad_core::script::reference::lookup(&word) {
                response.clone().on_hover_ui_at_pointer(|ui| {
                    super::reference::entry_ui(ui, f);
                });
            }
        }
    }

    fn paint_gutter_and_messages(
        &self,
        ui: &egui::Ui,
        gutter: Rect,
        lines: &[Rect],
        font: &FontId,
    ) {
        let painter = ui.painter();
        let visuals = ui.visuals();
        let dim = visuals.weak_text_color();
        for (i, r) in lines.iter().enumerate() {
            if !ui.clip_rect().y_range().intersects(r.y_range()) {
                continue;
            }
            let marked = self.marks.iter().any(|m| m.line == i + 1);
            let color = if marked { visuals.error_fg_color } else { dim };
            painter.text(
                egui::pos2(gutter.right() - 6.0, r.top()),
                egui::Align2::RIGHT_TOP,
                (i + 1).to_string(),
                font.clone(),
                color,
            );
        }
        for mark in &self.marks {
            let Some(r) = lines.get(mark.line.saturating_sub(1)) else {
                continue;
            };
            let first = mark.message.lines().next().unwrap_or_default();
            let pos = egui::pos2(r.right() + font.size * 2.0, r.top());
            painter.text(
                pos,
                egui::Align2::LEFT_TOP,
                format!("◀ {first}"),
                font.clone(),
                visuals.error_fg_color,
            );
        }
    }

    fn find_bar_ui(&mut self, ui: &mut egui::Ui) {
        let mut go: Option<bool> = None;
        ui.horizontal(|ui| {
            let label = ui.label("Find:").id;
            let field = ui.make_persistent_id("find-query");
            // Enter and Escape are taken before the field sees them (a
            // single-line field would give up the focus on Enter).
            if ui.memory(|m| m.has_focus(field)) {
                if ui.input_mut(|i| i.consume_key(Modifiers::SHIFT, Key::Enter)) {
                    go = Some(true);
                } else if ui.input_mut(|i| i.consume_key(Modifiers::NONE, Key::Enter)) {
                    go = Some(false);
                } else if ui.input_mut(|i| i.consume_key(Modifiers::NONE, Key::Escape)) {
                    self.find.open = false;
                }
            }
            let resp = ui
                .add(
                    egui::TextEdit::singleline(&mut self.find.query)
                        .id(field)
                        .desired_width(180.0),
                )
                .labelled_by(label);
            if std::mem::take(&mut self.find.focus_query) {
                resp.request_focus();
            }
            if resp.changed() {
                self.find.current = None;
            }
            let n = textops::find_all(&self.text, &self.find.query).len();
            if ui
                .button("Prev")
                .on_hover_text("Previous match (Shift+Enter)")
                .clicked()
            {
                go = Some(true);
            }
            if ui
                .button("Next")
                .on_hover_text("Next match (Enter, F3)")
                .clicked()
            {
                go = Some(false);
            }
            ui.label(match n {
                0 if self.find.query.is_empty() => String::new(),
                0 => "no matches".into(),
                1 => "1 match".into(),
                n => format!("{n} matches"),
            });
            if ui.button("Close").on_hover_text("Close (Esc)").clicked() {
                self.find.open = false;
            }
        });
        if ui.input_mut(|i| i.consume_key(Modifiers::NONE, Key::F3)) {
            go = Some(ui.input(|i| i.modifiers.shift));
        }
        if let Some(backwards) = go {
            self.find_next(ui.ctx(), backwards);
        }
    }

    /// Select the next (or previous) match of the find query and scroll to it.
    pub fn find_next(&mut self, ctx: &egui::Context, backwards: bool) -> Option<Range<usize>> {
        let matches = textops::find_all(&self.text, &self.find.query);
        let from = match &self.find.current {
            Some(m) if backwards => m.start,
            Some(m) => m.start + 1,
            None => textops::char_to_byte(&self.text, self.selection(ctx).start),
        };
        let i = textops::next_match(&matches, from, backwards)?;
        let m = matches[i].clone();
        self.find.current = Some(m.clone());
        let (a, b) = (
            textops::byte_to_char(&self.text, m.start),
            textops::byte_to_char(&self.text, m.end),
        );
        // The find field keeps the focus (Enter again finds the next one).
        self.jump = Some((a..b, false));
        Some(m)
    }

    /// Set the find query (the find bar's field; tests).
    pub fn set_find_query(&mut self, query: &str) {
        self.find.open = true;
        self.find.query = query.to_owned();
        self.find.current = None;
    }
}

/// The screen rect of each logical line (1 row each: the editor never wraps).
fn line_rects(galley: &egui::Galley, pos: egui::Pos2) -> Vec<Rect> {
    let mut out = Vec::new();
    let mut current: Option<Rect> = None;
    for row in &galley.rows {
        let r = row.rect().translate(pos.to_vec2());
        current = Some(current.map_or(r, |c| c.union(r)));
        if row.ends_with_newline {
            out.extend(current.take());
        }
    }
    out.extend(current);
    out
}
