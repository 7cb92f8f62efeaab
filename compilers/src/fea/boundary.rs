//! The deck's end node sets, `NBOTTOM` (clamped by `--step`) and `NTOP`
//! (moved), chosen so that the step compresses the part rather than poking
//! it at a few points:
//!
//! * by default, every node closer than one element size to the lowest
//!   (highest) z, or closer than `--fix-band MM`;
//! * or the nodes where a math string of x, y, z is true (non-zero):
//!   `--fix "z<0.5"`, `--load "z>29.5"`, for parts without flat ends.
//!
//! Each set is reported with its node count and the boundary area it
//! covers: the boundary faces whose every node is in the set, and their
//! projection on the xy plane against the part's footprint (the projection
//! of the whole boundary, rasterised). A set under a fifth of the
//! footprint gets a warning.

use glam::DVec3;
use serde::Serialize;
use volcad_core::expr::Expr;

use super::topology::Face;
use crate::job::ExportError;

/// A set covering less than this fraction of the footprint is warned about.
pub const SMALL_SET: f64 = 0.2;
/// Cells along the longer side of the footprint raster.
const RASTER: usize = 512;

/// How `NBOTTOM` and `NTOP` are chosen.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct EndSets {
    /// Width (mm) of the bands at the lowest and highest z (`None`: one
    /// element size).
    pub band: Option<f64>,
    /// A math string of x, y, z selecting `NBOTTOM` instead of the band.
    pub fix: Option<String>,
    /// The same for `NTOP`.
    pub load: Option<String>,
}

impl NodeSet {
    /// Set the areas from the mesh's boundary faces.
    pub fn measure(&mut self, nodes: &[DVec3], boundary: &[Face]) {
        (self.area, self.projected) = covered(nodes, boundary, &self.ids);
    }
}

/// One chosen set.
#[derive(Clone, Debug, PartialEq)]
pub struct NodeSet {
    /// 1-based node ids, ascending.
    pub ids: Vec<u32>,
    /// Boundary area whose faces lie wholly in the set (mm²).
    pub area: f64,
    /// That area projected on the xy plane (mm²).
    pub projected: f64,
    /// How it was chosen, for the summary.
    pub rule: String,
}

fn select(
    nodes: &[DVec3],
    option: &str,
    expr: &str,
    zspan: (f64, f64),
) -> Result<(Vec<u32>, String), ExportError> {
    let e = Expr::compile(expr, &["x", "y", "z"]).map_err(|err| {
        ExportError::param(
            option,
            format!("\"{expr}\": {err} (a condition on x, y, z in mm, e.g. \"z<0.5\")"),
        )
    })?;
    let ids: Vec<u32> = nodes
        .iter()
        .enumerate()
        .filter(|(_, p)| {
            let v = e.eval(&[p.x, p.y, p.z]);
            v != 0.0 && !v.is_nan()
        })
        .map(|(i, _)| i as u32 + 1)
        .collect();
    if ids.is_empty() {
        return Err(ExportError::param(
            option,
            format!(
                "\"{expr}\" selects no node; the mesh spans z {:.4} … {:.4} mm",
                zspan.0, zspan.1
            ),
        ));
    }
    Ok((ids, format!("{option} \"{expr}\"")))
}

fn band(nodes: &[DVec3], width: f64, bottom: bool, z: f64) -> Vec<u32> {
    // Strictly closer than the width: on a brick grid the next layer of
    // nodes sits exactly one voxel up and stays free.
    let w = width * (1.0 - 1e-9);
    nodes
        .iter()
        .enumerate()
        .filter(|(_, p)| if bottom { p.z - z < w } else { z - p.z < w })
        .map(|(i, _)| i as u32 + 1)
        .collect()
}

fn tri_areas(a: DVec3, b: DVec3, c: DVec3) -> (f64, f64) {
    let n = (b - a).cross(c - a);
    (0.5 * n.length(), 0.5 * n.z.abs())
}

/// The face's triangles (one, or a quad's two), as node indices.
fn triangles(f: &Face) -> impl Iterator<Item = [usize; 3]> + '_ {
    let quad = f[3] != u32::MAX;
    let first = [f[0], f[1], f[2]].map(|i| i as usize);
    let second = [f[0], f[2], f[3]].map(|i| i as usize);
    std::iter::once(first).chain(quad.then_some(second))
}

