//! Reading `.obj` and `.stl` files into vertices and triangles.
//!
//! OBJ goes through `tobj` (polygons fan-triangulated, normals and texture
//! coordinates ignored). STL has its own reader: ASCII when the file starts
//! with `solid` and parses as ASCII; otherwise binary, whose size must be
//! exactly `84 + 50·n` bytes for the `n` triangles its header announces
//! (many binary files also start with `solid`, hence the parse-first rule).
//!
//! STL stores every triangle with its own three corners, so identical
//! positions are welded (bit-exact, `-0 = +0`) to recover the shared edges
//! that the closed-mesh test and pseudo-normals need. OBJ positions are
//! welded the same way because `tobj` gives every object its own vertex list.

use std::collections::HashMap;
use std::path::Path;

use glam::DVec3;

use super::MeshError;

/// Loads the file, dispatching on the extension. Returns welded vertices and
/// triangles (indices valid, possibly empty).
pub(crate) fn load(path: &Path) -> Result<(Vec<DVec3>, Vec<[u32; 3]>), MeshError> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase())
        .unwrap_or_default();
    let (vertices, triangles) = match ext.as_str() {
        "obj" => load_obj(path)?,
        "stl" => {
            let bytes = std::fs::read(path).map_err(|e| io_error(path, e))?;
            parse_stl(path, &bytes)?
        }
        _ => {
            return Err(MeshError::UnsupportedFormat {
                path: path.to_path_buf(),
                extension: ext,
            });
        }
    };
    Ok(weld(&vertices, &triangles))
}

fn io_error(path: &Path, e: std::io::Error) -> MeshError {
    MeshError::Io {
        path: path.to_path_buf(),
        msg: e.to_string(),
    }
}

/// Merges bit-identical positions; triangles are re-indexed.
pub(crate) fn weld(vertices: &[DVec3], triangles: &[[u32; 3]]) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let key = |v: DVec3| {
        // +0.0 and -0.0 compare equal but have different bits.
        let k = |x: f64| if x == 0.0 { 0u64 } else { x.to_bits() };
        [k(v.x), k(v.y), k(v.z)]
    };
    let mut map: HashMap<[u64; 3], u32> = HashMap::with_capacity(vertices.len());
    let mut out = Vec::with_capacity(vertices.len());
    let remap: Vec<u32> = vertices
        .iter()
        .map(|&v| {
            *map.entry(key(v)).or_insert_with(|| {
                out.push(v);
                (out.len() - 1) as u32
            })
        })
        .collect();
    let tris = triangles
        .iter()
        .map(|t| {
            [
                remap[t[0] as usize],
                remap[t[1] as usize],
                remap[t[2] as usize],
            ]
        })
        .collect();
    (out, tris)
}

type Soup = (Vec<DVec3>, Vec<[u32; 3]>);

fn load_obj(path: &Path) -> Result<Soup, MeshError> {
    // Spelled out field by field; `..Default::default()` keeps it compiling
    // when a tobj feature adds options.
    #[allow(clippy::needless_update)]
    let opts = tobj::LoadOptions {
        triangulate: true,
        single_index: false,
        ignore_points: true,
        ignore_lines: true,
        ..Default::default()
    };
    let models = match tobj::load_obj(path, &opts) {
        Ok((models, _materials)) => models,
        Err(e) => {
            if matches!(e, tobj::LoadError::OpenFileFailed) {
                // tobj drops the OS error; ask again to report it.
                if let Err(io) = std::fs::metadata(path) {
                    return Err(io_error(path, io));
                }
            }
            // tobj reports no line number: find the first offending line.
            let text = std::fs::read_to_string(path).map_err(|e| io_error(path, e))?;
            return Err(match locate_obj_problem(&text) {
                Some((line, msg)) => MeshError::Parse {
                    path: path.to_path_buf(),
                    line,
                    msg,
                },
                None => MeshError::Obj {
                    path: path.to_path_buf(),
                    msg: e.to_string(),
                },
            });
        }
    };
    let mut vertices = Vec::new();
    let mut triangles = Vec::new();
    for m in &models {
        let base = vertices.len() as u32;
        let pos = &m.mesh.positions;
        for c in pos.chunks_exact(3) {
            vertices.push(DVec3::new(c[0] as f64, c[1] as f64, c[2] as f64));
        }
        let nv = (pos.len() / 3) as u32;
        for t in m.mesh.indices.chunks_exact(3) {
            if t.iter().any(|&i| i >= nv) {
                return Err(MeshError::Obj {
                    path: path.to_path_buf(),
                    msg: format!(
                        "object `{}` has a face index past its {nv} vertices",
                        m.name
                    ),
                });
            }
            triangles.push([base + t[0], base + t[1], base + t[2]]);
        }
    }
    if let Some(bad) = vertices.iter().position(|v| !v.is_finite()) {
        let text = std::fs::read_to_string(path).map_err(|e| io_error(path, e))?;
        let line = text
            .lines()
            .enumerate()
            .filter(|(_, l)| l.trim_start().starts_with("v "))
            .nth(bad)
            .map_or(0, |(i, _)| i + 1);
        return Err(MeshError::Parse {
            path: path.to_path_buf(),
            line,
            msg: "vertex coordinate is not a finite number".into(),
        });
    }
    Ok((vertices, triangles))
}

