//! Reading mesh files into welded vertices and triangles.
//!
//! The format is told by the file's content, never by its extension: a zip
//! (`PK\3\4`) is 3MF, `ply` on the first line is PLY, `OFF` (or `COFF`,
//! `NOFF`, …) is OFF, `solid` is ASCII STL unless the bytes do not parse as
//! text (many binary STLs start with `solid` too), a size of exactly
//! `84 + 50·n` bytes for the `n` triangles of a binary STL header is binary
//! STL, and other text is OBJ. The extension only picks which failure to
//! explain when nothing matches.
//!
//! Every reader returns a triangle soup; [`finish`] then welds bit-identical
//! positions (`-0 = +0`; STL stores every corner separately and 3MF every
//! object apart, so shared edges have to be recovered for the closed-mesh
//! test and the pseudo-normals), drops triangles that repeat a vertex and
//! repeated copies of a triangle (a million copies of one face would
//! otherwise fill the trees with coincident boxes), and reports how many.

mod obj;
mod off;
mod ply;
mod stl;
mod threemf;

use std::collections::HashSet;
use std::path::Path;

use glam::DVec3;

use super::MeshError;

/// Vertices and triangles (indices valid).
pub(crate) type Soup = (Vec<DVec3>, Vec<[u32; 3]>);

/// Coordinates beyond this magnitude are refused: the distance trees keep
/// `f32` boxes (±3.4e38), and no part is larger than a million kilometres
/// in any unit a mesh file uses; such values come from a wrong unit or a
/// corrupt file.
pub(crate) const MAX_COORD: f64 = 1e12;

/// What [`load`] read, after cleaning.
pub(crate) struct Loaded {
    pub vertices: Vec<DVec3>,
    pub triangles: Vec<[u32; 3]>,
    /// What cleaning removed, for [`super::TriangleMesh::warnings`].
    pub warnings: Vec<String>,
    /// Triangles in the file before cleaning.
    pub read_triangles: usize,
}

/// Reads the file (see the module docs). Refuses anything but a regular
/// file before opening it: a FIFO or a device would block or never end.
pub(crate) fn load(path: &Path) -> Result<Loaded, MeshError> {
    let meta = std::fs::metadata(path).map_err(|e| io_error(path, e))?;
    if !meta.is_file() {
        return Err(MeshError::NotRegular {
            path: path.to_path_buf(),
            kind: file_kind(&meta),
        });
    }
    let bytes = std::fs::read(path).map_err(|e| io_error(path, e))?;
    let (vertices, triangles) = parse(path, &bytes)?;
    finish(path, vertices, triangles)
}

/// Describes a file that is not a regular file, for the refusal.
fn file_kind(meta: &std::fs::Metadata) -> &'static str {
    let t = meta.file_type();
    if t.is_dir() {
        return "a folder";
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_fifo() {
            return "a FIFO (named pipe)";
        }
        if t.is_socket() {
            return "a socket";
        }
        if t.is_block_device() || t.is_char_device() {
            return "a device";
        }
    }
    "not a regular file"
}

pub(crate) fn io_error(path: &Path, e: std::io::Error) -> MeshError {
    MeshError::Io {
        path: path.to_path_buf(),
        msg: e.to_string(),
    }
}

/// Picks the reader by content (module docs).
pub(crate) fn parse(path: &Path, bytes: &[u8]) -> Result<Soup, MeshError> {
    if bytes.is_empty() {
        return Err(MeshError::EmptyFile {
            path: path.to_path_buf(),
        });
    }
    if bytes.starts_with(b"PK\x03\x04") {
        return threemf::parse(path, bytes);
    }
    let body = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    let first_line = body.split(|&b| b == b'\n').next().unwrap_or(b"");
    let first_word = first_line
        .split(|b| b.is_ascii_whitespace())
        .find(|w| !w.is_empty())
        .unwrap_or(b"");
    if first_word == b"ply" {
        return ply::parse(path, body);
    }
    if first_word.len() <= 6 && first_word.ends_with(b"OFF") {
        return off::parse(path, text(path, bytes)?);
    }
    if body.len() >= 5 && body[..5].eq_ignore_ascii_case(b"solid") {
        return stl::parse(path, bytes);
    }
    if stl::binary_size_matches(bytes) {
        return stl::parse_binary(path, bytes);
    }
    let is_text = !bytes.contains(&0) && std::str::from_utf8(body).is_ok();
    if is_text {
        return obj::parse(path, text(path, bytes)?);
    }
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .unwrap_or_default();
    if ext == "stl" {
        // Binary by its name: explain its size against its header.
        return stl::parse_binary(path, bytes);
    }
    Err(MeshError::UnknownFormat {
        path: path.to_path_buf(),
        detail: stl::binary_size_note(bytes),
    })
}

