//! Script tree -> prepared tree: resolve materials to dense slots, compute
//! bounding boxes, build spatial indices, check what can only be checked
//! with the whole tree (missing children, unbounded tiles).

use crate::expr::ExprSet;
use std::collections::{BTreeSet, HashMap};
use std::sync::Arc;

use glam::DVec3;

use super::flatten::{self, Shape, compose_moves, rotation};
use super::pnode::{Grade, LineCapsule, NAry, PNode, SimGrade, Slot};
use super::shapes::Capsule;
use super::strut_grid::{StrutGrid, octant_struts};
use super::tpms::Tpms;
use super::union_index::UnionIndex;
use super::{MAX_MATERIALS, PrepareError};
use crate::aabb::Aabb;
use crate::material::MaterialId;
use crate::node::{Node, NodeKind};

/// Unions with at least this many sharp children get a spatial index.
const INDEX_MIN_CHILDREN: usize = 8;

#[path = "prepare_prism.rs"]
mod prism;
#[path = "prepare_pyvcad3.rs"]
mod pyvcad3;

use prism::prism;

pub(super) struct Preparer {
    slots: HashMap<MaterialId, Slot>,
    cache: HashMap<*const NodeKind, Prepared>,
}

/// A prepared node, with what the limits below need.
#[derive(Clone)]
pub(super) struct Prepared {
    pub(super) node: Arc<PNode>,
    pub(super) bbox: Aabb,
    /// Levels of prepared nodes down to the deepest leaf.
    depth: u32,
    /// Nodes when each shared one is counted at every use (what an
    /// evaluation may visit), saturating.
    size: u64,
}

/// Deepest prepared tree: evaluation, intervals and fraction bounds recurse
/// once a level, each level a few hundred bytes of a thread's stack (the
/// fraction bounds' scratch arrays are 1 KiB), and a thread may have 2 MiB.
pub(super) const MAX_DEPTH: u32 = 500;

/// Most nodes a prepared tree may expand to (see [`Prepared::size`]).
pub(super) const MAX_EXPANDED: u64 = 1 << 24;

/// Every material id used in the tree, ascending.
pub(super) fn collect_materials(root: &Node) -> Vec<MaterialId> {
    let mut set = BTreeSet::new();
    let mut seen = std::collections::HashSet::new();
    let mut stack = vec![root];
    while let Some(n) = stack.pop() {
        if !seen.insert(n.ptr()) {
            continue;
        }
        let converted = crate::attribute::fraction_materials(n);
        set.extend(n.kind().own_materials().iter().chain(converted).copied());
        // FGrade replaces its child's materials (pyvcad's material_list
        // leaves them out too), so its child is not visited.
        if !matches!(n.kind(), NodeKind::FGrade { .. }) {
            stack.extend(n.kind().children());
        }
    }
    set.into_iter().collect()
}

impl Preparer {
    pub(super) fn new(materials: &[MaterialId]) -> Result<Self, PrepareError> {
        if materials.len() > MAX_MATERIALS {
            return Err(PrepareError {
                node: "design".into(),
                message: format!(
                    "uses {} materials; at most {MAX_MATERIALS} fit in one design",
                    materials.len()
                ),
            });
        }
        let slots = materials
            .iter()
            .enumerate()
            .map(|(i, m)| (*m, i as Slot))
            .collect();
        Ok(Self {
            slots,
            cache: HashMap::new(),
        })
    }

    /// Dense slot of `m`. Leaves under an FGrade keep no slot of their own
    /// (their fractions are never asked for) and get slot 0.
    fn slot(&self, m: MaterialId) -> Slot {
        self.slots.get(&m).copied().unwrap_or(0)
    }

