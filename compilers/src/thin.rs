//! Features the export's cell size cannot resolve, found before sampling
//! from the design's thinnest stated feature ([`Model::thinnest_feature`])
//! and, where the design holds geometry whose thickness is not stated,
//! from sampling its distance ([`Model::sampled_thinnest`]).
//!
//! A feature survives sampling when at least two cells span it: a strut of
//! diameter `t` sampled with cells larger than `t / 2` can fall between the
//! cell centres along part of its length and leave loose pieces (compare
//! the bodies `volcad export mesh assets/examples/bcc_sphere.rhai --out
//! DIR` reports with `--voxel 0.5` and `--voxel 0.25`: its struts are
//! 0.7 mm across).

use volcad_core::Model;
use volcad_core::model::{GAP_BAND, Sampled, Thinnest};

/// Cells across the thinnest feature that resolve it.
pub const CELLS_ACROSS: f64 = 2.0;

/// The largest size (mm) at most `limit` with two significant digits, so
/// a suggested option value holds as printed.
pub fn size_below(limit: f64) -> f64 {
    two_digits(limit, f64::floor)
}

/// The smallest size (mm) at least `limit` with two significant digits.
pub fn size_above(limit: f64) -> f64 {
    two_digits(limit, f64::ceil)
}

fn two_digits(x: f64, round: fn(f64) -> f64) -> f64 {
    if !(x > 0.0 && x.is_finite()) {
        return x;
    }
    let step = 10f64.powf(x.log10().floor() - 1.0);
    let q = x / step;
    // Within rounding of a whole number, take it: 0.35 / 0.01 is 34.99…
    let near = q.round();
    let s = if (q - near).abs() < 1e-9 * near {
        near
    } else {
        round(q)
    } * step;
    // Printed with `{}`, 0.35 must read 0.35, not 0.35000000000000003.
    format!("{s:.12}").parse().unwrap_or(s)
}

/// A `warning: …` line when cells of `size` mm (set by `option`) cannot
/// resolve the design's thinnest feature or keep its narrowest gap open,
/// naming the size that would; a plain note when the design holds geometry
/// whose thickness is not stated (measured by sampling,
/// [`Model::sampled_thinnest`], or not at all when the design is
/// unbounded). Designs whose thickness is all stated are not sampled.
pub fn thin_feature_notes(model: &Model, size: f64, option: &str) -> Vec<String> {
    let t = model.thinnest_feature();
    // A sampled feature is at least `2 h` thick and warns only when it is
    // narrower than two cells, so cells no larger than `h` never meet one:
    // fine exports skip the sampling (as costly as a coarse export).
    let spacing = model.thin_sampling_spacing();
    let fine = spacing.is_some_and(|h| size <= h);
    let sampled = if t.unknown.is_empty() || fine {
        None
    } else {
        model.sampled_thinnest_below(CELLS_ACROSS * size)
    };
    let mut out = Vec::new();
    out.extend(wall_note(&t, sampled.as_ref(), size, option));
    out.extend(gap_note(model, sampled.as_ref(), size, option));
    if !t.unknown.is_empty() {
        out.push(unknown_note(&t, sampled.as_ref(), spacing, size, option));
    }
    out
}

/// The cell size limit for a feature or gap `width` mm across: two cells
/// across it. A gap closes by the same rule a wall vanishes: with fewer
/// than two cells across, the cell centres can all fall on its sides
/// along part of its length, and the contour joins them there.
fn limit(width: f64) -> f64 {
    width / CELLS_ACROSS
}

/// A point for messages, to a tenth of a millimetre (and no `-0`).
fn near(at: glam::DVec3) -> String {
    let [x, y, z] = at.to_array().map(|v| (v * 10.0).round() / 10.0 + 0.0);
    format!("({x}, {y}, {z}) mm")
}

