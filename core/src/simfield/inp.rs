//! Reading the tetrahedral mesh of an Abaqus / CalculiX `.inp` deck.
//!
//! Only `*NODE` and `*ELEMENT` blocks are read; every other keyword block
//! (`*NSET`, `*ELSET`, `*MATERIAL`, `*STEP`, `*NODE PRINT`, …) is skipped, so
//! a complete analysis deck loads as well as a bare mesh. Keywords and
//! parameters are case-insensitive, `**` starts a comment line, data lines
//! are comma-separated and an element may continue on the next line after a
//! trailing comma (Abaqus Keywords Reference, "Input syntax rules").
//!
//! Tetrahedra: `C3D4*` (4 nodes) and `C3D10*` (10 nodes, of which the first
//! four are the corners; the field is then interpolated linearly). Other
//! element types are skipped with a warning. Node ids may come in any order
//! and need not be contiguous; nodes are kept in file order, which is the
//! row order of a headerless PointMap CSV.

use std::collections::HashMap;
use std::path::Path;

use glam::DVec3;

use super::SimFieldError;

/// The mesh part of a deck.
#[derive(Debug, Default)]
pub(crate) struct InpMesh {
    /// Node ids in file order.
    pub node_ids: Vec<u64>,
    /// Node positions in file order.
    pub nodes: Vec<DVec3>,
    /// 1-based line of each node.
    pub node_lines: Vec<usize>,
    /// Node id → index into `nodes`.
    pub index_of: HashMap<u64, u32>,
    /// Tetrahedra as node indices (corner nodes only).
    pub tets: Vec<[u32; 4]>,
    /// Element id of each tetrahedron.
    pub elem_ids: Vec<u64>,
    /// 1-based (first) line of each tetrahedron.
    pub elem_lines: Vec<usize>,
    /// Skipped element types and the like.
    pub warnings: Vec<String>,
}

/// What the current keyword block holds.
enum Block {
    /// Not in a block we read.
    Skip,
    /// `*NODE` data lines.
    Node,
    /// `*ELEMENT` with `n` nodes per element (corner nodes are the first 4).
    Tets { n: usize },
    /// `*ELEMENT` of a type we ignore.
    Ignored { kind: String },
}

/// Raw elements: (element id, corner node ids, line).
type RawTets = Vec<(u64, [u64; 4], usize)>;

/// A syntax error at 1-based `line` of `path`.
fn inp_err(path: &Path, line: usize, msg: String) -> SimFieldError {
    SimFieldError::Inp {
        path: path.to_path_buf(),
        line,
        msg,
    }
}