    /// Prepare `root`: every node once (cached by identity, so shared
    /// subtrees are prepared once), children before parents, in a loop
    /// with its own stack (trees can be a million levels deep before
    /// `flatten` reads their chains flat).
    pub(super) fn prepare(&mut self, root: &Node) -> Result<(Arc<PNode>, Aabb), PrepareError> {
        let mut stack = vec![(root, false)];
        while let Some((n, ready)) = stack.pop() {
            if self.cache.contains_key(&n.ptr()) {
                continue;
            }
            let shape = flatten::shape(n);
            if ready {
                let out = self.build_shape(n, shape)?;
                self.cache.insert(n.ptr(), out);
                continue;
            }
            stack.push((n, true));
            for c in shape.operands(n).into_iter().rev() {
                if !self.cache.contains_key(&c.ptr()) {
                    stack.push((c, false));
                }
            }
        }
        let out = self.get(root)?;
        Ok((out.node.clone(), out.bbox))
    }

    /// An operand already prepared (operands are prepared first).
    fn get(&self, n: &Node) -> Result<&Prepared, PrepareError> {
        self.cache
            .get(&n.ptr())
            .ok_or_else(|| err(n, "was not prepared before its parent (a bug in volcad)"))
    }

    fn build_shape(&mut self, n: &Node, shape: Shape<'_>) -> Result<Prepared, PrepareError> {
        let (mut depth, mut size) = (0u32, 1u64);
        for c in shape.operands(n) {
            let p = self.get(c)?;
            depth = depth.max(p.depth);
            size = size.saturating_add(p.size);
        }
        let (node, bbox) = match shape {
            Shape::Same(end) => return Ok(self.get(end)?.clone()),
            Shape::Plain => self.build(n)?,
            Shape::NAry(ops) => self.nary_node(n, &ops)?,
            Shape::Moves(chain, end) => compose_moves(&chain, self.get(end)?),
            Shape::Offsets(distances, end) => {
                let c = self.get(end)?;
                let bbox = distances.iter().rev().fold(c.bbox, |b, d| b.expand(*d));
                let o = distances.iter().rev().sum();
                let child = c.node.clone();
                (PNode::Offset { o, child }, bbox)
            }
            Shape::Differences(a, rights) => {
                let a = self.get(a)?.clone();
                let b = self.union_of(&rights)?;
                (
                    PNode::Difference {
                        a: a.node,
                        b,
                        smooth: 0.0,
                    },
                    a.bbox,
                )
            }
            Shape::Grade(end) => {
                let child = self.get(end)?.clone();
                self.grade(n, child)?
            }
        };
        let depth = depth + 1;
        if depth > MAX_DEPTH {
            return Err(err(
                n,
                &format!(
                    "is nested {depth} levels deep, more than the {MAX_DEPTH} an evaluation can follow \
                     (chains of sharp Unions, Intersections, Differences, FGrades, moves and Offsets \
                     are read flat; smooth unions, Blends, Shells, Tiles and mixed chains are not); a loop that wraps the design again \
                     on every pass builds this: collect the parts in an array and make one node of \
                     it, Union(false, parts), or wrap fewer times"
                ),
            ));
        }
        if size > MAX_EXPANDED {
            return Err(err(
                n,
                &format!(
                    "expands to {size} nodes when each shared part is counted at every use (at most \
                     {MAX_EXPANDED}), and an evaluation may visit them all; a node added to itself \
                     in a loop (a.add_child(a)) doubles it on every pass: build each part once and \
                     list the parts in one Union"
                ),
            ));
        }
        Ok(Prepared {
            node: Arc::new(node),
            bbox,
            depth,
            size,
        })
    }

    fn child(&self, parent: &Node, c: &Option<Node>) -> Result<(Arc<PNode>, Aabb), PrepareError> {
        match c {
            Some(c) => {
                let p = self.get(c)?;
                Ok((p.node.clone(), p.bbox))
            }
            None => Err(err(
                parent,
                "has no child; give one in the constructor or with set_child",
            )),
        }
    }

