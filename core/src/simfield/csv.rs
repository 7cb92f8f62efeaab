//! Reading nodal results from a CSV file.
//!
//! Two layouts:
//!
//! * **Header** (generic): the first line names the columns. A `node_id`
//!   (or `id`, `node`, `nodeid`) column maps each row to a mesh node by id,
//!   in any order; without it rows are nodes in `.inp` order. Every other
//!   column is a value by name, e.g. `node_id,x,y,z,dx,dy,dz`.
//! * **Headerless** (pyvcad/OpenVCAD `PointMap`): the first line is all
//!   numbers; each row is `x,y,z,u,v,w` and row *i* is node *i* of the
//!   `.inp`. The columns are exposed as `x,y,z,dx,dy,dz`. Unlike pyvcad the
//!   row count is checked.
//!
//! Every mesh node must get exactly one row; cells must be finite numbers.

use std::path::Path;

use super::SimFieldError;
use super::inp::{InpMesh, parse_id};

/// Column names of the headerless PointMap layout.
const POINTMAP: [&str; 6] = ["x", "y", "z", "dx", "dy", "dz"];

/// Names accepted for the node id column (case-insensitive).
const ID_NAMES: [&str; 4] = ["node_id", "id", "node", "nodeid"];

/// Parsed columns, each with one value per mesh node (node order), plus
/// warnings.
pub(crate) type Columns = (Vec<(String, Vec<f64>)>, Vec<String>);

/// Most value columns a results CSV may have besides the node id and x, y,
/// z: with the derived `len` and the nine coordinate variables they fill
/// the 64 expression slots a sample uses.
pub(crate) const MAX_VALUE_COLUMNS: usize = 54;

/// Reads the CSV at `path` for `mesh`.
pub(crate) fn parse(path: &Path, mesh: &InpMesh) -> Result<Columns, SimFieldError> {
    let bytes = std::fs::read(path).map_err(|e| SimFieldError::Io {
        path: path.to_path_buf(),
        msg: e.to_string(),
    })?;
    let text = String::from_utf8_lossy(&bytes);
    let text = text.strip_prefix('\u{feff}').unwrap_or(&text);
    let csv_err = |line: usize, msg: String| SimFieldError::Csv {
        path: path.to_path_buf(),
        line,
        msg,
    };
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty());
    let Some((first_ln, first)) = lines.next() else {
        return Err(csv_err(
            1,
            "the file is empty (expected a header or x,y,z,u,v,w rows)".into(),
        ));
    };
    let first_cells = cells(first);
    let headerless = first_cells.iter().all(|c| c.parse::<f64>().is_ok());
    let mut warnings = Vec::new();

    let (names, id_col, data): (Vec<String>, Option<usize>, Vec<(usize, &str)>) = if headerless {
        let data: Vec<(usize, &str)> = std::iter::once((first_ln, first)).chain(lines).collect();
        (POINTMAP.iter().map(|s| s.to_string()).collect(), None, data)
    } else {
        let (names, id_col) = header(&first_cells, first_ln, path, &mut warnings)?;
        (names, id_col, lines.collect())
    };

    let nodes = mesh.nodes.len();
    let value_cols: Vec<usize> = (0..names.len()).filter(|&k| Some(k) != id_col).collect();
    let mut columns: Vec<Vec<f64>> = vec![vec![f64::NAN; nodes]; value_cols.len()];
    let mut row_line: Vec<usize> = vec![0; nodes]; // 0 = no row yet
    if id_col.is_none() && data.len() != nodes {
        let line = data.get(nodes).or(data.last()).map_or(first_ln, |d| d.0);
        return Err(SimFieldError::RowCount {
            path: path.to_path_buf(),
            line,
            rows: data.len(),
            nodes,
        });
    }
    for (row, &(ln, line)) in data.iter().enumerate() {
        let c = cells(line);
        if c.len() != names.len() {
            let expected = if headerless {
                "6 numbers x,y,z,u,v,w (headerless PointMap row)".to_string()
            } else {
                format!("{} cells like the header", names.len())
            };
            return Err(csv_err(
                ln,
                format!("expected {expected}, found {} cells", c.len()),
            ));
        }
        let node = match id_col {
            None => row,
            Some(k) => {
                let id = parse_id(c[k]).ok_or_else(|| SimFieldError::Number {
                    path: path.to_path_buf(),
                    line: ln,
                    column: names[k].clone(),
                    text: c[k].to_string(),
                })?;
                let Some(&i) = mesh.index_of.get(&id) else {
                    return Err(SimFieldError::UnknownCsvNode {
                        path: path.to_path_buf(),
                        line: ln,
                        id,
                    });
                };
                if row_line[i as usize] != 0 {
                    return Err(SimFieldError::DuplicateRow {
                        path: path.to_path_buf(),
                        line: ln,
                        id,
                        first_line: row_line[i as usize],
                    });
                }
                i as usize
            }
        };
        row_line[node] = ln;
        for (j, &k) in value_cols.iter().enumerate() {
            columns[j][node] = c[k]
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| SimFieldError::Number {
                    path: path.to_path_buf(),
                    line: ln,
                    column: names[k].clone(),
                    text: c[k].to_string(),
                })?;
        }
    }
    if let Some(missing) = row_line.iter().position(|&l| l == 0) {
        return Err(SimFieldError::MissingRow {
            path: path.to_path_buf(),
            id: mesh.node_ids[missing],
            inp_line: mesh.node_lines[missing],
            missing: row_line.iter().filter(|&&l| l == 0).count(),
        });
    }
    let out = value_cols
        .iter()
        .zip(columns)
        .map(|(&k, v)| (names[k].clone(), v))
        .collect();
    Ok((out, warnings))
}

