//! Material tables: named base materials with display colours and, for FEA
//! export, elastic properties.
//!
//! The file format is pyvcad 2.3.4's
//! (`{"materials":[{"name","r","g","b","a"}]}`) with optional mechanical fields
//! (`youngs_modulus_mpa`, `poisson_ratio`, `density_g_cm3`). Ids follow
//! pyvcad: `void` is always id 0; the other entries get ids 1..N in file
//! order (an entry named `void` is skipped). When two entries share a name the
//! later one wins, as in pyvcad.

use std::collections::HashMap;
use std::path::Path;

use serde::{Deserialize, Serialize};

/// A material id as scripts see it (pyvcad's `uint8`). Id 0 is void.
pub type MaterialId = u8;

/// The id of the empty material.
pub const VOID: MaterialId = 0;

/// One base material.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Material {
    /// The name scripts use (`materials.id("red")`), case-sensitive.
    pub name: String,
    /// Red, 0-255.
    pub r: u8,
    /// Green, 0-255.
    pub g: u8,
    /// Blue, 0-255.
    pub b: u8,
    /// Alpha (opacity), 0-255.
    pub a: u8,
    /// Young's modulus in MPa, for FEA export.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub youngs_modulus_mpa: Option<f64>,
    /// Poisson ratio, for FEA export.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub poisson_ratio: Option<f64>,
    /// Density in g/cm³.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub density_g_cm3: Option<f64>,
    /// Other names scripts may use for this material (names of an older
    /// table), resolved to this entry's id.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub aliases: Vec<String>,
}

impl Material {
    /// RGBA colour, 0-255 per channel.
    pub fn rgba(&self) -> [u8; 4] {
        [self.r, self.g, self.b, self.a]
    }
}

#[derive(Deserialize)]
struct MaterialFile {
    materials: Vec<Material>,
}

/// Why a material table could not be loaded or a name not resolved.
#[derive(Debug, Clone, thiserror::Error, PartialEq)]
pub enum MaterialError {
    /// The JSON text is not a material table.
    #[error("material table {origin}: {message}")]
    Parse {
        /// File path or `"<built-in name>"`.
        origin: String,
        /// What serde_json said, with line and column.
        message: String,
    },
    /// The table has more entries than ids fit in a byte.
    #[error("material table {origin}: {count} materials; at most 255 fit (ids are one byte)")]
    TooMany {
        /// File path or `"<built-in name>"`.
        origin: String,
        /// Entries in the file.
        count: usize,
    },
    /// A script asked for a name the table does not have.
    #[error("unknown material \"{name}\"{}", suggest(.nearest))]
    UnknownName {
        /// The name asked for.
        name: String,
        /// The closest known names, best first.
        nearest: Vec<String>,
    },
    /// A script used an id the table does not have.
    #[error("unknown material id {id}: the table has ids 0..={max}")]
    UnknownId {
        /// The id used.
        id: i64,
        /// The largest id in the table.
        max: usize,
    },
}

fn suggest(nearest: &[String]) -> String {
    if nearest.is_empty() {
        String::new()
    } else {
        format!("; did you mean {}?", nearest.join(", "))
    }
}

/// A material table: id -> material, name -> id.
#[derive(Clone, Debug, PartialEq)]
pub struct MaterialTable {
    /// Index = id; entry 0 is void.
    materials: Vec<Material>,
    by_name: HashMap<String, MaterialId>,
    origin: String,
}

/// pyvcad's default table (`configs/default.json`): red, green, blue, ...
pub(crate) const DEFAULT_JSON: &str = include_str!("../../assets/materials/default.json");
/// pyvcad's J750 table (`configs/j750.json`: 33 materials, ids and colours
/// as pyvcad 2.3.4 has them), with elastic properties for the Vero and
/// Agilus30 families and the names of our older table as aliases
/// (VeroMagenta, VeroWhite, Agilus30).
pub(crate) const J750_JSON: &str = include_str!("../../assets/materials/j750.json");

impl MaterialTable {
    /// Parse a table from JSON text; `origin` names it in errors.
    pub fn from_json(text: &str, origin: &str) -> Result<Self, MaterialError> {
        // A UTF-8 byte-order mark (some editors write one) is not JSON.
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let file: MaterialFile = serde_json::from_str(text).map_err(|e| MaterialError::Parse {
            origin: origin.to_owned(),
            message: e.to_string(),
        })?;
        let mut materials = vec![Material {
            name: "void".into(),
            r: 0,
            g: 0,
            b: 0,
            a: 0,
            youngs_modulus_mpa: None,
            poisson_ratio: None,
            density_g_cm3: None,
            aliases: Vec::new(),
        }];
        materials.extend(file.materials.into_iter().filter(|m| m.name != "void"));
        if materials.len() > 256 {
            return Err(MaterialError::TooMany {
                origin: origin.to_owned(),
                count: materials.len() - 1,
            });
        }
        let mut by_name = HashMap::new();
        for (id, m) in materials.iter().enumerate() {
            for alias in &m.aliases {
                by_name.insert(alias.clone(), id as MaterialId);
            }
        }
        for (id, m) in materials.iter().enumerate() {
            // Later entries win, as in pyvcad; a real name beats an alias.
            by_name.insert(m.name.clone(), id as MaterialId);
        }
        Ok(Self {
            materials,
            by_name,
            origin: origin.to_owned(),
        })
    }