/// Parses the deck at `path`: keyword lines switch the block, data lines
/// of `*NODE` and `*ELEMENT` blocks are read, and the elements' node ids
/// are resolved once every node is known.
pub(crate) fn parse(path: &Path) -> Result<InpMesh, SimFieldError> {
    let bytes = std::fs::read(path).map_err(|e| SimFieldError::Io {
        path: path.to_path_buf(),
        msg: e.to_string(),
    })?;
    let text = String::from_utf8_lossy(&bytes);
    let err = |line: usize, msg: String| inp_err(path, line, msg);
    let mut mesh = InpMesh::default();
    let mut raw: RawTets = Vec::new();
    let mut ignored: Vec<(String, usize)> = Vec::new();
    let mut c3d10 = 0usize;
    let mut block = Block::Skip;
    // An element whose node list continues on the next line.
    let mut pending: Vec<String> = Vec::new();
    let mut pending_line = 0;
    // The current data line's fields (one buffer for every line).
    let mut fields: Vec<&str> = Vec::new();

    for (i, raw_line) in text.lines().enumerate() {
        let ln = i + 1;
        let line = raw_line.trim();
        if line.is_empty() || line.starts_with("**") {
            continue;
        }
        if let Some(keyword_line) = line.strip_prefix('*') {
            if !pending.is_empty() {
                return Err(err(
                    pending_line,
                    format!(
                        "element `{}` ends with a comma but no continuation line follows",
                        pending.join(",")
                    ),
                ));
            }
            block = keyword_block(keyword_line, path, ln, &mut mesh.warnings)?;
            continue;
        }
        match &block {
            Block::Skip => {}
            Block::Node => {
                split_fields_into(line, &mut fields);
                node_line(&mut mesh, &fields, line, path, ln)?;
            }
            Block::Tets { n } => {
                let n = *n;
                split_fields_into(line, &mut fields);
                if pending.is_empty() {
                    pending_line = ln;
                }
                let parsed = if pending.is_empty() && !(fields.len() < n + 1 && line.ends_with(','))
                {
                    // One line (most elements): from the borrowed fields.
                    element(&fields, n)
                } else {
                    // Continued over lines: owned fields until complete.
                    pending.extend(fields.iter().map(|f| f.to_string()));
                    if pending.len() < n + 1 && line.ends_with(',') {
                        continue; // continuation line follows
                    }
                    let owned = std::mem::take(&mut pending);
                    element(&owned.iter().map(String::as_str).collect::<Vec<_>>(), n)
                };
                let (id, corners) = parsed.map_err(|m| err(pending_line, m))?;
                if n == 10 {
                    c3d10 += 1;
                }
                raw.push((id, corners, pending_line));
            }
            Block::Ignored { kind } => match ignored.iter_mut().find(|(k, _)| k == kind) {
                Some((_, count)) => *count += 1,
                None => ignored.push((kind.clone(), 1)),
            },
        }
    }
    if !pending.is_empty() {
        return Err(err(
            pending_line,
            "the last element ends with a comma but the file ends".into(),
        ));
    }
    finish(mesh, raw, &ignored, c3d10, path)
}

/// The block a keyword line (without its `*`) at line `ln` opens; a
/// warning for what is not followed.
fn keyword_block(
    keyword_line: &str,
    path: &Path,
    ln: usize,
    warnings: &mut Vec<String>,
) -> Result<Block, SimFieldError> {
    let mut parts = keyword_line.split(',');
    let keyword = parts
        .next()
        .unwrap_or("")
        .split_whitespace()
        .collect::<Vec<_>>()
        .join(" ")
        .to_ascii_uppercase();
    let param = |name: &str| {
        keyword_line.split(',').skip(1).find_map(|p| {
            let (k, v) = p.split_once('=')?;
            k.trim()
                .eq_ignore_ascii_case(name)
                .then(|| v.trim().to_ascii_uppercase())
        })
    };
    Ok(match keyword.as_str() {
        "NODE" => Block::Node,
        "ELEMENT" => {
            let Some(kind) = param("TYPE") else {
                return Err(inp_err(
                    path,
                    ln,
                    "`*ELEMENT` needs a `TYPE=` parameter (e.g. TYPE=C3D4)".into(),
                ));
            };
            if kind.starts_with("C3D4") {
                Block::Tets { n: 4 }
            } else if kind.starts_with("C3D10") {
                Block::Tets { n: 10 }
            } else {
                Block::Ignored { kind }
            }
        }
        "INCLUDE" => {
            warnings.push(format!(
                "{}:{ln}: `*INCLUDE` is not followed; put the mesh in one file",
                path.display()
            ));
            Block::Skip
        }
        _ => Block::Skip,
    })
}

