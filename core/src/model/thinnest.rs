//! The design's thinnest feature, read from the prepared tree: the smallest
//! strut diameter, sphere or cylinder diameter, box side, prism or TPMS
//! wall, or shell, scaled by every `Scale` above it (its smallest factor)
//! and widened or narrowed by every `Offset` (twice its distance).
//!
//! An export samples the design on a grid: a feature thinner than about two
//! cells can fall between the cell centres and vanish, or leave pieces
//! joined at edges and corners. The exports compare this estimate with
//! their cell size before sampling.
//!
//! Geometry whose thickness the tree does not state (meshes, `Function`s,
//! simulation fields) is listed as unknown here and measured by sampling
//! ([`Model::sampled_thinnest`]); gaps between parts are measured apart
//! ([`Model::stated_gaps`]).

use std::collections::HashSet;
use std::sync::Arc;

use super::Model;
use super::pnode::PNode;

/// The thinnest feature found.
#[derive(Clone, Debug, PartialEq)]
pub struct Feature {
    /// Its thickness in mm (a strut's diameter, a wall's thickness).
    pub thickness: f64,
    /// What it is, for messages: "strut radius 0.35 mm".
    pub what: String,
}

/// The estimate over the whole design.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Thinnest {
    /// The thinnest stated feature, if any.
    pub feature: Option<Feature>,
    /// Geometry whose thickness is not stated in the tree (a mesh, a
    /// `Function`, a simulation field) is present: its features are not
    /// covered by `feature`.
    pub unknown: Vec<&'static str>,
}

impl Model {
    /// The design's thinnest stated feature (see the module doc). Walks the
    /// tree with an explicit stack, each shared subtree once per scale.
    pub fn thinnest_feature(&self) -> Thinnest {
        let mut out = Thinnest::default();
        let mut seen: HashSet<(*const PNode, u64, u64)> = HashSet::new();
        // (node, product of Scale factors, sum of Offsets in its frame)
        let mut stack: Vec<(&Arc<PNode>, f64, f64)> = vec![(&self.root, 1.0, 0.0)];
        while let Some((node, k, off)) = stack.pop() {
            if !seen.insert((Arc::as_ptr(node), k.to_bits(), off.to_bits())) {
                continue;
            }
            let mut stated = |t: f64, what: String| {
                let thickness = k * (t + 2.0 * off);
                let thinner = out.feature.as_ref().is_none_or(|f| thickness < f.thickness);
                if thickness > 0.0 && thickness.is_finite() && thinner {
                    out.feature = Some(Feature { thickness, what });
                }
            };
            match node.as_ref() {
                PNode::Sphere { r, .. } => stated(2.0 * r, format!("sphere radius {}", k * r)),
                PNode::Box { h, .. } => stated(
                    2.0 * h.min_element(),
                    format!("box side {}", 2.0 * k * h.min_element()),
                ),
                PNode::Cylinder { r, hh, .. } => {
                    let t = (2.0 * r).min(2.0 * hh);
                    stated(t, format!("cylinder size {}", k * t));
                }
                PNode::Strut { s, .. } => stated(2.0 * s.r, format!("strut radius {}", k * s.r)),
                PNode::Lattice { r, .. } => {
                    stated(2.0 * r, format!("lattice strut radius {}", k * r))
                }
                PNode::Prism { p, .. } => stated(
                    2.0 * p.w_half,
                    format!("prism width {}", 2.0 * k * p.w_half),
                ),
                PNode::Tpms { t, .. } => {
                    stated(t.thickness(), format!("TPMS wall {}", k * t.thickness()))
                }
                PNode::Shell { t, child } => {
                    stated(*t, format!("shell wall {}", k * t));
                    stack.push((child, k, off));
                }
                PNode::Mesh { .. } => out.unknown.push("a mesh"),
                PNode::Function { .. } => out.unknown.push("a Function"),
                PNode::SimField(_) => out.unknown.push("a simulation field"),
                PNode::Translate { child, .. }
                | PNode::Rotate { child, .. }
                | PNode::Tile { child, .. }
                | PNode::Blend { child, .. } => stack.push((child, k, off)),
                PNode::FGrade(g) => stack.push((&g.child, k, off)),
                PNode::AttrGrade { child, .. } => stack.push((child, k, off)),
                PNode::Scale { k: s, child, .. } => stack.push((child, k * s, off / s)),
                // A composed chain of moves scales by at least `a.k`.
                PNode::Affine(a) => stack.push((&a.child, k * a.k, off / a.k)),
                PNode::Mirror { child, .. } => stack.push((child, k, off)),
                PNode::Shape { .. } => out.unknown.push("a cone, torus, revolve or tapered strut"),
                PNode::Text { .. } => out.unknown.push("text"),
                PNode::Sum { children, .. } => {
                    out.unknown.push("a Sum");
                    stack.extend(children.iter().map(|c| (c, k, off)));
                }
                PNode::Offset { o, child } => stack.push((child, k, off + o)),
                PNode::Union(n) | PNode::Intersection(n) => {
                    stack.extend(n.children.iter().map(|c| (c, k, off)))
                }
                PNode::Difference { a, b, .. } => {
                    stack.push((a, k, off));
                    stack.push((b, k, off));
                }
            }
        }
        out.unknown.sort_unstable();
        out.unknown.dedup();
        out
    }
}

#[cfg(test)]
mod tests {
    use crate::script::{ScriptOptions, model_of};

    fn thinnest(src: &str) -> super::Thinnest {
        model_of(src, "t.rhai", &ScriptOptions::default())
            .expect("design prepares")
            .thinnest_feature()
    }

    #[test]
    fn struts_walls_scales_offsets_and_unknowns() {
        let t = thinnest(
            r#"let m = default_materials();
Intersection(false, [Tile(GraphLattice(LatticeType::BodyCenteredCubic, Vec3(5,5,5), 0.35, m.id("gray"))), Sphere(Vec3(0,0,0), 10, m.id("gray"))])"#,
        );
        let f = t.feature.expect("a strut");
        assert!((f.thickness - 0.7).abs() < 1e-12, "{f:?}");
        assert!(f.what.contains("0.35"), "{f:?}");
        assert!(t.unknown.is_empty());
        let t = thinnest(
            r#"let m = default_materials();
Union(false, [Scale(0.5, 0.5, 0.5, RectPrism(Vec3(0,0,0), Vec3(4,4,1), m.id("gray"))), Offset(-0.1, Sphere(Vec3(9,0,0), 2, m.id("gray")))])"#,
        );
        assert!((t.feature.expect("a box").thickness - 0.5).abs() < 1e-12);
        let t = thinnest(r#"Function("x*x+y*y+z*z-1", default_materials().id("gray"))"#);
        assert_eq!((t.feature, t.unknown), (None, vec!["a Function"]));
    }
}