    /// Load a table from a JSON file.
    pub fn load(path: &Path) -> Result<Self, MaterialError> {
        let text = std::fs::read_to_string(path).map_err(|e| MaterialError::Parse {
            origin: path.display().to_string(),
            message: e.to_string(),
        })?;
        Self::from_json(&text, &path.display().to_string())
    }

    /// pyvcad's default table.
    // The bundled JSON is compiled in and every test that prepares a
    // design parses it: it cannot fail in a build that passed its tests.
    #[allow(clippy::expect_used)]
    pub fn default_table() -> Self {
        Self::from_json(DEFAULT_JSON, "<default>").expect("bundled default.json is valid")
    }

    /// The J750-class table.
    // Compiled in as `default_table`'s is, and parsed by this module's tests.
    #[allow(clippy::expect_used)]
    pub fn j750() -> Self {
        Self::from_json(J750_JSON, "<j750>").expect("bundled j750.json is valid")
    }

    /// This table with the materials `with` gives in place of those at
    /// their ids (a printer's resin for each material of a design, the ids
    /// unchanged), named `origin`.
    pub fn replaced(&self, with: &[(MaterialId, Material)], origin: &str) -> Self {
        let mut materials = self.materials.clone();
        for (id, m) in with {
            if let Some(slot) = materials.get_mut(*id as usize) {
                *slot = m.clone();
            }
        }
        let by_name = materials
            .iter()
            .enumerate()
            .map(|(id, m)| (m.name.clone(), id as MaterialId))
            .collect();
        Self {
            materials,
            by_name,
            origin: origin.to_owned(),
        }
    }

    /// Where the table came from (a path or `<default>`).
    pub fn origin(&self) -> &str {
        &self.origin
    }

    /// The id of `name`, or an error listing the nearest known names.
    pub fn id(&self, name: &str) -> Result<MaterialId, MaterialError> {
        self.by_name
            .get(name)
            .copied()
            .ok_or_else(|| MaterialError::UnknownName {
                name: name.to_owned(),
                nearest: self.nearest_names(name, 3),
            })
    }

    /// The material with id `id`.
    pub fn get(&self, id: MaterialId) -> Option<&Material> {
        self.materials.get(id as usize)
    }

    /// Check that `id` is in the table.
    pub fn check_id(&self, id: i64) -> Result<MaterialId, MaterialError> {
        if id >= 0 && (id as usize) < self.materials.len() {
            Ok(id as MaterialId)
        } else {
            Err(MaterialError::UnknownId {
                id,
                max: self.materials.len() - 1,
            })
        }
    }

    /// The name of id `id` (`"?"` if absent).
    pub fn name(&self, id: MaterialId) -> &str {
        self.get(id).map(|m| m.name.as_str()).unwrap_or("?")
    }

    /// Number of ids including void.
    pub fn len(&self) -> usize {
        self.materials.len()
    }

    /// True when only void is present.
    pub fn is_empty(&self) -> bool {
        self.materials.len() <= 1
    }

    /// All materials by id (index 0 is void).
    pub fn materials(&self) -> &[Material] {
        &self.materials
    }

    /// Known names ordered by edit distance to `name` (case-insensitive), at most `n`.
    fn nearest_names(&self, name: &str, n: usize) -> Vec<String> {
        let wanted = name.to_lowercase();
        let mut scored: Vec<(usize, &str)> = self
            .materials
            .iter()
            .skip(1)
            .flat_map(|m| std::iter::once(&m.name).chain(&m.aliases))
            .map(|name| (edit_distance(&wanted, &name.to_lowercase()), name.as_str()))
            .collect();
        scored.sort();
        scored.dedup_by(|a, b| a.1 == b.1);
        scored
            .into_iter()
            .take(n)
            .map(|(_, s)| format!("\"{s}\""))
            .collect()
    }
}

/// The name of `names` nearest to `wanted` within two edits (the lowest
/// distance, then the first in order), for "did you mean" hints.
pub fn nearest_name<'a>(wanted: &str, names: impl IntoIterator<Item = &'a str>) -> Option<&'a str> {
    names
        .into_iter()
        .map(|n| (edit_distance(wanted, n), n))
        .filter(|(d, _)| *d <= 2)
        .min()
        .map(|(_, n)| n)
}