/// Finds the first OBJ line that `tobj` would reject: a `v` line without
/// three numbers or an `f` line with fewer than three vertices or an
/// invalid/out-of-range index.
fn locate_obj_problem(text: &str) -> Option<(usize, String)> {
    let total_v = text
        .lines()
        .filter(|l| l.split_whitespace().next() == Some("v"))
        .count() as i64;
    let mut seen_v = 0i64;
    for (i, raw) in text.lines().enumerate() {
        let line = raw.split('#').next().unwrap_or("");
        let mut it = line.split_whitespace();
        match it.next() {
            Some("v") => {
                seen_v += 1;
                let coords: Vec<&str> = it.collect();
                if coords.len() < 3 || coords[..3].iter().any(|c| c.parse::<f64>().is_err()) {
                    return Some((
                        i + 1,
                        format!("expected `v x y z` with 3 numbers, found `{}`", raw.trim()),
                    ));
                }
            }
            Some("f") => {
                let refs: Vec<&str> = it.collect();
                if refs.len() < 3 {
                    return Some((
                        i + 1,
                        format!("a face needs at least 3 vertices, found `{}`", raw.trim()),
                    ));
                }
                for r in refs {
                    let idx = r.split('/').next().unwrap_or("");
                    match idx.parse::<i64>() {
                        Ok(k) if k > 0 && k <= total_v => {}
                        Ok(k) if k < 0 && -k <= seen_v => {}
                        _ => {
                            return Some((
                                i + 1,
                                format!(
                                    "face vertex `{r}` is not a valid index (1..={total_v}, or negative relative)"
                                ),
                            ));
                        }
                    }
                }
            }
            _ => {}
        }
    }
    None
}

/// Parses STL bytes (ASCII or binary, see the module docs).
pub(crate) fn parse_stl(path: &Path, bytes: &[u8]) -> Result<Soup, MeshError> {
    let starts_solid = bytes.len() >= 5 && bytes[..5].eq_ignore_ascii_case(b"solid");
    if starts_solid {
        let text = std::str::from_utf8(bytes)
            .ok()
            .filter(|t| !t.contains('\0'));
        if let Some(text) = text {
            // A text file: its ASCII error is the one to report.
            return parse_ascii_stl(path, text);
        }
    }
    parse_binary_stl(path, bytes)
}

fn parse_binary_stl(path: &Path, bytes: &[u8]) -> Result<Soup, MeshError> {
    let bad = |msg: String| MeshError::BinaryStl {
        path: path.to_path_buf(),
        msg,
    };
    if bytes.len() < 84 {
        return Err(bad(format!(
            "file has {} bytes; a binary STL needs at least 84 (80-byte header + triangle count)",
            bytes.len()
        )));
    }
    let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as usize;
    let expected = 84 + 50 * n as u64;
    if bytes.len() as u64 != expected {
        return Err(bad(format!(
            "header announces {n} triangles, i.e. 84 + 50·{n} = {expected} bytes, but the file has {} bytes \
             (not ASCII STL either: it does not start with `solid` followed by facets)",
            bytes.len()
        )));
    }
    let f =
        |o: usize| f32::from_le_bytes([bytes[o], bytes[o + 1], bytes[o + 2], bytes[o + 3]]) as f64;
    let mut vertices = Vec::with_capacity(3 * n);
    let mut triangles = Vec::with_capacity(n);
    for t in 0..n {
        let base = 84 + 50 * t + 12; // skip the stored normal
        for k in 0..3 {
            let o = base + 12 * k;
            let v = DVec3::new(f(o), f(o + 4), f(o + 8));
            if !v.is_finite() {
                return Err(bad(format!(
                    "triangle {t} (byte {o}) has a non-finite coordinate"
                )));
            }
            vertices.push(v);
        }
        let i = 3 * t as u32;
        triangles.push([i, i + 1, i + 2]);
    }
    Ok((vertices, triangles))
}

