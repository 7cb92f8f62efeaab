//! Completion in the editor: node and function names from the language
//! reference (inserting their argument skeleton), the loaded table's
//! material names inside `id("…")`, and the design's `param` names.
//! Ctrl+Space opens the list; typing two letters of a name opens it too.
//! Up/Down choose, Enter or Tab insert, Escape closes.

use std::ops::Range;

use egui::{Key, Modifiers};
use volcad_core::script::reference;

/// Names the design offers besides the reference (updated after each
/// successful run).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Vocabulary {
    /// Material names of the design's table.
    pub materials: Vec<String>,
    /// The design's `param` names.
    pub params: Vec<String>,
}

/// One suggestion.
#[derive(Clone, Debug, PartialEq)]
pub struct Item {
    /// What the list shows.
    pub label: String,
    /// What replaces the word before the cursor.
    pub insert: String,
    /// A hint beside the label.
    pub detail: String,
}

/// The open list, if any.
#[derive(Default)]
pub struct Completion {
    /// Char range of the word being completed.
    word: Range<usize>,
    items: Vec<Item>,
    selected: usize,
}

/// What the user chose this frame.
pub enum Choice {
    /// Replace `range` (chars) with `text`.
    Insert {
        /// The word's char range.
        range: Range<usize>,
        /// The replacement.
        text: String,
    },
}

impl Choice {
    /// The edit that applies it to `text`: the replacement, with the
    /// cursor after it.
    pub fn edit(&self, text: &str) -> super::textops::Edit {
        let Choice::Insert { range, text: with } = self;
        let mut out: String = text.chars().take(range.start).collect();
        out.push_str(with);
        out.extend(text.chars().skip(range.end));
        let at = range.start + with.chars().count();
        super::textops::Edit {
            text: out,
            selection: at..at,
        }
    }
}

/// The word before `cursor` (chars): identifier characters, and whether it
/// stands inside a string literal opened by `id("` (a material name).
fn word_before(text: &str, cursor: usize) -> (Range<usize>, String, bool) {
    let chars: Vec<char> = text.chars().take(cursor).collect();
    let mut start = chars.len();
    while start > 0 && (chars[start - 1].is_alphanumeric() || chars[start - 1] == '_') {
        start -= 1;
    }
    let word: String = chars[start..].iter().collect();
    let before: String = chars[..start].iter().rev().take(4).collect();
    // Material names only inside `id("…")`, not in any string literal.
    let in_id = before.starts_with("\"(di");
    (start..chars.len(), word, in_id)
}

/// Suggestions for `word` (case-insensitive prefix).
pub fn suggestions(word: &str, in_string: bool, vocab: &Vocabulary) -> Vec<Item> {
    let w = word.to_lowercase();
    let starts = |name: &str| name.to_lowercase().starts_with(&w);
    if in_string {
        return vocab
            .materials
            .iter()
            .filter(|m| starts(m))
            .map(|m| Item {
                label: m.clone(),
                insert: m.clone(),
                detail: "material".into(),
            })
            .collect();
    }
    let mut items: Vec<Item> = reference::FUNCTIONS
        .iter()
        .filter(|f| starts(f.name))
        .map(|f| Item {
            label: f.name.to_owned(),
            insert: if f.group == reference::Group::Method {
                f.name.to_owned()
            } else {
                f.skeleton.to_owned()
            },
            detail: f.summary.to_owned(),
        })
        .collect();
    items.extend(vocab.params.iter().filter(|p| starts(p)).map(|p| Item {
        label: p.clone(),
        insert: format!("param(\"{p}\", "),
        detail: "parameter".into(),
    }));
    items
}

impl Completion {
    /// True while the list shows.
    pub fn is_open(&self) -> bool {
        !self.items.is_empty()
    }

    /// The list (for tests and drawing).
    pub fn items(&self) -> &[Item] {
        &self.items
    }

    /// The highlighted entry.
    pub fn selected(&self) -> usize {
        self.selected
    }

    /// Close the list.
    pub fn close(&mut self) {
        self.items.clear();
        self.selected = 0;
    }