/// Levenshtein distance, for "did you mean" suggestions.
pub(crate) fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    let mut cur = vec![0; b.len() + 1];
    for (i, ca) in a.chars().enumerate() {
        cur[0] = i + 1;
        for (j, cb) in b.iter().enumerate() {
            let cost = usize::from(ca != *cb);
            cur[j + 1] = (prev[j] + cost).min(prev[j + 1] + 1).min(cur[j] + 1);
        }
        std::mem::swap(&mut prev, &mut cur);
    }
    prev[b.len()]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_ids_match_pyvcad() {
        let t = MaterialTable::default_table();
        assert_eq!(t.id("red").unwrap(), 1);
        assert_eq!(t.id("blue").unwrap(), 3);
        assert_eq!(t.id("gray").unwrap(), 11);
        assert_eq!(t.id("clear").unwrap(), 14);
        assert_eq!(t.id("support").unwrap(), 16);
        assert_eq!(t.get(0).unwrap().a, 0);
        assert_eq!(t.get(10).unwrap().rgba(), [236, 0, 240, 255]);
    }

    #[test]
    fn unknown_name_lists_nearest() {
        let t = MaterialTable::default_table();
        let e = t.id("gren").unwrap_err().to_string();
        assert!(e.contains("unknown material \"gren\""), "{e}");
        assert!(e.contains("\"green\""), "{e}");
    }

    #[test]
    fn void_is_skipped_and_duplicates_take_the_last() {
        let t = MaterialTable::from_json(
            r#"{"materials":[{"name":"a","r":1,"g":2,"b":3,"a":4},{"name":"void","r":0,"g":0,"b":0,"a":0},{"name":"a","r":9,"g":9,"b":9,"a":9}]}"#,
            "t",
        )
        .unwrap();
        assert_eq!(t.len(), 3);
        assert_eq!(t.id("a").unwrap(), 2);
        assert_eq!(t.id("void").unwrap(), 0);
    }

    /// pyvcad 2.3.4's `j750_materials`: `name(i)` for i = 1..=33 and a few
    /// `color(i)` values.
    #[test]
    fn j750_is_pyvcads_table() {
        let t = MaterialTable::j750();
        // As pyvcad 2.3.4 prints them; the first six are also
        // compilers' `J750_COLOR_RESINS`, which this test must not read.
        let names = [
            "VeroCyan",
            "VeroMgnt",
            "VeroYellow",
            "VeroBlack",
            "VeroPureWht",
            "VeroClear",
            "VeroBlue",
            "VeroGrey",
            "Agilus30Cyn",
            "Agilus30Mgn",
            "Agilus30Ylw",
            "Agilus30Blk",
            "Agilus30Wht",
            "Agilus30Clr",
            "AirVoid",
            "M.Cleanser",
            "FullCure705",
            "FullCure720",
            "SUP706",
            "Tango+",
            "TangoBlack+",
            "VeroCY-V",
            "VeroMGT-V",
            "VeroYL-V",
            "VUltraBlack",
            "VUltraWhite",
            "VerUltraClr",
            "VeroFlexCY",
            "VeroFlexMGT",
            "VeroFlexYL",
            "VeroFlexBK",
            "VeroFlexWT",
            "VeroFlexCLR",
        ];
        assert_eq!(t.len(), 34);
        for (i, n) in names.iter().enumerate() {
            assert_eq!(t.name(i as MaterialId + 1), *n);
            assert_eq!(t.id(n).unwrap(), i as MaterialId + 1);
        }
        assert_eq!(t.get(1).unwrap().rgba(), [0, 255, 255, 255]);
        assert_eq!(t.get(14).unwrap().rgba(), [244, 250, 252, 50]);
        assert_eq!(t.get(16).unwrap().rgba(), [64, 160, 255, 220]);
        // Our older names resolve to pyvcad's entries.
        assert_eq!(t.id("VeroMagenta").unwrap(), 2);
        assert_eq!(t.id("VeroWhite").unwrap(), 5);
        assert_eq!(t.id("Agilus30").unwrap(), 14);
        let e = t.id("VeroMagneta").unwrap_err().to_string();
        assert!(
            e.contains("\"VeroMagenta\"") || e.contains("\"VeroMgnt\""),
            "{e}"
        );
    }

    #[test]
    fn j750_has_elastic_properties() {
        let t = MaterialTable::j750();
        let a = t.get(t.id("Agilus30").unwrap()).unwrap();
        assert_eq!(a.youngs_modulus_mpa, Some(0.383));
        assert_eq!(a.poisson_ratio, Some(0.5));
        let v = t.get(t.id("VeroCyan").unwrap()).unwrap();
        assert_eq!(v.youngs_modulus_mpa, Some(2850.0));
    }

    #[test]
    fn bad_json_says_where() {
        let e = MaterialTable::from_json("{\"materials\": [ {\"name\": 3} ]}", "x.json")
            .unwrap_err()
            .to_string();
        assert!(e.contains("x.json") && e.contains("line 1"), "{e}");
    }
}
