//! Options both front ends take as text (`--layers 100..200` on the
//! command line, the studio's "Layers" field), parsed one way so a value
//! means the same and is refused with the same words in both.

use std::ops::Range;

use crate::job::ExportError;

/// A layer range: `A..B` (A to B − 1) or `A..=B` (A to B), global layer
/// indices; errors under `flag`.
pub fn parse_layers(flag: &str, s: &str) -> Result<Range<usize>, ExportError> {
    let bad = |why: &str| ExportError::param(flag, format!("\"{s}\": {why}"));
    let (a, b, inclusive) = match s.split_once("..=") {
        Some((a, b)) => (a, b, true),
        None => {
            let (a, b) = s.split_once("..").ok_or_else(|| {
                bad("expected A..B (B excluded) or A..=B (B included), e.g. 100..200")
            })?;
            (a, b, false)
        }
    };
    let a: usize = a
        .trim()
        .parse()
        .map_err(|_| bad("bad start (a layer index, 0 or more)"))?;
    let b: usize = b
        .trim()
        .parse()
        .map_err(|_| bad("bad end (a layer index, 0 or more)"))?;
    let end = if inclusive { b.checked_add(1) } else { Some(b) };
    match end {
        Some(end) if a < end => Ok(a..end),
        _ => Err(bad(
            "the range holds no layer; A..B writes A to B-1, A..=B writes A to B",
        )),
    }
}

/// Two finite numbers `A,B` of `flag` (`example` shows the form).
pub fn parse_pair(flag: &str, s: &str, example: &str) -> Result<[f64; 2], ExportError> {
    let bad = || {
        ExportError::param(
            flag,
            format!("\"{s}\": give two finite numbers A,B, e.g. {example}"),
        )
    };
    let v: Vec<f64> = s
        .split(',')
        .map(|p| p.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| bad())?;
    match v.as_slice() {
        [a, b] if a.is_finite() && b.is_finite() => Ok([*a, *b]),
        _ => Err(bad()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_and_pairs() {
        assert_eq!(parse_layers("--layers", "3..7").unwrap(), 3..7);
        assert_eq!(parse_layers("--layers", " 3 ..= 7 ").unwrap(), 3..8);
        for (s, why) in [
            ("7..3", "holds no layer"),
            ("3-7", "expected A..B"),
            ("x..3", "bad start"),
            ("3..y", "bad end"),
        ] {
            let e = parse_layers("--layers", s).unwrap_err().to_string();
            assert!(
                e.starts_with(&format!("--layers: \"{s}\"")) && e.contains(why),
                "{e}"
            );
        }
        assert_eq!(
            parse_pair("--offset", "10, -5", "10,-5").unwrap(),
            [10.0, -5.0]
        );
        for s in ["1", "1,2,3", "a,b", "1,inf"] {
            let e = parse_pair("--offset", s, "10,-5").unwrap_err().to_string();
            assert!(e.contains("give two finite numbers A,B, e.g. 10,-5"), "{e}");
        }
    }
}
