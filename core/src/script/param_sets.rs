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

/// Why a parameter-set file could not be read or written, or a set not
/// found.
#[derive(Debug, thiserror::Error)]
pub enum ParamSetError {
    /// The file could not be read or written.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// What the system said.
        source: std::io::Error,
    },
    /// The file is not JSON of a parameter-set file.
    #[error("{}:{line}:{column}: not a parameter-set file: {source}", path.display())]
    Format {
        /// The file.
        path: PathBuf,
        /// Line of the error (from 1).
        line: usize,
        /// Column of the error (from 1).
        column: usize,
        /// What the JSON reader said.
        source: serde_json::Error,
    },
    /// The sets could not be written as JSON.
    #[error("{}: {source}", path.display())]
    Encode {
        /// The file.
        path: PathBuf,
        /// What the JSON writer said.
        source: serde_json::Error,
    },
    /// A value of a set is not a finite number.
    #[error("{}: set \"{set}\": parameter \"{param}\" is not a number: {value}", path.display())]
    NotANumber {
        /// The file.
        path: PathBuf,
        /// The set.
        set: String,
        /// The parameter.
        param: String,
        /// The value as written (debug form).
        value: String,
    },
    /// No set of that name.
    #[error("no parameter set \"{name}\"; the file has {}", if sets.is_empty() { "none".to_owned() } else { sets.join(", ") })]
    NoSuchSet {
        /// The name asked for.
        name: String,
        /// The sets there are, in order.
        sets: Vec<String>,
    },
}

impl ParamSets {
    /// Read `path`; errors name the file and say what is wrong.
    pub fn load(path: &Path) -> Result<ParamSets, ParamSetError> {
        let io = |source| ParamSetError::Io {
            path: path.to_owned(),
            source,
        };
        let text = std::fs::read_to_string(path).map_err(io)?;
        let text = text.strip_prefix('\u{feff}').unwrap_or(&text);
        let sets: ParamSets = serde_json::from_str(text).map_err(|e| ParamSetError::Format {
            path: path.to_owned(),
            line: e.line(),
            column: e.column(),
            source: e,
        })?;
        for (name, set) in &sets.sets {
            for (p, v) in set {
                if v.number().is_none_or(|x| !x.is_finite()) {
                    return Err(ParamSetError::NotANumber {
                        path: path.to_owned(),
                        set: name.clone(),
                        param: p.clone(),
                        value: format!("{v:?}"),
                    });
                }
            }
        }
        Ok(sets)
    }

    /// Write to `path` (pretty, sets and names in order: diffs stay small).
    pub fn save(&self, path: &Path) -> Result<(), ParamSetError> {
        let mut text =
            serde_json::to_string_pretty(self).map_err(|source| ParamSetError::Encode {
                path: path.to_owned(),
                source,
            })?;
        text.push('\n');
        std::fs::write(path, text).map_err(|source| ParamSetError::Io {
            path: path.to_owned(),
            source,
        })
    }

    /// The values of set `name`, or an error listing the sets there are.
    pub fn values(&self, name: &str) -> Result<HashMap<String, f64>, ParamSetError> {
        let set = self
            .sets
            .get(name)
            .ok_or_else(|| ParamSetError::NoSuchSet {
                name: name.to_owned(),
                sets: self.sets.keys().cloned().collect(),
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
        let e = s.values("thick").unwrap_err().to_string();
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
        let e = ParamSets::load(&p).unwrap_err().to_string();
        assert!(e.contains("\"w\" is not a number"), "{e}");
        std::fs::write(&p, "{\"parameterSets\": [1, 2]").expect("write");
        let e = ParamSets::load(&p).unwrap_err().to_string();
        assert!(e.contains("bad.params.json:1:"), "{e}");
    }
}