/// The boundary area (mm²) whose faces lie wholly in the set `ids`
/// (1-based), and its projection on the xy plane.
pub fn covered(nodes: &[DVec3], boundary: &[Face], ids: &[u32]) -> (f64, f64) {
    let mut member = vec![false; nodes.len()];
    for &i in ids {
        member[i as usize - 1] = true;
    }
    let (mut area, mut projected) = (0.0, 0.0);
    for f in boundary {
        let n = if f[3] == u32::MAX { 3 } else { 4 };
        if f[..n].iter().all(|&i| member[i as usize]) {
            for [a, b, c] in triangles(f) {
                let (s, p) = tri_areas(nodes[a], nodes[b], nodes[c]);
                area += s;
                projected += p;
            }
        }
    }
    (area, projected)
}

/// The part's footprint (mm²): the area of the union of the boundary's
/// projections on the xy plane, counted on a raster of cell centres.
pub fn footprint(nodes: &[DVec3], boundary: &[Face]) -> f64 {
    let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
    for p in nodes {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    let span = (hi - lo).truncate().max_element();
    if span.is_nan() || span <= 0.0 {
        return 0.0;
    }
    let cell = span / RASTER as f64;
    let nx = ((hi.x - lo.x) / cell).ceil() as usize + 1;
    let ny = ((hi.y - lo.y) / cell).ceil() as usize + 1;
    let mut hit = vec![false; nx * ny];
    for f in boundary {
        for [a, b, c] in triangles(f) {
            let [a, b, c] = [nodes[a], nodes[b], nodes[c]].map(|p| (p - lo).truncate() / cell);
            let twice = (b - a).perp_dot(c - a);
            if twice.abs() < 1e-12 {
                continue;
            }
            let (mn, mx) = (a.min(b).min(c), a.max(b).max(c));
            let (i0, i1) = (
                mn.x.floor().max(0.0) as usize,
                (mx.x.ceil() as usize).min(nx),
            );
            let (j0, j1) = (
                mn.y.floor().max(0.0) as usize,
                (mx.y.ceil() as usize).min(ny),
            );
            for j in j0..j1 {
                for i in i0..i1 {
                    let q = glam::DVec2::new(i as f64 + 0.5, j as f64 + 0.5);
                    let s = twice.signum();
                    let inside = s * (b - a).perp_dot(q - a) >= 0.0
                        && s * (c - b).perp_dot(q - b) >= 0.0
                        && s * (a - c).perp_dot(q - c) >= 0.0;
                    hit[j * nx + i] |= inside;
                }
            }
        }
    }
    hit.iter().filter(|h| **h).count() as f64 * cell * cell
}

/// The lowest and highest z of `nodes`.
pub fn z_span(nodes: &[DVec3]) -> (f64, f64) {
    nodes
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
            (a.min(p.z), b.max(p.z))
        })
}

/// `NBOTTOM` and `NTOP` of a mesh with these nodes; `element` is the
/// element size the default band uses. Their areas are left at 0 for
/// [`NodeSet::measure`] (the boundary faces come later, computed while the
/// deck is written).
pub fn end_sets(
    nodes: &[DVec3],
    rule: &EndSets,
    element: f64,
) -> Result<(NodeSet, NodeSet), ExportError> {
    let (zmin, zmax) = z_span(nodes);
    let width = match rule.band {
        Some(w) if !(w.is_finite() && w > 0.0) => {
            return Err(ExportError::param(
                "--fix-band",
                format!("the band must be a width > 0 mm, got {w}"),
            ));
        }
        Some(w) => w,
        None => element,
    };
    let pick = |expr: &Option<String>, option: &str, bottom: bool| {
        Ok::<_, ExportError>(match expr {
            Some(e) => select(nodes, option, e, (zmin, zmax))?,
            None => {
                let (z, end) = if bottom {
                    (zmin, "lowest")
                } else {
                    (zmax, "highest")
                };
                (
                    band(nodes, width, bottom, z),
                    format!("within {width} mm of the {end} z ({z:.4})"),
                )
            }
        })
    };
    let (bottom, b_rule) = pick(&rule.fix, "--fix", true)?;
    let (top, t_rule) = pick(&rule.load, "--load", false)?;
    let shared = count_shared(&bottom, &top);
    if shared > 0 {
        return Err(ExportError::param(
            if rule.fix.is_some() {
                "--fix"
            } else {
                "--load"
            },
            format!(
                "NBOTTOM ({b_rule}) and NTOP ({t_rule}) share {shared} nodes, which cannot be both clamped and moved; choose sets apart (a narrower --fix-band, or --fix/--load conditions that do not overlap)"
            ),
        ));
    }
    let set = |ids: Vec<u32>, rule: String| NodeSet {
        ids,
        area: 0.0,
        projected: 0.0,
        rule,
    };
    Ok((set(bottom, b_rule), set(top, t_rule)))
}

/// `z` with three significant digits, for an example option value.
fn round_for_option(z: f64) -> f64 {
    let text = format!("{z:.3e}");
    text.parse().unwrap_or(z)
}

