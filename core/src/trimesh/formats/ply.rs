//! PLY (Stanford polygon format), ASCII and binary little/big endian.
//!
//! The header declares elements (`element NAME COUNT`) and their properties
//! (`property TYPE NAME` or `property list COUNT_TYPE ITEM_TYPE NAME`);
//! `vertex` needs `x`, `y`, `z`, `face` a list named `vertex_indices` (or
//! `vertex_index`); polygons are fan-triangulated and every other element
//! and property is read past. Own reader: the PLY crates on crates.io are
//! unmaintained or pull in far more than the ~250 lines this needs, and this
//! one names the line and column (ASCII) or the byte (binary) of a bad
//! value, and never reserves more than the file could hold.

use std::path::Path;

use glam::DVec3;

use super::{MeshError, Soup, capacity, coord, excerpt, fan, parse_error, range_check, words};

#[derive(Clone, Copy, PartialEq)]
enum Encoding {
    Ascii,
    Little,
    Big,
}

#[derive(Clone, Copy)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn parse(name: &str) -> Option<Scalar> {
        Some(match name {
            "char" | "int8" => Scalar::I8,
            "uchar" | "uint8" => Scalar::U8,
            "short" | "int16" => Scalar::I16,
            "ushort" | "uint16" => Scalar::U16,
            "int" | "int32" => Scalar::I32,
            "uint" | "uint32" => Scalar::U32,
            "float" | "float32" => Scalar::F32,
            "double" | "float64" => Scalar::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }
}

struct Property {
    name: String,
    /// `Some(count type)` for a list.
    list: Option<Scalar>,
    item: Scalar,
}

impl Property {
    /// `property TYPE NAME` or `property list COUNT_TYPE ITEM_TYPE NAME`.
    fn parse(w: &[(usize, &str)]) -> Result<Property, String> {
        let word = |k: usize| w.get(k).map(|x| x.1);
        let found = excerpt(&w.iter().map(|x| x.1).collect::<Vec<_>>().join(" "));
        if word(1) == Some("list") {
            let ct = word(2).and_then(Scalar::parse);
            match (ct, word(3).and_then(Scalar::parse), word(4)) {
                (Some(ct), Some(item), Some(n)) => Ok(Property {
                    name: n.to_string(),
                    list: Some(ct),
                    item,
                }),
                _ => Err(format!(
                    "expected `property list COUNT_TYPE ITEM_TYPE NAME` with types {TYPES}, found `{found}`"
                )),
            }
        } else {
            match (word(1).and_then(Scalar::parse), word(2)) {
                (Some(item), Some(n)) => Ok(Property {
                    name: n.to_string(),
                    list: None,
                    item,
                }),
                _ => Err(format!(
                    "expected `property TYPE NAME` with a type of {TYPES}, found `{found}`"
                )),
            }
        }
    }
}

struct Element {
    name: String,
    count: u64,
    props: Vec<Property>,
}

const TYPES: &str = "char uchar short ushort int uint float double (or int8 … float64)";

pub(super) fn parse(path: &Path, bytes: &[u8]) -> Result<Soup, MeshError> {
    let err = parse_error(path);
    let (encoding, elements, body, body_line) = header(bytes).map_err(|(l, c, m)| err(l, c, m))?;
    let mut reader = match encoding {
        Encoding::Ascii => {
            let text = std::str::from_utf8(body).map_err(|_| {
                err(
                    body_line,
                    0,
                    "an ASCII PLY holds text only after `end_header`".into(),
                )
            })?;
            Body::Ascii(AsciiBody::new(text, body_line))
        }
        e => Body::Binary {
            bytes: body,
            pos: 0,
            big: e == Encoding::Big,
            start: bytes.len() - body.len(),
        },
    };
    let mut vertices = Vec::new();
    let mut triangles = Vec::new();
    let mut poly = Vec::new();
    for el in &elements {
        let is_vertex = el.name == "vertex";
        let xyz = ["x", "y", "z"].map(|n| {
            el.props
                .iter()
                .position(|p| p.name == n && p.list.is_none())
        });
        let faces = el.props.iter().position(|p| {
            p.list.is_some() && (p.name == "vertex_indices" || p.name == "vertex_index")
        });
        if is_vertex {
            let min_bytes = el
                .props
                .iter()
                .map(|p| p.list.unwrap_or(p.item).size())
                .sum();
            vertices.reserve(capacity(el.count, body.len(), min_bytes));
        }
        // An element without properties takes no bytes: nothing to read,
        // however large its count.
        let count = if el.props.is_empty() { 0 } else { el.count };
        for i in 0..count {
            let at = |e: ReadError| e.into_mesh_error(path, &el.name, i, el.count);
            let mut p = [0.0; 3];
            for (k, prop) in el.props.iter().enumerate() {
                let axis = xyz.iter().position(|&x| x == Some(k)).filter(|_| is_vertex);
                match prop.list {
                    None => {
                        let v = reader.value(prop.item, axis.is_some()).map_err(at)?;
                        if let Some(a) = axis {
                            p[a] = v;
                        }
                    }
                    Some(ct) => {
                        let n = reader.index(ct, u32::MAX as u64).map_err(at)?;
                        poly.clear();
                        for _ in 0..n {
                            poly.push(reader.index(prop.item, u32::MAX as u64).map_err(at)? as u32);
                        }
                        if el.name == "face" && faces == Some(k) {
                            fan(&poly, &mut triangles);
                        }
                    }
                }
            }
            if is_vertex {
                vertices.push(DVec3::from_array(p));
            }
        }
    }
    let nv = vertices.len();
    if let Some((t, &bad)) = triangles
        .iter()
        .enumerate()
        .find_map(|(t, tri)| tri.iter().find(|&&i| i as usize >= nv).map(|b| (t, b)))
    {
        return Err(MeshError::Invalid {
            path: path.to_path_buf(),
            msg: format!(
                "PLY face triangle {} uses vertex {bad}, but the file has {nv} vertices (0-based: 0..{nv})",
                t + 1
            ),
        });
    }
    Ok((vertices, triangles))
}