/// The file as UTF-8 text without a byte-order mark; invalid bytes are
/// reported at their line and column.
pub(crate) fn text<'a>(path: &Path, bytes: &'a [u8]) -> Result<&'a str, MeshError> {
    let body = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    std::str::from_utf8(body).map_err(|e| {
        let ok = &body[..e.valid_up_to()];
        let line = ok.iter().filter(|&&b| b == b'\n').count() + 1;
        let start = ok.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1);
        let column = std::str::from_utf8(&ok[start..]).map_or(1, |s| s.chars().count() + 1);
        MeshError::Parse {
            path: path.to_path_buf(),
            line,
            column,
            msg: "the file is not UTF-8 text here (a binary file that is no mesh format we read?)"
                .into(),
        }
    })
}

/// Parses one coordinate of a text format, with the reason a value is
/// refused (the caller adds file, line and column).
pub(crate) fn coord(word: &str) -> Result<f64, String> {
    let tok = excerpt(word);
    let v: f64 = word
        .parse()
        .map_err(|_| format!("`{tok}` is not a number"))?;
    if v.is_nan() {
        return Err(format!(
            "`{tok}` is not a number (NaN); write a finite coordinate"
        ));
    }
    if v.is_infinite() {
        let lower = tok.to_ascii_lowercase();
        return Err(if lower.contains("inf") {
            format!("`{tok}` is infinite; write a finite coordinate")
        } else {
            format!("`{tok}` overflows: it is out of the range of a 64-bit float (±1.8e308)")
        });
    }
    range_check(v)
        .map(|()| v)
        .map_err(|m| format!("`{tok}` {m}"))
}

/// Most characters of the file's text that a message quotes.
const QUOTE_CHARS: usize = 60;

/// `s`, or its first [`QUOTE_CHARS`] characters and `…`: a 10 MB line is
/// not echoed whole.
pub(crate) fn excerpt(s: &str) -> String {
    match s.char_indices().nth(QUOTE_CHARS) {
        Some((cut, _)) => format!("{}…", &s[..cut]),
        None => s.to_string(),
    }
}

/// The message for a line that is not the statement `what` names:
/// "expected WHAT, found `LINE`" (the line trimmed and cut to an excerpt).
pub(crate) fn expected(what: &str, line: &str) -> String {
    format!("expected {what}, found `{}`", excerpt(line.trim()))
}

/// Refuses magnitudes beyond [`MAX_COORD`].
pub(crate) fn range_check(v: f64) -> Result<(), String> {
    if v.abs() > MAX_COORD {
        Err(format!(
            "is out of range: mesh coordinates must lie within ±{MAX_COORD:e} (check the file's unit)"
        ))
    } else {
        Ok(())
    }
}

/// A [`MeshError::Parse`] maker for `path`: `(line, column, message)`.
pub(crate) fn parse_error(path: &Path) -> impl Fn(usize, usize, String) -> MeshError + '_ {
    move |line, column, msg| MeshError::Parse {
        path: path.to_path_buf(),
        line,
        column,
        msg,
    }
}

/// The first three of a line's words (at least three) as a point, each
/// checked by [`coord`].
pub(crate) fn point(
    words: &[(usize, &str)],
    line: usize,
    err: &impl Fn(usize, usize, String) -> MeshError,
) -> Result<DVec3, MeshError> {
    let mut p = [0.0; 3];
    for (k, &(c, s)) in words[..3].iter().enumerate() {
        p[k] = coord(s).map_err(|m| err(line, c, m))?;
    }
    Ok(DVec3::from_array(p))
}