fn count_shared(a: &[u32], b: &[u32]) -> usize {
    let (mut i, mut j, mut n) = (0, 0, 0);
    while i < a.len() && j < b.len() {
        match a[i].cmp(&b[j]) {
            std::cmp::Ordering::Less => i += 1,
            std::cmp::Ordering::Greater => j += 1,
            std::cmp::Ordering::Equal => {
                n += 1;
                i += 1;
                j += 1;
            }
        }
    }
    n
}

/// Summary lines for the two sets against the footprint, warnings
/// written as `warning: …`; `zspan` is the mesh's lowest and highest z, for
/// the example conditions (the tenth of the height at each end).
pub fn notes(bottom: &NodeSet, top: &NodeSet, footprint: f64, zspan: (f64, f64)) -> Vec<String> {
    let tenth = 0.1 * (zspan.1 - zspan.0);
    let examples = [
        format!("z<{}", round_for_option(zspan.0 + tenth)),
        format!("z>{}", round_for_option(zspan.1 - tenth)),
    ];
    let mut out = Vec::new();
    for ((name, s, option), example) in [("NBOTTOM", bottom, "--fix"), ("NTOP", top, "--load")]
        .into_iter()
        .zip(examples)
    {
        let share = if footprint > 0.0 {
            s.projected / footprint
        } else {
            1.0
        };
        out.push(format!(
            "{name}: {} nodes {}, {:.4} mm² of surface ({:.4} mm² seen from z, {:.0} % of the part's {:.4} mm² footprint)",
            s.ids.len(),
            s.rule,
            s.area,
            s.projected,
            100.0 * share,
            footprint
        ));
        if share < SMALL_SET {
            out.push(format!(
                "warning: {name} covers only {:.1} % of the part's footprint: a step on it pokes the part at a few points rather than loading its end; widen the band (--fix-band MM) or select the nodes with {option} (e.g. {option} \"{example}\")",
                100.0 * share,
            ));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit square's two triangles at z = 0 and a triangle at z = 1
    /// covering half of it.
    fn plate() -> (Vec<DVec3>, Vec<Face>) {
        let nodes = vec![
            DVec3::new(0., 0., 0.),
            DVec3::new(1., 0., 0.),
            DVec3::new(1., 1., 0.),
            DVec3::new(0., 1., 0.),
            DVec3::new(0., 0., 1.),
            DVec3::new(1., 0., 1.),
            DVec3::new(1., 1., 1.),
        ];
        let faces = vec![[0, 1, 2, 3], [4, 5, 6, u32::MAX]];
        (nodes, faces)
    }

    #[test]
    fn bands_expressions_areas_and_footprint() {
        let (nodes, faces) = plate();
        assert!((footprint(&nodes, &faces) - 1.0).abs() < 0.01);
        let sets = |rule: &EndSets| {
            end_sets(&nodes, rule, 0.5).map(|(mut b, mut t)| {
                b.measure(&nodes, &faces);
                t.measure(&nodes, &faces);
                (b, t)
            })
        };
        let (b, t) = sets(&EndSets::default()).unwrap();
        assert_eq!(
            (b.ids.clone(), t.ids.clone()),
            (vec![1, 2, 3, 4], vec![5, 6, 7])
        );
        assert!((b.area - 1.0).abs() < 1e-12 && (t.projected - 0.5).abs() < 1e-12);
        let n = notes(&b, &t, 1.0, (0.0, 1.0));
        assert!(!n.iter().any(|l| l.starts_with("warning")), "{n:?}");
        let rule = EndSets {
            fix: Some("z<0.5 and x<0.5".into()),
            ..EndSets::default()
        };
        let (b, _) = sets(&rule).unwrap();
        assert_eq!((b.ids.clone(), b.area), (vec![1, 4], 0.0));
        let n = notes(&b, &t, 1.0, (0.0, 30.0));
        assert!(
            n[1].starts_with("warning: NBOTTOM covers only 0.0 %"),
            "{n:?}"
        );
        assert!(n[1].ends_with(r#"--fix "z<3")"#), "{n:?}");
        let empty = EndSets {
            load: Some("z>2".into()),
            ..EndSets::default()
        };
        let e = sets(&empty).unwrap_err().to_string();
        assert!(e.contains("--load") && e.contains("selects no node"), "{e}");
        let wide = EndSets {
            band: Some(2.0),
            ..EndSets::default()
        };
        let e = sets(&wide).unwrap_err().to_string();
        assert!(e.contains("share 7 nodes"), "{e}");
        let bad = EndSets {
            fix: Some("z<".into()),
            ..EndSets::default()
        };
        let e = sets(&bad).unwrap_err().to_string();
        assert!(e.contains("--fix") && e.contains("z<"), "{e}");
    }
}