type HeaderError = (usize, usize, String);

/// The encoding, the elements, the body and the body's first line number.
type Header<'a> = (Encoding, Vec<Element>, &'a [u8], usize);

/// Reads the header.
fn header(bytes: &[u8]) -> Result<Header<'_>, HeaderError> {
    let mut encoding = None;
    let mut elements: Vec<Element> = Vec::new();
    let mut pos = 0;
    let mut ln = 0;
    loop {
        ln += 1;
        let Some(len) = bytes[pos..].iter().position(|&b| b == b'\n') else {
            return Err((
                ln,
                0,
                "the header has no `end_header` line: truncated?".into(),
            ));
        };
        let raw = &bytes[pos..pos + len];
        pos += len + 1;
        let line = std::str::from_utf8(raw)
            .map_err(|_| (ln, 0, "the PLY header must be ASCII text".to_string()))?;
        let w: Vec<(usize, &str)> = words(line).collect();
        let Some(&(col, key)) = w.first() else {
            continue;
        };
        let bad = |c: usize, m: String| Err((ln, c, m));
        match key {
            "ply" | "comment" | "obj_info" => {}
            "format" => {
                encoding = Some(match w.get(1).map(|x| x.1) {
                    Some("ascii") => Encoding::Ascii,
                    Some("binary_little_endian") => Encoding::Little,
                    Some("binary_big_endian") => Encoding::Big,
                    _ => {
                        return bad(
                            col,
                            format!(
                                "expected `format ascii|binary_little_endian|binary_big_endian 1.0`, found `{}`",
                                excerpt(line.trim())
                            ),
                        );
                    }
                });
            }
            "element" => {
                let count = w.get(2).and_then(|x| x.1.parse::<u64>().ok());
                let (Some(name), Some(count)) = (w.get(1), count) else {
                    return bad(
                        col,
                        format!(
                            "expected `element NAME COUNT`, found `{}`",
                            excerpt(line.trim())
                        ),
                    );
                };
                elements.push(Element {
                    name: name.1.to_string(),
                    count,
                    props: Vec::new(),
                });
            }
            "property" => {
                let Some(el) = elements.last_mut() else {
                    return bad(col, "`property` before any `element`".into());
                };
                let prop = Property::parse(&w).map_err(|m| (ln, col, m))?;
                el.props.push(prop);
            }
            "end_header" => break,
            _ => {
                return bad(
                    col,
                    format!("unknown PLY header line `{}`", excerpt(line.trim())),
                );
            }
        }
    }
    let Some(encoding) = encoding else {
        return Err((ln, 0, "the header has no `format` line".into()));
    };
    for el in &elements {
        if el.name == "vertex" {
            for n in ["x", "y", "z"] {
                if !el.props.iter().any(|p| p.name == n && p.list.is_none()) {
                    return Err((ln, 0, format!("element `vertex` has no property `{n}`")));
                }
            }
        }
    }
    if !elements.iter().any(|e| e.name == "face") {
        return Err((
            ln,
            0,
            "the header declares no `element face`: a point cloud has no surface".into(),
        ));
    }
    Ok((encoding, elements, &bytes[pos..], ln + 1))
}