    /// Keys while the list is open, taken before the editor sees them.
    pub fn keys(&mut self, ctx: &egui::Context) -> Option<Choice> {
        if !self.is_open() {
            return None;
        }
        let n = self.items.len();
        let pressed = |k| ctx.input_mut(|i| i.consume_key(Modifiers::NONE, k));
        if pressed(Key::Escape) {
            self.close();
        } else if pressed(Key::ArrowDown) {
            self.selected = (self.selected + 1) % n;
        } else if pressed(Key::ArrowUp) {
            self.selected = (self.selected + n - 1) % n;
        } else if pressed(Key::Enter) || pressed(Key::Tab) {
            let item = self.items[self.selected.min(n - 1)].clone();
            let range = self.word.clone();
            self.close();
            return Some(Choice::Insert {
                range,
                text: item.insert,
            });
        }
        None
    }

    /// Open, update or close the list after the text or cursor changed.
    /// `forced`: Ctrl+Space (any prefix, even empty); otherwise the list
    /// opens after two letters of a name typed this frame.
    pub fn update(
        &mut self,
        text: &str,
        cursor: usize,
        typed: bool,
        forced: bool,
        vocab: &Vocabulary,
    ) {
        let (range, word, in_id) = word_before(text, cursor);
        let starts_name = word.chars().next().is_some_and(|c| !c.is_ascii_digit());
        // An open list follows the word (typing, or the cursor moving
        // within it) until the word ends.
        let wanted = forced
            || (typed && word.chars().count() >= 2 && starts_name)
            || (self.is_open() && !word.is_empty());
        if !wanted || (!forced && word.is_empty()) {
            self.close();
            return;
        }
        let items = suggestions(&word, in_id, vocab);
        // An exact, complete name needs no list.
        if !forced && items.len() == 1 && items[0].label == word {
            self.close();
            return;
        }
        if items != self.items {
            self.selected = 0;
        }
        self.items = items;
        self.word = range;
    }

    /// Draw the list below `at` (screen position of the cursor).
    pub fn ui(&mut self, ctx: &egui::Context, at: egui::Pos2) {
        if !self.is_open() {
            return;
        }
        egui::Area::new(egui::Id::unique("volcad-completion"))
            .order(egui::Order::Foreground)
            .fixed_pos(at)
            .show(ctx, |ui| {
                egui::Frame::popup(ui.style()).show(ui, |ui| {
                    ui.set_max_width(460.0);
                    for (i, item) in self.items.iter().enumerate().take(12) {
                        let text = egui::RichText::new(&item.label).monospace();
                        let r = ui.selectable_label(i == self.selected, text);
                        if i == self.selected {
                            ui.weak(&item.detail);
                        }
                        if r.hovered() {
                            self.selected = i;
                        }
                    }
                });
            });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_materials_and_params_are_suggested() {
        let vocab = Vocabulary {
            materials: vec!["red".into(), "blue".into(), "VeroCyan".into()],
            params: vec!["radius".into()],
        };
        let s = suggestions("Sph", false, &vocab);
        assert_eq!(s[0].label, "Sphere");
        assert!(s[0].insert.starts_with("Sphere(Vec3("));
        assert_eq!(suggestions("ver", true, &vocab)[0].insert, "VeroCyan");
        assert!(
            suggestions("rad", false, &vocab)
                .iter()
                .any(|i| i.label == "radius")
        );
    }

    #[test]
    fn the_word_before_the_cursor_and_strings() {
        let t = "let m = default_materials();\nm.id(\"bl";
        let (r, w, s) = word_before(t, t.chars().count());
        assert_eq!((w.as_str(), s), ("bl", true));
        assert_eq!(r.end - r.start, 2);
        let (_, w, s) = word_before("Uni", 3);
        assert_eq!((w.as_str(), s), ("Uni", false));
        let t = "Mesh(\"bu";
        let (_, w, s) = word_before(t, t.chars().count());
        assert_eq!((w.as_str(), s), ("bu", false), "a path is not a material");
    }

    #[test]
    fn two_letters_open_and_escape_closes() {
        let vocab = Vocabulary::default();
        let mut c = Completion::default();
        c.update("S", 1, true, false, &vocab);
        assert!(!c.is_open());
        c.update("Sp", 2, true, false, &vocab);
        assert!(c.is_open());
        c.update("Sp ", 3, true, false, &vocab);
        assert!(!c.is_open());
        c.update("", 0, false, true, &vocab);
        assert!(c.is_open(), "Ctrl+Space lists everything");
    }
}
