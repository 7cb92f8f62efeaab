//! Rhai highlighting: syntect with our grammar
//! (`assets/syntax/rhai.sublime-syntax`), through egui_extras' memoized
//! highlighter. The syntect settings are built once per process and shared
//! in one `Arc` (egui_extras memoizes by their address).

use std::sync::{Arc, OnceLock};

use egui::text::LayoutJob;
use egui_extras::syntax_highlighting::{CodeTheme, SyntectSettings, highlight_with};
use syntect::parsing::{SyntaxDefinition, SyntaxSetBuilder};

/// The grammar, compiled into the binary.
pub const RHAI_GRAMMAR: &str = include_str!("../../../assets/syntax/rhai.sublime-syntax");

/// Language name the grammar declares.
pub const LANGUAGE: &str = "Rhai";

/// The shared syntect settings: our Rhai grammar and syntect's themes.
pub fn settings() -> Arc<SyntectSettings> {
    static SETTINGS: OnceLock<Arc<SyntectSettings>> = OnceLock::new();
    SETTINGS.get_or_init(|| Arc::new(build_settings())).clone()
}

fn build_settings() -> SyntectSettings {
    let mut builder = SyntaxSetBuilder::new();
    // The grammar is ours and tested (this file's tests load it); a broken
    // grammar falls back to plain text rather than taking the studio down.
    match SyntaxDefinition::load_from_str(RHAI_GRAMMAR, true, None) {
        Ok(def) => builder.add(def),
        Err(e) => eprintln!("volcad-studio: the Rhai grammar did not load ({e}); no highlighting"),
    }
    builder.add_plain_text_syntax();
    SyntectSettings {
        ps: builder.build(),
        ts: syntect::highlighting::ThemeSet::load_defaults(),
    }
}

/// Highlight `code` as Rhai in a monospace font of `font_size` points.
pub fn layout_job(
    ctx: &egui::Context,
    style: &egui::Style,
    settings: &SyntectSettings,
    code: &str,
    font_size: f32,
) -> LayoutJob {
    let theme = if style.visuals.dark_mode {
        CodeTheme::dark(font_size)
    } else {
        CodeTheme::light(font_size)
    };
    highlight_with(ctx, style, &theme, code, LANGUAGE, settings)
}

#[cfg(test)]
mod tests {
    use super::*;
    use syntect::parsing::{ParseState, ScopeStack};

    /// Scopes of each token of one line.
    fn scopes(line: &str) -> Vec<(String, String)> {
        let set = &settings().ps;
        let syntax = set.find_syntax_by_name(LANGUAGE).expect("the Rhai grammar");
        let mut state = ParseState::new(syntax);
        let ops = state.parse_line(line, set).expect("parse");
        let mut stack = ScopeStack::new();
        let mut out = Vec::new();
        let mut last = 0;
        for (i, op) in ops {
            if i > last {
                out.push((line[last..i].to_owned(), format!("{stack:?}")));
            }
            stack.apply(&op).expect("scope op");
            last = i;
        }
        out.push((line[last..].to_owned(), format!("{stack:?}")));
        out
    }

    fn scope_of(line: &str, token: &str) -> String {
        scopes(line)
            .into_iter()
            .find(|(t, _)| t.trim() == token)
            .map(|(_, s)| s)
            .unwrap_or_else(|| panic!("no token {token:?} in {:?}", scopes(line)))
    }

    #[test]
    fn the_design_grammar_is_found_by_name_and_extension() {
        assert!(settings().ps.find_syntax_by_name(LANGUAGE).is_some());
        assert!(settings().ps.find_syntax_by_extension("rhai").is_some());
    }

    #[test]
    fn tokens_get_the_expected_scopes() {
        let l = "let bar = RectPrism(Vec3(0, 0, 0), 1.5e2, m.id(\"gray\")); // note\n";
        assert!(scope_of(l, "let").contains("storage.type"));
        assert!(scope_of(l, "RectPrism").contains("support.class"));
        assert!(scope_of(l, "1.5e2").contains("constant.numeric"));
        assert!(scope_of(l, "gray").contains("string.quoted.double"));
        assert!(scope_of(l, "// note").contains("comment.line"));
        assert!(scope_of(l, "id").contains("variable.function"));
        let f = "fn strut(a, b) { if a > b { return true; } }\n";
        assert!(scope_of(f, "strut").contains("entity.name.function"));
        assert!(scope_of(f, "if").contains("keyword.control"));
        assert!(scope_of(f, "true").contains("constant.language"));
    }

    #[test]
    fn block_comments_nest_and_templates_interpolate() {
        let set = &settings().ps;
        let syntax = set.find_syntax_by_name(LANGUAGE).unwrap();
        let mut state = ParseState::new(syntax);
        state.parse_line("/* a /* b */\n", set).unwrap();
        // Still inside the outer comment on the next line.
        let ops = state.parse_line("still */ let\n", set).unwrap();
        assert!(!ops.is_empty());
        let t = scope_of("let s = `x ${1 + 2} y`;\n", "1");
        assert!(t.contains("constant.numeric"), "{t}");
    }
}