    /// `n` as a distance node over its prepared children, and its box.
    // Its arms take the same node fields apart as the attributes'
    // `Builder::op` (core/src/attribute/prepared.rs) and look alike, but
    // build a distance node, not a point move.
    fn build(&mut self, n: &Node) -> Result<(PNode, Aabb), PrepareError> {
        Ok(match n.kind() {
            NodeKind::Translate { offset, child } => {
                let (c, b) = self.child(n, child)?;
                (
                    PNode::Translate {
                        t: *offset,
                        child: c,
                    },
                    Aabb::new(b.min + *offset, b.max + *offset),
                )
            }
            NodeKind::Rotate {
                pitch,
                yaw,
                roll,
                around,
                child,
            } => {
                let (c, b) = self.child(n, child)?;
                let r = rotation(*pitch, *yaw, *roll);
                (
                    PNode::Rotate {
                        to_local: r.transpose(),
                        around: *around,
                        child: c,
                    },
                    b.transformed(&r, *around),
                )
            }
            NodeKind::Scale { factors, child } => {
                let (c, b) = self.child(n, child)?;
                let k = factors.abs().min_element();
                (
                    PNode::Scale {
                        inv: DVec3::ONE / *factors,
                        k,
                        child: c,
                    },
                    b.scaled(*factors),
                )
            }
            // With children, these are `Shape::NAry` or `Shape::Same`.
            NodeKind::Union { .. } | NodeKind::Intersection { .. } => {
                return Err(err(
                    n,
                    "has no children; add some with add_child or pass a list",
                ));
            }
            NodeKind::Difference {
                smooth,
                left,
                right,
            } => {
                let (a, ba) = self.child(n, left)?;
                let b = match right {
                    Some(r) => self.get(r)?.node.clone(),
                    None => return Err(err(n, "has no right child (the part to subtract)")),
                };
                (
                    PNode::Difference {
                        a,
                        b,
                        smooth: *smooth,
                    },
                    ba,
                )
            }
            NodeKind::Offset { distance, child } => {
                let (c, b) = self.child(n, child)?;
                (
                    PNode::Offset {
                        o: *distance,
                        child: c,
                    },
                    b.expand(*distance),
                )
            }
            NodeKind::Shell { thickness, child } => {
                let (c, b) = self.child(n, child)?;
                (
                    PNode::Shell {
                        t: thickness.abs(),
                        child: c,
                    },
                    b,
                )
            }
            NodeKind::Tile { cell, child } => {
                let (c, b) = self.child(n, child)?;
                let cell = match cell {
                    Some(c) => *c,
                    None if b.is_finite() && b.size().min_element() > 0.0 => b.size(),
                    None => {
                        return Err(err(
                            n,
                            "cannot take its cell size from a child with an unbounded or flat box; give the cell size: Tile(cx, cy, cz, child)",
                        ));
                    }
                };
                (PNode::Tile { cell, child: c }, Aabb::EVERYTHING)
            }
            // With a child, this is `Shape::Grade`.
            NodeKind::FGrade { child, .. } => {
                self.child(n, child)?;
                return Err(err(n, "was not read as a grade (a bug in volcad)"));
            }
            NodeKind::Blend { radius, child } => {
                let (c, b) = self.child(n, child)?;
                (
                    PNode::Blend {
                        r: *radius,
                        child: c,
                    },
                    b,
                )
            }
            _ => self.build_leaf(n)?,
        })
    }

    /// A leaf: a primitive, lattice, mesh or FEA field.
    fn build_leaf(&self, n: &Node) -> Result<(PNode, Aabb), PrepareError> {
        Ok(match n.kind() {
            NodeKind::Sphere {
                center,
                radius,
                material,
            } => (
                PNode::Sphere {
                    c: *center,
                    r: *radius,
                    m: self.slot(*material),
                },
                Aabb::from_center_size(*center, DVec3::splat(2.0 * radius)),
            ),
            NodeKind::RectPrism {
                center,
                size,
                material,
            } => (
                PNode::Box {
                    c: *center,
                    h: *size * 0.5,
                    m: self.slot(*material),
                },
                Aabb::from_center_size(*center, *size),
            ),
            NodeKind::Cylinder {
                center,
                radius,
                height,
                material,
            } => (
                PNode::Cylinder {
                    c: *center,
                    r: *radius,
                    hh: height * 0.5,
                    m: self.slot(*material),
                },
                Aabb::from_center_size(*center, DVec3::new(2.0 * radius, 2.0 * radius, *height)),
            ),
            NodeKind::Strut {
                a,
                b,
                radius,
                material,
            } => {
                let s = Capsule::new(*a, *b, *radius);
                (
                    PNode::Strut {
                        s,
                        m: self.slot(*material),
                    },
                    s.bbox(),
                )
            }
            NodeKind::PolygonExtrude {
                vertices,
                height,
                symmetric,
                material,
            } => {
                let (prism, bbox) = prism(vertices, *height, *symmetric).map_err(|m| err(n, &m))?;
                (
                    PNode::Prism {
                        p: Box::new(prism),
                        m: self.slot(*material),
                    },
                    bbox,
                )
            }
            _ => self.build_field(n)?,
        })
    }