/// Why a value of the body could not be read.
enum ReadError {
    /// The body ended (binary: byte offset in the file).
    End,
    /// ASCII: line, column and reason.
    Text(usize, usize, String),
    /// Binary: byte offset in the file and reason.
    Byte(usize, String),
}

impl ReadError {
    fn into_mesh_error(self, path: &Path, el: &str, i: u64, n: u64) -> MeshError {
        let what = format!("element `{el}` {} of {n}", i + 1);
        match self {
            ReadError::End => MeshError::Invalid {
                path: path.to_path_buf(),
                msg: format!("PLY: the file ends inside {what}: truncated?"),
            },
            ReadError::Text(line, column, msg) => MeshError::Parse {
                path: path.to_path_buf(),
                line,
                column,
                msg: format!("{what}: {msg}"),
            },
            ReadError::Byte(at, msg) => MeshError::Invalid {
                path: path.to_path_buf(),
                msg: format!("PLY: byte {at}, {what}: {msg}"),
            },
        }
    }
}

/// ASCII body: words with their line and column.
struct AsciiBody<'a> {
    lines: std::iter::Enumerate<std::str::Lines<'a>>,
    first_line: usize,
    line: usize,
    words: Vec<(usize, &'a str)>,
    next: usize,
}

impl<'a> AsciiBody<'a> {
    fn new(text: &'a str, first_line: usize) -> Self {
        AsciiBody {
            lines: text.lines().enumerate(),
            first_line,
            line: first_line,
            words: Vec::new(),
            next: 0,
        }
    }

    fn word(&mut self) -> Option<(usize, usize, &'a str)> {
        while self.next >= self.words.len() {
            let (i, l) = self.lines.next()?;
            self.line = self.first_line + i;
            self.words = words(l).collect();
            self.next = 0;
        }
        self.next += 1;
        let (c, w) = self.words[self.next - 1];
        Some((self.line, c, w))
    }
}

enum Body<'a> {
    Ascii(AsciiBody<'a>),
    Binary {
        bytes: &'a [u8],
        pos: usize,
        big: bool,
        start: usize,
    },
}

impl Body<'_> {
    /// One scalar; `coordinate` applies the coordinate checks.
    fn value(&mut self, s: Scalar, coordinate: bool) -> Result<f64, ReadError> {
        match self {
            Body::Ascii(a) => {
                let (l, c, w) = a.word().ok_or(ReadError::End)?;
                if coordinate {
                    coord(w).map_err(|m| ReadError::Text(l, c, m))
                } else {
                    w.parse::<f64>().map_err(|_| {
                        ReadError::Text(l, c, format!("`{}` is not a number", excerpt(w)))
                    })
                }
            }
            Body::Binary {
                bytes,
                pos,
                big,
                start,
            } => {
                let n = s.size();
                let b = bytes.get(*pos..*pos + n).ok_or(ReadError::End)?;
                let at = *start + *pos;
                *pos += n;
                let v = decode(s, b, *big);
                if coordinate && !v.is_finite() {
                    return Err(ReadError::Byte(
                        at,
                        format!("coordinate {v} is not a finite number"),
                    ));
                }
                if coordinate && let Err(m) = range_check(v) {
                    return Err(ReadError::Byte(at, format!("coordinate {v} {m}")));
                }
                Ok(v)
            }
        }
    }

    /// A list count or vertex index: a whole number in `0..=max`.
    fn index(&mut self, s: Scalar, max: u64) -> Result<u64, ReadError> {
        let v = self.value(s, false)?;
        if v.fract() == 0.0 && (0.0..=max as f64).contains(&v) {
            return Ok(v as u64);
        }
        let msg = format!("{v} is not a count or vertex number (a whole number from 0)");
        Err(match self {
            Body::Ascii(a) => ReadError::Text(a.line, a.words[a.next - 1].0, msg),
            Body::Binary { pos, start, .. } => ReadError::Byte(*start + *pos - s.size(), msg),
        })
    }
}

fn decode(s: Scalar, b: &[u8], big: bool) -> f64 {
    macro_rules! num {
        ($t:ty, $n:literal) => {{
            let mut a = [0u8; $n];
            a.copy_from_slice(b);
            (if big {
                <$t>::from_be_bytes(a)
            } else {
                <$t>::from_le_bytes(a)
            }) as f64
        }};
    }
    match s {
        Scalar::I8 => b[0] as i8 as f64,
        Scalar::U8 => b[0] as f64,
        Scalar::I16 => num!(i16, 2),
        Scalar::U16 => num!(u16, 2),
        Scalar::I32 => num!(i32, 4),
        Scalar::U32 => num!(u32, 4),
        Scalar::F32 => num!(f32, 4),
        Scalar::F64 => num!(f64, 8),
    }
}
