//! Reading CalculiX results (`.frd`) back, and the result CSV.
//!
//! The ASCII `.frd` layout (CalculiX 2.20, its manual's "Result Format" chapter):
//!
//! ```text
//!     2C ... <fmt>            node block; fmt 0/1 = ASCII (I5 / I10 ids), 2 = binary
//!  -1<id><x><y><z>            one record per node: id I5 or I10, values E12.5
//!  -3                         end of block
//!     1PSTEP  <n> <inc> <step>
//!   100C ... <fmt>            result block
//!  -4  DISP  4  1             block name
//!  -5  D1 ...                 one line per component
//!  -1<id><v1><v2>...          values, E12.5, no separators (`2.4E-02-5.3E+00`)
//!  -2<values>                 continuation of the previous record
//!  -3
//! ```
//!
//! Values are fixed-width columns: splitting on whitespace would merge
//! `2.42858E-02-5.31146E+00`, so records are sliced. The last `DISP` block
//! (the last increment) is the displacement.

use std::collections::BTreeMap;
use std::io::{BufRead, BufReader};
use std::path::Path;

/// Nodes and displacements from a `.frd`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FrdResult {
    /// Node id and undeformed position (6 significant digits in the file).
    pub nodes: Vec<(u32, [f64; 3])>,
    /// Node id and displacement (mm), ascending id, from the last `DISP` block.
    pub displacements: Vec<(u32, [f64; 3])>,
}