/// Whitespace-separated words of a line with their 1-based columns.
pub(crate) fn words(line: &str) -> impl Iterator<Item = (usize, &str)> {
    let base = line.as_ptr() as usize;
    line.split_whitespace().map(move |w| {
        let off = w.as_ptr() as usize - base;
        (line[..off].chars().count() + 1, w)
    })
}

/// Capacity to reserve for `count` items that take at least `min_bytes`
/// each of the `available` bytes: a header may announce a billion.
pub(crate) fn capacity(count: u64, available: usize, min_bytes: usize) -> usize {
    count.min((available / min_bytes.max(1)) as u64) as usize
}

/// Welds, drops repeated-vertex triangles and repeated triangles, checks the
/// coordinates' range (3MF transforms and units may move them).
fn finish(
    path: &Path,
    vertices: Vec<DVec3>,
    triangles: Vec<[u32; 3]>,
) -> Result<Loaded, MeshError> {
    if let Some((i, v)) = vertices
        .iter()
        .enumerate()
        .find(|(_, v)| !v.is_finite() || v.abs().max_element() > MAX_COORD)
    {
        return Err(MeshError::Invalid {
            path: path.to_path_buf(),
            msg: format!(
                "vertex {} at ({}, {}, {}) is out of range: mesh coordinates must lie within ±{MAX_COORD:e} (check the file's unit and transforms)",
                i + 1,
                v.x,
                v.y,
                v.z
            ),
        });
    }
    let read_triangles = triangles.len();
    let (vertices, triangles) = weld(&vertices, &triangles);
    let (triangles, repeated_vertex, duplicates) = drop_redundant(triangles);
    let mut warnings = Vec::new();
    if repeated_vertex > 0 {
        warnings.push(format!(
            "removed {repeated_vertex} degenerate triangles (a corner repeated after welding)"
        ));
    }
    if duplicates > 0 {
        warnings.push(format!(
            "removed {duplicates} duplicate triangles (the same corners in the same order as another)"
        ));
    }
    Ok(Loaded {
        vertices,
        triangles,
        warnings,
        read_triangles,
    })
}

/// Drops triangles that use a vertex twice and later copies of a triangle
/// with the same cyclic order (a copy with the opposite order is another
/// face and stays). Returns the kept triangles and both counts.
fn drop_redundant(triangles: Vec<[u32; 3]>) -> (Vec<[u32; 3]>, usize, usize) {
    let mut seen: HashSet<[u32; 3]> = HashSet::with_capacity(triangles.len());
    let (mut repeated, mut duplicates) = (0, 0);
    let mut kept = Vec::with_capacity(triangles.len());
    for t in triangles {
        if t[0] == t[1] || t[1] == t[2] || t[2] == t[0] {
            repeated += 1;
            continue;
        }
        // The rotation that starts at the smallest index names the cycle.
        let k = (0..3).min_by_key(|&k| t[k]).unwrap_or(0);
        let key = [t[k], t[(k + 1) % 3], t[(k + 2) % 3]];
        if seen.insert(key) {
            kept.push(t);
        } else {
            duplicates += 1;
        }
    }
    (kept, repeated, duplicates)
}

/// Merges bit-identical positions; triangles are re-indexed.
pub(crate) fn weld(vertices: &[DVec3], triangles: &[[u32; 3]]) -> Soup {
    let key = |v: DVec3| {
        // +0.0 and -0.0 compare equal but have different bits.
        let k = |x: f64| if x == 0.0 { 0u64 } else { x.to_bits() };
        [k(v.x), k(v.y), k(v.z)]
    };
    let mut map = std::collections::HashMap::with_capacity(vertices.len());
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
        .map(|t| t.map(|i| remap[i as usize]))
        .collect();
    (out, tris)
}

/// Fan triangulation of a polygon given as vertex indices.
pub(crate) fn fan(poly: &[u32], out: &mut Vec<[u32; 3]>) {
    for k in 1..poly.len().saturating_sub(1) {
        out.push([poly[0], poly[k], poly[k + 1]]);
    }
}
