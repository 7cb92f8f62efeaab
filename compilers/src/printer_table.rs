//! A printer's own material table: what each material of a design is
//! called and coloured in the files a printer reads.
//!
//! A J750 (PolyJet) job names its resins (`VeroCyan`, `VeroMgnt`, ...): a
//! design built on `default_materials()` (`red`, `blue`, ...) means
//! nothing to it. Each material of the design is looked up by name in the
//! printer's table, through an optional map (`--map red=VeroMgnt`); a name
//! the table lacks is refused with the resins nearest in colour.

use volcad_core::{MaterialTable, Model};

use crate::job::ExportError;

/// One material as the printer's files carry it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PrinterMaterial {
    /// The design's own name for it.
    pub design_name: String,
    /// The printer table's name.
    pub name: String,
    /// The printer table's colour.
    pub rgba: [u8; 4],
}

/// Parse `--map a=B,c=D` into pairs (design name, printer name).
pub fn parse_map(text: &str) -> Result<Vec<(String, String)>, ExportError> {
    text.split(',')
        .map(str::trim)
        .filter(|p| !p.is_empty())
        .map(|pair| match pair.split_once('=') {
            Some((a, b)) if !a.trim().is_empty() && !b.trim().is_empty() => {
                Ok((a.trim().to_owned(), b.trim().to_owned()))
            }
            _ => Err(ExportError::param(
                "--map",
                format!("{pair:?}: expected DESIGN=PRINTER, e.g. red=VeroMgnt"),
            )),
        })
        .collect()
}

/// Each material of `model` (in `Model::materials()` order) as `table`
/// names it, through `map`; an error names every material the table lacks
/// with the nearest resins by colour, and every map entry that names no
/// material of the design or no resin of the table. `printer` names the
/// table in messages ("J750").
pub fn resolve(
    model: &Model,
    table: &MaterialTable,
    map: &[(String, String)],
    printer: &str,
) -> Result<Vec<PrinterMaterial>, ExportError> {
    let design = model.table();
    let names: Vec<&str> = model
        .materials()
        .iter()
        .map(|id| design.name(*id))
        .collect();
    let mut problems = Vec::new();
    for (from, to) in map {
        if !names.contains(&from.as_str()) {
            problems.push(format!(
                "--map {from}={to}: the design has no material {from:?} (it uses {})",
                names.join(", ")
            ));
        } else if table.id(to).is_err() {
            problems.push(format!(
                "--map {from}={to}: {to:?} is not a {printer} material; nearest by colour to {from}: {}",
                nearest_by_colour(table, design_rgba(model, from), 3).join(", ")
            ));
        }
    }
    let mut out = Vec::new();
    for (id, design_name) in model.materials().iter().zip(&names) {
        let target = map
            .iter()
            .find(|(from, _)| from == design_name)
            .map_or(*design_name, |(_, to)| to.as_str());
        match table.id(target).ok().and_then(|t| table.get(t)) {
            Some(m) => out.push(PrinterMaterial {
                design_name: (*design_name).to_owned(),
                name: m.name.clone(),
                rgba: m.rgba(),
            }),
            None if map.iter().any(|(f, _)| f == design_name) => {}
            None => {
                let rgba = design.get(*id).map_or([0; 4], |m| m.rgba());
                let near = nearest_by_colour(table, rgba, 3);
                problems.push(format!(
                    "material {design_name:?} is not a {printer} material; nearest by colour: {}; map it with --map {design_name}={}",
                    near.join(", "),
                    near.first().map_or("VeroCyan", String::as_str)
                ));
            }
        }
    }
    if problems.is_empty() {
        Ok(out)
    } else {
        Err(ExportError::param("--map", problems.join("\n")))
    }
}

fn design_rgba(model: &Model, name: &str) -> [u8; 4] {
    let t = model.table();
    t.id(name)
        .ok()
        .and_then(|id| t.get(id))
        .map_or([0; 4], |m| m.rgba())
}

/// The `n` names of `table` nearest to `rgba` (squared RGB distance; ties
/// in table order).
pub fn nearest_by_colour(table: &MaterialTable, rgba: [u8; 4], n: usize) -> Vec<String> {
    let d = |m: [u8; 4]| -> i32 {
        (0..3)
            .map(|c| (i32::from(m[c]) - i32::from(rgba[c])).pow(2))
            .sum()
    };
    let mut all: Vec<(i32, usize, &str)> = table
        .materials()
        .iter()
        .enumerate()
        .skip(1)
        .map(|(i, m)| (d(m.rgba()), i, m.name.as_str()))
        .collect();
    all.sort();
    all.into_iter()
        .take(n)
        .map(|(.., s)| s.to_owned())
        .collect()
}

/// `model` relabelled with the printer's names and colours (same ids, so
/// the same voxels): what slice stacks write for `--preset j750`.
pub fn relabel(
    model: &Model,
    mats: &[PrinterMaterial],
    table: &MaterialTable,
    printer: &str,
) -> Model {
    let with: Vec<_> = model
        .materials()
        .iter()
        .zip(mats)
        .filter_map(|(id, m)| {
            let t = table.id(&m.name).ok()?;
            Some((*id, table.get(t)?.clone()))
        })
        .collect();
    let origin = format!("{} as {printer}", model.table().origin());
    model
        .clone()
        .with_table(std::sync::Arc::new(model.table().replaced(&with, &origin)))
}

/// True for the slice-stack presets that are J750 grids (`j750`,
/// `j750-hq`): choosing one also means the J750 material table.
pub fn is_j750_preset(name: &str) -> bool {
    name.eq_ignore_ascii_case("j750") || name.eq_ignore_ascii_case("j750-hq")
}

/// The J750's net build size (mm, X × Y × Z): 490 × 390 × 200 (Stratasys
/// J750 specifications, "net build size").
pub const J750_TRAY_MM: [f64; 3] = [490.0, 390.0, 200.0];

/// Refuses a part larger than the J750's tray ([`J750_TRAY_MM`]) on any
/// axis, naming both sizes, before any work.
pub fn check_j750_tray(model: &Model) -> Result<(), ExportError> {
    let size = model.bbox().size().to_array();
    // NaN sizes (an unbounded design) count as too large.
    let fits = size.iter().zip(J750_TRAY_MM).all(|(s, t)| *s <= t);
    if !fits {
        let [x, y, z] = size;
        let [tx, ty, tz] = J750_TRAY_MM;
        return Err(ExportError::param(
            "--preset",
            format!(
                "the part is {x:.1} × {y:.1} × {z:.1} mm; a J750 builds at most {tx} × {ty} × {tz} mm: scale the design down or split it"
            ),
        ));
    }
    Ok(())
}

/// `model` as a J750 stack writes it: relabelled with J750 resins through
/// `map`, or refused naming each material the table lacks with the
/// nearest resins (what `--preset j750` and the studio's J750 choice do);
/// a part larger than the tray is refused ([`check_j750_tray`]).
pub fn j750_model(
    model: &std::sync::Arc<Model>,
    map: &[(String, String)],
) -> Result<std::sync::Arc<Model>, ExportError> {
    check_j750_tray(model)?;
    let table = MaterialTable::j750();
    let mats = resolve(model, &table, map, "J750")?;
    Ok(std::sync::Arc::new(relabel(model, &mats, &table, "J750")))
}

/// The palette by code from resolved materials: 0 is void `(0, 0, 0, 0)`.
pub fn palette_of(mats: &[PrinterMaterial]) -> Vec<[u8; 4]> {
    std::iter::once([0; 4])
        .chain(mats.iter().map(|m| m.rgba))
        .collect()
}