/// Why a result file could not be read.
#[derive(Debug, thiserror::Error)]
pub enum FrdError {
    /// The file could not be read or written (the OS error is part of the
    /// message, not a chained source, so it is printed once).
    #[error("{path}: {err}")]
    Io {
        /// The file.
        path: String,
        /// The OS error.
        err: std::io::Error,
    },
    /// A line is not what the format says.
    #[error("{path}{}: {message}", line_place(.line))]
    Parse {
        /// The file.
        path: String,
        /// 1-based line; 0 where the fault is no one line's (a node that
        /// has a result but no coordinates), and then not printed.
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// No displacement block.
    #[error("{0}: no DISP block (did ccx fail, or does the deck lack *NODE FILE / U?)")]
    NoDisplacement(String),
}

/// `:LINE` for a known line, nothing for 0 (`path:0:` reads as a place).
fn line_place(line: &usize) -> String {
    if *line > 0 {
        format!(":{line}")
    } else {
        String::new()
    }
}

fn io_err(path: &Path, err: std::io::Error) -> FrdError {
    FrdError::Io {
        path: path.display().to_string(),
        err,
    }
}

/// `(id, values)` of a ` -1` / ` -2` record: id width 5 (fmt 0) or 10.
fn record(line: &str, wide: bool) -> Result<(Option<u32>, Vec<f64>), String> {
    let b = line.as_bytes();
    let idw = if wide { 10 } else { 5 };
    if b.len() < 3 + idw {
        return Ok((None, Vec::new()));
    }
    let id_txt = line.get(3..3 + idw).ok_or("not ASCII")?.trim();
    let id = if id_txt.is_empty() {
        None
    } else {
        Some(
            id_txt
                .parse::<u32>()
                .map_err(|e| format!("node id \"{id_txt}\": {e}"))?,
        )
    };
    let body = line.get(3 + idw..).ok_or("not ASCII")?.trim_end();
    let mut vals = Vec::new();
    let mut k = 0;
    while k < body.len() {
        let f = body
            .get(k..(k + 12).min(body.len()))
            .ok_or("not ASCII")?
            .trim();
        if !f.is_empty() {
            vals.push(
                f.parse::<f64>()
                    .map_err(|e| format!("value \"{f}\": {e}"))?,
            );
        }
        k += 12;
    }
    Ok((id, vals))
}

/// The format flag at the end of a `2C` / `100C` header (1 when absent).
fn fmt_flag(line: &str) -> i32 {
    line.split_whitespace()
        .last()
        .and_then(|t| t.parse().ok())
        .unwrap_or(1)
}

/// Read an ASCII `.frd`: node coordinates and the last `DISP` block.
pub fn read_frd(path: &Path) -> Result<FrdResult, FrdError> {
    let file = std::fs::File::open(path).map_err(|e| io_err(path, e))?;
    let name = path.display().to_string();
    let perr = |line: usize, message: String| FrdError::Parse {
        path: name.clone(),
        line,
        message,
    };
    #[derive(PartialEq)]
    enum State {
        Idle,
        Nodes,
        Result,
    }
    let mut state = State::Idle;
    let mut wide = true;
    let mut nodes: BTreeMap<u32, [f64; 3]> = BTreeMap::new();
    let mut block_name = String::new();
    let mut block: BTreeMap<u32, Vec<f64>> = BTreeMap::new();
    let mut last: Option<u32> = None;
    let mut disp: Option<BTreeMap<u32, Vec<f64>>> = None;
    for (n, line) in BufReader::new(file).split(b'\n').enumerate() {
        let raw = line.map_err(|e| io_err(path, e))?;
        let line = String::from_utf8_lossy(&raw);
        let line = line.trim_end_matches('\r');
        let ln = n + 1;
        match state {
            State::Idle => {
                if line.starts_with("    2C") || line.starts_with("  100C") {
                    let f = fmt_flag(line);
                    if f >= 2 {
                        return Err(perr(ln, "binary .frd is not supported; CalculiX writes ASCII unless asked otherwise".into()));
                    }
                    wide = f == 1;
                    if line.starts_with("    2C") {
                        state = State::Nodes;
                    } else {
                        state = State::Result;
                        block_name.clear();
                        block.clear();
                        last = None;
                    }
                }
            }
            _ if line.starts_with(" -3") => {
                if state == State::Result && block_name.eq_ignore_ascii_case("DISP") {
                    disp = Some(std::mem::take(&mut block));
                }
                state = State::Idle;
            }
            State::Nodes => {
                if line.starts_with(" -1") {
                    let (id, v) = record(line, wide).map_err(|m| perr(ln, m))?;
                    match (id, v.as_slice()) {
                        (Some(id), [x, y, z, ..]) => {
                            nodes.insert(id, [*x, *y, *z]);
                        }
                        _ => {
                            return Err(perr(
                                ln,
                                "node record without id and three coordinates".into(),
                            ));
                        }
                    }
                }
            }
            State::Result => {
                if let Some(rest) = line.strip_prefix(" -4") {
                    block_name = rest.split_whitespace().next().unwrap_or("").to_string();
                } else if line.starts_with(" -1") {
                    let (id, v) = record(line, wide).map_err(|m| perr(ln, m))?;
                    let id =
                        id.ok_or_else(|| perr(ln, "result record without a node id".into()))?;
                    block.insert(id, v);
                    last = Some(id);
                } else if line.starts_with(" -2") {
                    let (_, v) = record(line, wide).map_err(|m| perr(ln, m))?;
                    if let Some(vals) = last.and_then(|id| block.get_mut(&id)) {
                        vals.extend(v);
                    }
                }
            }
        }
    }
    let disp = disp.ok_or(FrdError::NoDisplacement(name.clone()))?;
    let mut displacements = Vec::with_capacity(disp.len());
    for (id, v) in disp {
        if v.len() < 3 {
            return Err(perr(
                0,
                format!("node {id}: DISP record has {} values, expected 3", v.len()),
            ));
        }
        displacements.push((id, [v[0], v[1], v[2]]));
    }
    Ok(FrdResult {
        nodes: nodes.into_iter().collect(),
        displacements,
    })
}

/// Exact node coordinates from the `*NODE` block(s) of an `.inp`.
pub fn read_inp_nodes(path: &Path) -> Result<BTreeMap<u32, [f64; 3]>, FrdError> {
    let text = std::fs::read_to_string(path).map_err(|e| io_err(path, e))?;
    let mut out = BTreeMap::new();
    let mut on = false;
    for (n, raw) in text.lines().enumerate() {
        let s = raw.trim();
        if s.is_empty() || s.starts_with("**") {
            continue;
        }
        if s.starts_with('*') {
            let kw: String = s
                .to_ascii_uppercase()
                .chars()
                .filter(|c| !c.is_whitespace())
                .collect();
            on = kw.starts_with("*NODE")
                && !["*NODEPRINT", "*NODEFILE", "*NODEOUTPUT"]
                    .iter()
                    .any(|k| kw.starts_with(k));
            continue;
        }
        if on {
            let f: Vec<&str> = s.split(',').map(str::trim).collect();
            let bad = || FrdError::Parse {
                path: path.display().to_string(),
                line: n + 1,
                message: format!("node line \"{s}\": expected id, x, y, z"),
            };
            if f.len() < 4 {
                return Err(bad());
            }
            let id: u32 = f[0].parse().map_err(|_| bad())?;
            let mut p = [0.0; 3];
            for (o, t) in p.iter_mut().zip(&f[1..4]) {
                *o = t.parse().map_err(|_| bad())?;
            }
            out.insert(id, p);
        }
    }
    Ok(out)
}

/// Figures of a written result CSV.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CsvStats {
    /// Rows written.
    pub rows: usize,
    /// Largest displacement magnitude (mm).
    pub max_displacement: f64,
}

