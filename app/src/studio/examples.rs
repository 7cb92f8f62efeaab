//! The Examples menu: every `assets/examples/*.rhai`, embedded at build time
//! (see `app/build.rs`), so the binary works wherever it is copied. Examples
//! that read data files (CSV, OBJ) run with their source folder as base
//! directory when it exists (a source checkout, or `assets/examples` beside
//! the binary).

use std::path::PathBuf;

include!(concat!(env!("OUT_DIR"), "/examples.rs"));

/// The graded bar, used when no examples were bundled.
pub const GRADED_BAR: &str = r#"// Graded bar: red to blue along x.
let m = default_materials();
let bar = RectPrism(Vec3(0, 0, 0), Vec3(15, 10, 5), m.id("gray"));
FGrade(["x/15+0.5", "-x/15+0.5"], [m.id("red"), m.id("blue")], true, bar)
"#;

/// A bundled example.
#[derive(Clone, Debug, PartialEq)]
pub struct Example {
    /// File name (`graded_bar.rhai`).
    pub file: &'static str,
    /// Menu title: the first comment line, else the file name in words.
    pub title: String,
    /// The script.
    pub source: &'static str,
}

/// All bundled examples (the inline graded bar if none were bundled).
pub fn all() -> Vec<Example> {
    let mut v: Vec<Example> = EMBEDDED
        .iter()
        .map(|(file, source)| Example {
            file,
            title: title(file, source),
            source,
        })
        .collect();
    if v.is_empty() {
        v.push(Example {
            file: "graded_bar.rhai",
            title: title("graded_bar.rhai", GRADED_BAR),
            source: GRADED_BAR,
        });
    }
    v
}

/// The example the studio opens with: the graded bar if bundled, else the
/// first one.
pub fn default_example() -> Example {
    let all = all();
    all.iter()
        .find(|e| e.file.contains("graded_bar"))
        .cloned()
        .unwrap_or_else(|| all[0].clone())
}

/// The bundled example called `file` (`graded_bar.rhai` or `graded_bar`).
pub fn find(file: &str) -> Option<Example> {
    all()
        .into_iter()
        .find(|e| e.file == file || e.file.trim_end_matches(".rhai") == file)
}

fn title(file: &str, source: &str) -> String {
    let first = source.lines().next().unwrap_or_default().trim();
    if let Some(c) = first.strip_prefix("//") {
        let c = c.trim_start_matches('/').trim();
        // "Graded bar: red to blue" → "Graded bar"; but a heading that only
        // says where it comes from ("Paper listing 3: a colour sheet",
        // "Lattice grading (b): per unit cell") gives way to what follows.
        let mut parts = c.splitn(2, ':');
        let head = parts.next().unwrap_or(c).trim();
        let says_what =
            |h: &str| !(h.starts_with("Paper listing") || h.starts_with("Lattice grading"));
        let c = match parts.next() {
            Some(rest) if !says_what(head) => rest,
            _ => head,
        };
        let c = c.split(['.', '—', ':']).next().unwrap_or(c).trim();
        if !c.is_empty() && c.len() <= 60 {
            let mut chars = c.chars();
            return chars
                .next()
                .map(|f| f.to_uppercase().chain(chars).collect())
                .unwrap_or_default();
        }
    }
    let stem = file.trim_end_matches(".rhai").replace(['_', '-'], " ");
    let mut chars = stem.chars();
    chars
        .next()
        .map(|c| c.to_uppercase().chain(chars).collect())
        .unwrap_or_default()
}

/// The folder examples read their data files from, when it exists: the
/// source tree's `assets/examples`, or `assets/examples` beside the binary.
pub fn base_dir() -> Option<PathBuf> {
    let source = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../assets/examples");
    let beside_exe = std::env::current_exe()
        .ok()
        .and_then(|e| e.parent().map(|p| p.join("assets/examples")));
    [Some(source), beside_exe]
        .into_iter()
        .flatten()
        .find(|p| p.is_dir())
        .map(|p| p.canonicalize().unwrap_or(p))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn there_is_always_a_default_example() {
        let e = default_example();
        assert!(e.source.contains("default_materials") || e.source.contains("materials"));
        assert!(!all().is_empty());
    }

    #[test]
    fn titles_come_from_comments_or_names() {
        assert_eq!(
            title("x.rhai", "// Graded bar: red to blue\n"),
            "Graded bar"
        );
        assert_eq!(
            title("bcc_lattice_sphere.rhai", "let m = 1;"),
            "Bcc lattice sphere"
        );
        assert_eq!(
            title(
                "s.rhai",
                "// Paper listing 3: a 12 x 12 colour calibration sheet (cyan).\n"
            ),
            "A 12 x 12 colour calibration sheet (cyan)"
        );
        for e in all() {
            assert!(!e.title.starts_with("Paper listing"), "{}", e.title);
        }
    }
}
