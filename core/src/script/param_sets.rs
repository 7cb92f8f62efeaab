//! Named sets of parameter values kept beside a design
//! (`design.params.json`), in the layout of OpenSCAD's customizer files so
//! the idea is familiar:
//!
//! ```json
//! { "fileFormatVersion": "1",
//!   "parameterSets": { "thin": { "wall": "0.8", "radius": "12" } } }
//! ```
//!
//! Values are written as strings, as OpenSCAD does; numbers are read too.
//! `"lastSet"` (ours) names the set the studio had chosen, so reopening the
//! design brings its sliders back. The studio saves and switches sets; the
//! command line applies one with `--params FILE --set NAME`.

use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

/// A design's parameter sets.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ParamSets {
    /// OpenSCAD's version field ("1").
    #[serde(rename = "fileFormatVersion", default = "version")]
    pub file_format_version: String,
    /// Sets by name: parameter name → value.
    #[serde(rename = "parameterSets", default)]
    pub sets: BTreeMap<String, BTreeMap<String, Value>>,
    /// The set chosen last (the studio's).
    #[serde(rename = "lastSet", default, skip_serializing_if = "Option::is_none")]
    pub last_set: Option<String>,
}

fn version() -> String {
    "1".into()
}

/// A value as OpenSCAD writes it (a string) or as a number.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum Value {
    /// `"12.5"`.
    Text(String),
    /// `12.5`.
    Number(f64),
}

impl Value {
    fn number(&self) -> Option<f64> {
        match self {
            Value::Number(v) => Some(*v),
            Value::Text(s) => s.trim().parse().ok(),
        }
    }
}

/// The sets file beside `design` (`part.rhai` → `part.params.json`).
pub fn path_beside(design: &Path) -> PathBuf {
    let stem = design
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "design".into());
    design.with_file_name(format!("{stem}.params.json"))
}

impl ParamSets {
    /// Read `path`; errors name the file and say what is wrong.
    pub fn load(path: &Path) -> Result<ParamSets, String> {
        let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
        let text = text.strip_prefix('\u{feff}').unwrap_or(&text);
        let sets: ParamSets = serde_json::from_str(text).map_err(|e| {
            format!(
                "{}:{}:{}: not a parameter-set file: {e}",
                path.display(),
                e.line(),
                e.column()
            )
        })?;
        for (name, set) in &sets.sets {
            for (p, v) in set {
                if v.number().is_none_or(|x| !x.is_finite()) {
                    return Err(format!(
                        "{}: set \"{name}\": parameter \"{p}\" is not a number: {v:?}",
                        path.display()
                    ));
                }
            }
        }
        Ok(sets)
    }

    /// Write to `path` (pretty, sets and names in order: diffs stay small).
    pub fn save(&self, path: &Path) -> Result<(), String> {
        let mut text =
            serde_json::to_string_pretty(self).map_err(|e| format!("{}: {e}", path.display()))?;
        text.push('\n');
        std::fs::write(path, text).map_err(|e| format!("{}: {e}", path.display()))
    }

    /// The values of set `name`, or an error listing the sets there are.
    pub fn values(&self, name: &str) -> Result<HashMap<String, f64>, String> {
        let set = self.sets.get(name).ok_or_else(|| {
            let names: Vec<&str> = self.sets.keys().map(String::as_str).collect();
            format!(
                "no parameter set \"{name}\"; the file has {}",
                if names.is_empty() {
                    "none".to_owned()
                } else {
                    names.join(", ")
                }
            )
        })?;
        Ok(set
            .iter()
            .filter_map(|(k, v)| v.number().map(|x| (k.clone(), x)))
            .collect())
    }

    /// Store `values` as set `name` (replacing it) and make it the last set.
    pub fn store(&mut self, name: &str, values: &HashMap<String, f64>) {
        let set = values
            .iter()
            .map(|(k, v)| (k.clone(), Value::Text(v.to_string())))
            .collect();
        self.sets.insert(name.to_owned(), set);
        self.last_set = Some(name.to_owned());
        if self.file_format_version.is_empty() {
            self.file_format_version = version();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_openscad_files_and_round_trips() {
        let dir = tempfile::tempdir().expect("temp dir");
        let p = dir.path().join("part.params.json");
        std::fs::write(
            &p,
            r#"{"fileFormatVersion": "1", "parameterSets": {"thin": {"wall": "0.8", "r": 12}}}"#,
        )
        .expect("write");
        let mut s = ParamSets::load(&p).expect("load");
        let v = s.values("thin").expect("thin");
        assert_eq!(v["wall"], 0.8);
        assert_eq!(v["r"], 12.0);
        let e = s.values("thick").unwrap_err();
        assert!(
            e.contains("no parameter set \"thick\"") && e.contains("thin"),
            "{e}"
        );
        s.store("thick", &HashMap::from([("wall".to_string(), 2.5)]));
        s.save(&p).expect("save");
        let back = ParamSets::load(&p).expect("reload");
        assert_eq!(back.values("thick").expect("thick")["wall"], 2.5);
        assert_eq!(back.last_set.as_deref(), Some("thick"));
        assert_eq!(
            path_beside(Path::new("/a/part.rhai")),
            Path::new("/a/part.params.json")
        );
    }

    #[test]
    fn bad_files_say_where() {
        let dir = tempfile::tempdir().expect("temp dir");
        let p = dir.path().join("bad.params.json");
        std::fs::write(&p, "{\"parameterSets\": {\"a\": {\"w\": \"wide\"}}}").expect("write");
        let e = ParamSets::load(&p).unwrap_err();
        assert!(e.contains("\"w\" is not a number"), "{e}");
        std::fs::write(&p, "{\"parameterSets\": [1, 2]").expect("write");
        let e = ParamSets::load(&p).unwrap_err();
        assert!(e.contains("bad.params.json:1:"), "{e}");
    }
}