/// One `*NODE` data line (`fields` of `line`, at line `ln`) into `mesh`.
fn node_line(
    mesh: &mut InpMesh,
    fields: &[&str],
    line: &str,
    path: &Path,
    ln: usize,
) -> Result<(), SimFieldError> {
    let err = |msg: String| inp_err(path, ln, msg);
    if fields.len() < 4 {
        return Err(err(format!(
            "expected a node line `id, x, y, z`, found `{line}`"
        )));
    }
    let id = parse_id(fields[0])
        .ok_or_else(|| err(format!("node id `{}` is not a positive integer", fields[0])))?;
    let mut xyz = [0.0; 3];
    for (k, f) in fields[1..4].iter().enumerate() {
        xyz[k] = f
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| {
                err(format!(
                    "node {id}: coordinate `{f}` is not a finite number"
                ))
            })?;
    }
    if let Some(&prev) = mesh.index_of.get(&id) {
        return Err(SimFieldError::DuplicateNode {
            path: path.to_path_buf(),
            line: ln,
            id,
            first_line: mesh.node_lines[prev as usize],
        });
    }
    mesh.index_of.insert(id, mesh.nodes.len() as u32);
    mesh.node_ids.push(id);
    mesh.nodes.push(DVec3::from_array(xyz));
    mesh.node_lines.push(ln);
    Ok(())
}

/// After the last line: the warnings for ignored and quadratic elements,
/// the errors for a deck without nodes or tetrahedra, and each raw
/// element's node ids resolved to node indices.
fn finish(
    mut mesh: InpMesh,
    raw: RawTets,
    ignored: &[(String, usize)],
    c3d10: usize,
    path: &Path,
) -> Result<InpMesh, SimFieldError> {
    if mesh.nodes.is_empty() {
        return Err(SimFieldError::NoNodes {
            path: path.to_path_buf(),
        });
    }
    for (kind, count) in ignored {
        mesh.warnings.push(format!(
            "{}: ignored {count} data lines of element type {kind} (only C3D4 and C3D10 tetrahedra are used)",
            path.display()
        ));
    }
    if raw.is_empty() {
        return Err(SimFieldError::NoTets {
            path: path.to_path_buf(),
            ignored: ignored
                .iter()
                .map(|(k, _)| k.clone())
                .collect::<Vec<_>>()
                .join(", "),
        });
    }
    if c3d10 > 0 {
        mesh.warnings.push(format!(
            "{}: {c3d10} C3D10 elements are interpolated linearly from their 4 corner nodes",
            path.display()
        ));
    }
    for (id, corners, line) in raw {
        let mut tet = [0u32; 4];
        for (k, node) in corners.iter().enumerate() {
            tet[k] = *mesh.index_of.get(node).ok_or(SimFieldError::UnknownNode {
                path: path.to_path_buf(),
                line,
                element: id,
                node: *node,
            })?;
        }
        mesh.tets.push(tet);
        mesh.elem_ids.push(id);
        mesh.elem_lines.push(line);
    }
    Ok(mesh)
}

/// Comma-separated fields of `line` into `out`, trimmed, without the empty
/// field a trailing comma leaves.
fn split_fields_into<'a>(line: &'a str, out: &mut Vec<&'a str>) {
    out.clear();
    out.extend(line.split(',').map(str::trim));
    if out.last() == Some(&"") {
        out.pop();
    }
}

/// An element's id and corner node ids from its fields (`id, n1, …, nn`),
/// or what is wrong with them.
fn element(fields: &[&str], n: usize) -> Result<(u64, [u64; 4]), String> {
    if fields.len() != n + 1 {
        return Err(format!(
            "expected an element line `id, n1, …, n{n}` ({} fields), found {} fields",
            n + 1,
            fields.len()
        ));
    }
    let id = parse_id(fields[0])
        .ok_or_else(|| format!("element id `{}` is not a positive integer", fields[0]))?;
    let mut corners = [0u64; 4];
    for (k, f) in fields[1..5].iter().enumerate() {
        corners[k] = parse_id(f)
            .ok_or_else(|| format!("element {id}: node id `{f}` is not a positive integer"))?;
    }
    Ok((id, corners))
}

/// A node or element id: a positive integer (`12` or `12.0`).
pub(crate) fn parse_id(s: &str) -> Option<u64> {
    s.parse::<u64>().ok().or_else(|| {
        let v = s.parse::<f64>().ok()?;
        (v.fract() == 0.0 && (0.0..1.8e19).contains(&v)).then_some(v as u64)
    })
}
