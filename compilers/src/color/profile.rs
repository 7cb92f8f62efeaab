//! The colour resins of a full-colour stack, and the optional measured
//! profile (`--color-profile FILE`) that replaces their colours.
//!
//! A profile is a CSV table, one resin a row: a header `name,L,a,b`
//! (CIELAB, D50, as a spectrophotometer reports a printed swatch) or
//! `name,r,g,b` (sRGB, 0-255), then rows such as `VeroCyan,55.2,-37.1,-50.3`.
//! Blank lines and lines starting with `#` are skipped. Names are J750
//! resins; the rows are the resins the stack uses, in their order. An ICC
//! profile is not read: a PolyJet ICC output profile maps colours to ink
//! amounts for the printer's own halftoning, not to one resin per voxel,
//! and reading one needs a colour-management engine (lcms2, C); the
//! measured colour of each resin is all that the choice per voxel needs.

use std::path::Path;

use volcad_core::MaterialTable;

use super::oklab::{self, Lab};
use crate::job::ExportError;

/// One colour resin.
#[derive(Clone, Debug, PartialEq)]
pub struct Resin {
    /// The printer table's name (`VeroCyan`).
    pub name: String,
    /// The colour its pixels get in the slices: the printer table's.
    pub rgba: [u8; 4],
    /// Its colour in OKLab (the table's sRGB, or the profile's).
    pub lab: Lab,
    /// 0 (clear) to 1 (opaque): the table's alpha.
    pub opacity: f64,
}

/// The J750's colour resins, named as in its material table (its
/// `VeroPureWht` is Stratasys' VeroPureWhite): cyan, magenta, yellow,
/// black, white and clear.
// The first six names of `MaterialTable::j750`, whose test in
// core/src/material.rs writes pyvcad's whole table out as measured: two
// lists that look alike, this one what the colour export picks from.
pub const J750_COLOR_RESINS: [&str; 6] = [
    "VeroCyan",
    "VeroMgnt",
    "VeroYellow",
    "VeroBlack",
    "VeroPureWht",
    "VeroClear",
];

/// Most resins a profile may list.
pub const MAX_RESINS: usize = 16;

const FLAG: &str = "--color-profile";

/// The resin `name` from the J750 table, coloured by its sRGB there.
fn table_resin(table: &MaterialTable, name: &str) -> Option<Resin> {
    let m = table.get(table.id(name).ok()?)?;
    let rgba = m.rgba();
    Some(Resin {
        name: m.name.clone(),
        rgba,
        lab: oklab::from_srgb([0, 1, 2].map(|i| f64::from(rgba[i]) / 255.0)),
        opacity: f64::from(rgba[3]) / 255.0,
    })
}

/// The resins of a full-colour stack: the J750 colour set with the table's
/// sRGB, or the rows of `profile`.
pub fn resins(profile: Option<&Path>) -> Result<Vec<Resin>, ExportError> {
    let table = MaterialTable::j750();
    match profile {
        None => J750_COLOR_RESINS
            .iter()
            .map(|n| {
                table_resin(&table, n)
                    .ok_or_else(|| ExportError::Other(format!("the J750 table lacks {n}")))
            })
            .collect(),
        Some(path) => {
            let text = std::fs::read_to_string(path)
                .map_err(|e| ExportError::param(FLAG, format!("{}: {e}", path.display())))?;
            parse_profile(&text, &path.display().to_string(), &table)
        }
    }
}

/// Whether a profile gives CIELAB or sRGB.
#[derive(Clone, Copy)]
enum Space {
    CieLab,
    Srgb,
}

fn header_space(cols: &[&str]) -> Option<Space> {
    let c: Vec<String> = cols
        .iter()
        .map(|c| c.trim().trim_end_matches('*').to_ascii_lowercase())
        .collect();
    match c.iter().map(String::as_str).collect::<Vec<_>>().as_slice() {
        ["name", "l", "a", "b"] => Some(Space::CieLab),
        ["name", "r", "g", "b"] => Some(Space::Srgb),
        _ => None,
    }
}