    /// A leaf defined by a field or a list: a math string, TPMS,
    /// lattice, mesh or FEA field.
    fn build_field(&self, n: &Node) -> Result<(PNode, Aabb), PrepareError> {
        Ok(match n.kind() {
            NodeKind::Function {
                expr,
                material,
                min,
                max,
            } => {
                let clip = Aabb::new(*min, *max);
                (
                    PNode::Function {
                        expr: expr.clone(),
                        clip_c: clip.center(),
                        clip_h: clip.size() * 0.5,
                        m: self.slot(*material),
                    },
                    clip,
                )
            }
            NodeKind::Tpms {
                kind,
                cell,
                thickness,
                material,
            } => (
                PNode::Tpms {
                    t: Tpms::new(*kind, *cell, *thickness),
                    m: self.slot(*material),
                },
                Aabb::EVERYTHING,
            ),
            NodeKind::GraphLattice {
                edges,
                cell,
                radius,
                material,
            } => {
                let struts: Vec<Capsule> = edges
                    .iter()
                    .map(|(a, b)| Capsule::new(*a, *b, *radius))
                    .collect();
                let bbox = match cell {
                    Some(c) => Aabb::from_center_size(DVec3::ZERO, *c),
                    None => struts.iter().fold(Aabb::EMPTY, |b, s| b.union(&s.bbox())),
                };
                // Symmetric cells are evaluated at `|p|` over the struts of
                // the positive octant (see `octant_struts`).
                let (struts, fold) = match octant_struts(&struts) {
                    Some(few) => (few, true),
                    None => (struts, false),
                };
                (
                    PNode::Lattice {
                        grid: cell.and_then(|c| StrutGrid::new(&struts, c * 0.5).map(Box::new)),
                        struts,
                        fold,
                        r: *radius,
                        clip_h: cell.map(|c| c * 0.5),
                        m: self.slot(*material),
                    },
                    bbox,
                )
            }
            NodeKind::Mesh { mesh, material } => (
                PNode::Mesh {
                    mesh: mesh.clone(),
                    m: self.slot(*material),
                },
                mesh.bbox(),
            ),
            NodeKind::SimulationField {
                field,
                exprs,
                materials,
            } => {
                too_many_expressions(n, exprs.len())?;
                let used = exprs.iter().fold(0, |m, e| m | e.used_vars());
                let mats = materials.iter().map(|m| self.slot(*m)).collect();
                let bbox = field.bbox();
                (
                    PNode::SimField(Box::new(SimGrade {
                        field: field.clone(),
                        exprs: exprs.clone(),
                        set: ExprSet::new(exprs.clone()),
                        mats,
                        used,
                    })),
                    bbox,
                )
            }
            _ => self.build_pyvcad3(n)?,
        })
    }

    /// An FGrade node `n` over the prepared `child`.
    fn grade(&self, n: &Node, child: Prepared) -> Result<(PNode, Aabb), PrepareError> {
        let NodeKind::FGrade {
            exprs, materials, ..
        } = n.kind()
        else {
            return Err(err(n, "is not an FGrade (a bug in volcad)"));
        };
        too_many_expressions(n, exprs.len())?;
        let used = exprs.iter().fold(0, |m, e| m | e.used_vars());
        let mats = materials.iter().map(|m| self.slot(*m)).collect();
        let grade = Grade {
            exprs: exprs.clone(),
            set: ExprSet::new(exprs.clone()),
            mats,
            used,
            child: child.node,
        };
        Ok((PNode::FGrade(Box::new(grade)), child.bbox))
    }

