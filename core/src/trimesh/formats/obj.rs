//! Wavefront OBJ: `v x y z` positions and `f` faces (`i`, `i/t`, `i//n`,
//! `i/t/n`; negative indices count back from the last vertex read; polygons
//! fan-triangulated). Everything after `#` is a comment, other statements
//! (normals, texture coordinates, groups, materials, lines, points) are
//! skipped.
//!
//! Read here rather than by `tobj`: `tobj` stores `f32` positions (so
//! `1e39` came out infinite), reads a trailing `# comment` on a `v` line as
//! a vertex colour, and reports no line; this reader keeps `f64`, and every
//! refusal names its line and column.

use std::path::Path;

use glam::DVec3;

use super::{MeshError, Soup, excerpt, expected, fan, parse_error, point, words};

/// Column, resolved 0-based index, index as written.
type FaceRef = (usize, i64, i64);

/// A face whose indices are checked once all vertices are known (a face may
/// name a vertex defined after it).
struct Face {
    line: usize,
    /// 1-based column, resolved 0-based index (`i64` until checked) and
    /// the number as written.
    refs: Vec<FaceRef>,
}

pub(super) fn parse(path: &Path, text: &str) -> Result<Soup, MeshError> {
    let err = parse_error(path);
    let mut vertices: Vec<DVec3> = Vec::new();
    let mut faces: Vec<Face> = Vec::new();
    let mut statements = 0usize;
    for (i, raw) in text.lines().enumerate() {
        let ln = i + 1;
        let line = raw.split('#').next().unwrap_or("");
        let mut it = words(line);
        let Some((col, word)) = it.next() else {
            continue;
        };
        match word {
            "v" => {
                statements += 1;
                let nums: Vec<(usize, &str)> = it.collect();
                // x y z, then an optional w or an r g b colour.
                if nums.len() < 3 {
                    return Err(err(ln, col, expected("`v x y z` with 3 numbers", raw)));
                }
                vertices.push(point(&nums, ln, &err)?);
            }
            "f" => {
                statements += 1;
                let refs = face_refs(it, vertices.len()).map_err(|(c, m)| err(ln, c, m))?;
                if refs.len() < 3 {
                    return Err(err(
                        ln,
                        col,
                        format!(
                            "a face needs at least 3 vertices, found `{}`",
                            excerpt(raw.trim())
                        ),
                    ));
                }
                faces.push(Face { line: ln, refs });
            }
            "vn" | "vt" | "vp" | "o" | "g" | "s" | "l" | "p" | "usemtl" | "mtllib" => {
                statements += 1;
            }
            _ => {}
        }
    }
    if statements == 0 {
        return Err(MeshError::UnknownFormat {
            path: path.to_path_buf(),
            detail: "a text file without a single OBJ statement (`v`, `f`)".into(),
        });
    }
    let n = vertices.len() as i64;
    let mut triangles = Vec::with_capacity(faces.len());
    let mut poly = Vec::new();
    for f in &faces {
        poly.clear();
        for &(c, k, written) in &f.refs {
            if !(0..n).contains(&k) {
                return Err(err(
                    f.line,
                    c,
                    format!(
                        "face vertex {written} does not exist: the file has {n} vertices (write 1..={n}, or -1 for the last one read before the face)"
                    ),
                ));
            }
            poly.push(k as u32);
        }
        fan(&poly, &mut triangles);
    }
    Ok((vertices, triangles))
}

/// The position indices of an `f` statement, 0-based (negative ones
/// resolved against the `read` vertices so far; range checked later).
fn face_refs<'a>(
    words: impl Iterator<Item = (usize, &'a str)>,
    read: usize,
) -> Result<Vec<FaceRef>, (usize, String)> {
    words
        .map(|(c, w)| {
            let idx = w.split('/').next().unwrap_or("");
            match idx.parse::<i64>() {
                Ok(k) if k > 0 => Ok((c, k - 1, k)),
                Ok(k) if k < 0 => Ok((c, read as i64 + k, k)),
                _ => Err((
                    c,
                    format!(
                        "face vertex `{}` is not a vertex number (1-based, or negative counting back from the last vertex)",
                        excerpt(w)
                    ),
                )),
            }
        })
        .collect()
}