/// The result CSV's text (`node_id,x,y,z,dx,dy,dz`, one row a node with a
/// result) and its figures; nothing is written, so a deck that does not
/// match leaves no file behind.
pub fn result_csv(frd: &FrdResult, inp: Option<&Path>) -> Result<(String, CsvStats), FrdError> {
    use std::fmt::Write as _;
    let coords: BTreeMap<u32, [f64; 3]> = match inp {
        Some(p) => read_inp_nodes(p)?,
        None => frd.nodes.iter().copied().collect(),
    };
    let mut text = String::from("node_id,x,y,z,dx,dy,dz\n");
    let mut stats = CsvStats::default();
    for (id, u) in &frd.displacements {
        let p = coords.get(id).ok_or_else(|| FrdError::Parse {
            path: inp.map(|p| p.display().to_string()).unwrap_or_default(),
            line: 0,
            message: format!(
                "node {id} has a result but no coordinates (is this the deck that was run?)"
            ),
        })?;
        let _ = writeln!(
            text,
            "{id},{},{},{},{},{},{}",
            p[0], p[1], p[2], u[0], u[1], u[2]
        );
        stats.rows += 1;
        stats.max_displacement = stats
            .max_displacement
            .max((u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt());
    }
    Ok((text, stats))
}

/// Write `node_id,x,y,z,dx,dy,dz`, one row per node with a result, ascending
/// id. Coordinates come from `inp`'s `*NODE` block when given (exact), else
/// from the `.frd` (6 significant digits).
pub fn write_result_csv(
    frd: &FrdResult,
    inp: Option<&Path>,
    out: &Path,
) -> Result<CsvStats, FrdError> {
    let (text, stats) = result_csv(frd, inp)?;
    std::fs::write(out, text).map_err(|e| io_err(out, e))?;
    Ok(stats)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn records_are_sliced_not_split() {
        let (id, v) = record(" -1         3 6.69394E-01 2.42858E-02-5.31146E+00", true).unwrap();
        assert_eq!(id, Some(3));
        assert_eq!(v, vec![0.669394, 0.0242858, -5.31146]);
        let (id, v) = record(" -1    3 1.00000E+00-2.00000E+00 3.00000E+00", false).unwrap();
        assert_eq!((id, v), (Some(3), vec![1.0, -2.0, 3.0]));
    }
}
