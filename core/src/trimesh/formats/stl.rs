//! STL, ASCII and binary.
//!
//! A file that starts with `solid` and is text is ASCII; otherwise binary,
//! whose size must be exactly `84 + 50·n` bytes for the `n` triangles its
//! header announces (many binary files also start with `solid`, hence the
//! parse-first rule). The size is checked before anything is allocated, so a
//! header that claims a billion triangles costs nothing.

use std::path::Path;

use glam::DVec3;

use super::{MeshError, Soup, expected, parse_error, point, range_check, words};

/// Parses STL bytes (ASCII or binary, see the module docs).
pub(super) fn parse(path: &Path, bytes: &[u8]) -> Result<Soup, MeshError> {
    let body = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    let text = std::str::from_utf8(body).ok().filter(|t| !t.contains('\0'));
    match text {
        // A text file: its ASCII error is the one to report.
        Some(text) if !binary_size_matches(bytes) => parse_ascii(path, text),
        Some(text) => parse_ascii(path, text).or_else(|_| parse_binary(path, bytes)),
        None => parse_binary(path, bytes),
    }
}

/// The triangle count of a binary STL header, if the file has one.
fn header_count(bytes: &[u8]) -> Option<u64> {
    let c = bytes.get(80..84)?;
    Some(u32::from_le_bytes([c[0], c[1], c[2], c[3]]) as u64)
}

/// True when the size is exactly that of a binary STL with the header's
/// triangle count.
pub(super) fn binary_size_matches(bytes: &[u8]) -> bool {
    header_count(bytes).is_some_and(|n| bytes.len() as u64 == 84 + 50 * n)
}

/// Why the bytes are not a binary STL, for the unknown-format message.
pub(super) fn binary_size_note(bytes: &[u8]) -> String {
    match header_count(bytes) {
        None => format!(
            "{} bytes, shorter than a binary STL's 84-byte header",
            bytes.len()
        ),
        Some(n) => format!(
            "read as a binary STL its header announces {n} triangles, i.e. 84 + 50·{n} = {} bytes, but the file has {}",
            84 + 50 * n,
            bytes.len()
        ),
    }
}

pub(super) fn parse_binary(path: &Path, bytes: &[u8]) -> Result<Soup, MeshError> {
    let bad = |msg: String| MeshError::BinaryStl {
        path: path.to_path_buf(),
        msg,
    };
    let Some(n) = header_count(bytes) else {
        return Err(bad(format!(
            "file has {} bytes; a binary STL needs at least 84 (80-byte header + triangle count)",
            bytes.len()
        )));
    };
    if !binary_size_matches(bytes) {
        let expected = 84 + 50 * n;
        let what = if (bytes.len() as u64) < expected {
            "truncated, or not a binary STL"
        } else {
            "trailing bytes, or not a binary STL"
        };
        return Err(bad(format!(
            "header announces {n} triangles, i.e. 84 + 50·{n} = {expected} bytes, but the file has {} bytes ({what}; \
             not ASCII STL either: that starts with `solid` followed by facets)",
            bytes.len()
        )));
    }
    let n = n as usize;
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
                    "triangle {} (byte {o}) has a coordinate that is not a finite number: ({}, {}, {})",
                    t + 1,
                    v.x,
                    v.y,
                    v.z
                )));
            }
            if let Err(m) = range_check(v.abs().max_element()) {
                return Err(bad(format!(
                    "triangle {} (byte {o}): a coordinate of ({}, {}, {}) {m}",
                    t + 1,
                    v.x,
                    v.y,
                    v.z
                )));
            }
            vertices.push(v);
        }
        let i = 3 * t as u32;
        triangles.push([i, i + 1, i + 2]);
    }
    Ok((vertices, triangles))
}

/// Where the ASCII reader stands.
#[derive(Clone, Copy, PartialEq)]
enum State {
    Outside,
    InSolid,
    InLoop,
}

/// ASCII STL: `solid name`, then `facet normal nx ny nz / outer loop /
/// vertex x y z ×3 / endloop / endfacet`, then `endsolid name`. Keywords are
/// case-insensitive; several solids may follow each other; a loop with more
/// than three vertices is fan-triangulated.
fn parse_ascii(path: &Path, text: &str) -> Result<Soup, MeshError> {
    let err = parse_error(path);
    let mut vertices: Vec<DVec3> = Vec::new();
    let mut triangles = Vec::new();
    let mut state = State::Outside;
    let mut loop_start = 0usize;
    let mut last_line = 0;
    for (i, raw) in text.lines().enumerate() {
        let ln = i + 1;
        last_line = ln;
        let mut it = words(raw);
        let Some((col, word)) = it.next() else {
            continue;
        };
        match (word.to_ascii_lowercase().as_str(), state) {
            ("solid", State::Outside) => state = State::InSolid,
            ("endsolid", State::InSolid) => state = State::Outside,
            ("facet", State::InSolid) => {
                let ok = it
                    .next()
                    .is_some_and(|(_, w)| w.eq_ignore_ascii_case("normal"));
                let nums: Vec<(usize, &str)> = it.collect();
                if !ok || nums.len() != 3 || nums.iter().any(|(_, s)| s.parse::<f64>().is_err()) {
                    return Err(err(ln, col, expected("`facet normal nx ny nz`", raw)));
                }
            }
            ("outer", State::InSolid) => {
                if !it
                    .next()
                    .is_some_and(|(_, w)| w.eq_ignore_ascii_case("loop"))
                {
                    return Err(err(ln, col, expected("`outer loop`", raw)));
                }
                state = State::InLoop;
                loop_start = vertices.len();
            }
            ("vertex", State::InLoop) => {
                let nums: Vec<(usize, &str)> = it.collect();
                if nums.len() != 3 {
                    return Err(err(ln, col, expected("`vertex x y z` with 3 numbers", raw)));
                }
                vertices.push(point(&nums, ln, &err)?);
            }
            ("endloop", State::InLoop) => {
                let n = vertices.len() - loop_start;
                if n < 3 {
                    return Err(err(
                        ln,
                        col,
                        format!("a facet needs at least 3 vertices, found {n}"),
                    ));
                }
                let s = loop_start as u32;
                for k in 1..n as u32 - 1 {
                    triangles.push([s, s + k, s + k + 1]);
                }
                state = State::InSolid;
            }
            ("endfacet", State::InSolid) => {}
            _ => {
                let what = match state {
                    State::InLoop => "`vertex x y z` or `endloop`",
                    State::InSolid => "`facet normal`, `outer loop`, `endfacet` or `endsolid`",
                    State::Outside => "`solid`",
                };
                return Err(err(ln, col, expected(what, raw)));
            }
        }
    }
    if state == State::InLoop {
        return Err(err(
            last_line,
            0,
            "file ends inside a facet (`outer loop` without `endloop`): truncated?".into(),
        ));
    }
    Ok((vertices, triangles))
}