/// Parse a profile's text (`file` names it in messages).
pub fn parse_profile(
    text: &str,
    file: &str,
    table: &MaterialTable,
) -> Result<Vec<Resin>, ExportError> {
    let bad = |line: usize, col: usize, msg: String| {
        ExportError::param(FLAG, format!("{file}:{line}:{col}: {msg}"))
    };
    let mut rows = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l))
        .filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'));
    let Some((hl, header)) = rows.next() else {
        return Err(bad(1, 1, "empty; write a header `name,L,a,b` (CIELAB D50) or `name,r,g,b` (sRGB 0-255) and one row per resin".into()));
    };
    let space = header_space(&header.split(',').collect::<Vec<_>>()).ok_or_else(|| {
        bad(
            hl,
            1,
            format!(
                "header {header:?}: expected `name,L,a,b` (CIELAB D50) or `name,r,g,b` (sRGB 0-255)"
            ),
        )
    })?;
    let mut out: Vec<Resin> = Vec::new();
    for (ln, line) in rows {
        let fields: Vec<&str> = line.split(',').collect();
        let col = |i: usize| 1 + fields[..i].iter().map(|f| f.len() + 1).sum::<usize>();
        if fields.len() != 4 {
            return Err(bad(
                ln,
                1,
                format!(
                    "{} fields; a row is a resin name and three numbers, e.g. VeroCyan,55.2,-37.1,-50.3",
                    fields.len()
                ),
            ));
        }
        let name = fields[0].trim();
        let mut resin = table_resin(table, name).ok_or_else(|| {
            bad(
                ln,
                col(0),
                format!(
                    "{name:?} is not a J750 resin; the colour resins are {}",
                    J750_COLOR_RESINS.join(", ")
                ),
            )
        })?;
        if out.iter().any(|r| r.name == resin.name) {
            return Err(bad(
                ln,
                col(0),
                format!("{name} is listed twice; keep one row per resin"),
            ));
        }
        let mut v = [0.0; 3];
        for i in 0..3 {
            let f = fields[i + 1].trim();
            let (lo, hi, what) = match (space, i) {
                (Space::CieLab, 0) => (0.0, 100.0, "L* (0 to 100)"),
                (Space::CieLab, _) => (-128.0, 127.0, "a* and b* (-128 to 127)"),
                (Space::Srgb, _) => (0.0, 255.0, "sRGB components (0 to 255)"),
            };
            v[i] = match f.parse::<f64>() {
                Ok(x) if x.is_finite() && (lo..=hi).contains(&x) => x,
                _ => {
                    return Err(bad(
                        ln,
                        col(i + 1),
                        format!("{f:?}: {what} must be numbers in that range"),
                    ));
                }
            };
        }
        resin.lab = match space {
            Space::CieLab => oklab::from_cielab_d50(v),
            Space::Srgb => oklab::from_srgb(v.map(|c| c / 255.0)),
        };
        out.push(resin);
    }
    if out.len() < 2 || out.len() > MAX_RESINS || out.iter().all(|r| r.opacity < 0.5) {
        return Err(bad(
            hl,
            1,
            format!(
                "{} resins: list 2 to {MAX_RESINS}, at least one of them opaque (a Vero colour, not VeroClear)",
                out.len()
            ),
        ));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn profiles_parse_and_bad_ones_name_line_and_column() {
        let t = MaterialTable::j750();
        let r = parse_profile(
            "# measured\nname,L*,a*,b*\nVeroCyan,55,-37,-50\n\nVeroPureWht,95,0,2\n",
            "p.csv",
            &t,
        )
        .unwrap();
        assert_eq!(r.len(), 2);
        assert_eq!(r[0].name, "VeroCyan");
        assert_eq!(
            r[0].rgba,
            [0, 255, 255, 255],
            "pixels keep the table's colour"
        );
        assert!((r[1].lab[0] - 0.96).abs() < 0.02, "{:?}", r[1].lab);
        let rgb = parse_profile(
            "name,r,g,b\nVeroBlack,20,20,22\nVeroClear,240,240,240\n",
            "p.csv",
            &t,
        )
        .unwrap();
        assert!(rgb[1].opacity < 0.01);
        let e = |text: &str| parse_profile(text, "p.csv", &t).unwrap_err().to_string();
        assert!(
            e("name,x,y,z\n").contains("p.csv:1:1: header"),
            "{}",
            e("name,x,y,z\n")
        );
        let m = e("name,L,a,b\nVeroCyan,55,-37,-50\nVeroCyna,50,0,0\n");
        assert!(
            m.contains("p.csv:3:1: \"VeroCyna\" is not a J750 resin"),
            "{m}"
        );
        let m = e("name,L,a,b\nVeroCyan,55,-37,-50\nVeroBlack,5,abc,0\n");
        assert!(m.contains("p.csv:3:13: \"abc\""), "{m}");
        let m = e("name,L,a,b\nVeroClear,95,0,0\n");
        assert!(m.contains("list 2 to 16"), "{m}");
    }
}