    /// A union or intersection node `n` over its (flattened) operands.
    fn nary_node(&self, n: &Node, ops: &[&Node]) -> Result<(PNode, Aabb), PrepareError> {
        let (smooth, blend, is_union) = match n.kind() {
            NodeKind::Union { smooth, blend, .. } => (*smooth, *blend, true),
            NodeKind::Intersection { smooth, blend, .. } => (*smooth, *blend, false),
            _ => return Err(err(n, "is not a union or intersection (a bug in volcad)")),
        };
        let parts = ops
            .iter()
            .map(|c| self.get(c).cloned())
            .collect::<Result<Vec<_>, _>>()?;
        let nary = nary(parts, smooth, blend, is_union);
        Ok(if is_union {
            let bbox = nary.boxes.iter().fold(Aabb::EMPTY, |a, b| a.union(b));
            (PNode::Union(Box::new(nary)), bbox.expand(smooth.max(0.0)))
        } else {
            let bbox = nary
                .boxes
                .iter()
                .fold(Aabb::EVERYTHING, |a, b| a.intersection(b));
            (PNode::Intersection(Box::new(nary)), bbox)
        })
    }

    /// The sharp union of `ops` (one operand: itself).
    fn union_of(&self, ops: &[&Node]) -> Result<Arc<PNode>, PrepareError> {
        let parts = ops
            .iter()
            .map(|c| self.get(c).cloned())
            .collect::<Result<Vec<_>, _>>()?;
        if parts.len() == 1 {
            return Ok(parts[0].node.clone());
        }
        Ok(Arc::new(PNode::Union(Box::new(nary(
            parts, 0.0, false, true,
        )))))
    }
}

/// A union or intersection over prepared children (at least one).
fn nary(mut parts: Vec<Prepared>, smooth: f64, blend: bool, is_union: bool) -> NAry {
    if !blend && smooth <= 0.0 {
        // A leaf equal to an earlier one changes neither the minimum (or
        // maximum) nor which child first contains a point; a union of
        // thousands of coincident spheres lists one.
        let mut seen = std::collections::HashSet::new();
        parts.retain(|p| p.node.leaf_key().is_none_or(|k| seen.insert(k)));
    }
    let boxes: Vec<Aabb> = parts.iter().map(|p| p.bbox).collect();
    let nodes: Vec<Arc<PNode>> = parts.into_iter().map(|p| p.node).collect();
    let lipschitz = smooth <= 0.0 && nodes.iter().all(|n| n.is_lipschitz());
    // 1-Lipschitz children are listed by `d(centre) − half diagonal`, so
    // queries can tighten it to `d(centre) − |p − centre|` (the slack).
    let index = (is_union && smooth <= 0.0 && nodes.len() >= INDEX_MIN_CHILDREN).then(|| {
        UnionIndex::build(&boxes, |i, cell| {
            if lipschitz {
                nodes[i].dist(cell.center()) - cell.half_diagonal()
            } else {
                nodes[i].interval(cell).lo
            }
        })
    });
    let capsules = if nodes.iter().any(|n| NAry::capsule_of(n).is_some()) {
        nodes
            .iter()
            .map(|n| LineCapsule::of(NAry::capsule_of(n)))
            .collect()
    } else {
        Vec::new()
    };
    let fixed = nodes.iter().map(|n| n.fixed_fractions()).collect();
    NAry {
        children: nodes,
        boxes,
        smooth: smooth.max(0.0),
        blend,
        index,
        capsules,
        fixed,
        lipschitz,
    }
}

/// A grade evaluates its expressions into a scratch array of
/// [`MAX_MATERIALS`] values (one per listed material; a material may be
/// listed more than once, so the design's material limit does not bound
/// them).
fn too_many_expressions(n: &Node, count: usize) -> Result<(), PrepareError> {
    if count > MAX_MATERIALS {
        return Err(err(
            n,
            &format!("has {count} expressions; at most {MAX_MATERIALS} fit in one grade"),
        ));
    }
    Ok(())
}

fn err(n: &Node, message: &str) -> PrepareError {
    PrepareError {
        node: n.describe(),
        message: message.to_owned(),
    }
}
