//! Object File Format: a header word ending in `OFF` (`OFF`, `COFF`,
//! `NOFF`, `CNOFF`, …), the counts `vertices faces edges`, one vertex per
//! line (`x y z`, then optional normal or colour values), one face per line
//! (`n i0 … i(n-1)`, 0-based, then an optional colour). `#` starts a
//! comment. Polygons are fan-triangulated.

use std::path::Path;

use super::{MeshError, Soup, capacity, excerpt, fan, parse_error, point, words};

pub(super) fn parse(path: &Path, text: &str) -> Result<Soup, MeshError> {
    let err = parse_error(path);
    // Lines with their words, comments and blank lines left out.
    let mut lines = text.lines().enumerate().filter_map(|(i, raw)| {
        let w: Vec<(usize, &str)> = words(raw.split('#').next().unwrap_or("")).collect();
        (!w.is_empty()).then_some((i + 1, w))
    });
    let Some((_, mut header)) = lines.next() else {
        return Err(err(1, 1, "expected `OFF`".into()));
    };
    header.remove(0);
    // The counts may follow the keyword on its line.
    let (count_line, counts) = if header.is_empty() {
        lines.next().ok_or_else(|| {
            err(
                1,
                0,
                "file ends after `OFF`; expected `vertices faces edges`".into(),
            )
        })?
    } else {
        (1, header)
    };
    let count = |k: usize| -> Result<u64, MeshError> {
        let (c, w) = counts.get(k).copied().unwrap_or((0, ""));
        w.parse::<u64>().map_err(|_| {
            err(
                count_line,
                c,
                format!(
                    "expected the counts `vertices faces edges`, found `{}` (a whole number)",
                    excerpt(w)
                ),
            )
        })
    };
    let (nv, nf) = (count(0)?, count(1)?);
    let mut vertices = Vec::with_capacity(capacity(nv, text.len(), 6));
    let mut last = count_line;
    for k in 0..nv {
        let Some((ln, w)) = lines.next() else {
            return Err(err(
                last,
                0,
                format!(
                    "file ends after {k} of the {nv} vertices the header announces: truncated?"
                ),
            ));
        };
        last = ln;
        if w.len() < 3 {
            return Err(err(
                ln,
                w[0].0,
                format!("expected a vertex `x y z`, found {} numbers", w.len()),
            ));
        }
        vertices.push(point(&w, ln, &err)?);
    }
    let mut triangles = Vec::with_capacity(capacity(nf, text.len(), 8));
    let mut poly = Vec::new();
    for k in 0..nf {
        let Some((ln, w)) = lines.next() else {
            return Err(err(
                last,
                0,
                format!("file ends after {k} of the {nf} faces the header announces: truncated?"),
            ));
        };
        last = ln;
        let n = w[0]
            .1
            .parse::<usize>()
            .ok()
            .filter(|&n| n >= 3 && n < w.len());
        let Some(n) = n else {
            return Err(err(
                ln,
                w[0].0,
                format!(
                    "expected a face `n i0 … i(n-1)` with n ≥ 3 vertex numbers, found `{}`",
                    excerpt(&w.iter().map(|x| x.1).collect::<Vec<_>>().join(" "))
                ),
            ));
        };
        poly.clear();
        for &(c, s) in &w[1..=n] {
            match s.parse::<u64>() {
                Ok(i) if i < nv => poly.push(i as u32),
                _ => {
                    return Err(err(
                        ln,
                        c,
                        format!(
                            "face vertex `{}` is not one of the {nv} vertices (0-based: 0..{nv})",
                            excerpt(s)
                        ),
                    ));
                }
            }
        }
        fan(&poly, &mut triangles);
    }
    Ok((vertices, triangles))
}