/// The column names of a header line (`cells` of line `ln`) and which of
/// them is the node id; warnings for renamed columns.
fn header(
    first_cells: &[&str],
    first_ln: usize,
    path: &Path,
    warnings: &mut Vec<String>,
) -> Result<(Vec<String>, Option<usize>), SimFieldError> {
    let csv_err = |line: usize, msg: String| SimFieldError::Csv {
        path: path.to_path_buf(),
        line,
        msg,
    };
    let mut names = Vec::with_capacity(first_cells.len());
    for (k, raw) in first_cells.iter().enumerate() {
        let unquoted = raw.trim_matches('"').trim();
        let name = sanitize(unquoted, k);
        if name != unquoted {
            warnings.push(format!(
                "{}:{first_ln}: column `{raw}` is called `{name}` (names must be identifiers)",
                path.display()
            ));
        }
        if names.contains(&name) {
            return Err(csv_err(
                first_ln,
                format!("column name `{name}` appears twice"),
            ));
        }
        names.push(name);
    }
    let id_col = names
        .iter()
        .position(|n| ID_NAMES.iter().any(|id| n.eq_ignore_ascii_case(id)));
    if names.len() - id_col.is_some() as usize == 0 {
        return Err(csv_err(first_ln, "the header names no value column".into()));
    }
    let values = names
        .iter()
        .enumerate()
        .filter(|&(k, n)| Some(k) != id_col && super::coordinate_axis(n).is_none())
        .count();
    if values > MAX_VALUE_COLUMNS {
        return Err(csv_err(
            first_ln,
            format!(
                "the header names {values} value columns besides the node id and x, y, z; at most {MAX_VALUE_COLUMNS} are supported"
            ),
        ));
    }
    Ok((names, id_col))
}

/// Comma-separated cells, trimmed, without a trailing empty cell.
fn cells(line: &str) -> Vec<&str> {
    let mut c: Vec<&str> = line.split(',').map(str::trim).collect();
    if c.len() > 1 && c.last() == Some(&"") {
        c.pop();
    }
    c
}

/// A column name usable as an expression variable: characters other than
/// ASCII letters, digits and `_` become `_`; a leading digit gets a `_`
/// prefix; an empty name becomes `column<k+1>`.
fn sanitize(raw: &str, k: usize) -> String {
    if raw.is_empty() {
        return format!("column{}", k + 1);
    }
    let mut s = crate::names::underscore_other(raw, |c| c.is_ascii_alphanumeric() || c == '_');
    if s.starts_with(|c: char| c.is_ascii_digit()) {
        s.insert(0, '_');
    }
    s
}