/// The warning for the thinnest wall or strut, stated or sampled.
fn wall_note(t: &Thinnest, sampled: Option<&Sampled>, size: f64, option: &str) -> Option<String> {
    let found = sampled.and_then(|s| s.feature.as_ref().map(|f| (s.spacing, f)));
    let stated = t.feature.as_ref();
    match (stated, found) {
        (_, Some((h, f)))
            if stated.is_none_or(|s| f.thickness < s.thickness) && size > limit(f.thickness) =>
        {
            Some(format!(
                "warning: the design's thinnest feature (a wall or strut of {} about {} mm across near {}, measured by sampling every {} mm) is narrower than two cells of {option} {size}: it can vanish or break into loose pieces; {option} {} resolves it",
                t.unknown.join(" or "),
                two_digits(f.thickness, f64::round),
                near(f.at),
                size_above(h),
                size_below(limit(f.thickness))
            ))
        }
        (Some(f), _) if size > limit(f.thickness) => Some(format!(
            "warning: the design's thinnest feature ({} mm, {} mm across) is narrower than two cells of {option} {size}: it can vanish or break into loose pieces; {option} {} resolves it",
            f.what,
            f.thickness,
            size_below(limit(f.thickness))
        )),
        _ => None,
    }
}

/// The warning for the narrowest gap between parts (or slot), stated by
/// the tree ([`Model::stated_gaps`]) or found by sampling.
fn gap_note(model: &Model, sampled: Option<&Sampled>, size: f64, option: &str) -> Option<String> {
    let stated = model.stated_gaps(CELLS_ACROSS * size).narrowest;
    let found = sampled.and_then(|s| s.gap.as_ref().map(|g| (s.spacing, g)));
    let (width, what) = match (stated, found) {
        (Some(s), Some((_, g))) if s.width <= g.thickness => {
            (s.width, format!("{} near {}", s.what, near(s.at)))
        }
        (_, Some((h, g))) => (
            g.thickness,
            format!(
                "near {}, measured by sampling every {} mm",
                near(g.at),
                size_above(h)
            ),
        ),
        (stated, None) => {
            let s = stated?;
            (s.width, format!("{} near {}", s.what, near(s.at)))
        }
    };
    (size > limit(width)).then(|| format!(
        "warning: a gap between parts about {} mm across ({what}) is narrower than two cells of {option} {size}: it can close and join the parts on either side; {option} {} keeps it open",
        two_digits(width, f64::round),
        size_below(limit(width))
    ))
}

/// Which geometry was measured by sampling, at what spacing, or why not.
fn unknown_note(
    t: &Thinnest,
    sampled: Option<&Sampled>,
    spacing: Option<f64>,
    size: f64,
    option: &str,
) -> String {
    match sampled {
        Some(s) => {
            // Gaps are sampled within a band of the surface; wider ones
            // matter only to cells larger than half the band's width.
            let wide = 2.0 * GAP_BAND * s.spacing;
            let gaps = if CELLS_ACROSS * size > wide {
                format!(" (nor gaps wider than {} mm)", size_below(wide))
            } else {
                String::new()
            };
            format!(
                "thin features of {} were measured by sampling every {} mm: features thinner than {} mm are not checked against {option} {size}{gaps}",
                t.unknown.join(" and "),
                size_above(s.spacing),
                size_above(3.0 * s.spacing),
            )
        }
        None => match spacing {
            Some(h) => format!(
                "thin features of {} were not sampled: sampling every {} mm finds features down to {} mm, which {option} {size} resolves",
                t.unknown.join(" and "),
                size_above(h),
                size_above(2.0 * h)
            ),
            None => format!(
                "thin features of {} are not checked against {option} {size} (their thickness is not stated in the design, and it is unbounded, so it cannot be sampled)",
                t.unknown.join(" and ")
            ),
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_below_with_two_digits() {
        assert_eq!(size_below(0.35), 0.35);
        assert_eq!(size_below(0.3549), 0.35);
        assert_eq!(size_below(1.25), 1.2);
        assert_eq!(size_below(12.7), 12.0);
        assert_eq!(size_below(0.0071), 0.0071);
        assert_eq!(size_above(0.351), 0.36);
        assert_eq!(size_above(0.35), 0.35);
        assert_eq!(size_above(2.01), 2.1);
    }
}