/// ASCII STL: `solid name`, then `facet normal nx ny nz / outer loop /
/// vertex x y z ×3 / endloop / endfacet`, then `endsolid name`. Keywords are
/// case-insensitive; several solids may follow each other; a loop with more
/// than three vertices is fan-triangulated.
fn parse_ascii_stl(path: &Path, text: &str) -> Result<Soup, MeshError> {
    let err = |line: usize, msg: String| MeshError::Parse {
        path: path.to_path_buf(),
        line,
        msg,
    };
    let mut vertices: Vec<DVec3> = Vec::new();
    let mut triangles = Vec::new();
    let mut in_solid = false;
    let mut in_loop = false;
    let mut loop_start = 0usize;
    let mut last_line = 0;
    for (i, raw) in text.lines().enumerate() {
        let ln = i + 1;
        last_line = ln;
        let mut it = raw.split_whitespace();
        let Some(word) = it.next() else { continue };
        match word.to_ascii_lowercase().as_str() {
            "solid" if !in_solid => in_solid = true,
            "endsolid" if in_solid && !in_loop => in_solid = false,
            "facet" if in_solid && !in_loop => {
                let ok = it.next().is_some_and(|w| w.eq_ignore_ascii_case("normal"));
                let nums: Vec<&str> = it.collect();
                if !ok || nums.len() != 3 || nums.iter().any(|s| s.parse::<f64>().is_err()) {
                    return Err(err(
                        ln,
                        format!("expected `facet normal nx ny nz`, found `{}`", raw.trim()),
                    ));
                }
            }
            "outer" if in_solid && !in_loop => {
                if !it.next().is_some_and(|w| w.eq_ignore_ascii_case("loop")) {
                    return Err(err(
                        ln,
                        format!("expected `outer loop`, found `{}`", raw.trim()),
                    ));
                }
                in_loop = true;
                loop_start = vertices.len();
            }
            "vertex" if in_loop => {
                let nums: Vec<&str> = it.collect();
                let parsed: Vec<f64> = nums.iter().filter_map(|s| s.parse::<f64>().ok()).collect();
                if nums.len() != 3 || parsed.len() != 3 || parsed.iter().any(|x| !x.is_finite()) {
                    return Err(err(
                        ln,
                        format!(
                            "expected `vertex x y z` with 3 finite numbers, found `{}`",
                            raw.trim()
                        ),
                    ));
                }
                vertices.push(DVec3::new(parsed[0], parsed[1], parsed[2]));
            }
            "endloop" if in_loop => {
                let n = vertices.len() - loop_start;
                if n < 3 {
                    return Err(err(
                        ln,
                        format!("a facet needs at least 3 vertices, found {n}"),
                    ));
                }
                let s = loop_start as u32;
                for k in 1..n as u32 - 1 {
                    triangles.push([s, s + k, s + k + 1]);
                }
                in_loop = false;
            }
            "endfacet" if in_solid && !in_loop => {}
            _ => {
                let expected = if in_loop {
                    "`vertex x y z` or `endloop`"
                } else if in_solid {
                    "`facet normal`, `outer loop`, `endfacet` or `endsolid`"
                } else {
                    "`solid`"
                };
                return Err(err(
                    ln,
                    format!("expected {expected}, found `{}`", raw.trim()),
                ));
            }
        }
    }
    if in_loop {
        return Err(err(
            last_line,
            "file ends inside a facet (`outer loop` without `endloop`)".into(),
        ));
    }
    Ok((vertices, triangles))
}
