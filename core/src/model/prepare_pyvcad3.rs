//! Preparing the nodes pyvcad 3 added (cone, torus, revolve, tapered
//! strut, mirror, sum), and Text: split from `prepare.rs` to keep each file
//! readable; the same `Preparer`, whose operands are prepared first.

use glam::DVec3;

use std::sync::Arc;

use super::super::pnode::PNode;
use super::super::shapes::Capsule;
use super::super::shapes::{Beam, Cone, Revolve, Shape};
use super::super::{PrepareError, SubPreparer};
use super::{Preparer, err};
use crate::aabb::Aabb;
use crate::attribute::FractionSource;
use crate::material::MaterialId;
use crate::node::{CapMode, Node, NodeKind};

impl Preparer {
    /// The nodes of pyvcad 3 (`shapes`), Text, and the Mirror and Sum
    /// composites, over their operands prepared before them.
    pub(super) fn build_pyvcad3(&self, n: &Node) -> Result<(PNode, Aabb), PrepareError> {
        let kind = n.kind();
        let shape = |s: Shape, m: MaterialId, this: &Self| {
            let b = s.bbox();
            (
                PNode::Shape {
                    s: Box::new(s),
                    m: this.slot(m),
                },
                b,
            )
        };
        Ok(match kind {
            NodeKind::Cone {
                angle,
                height,
                material,
            } => shape(Shape::Cone(Cone::new(*angle, *height)), *material, self),
            NodeKind::Torus {
                major,
                minor,
                material,
            } => shape(
                Shape::Torus {
                    major: *major,
                    minor: *minor,
                },
                *material,
                self,
            ),
            NodeKind::PolygonRevolve {
                vertices,
                axis_start,
                axis_end,
                sweep_degrees,
                material,
            } => {
                let r = Revolve::build(vertices, *axis_start, *axis_end, *sweep_degrees)
                    .map_err(|m| err(n, &m))?;
                shape(Shape::Revolve(Box::new(r)), *material, self)
            }
            NodeKind::TaperedStrut {
                a,
                b,
                radius_a,
                radius_b,
                cap_a,
                cap_b,
                material,
            } => {
                let rounded = |c: &CapMode| *c != CapMode::Butt;
                if radius_a == radius_b && rounded(cap_a) && rounded(cap_b) {
                    // Equal radii with round ends: a capsule, exactly.
                    let s = Capsule::new(*a, *b, *radius_a);
                    (
                        PNode::Strut {
                            s,
                            m: self.slot(*material),
                        },
                        s.bbox(),
                    )
                } else if a == b {
                    return Err(err(
                        n,
                        "start and end are the same point; a tapered strut needs a length",
                    ));
                } else {
                    let beam = Beam::new(*a, *b, *radius_a, *radius_b, *cap_a, *cap_b);
                    shape(Shape::Beam(beam), *material, self)
                }
            }
            NodeKind::Mirror {
                point,
                normal,
                child,
            } => {
                let (c, b) = self.child(n, child)?;
                let m = super::super::distance_interval::reflection(*normal);
                (
                    PNode::Mirror {
                        point: *point,
                        normal: *normal,
                        child: c,
                    },
                    b.transformed(&m, *point),
                )
            }
            NodeKind::Sum { iso, children } => self.build_sum(n, *iso, children)?,
            NodeKind::Text {
                shape,
                depth,
                material,
                ..
            } => {
                let (lo, hi) = shape.bounds();
                let hz = depth * 0.5;
                (
                    PNode::Text {
                        shape: shape.clone(),
                        hz,
                        m: self.slot(*material),
                    },
                    Aabb::new(DVec3::new(lo.x, lo.y, -hz), DVec3::new(hi.x, hi.y, hz)),
                )
            }
            // Identity with a child is read as its child (`flatten::shape`)
            // unless it converts a scalar to fractions.
            NodeKind::Identity { child: Some(c) } => self.attr_grade(n, c)?,
            NodeKind::Identity { child: None } => {
                return Err(err(
                    n,
                    "has no child; give one in the constructor or with set_child",
                ));
            }
            _ => return Err(err(n, "is not a leaf (a bug in volcad)")),
        })
    }

    /// `Sum`: the children's distances added, with `iso` added to the sum.
    fn build_sum(
        &self,
        n: &Node,
        iso: f64,
        children: &[Node],
    ) -> Result<(PNode, Aabb), PrepareError> {
        if children.is_empty() {
            return Err(err(
                n,
                "has no children; add some with add_child or pass a list",
            ));
        }
        let mut nodes = Vec::with_capacity(children.len());
        let mut bbox = Aabb::EMPTY;
        for c in children {
            let p = self.get(c)?;
            nodes.push(p.node.clone());
            bbox = bbox.union(&p.bbox);
        }
        // Outside every child's box each dᵢ > 0, so Σdᵢ + iso ≤ 0
        // needs every dᵢ ≤ −iso: within −iso of every box.
        Ok((
            PNode::Sum {
                iso,
                children: nodes,
            },
            bbox.expand((-iso).max(0.0)),
        ))
    }
}

impl Preparer {
    /// `Convert(child, from, fractions([a, b]), table)`: the child's
    /// distance, fractions from its attribute `from` (an attribute
    /// evaluator of the child's subtree, whose distances come from this
    /// preparer's cache: the child is prepared already).
    fn attr_grade(&self, n: &Node, c: &Node) -> Result<(PNode, Aabb), PrepareError> {
        let Some(conv) = n.attributes().and_then(|a| a.to_fractions.as_ref()) else {
            return Err(err(n, "was not read as its child (a bug in volcad)"));
        };
        let child = self.get(c)?.clone();
        let mut materials: Vec<(MaterialId, u16)> =
            self.slots.iter().map(|(m, s)| (*m, *s)).collect();
        materials.sort_by_key(|(_, s)| *s);
        let materials: Vec<MaterialId> = materials.into_iter().map(|(m, _)| m).collect();
        let sub = SubPreparer(Preparer {
            slots: self.slots.clone(),
            cache: self.cache.clone(),
        });
        let slots = conv.materials.iter().map(|m| self.slot(*m)).collect();
        let src = FractionSource::build(n, conv, c, &materials, slots, sub)?;
        let node = PNode::AttrGrade {
            child: child.node,
            src: Arc::new(src),
        };
        Ok((node, child.bbox))
    }
}
