//! How prepare reads a node: as written, or as one flat node standing for
//! a chain of nodes that compose.
//!
//! Scripts grow designs in loops (`n = Union(false, [n, s])`, `n =
//! Translate(1, 0, 0, n)`, `n = Difference(n, hole)`), which nests the tree
//! as deep as the loop runs. Evaluation walks the prepared tree
//! recursively, so these chains are read flat here, which also makes them
//! as fast as the same design written as one list:
//!
//! * a sharp, non-blending union (intersection) of sharp, non-blending
//!   unions (intersections) is one union over their children in order
//!   (min and max are associative; the first child containing a point is
//!   the same child; a child listed twice adds nothing);
//! * a union or intersection of one child is that child (same distance,
//!   same fractions);
//! * `Difference(Difference(a, b₁), b₂)` (sharp) is `Difference(a,
//!   Union(b₁, b₂))`: `max(max(a, −b₁), −b₂) = max(a, −min(b₁, b₂))`, and a
//!   difference takes `a`'s fractions;
//! * an FGrade of an FGrade grades the inner child: the inner grade's
//!   fractions are replaced, its distance is its child's;
//! * a run of [`COMPOSE_MIN`] or more moves (Translate, Rotate, Scale)
//!   is one affine map, and of Offsets one offset. Shorter runs stay as
//!   written, so their values stay bit for bit those of each node in turn.

use std::collections::HashSet;

use glam::{DMat3, DVec3};

use super::pnode::{Affine, PNode};
use super::prepare::Prepared;
use crate::aabb::Aabb;
use crate::node::{Node, NodeKind};

/// Runs of moves or offsets at least this long are composed into one node.
pub(super) const COMPOSE_MIN: usize = 8;

/// The way a node is prepared.
pub(super) enum Shape<'a> {
    /// As written, over its own children.
    Plain,
    /// A union or intersection over these operands (more than one).
    NAry(Vec<&'a Node>),
    /// The same as this other node (a union or intersection of one child).
    Same(&'a Node),
    /// Moves, outermost first, over `end`.
    Moves(Vec<&'a NodeKind>, &'a Node),
    /// Offsets whose distances add up to the first, over the second.
    Offsets(Vec<f64>, &'a Node),
    /// `a` minus the union of `rights` (no repeats; from two or more levels).
    Differences(&'a Node, Vec<&'a Node>),
    /// An FGrade (this node's expressions) over `end`.
    Grade(&'a Node),
}

impl<'a> Shape<'a> {
    /// The nodes this one is built from, each prepared before it.
    pub(super) fn operands(&self, n: &'a Node) -> Vec<&'a Node> {
        match self {
            Shape::Plain => n.kind().children(),
            Shape::NAry(ops) => ops.clone(),
            Shape::Same(end)
            | Shape::Moves(_, end)
            | Shape::Offsets(_, end)
            | Shape::Grade(end) => {
                vec![*end]
            }
            Shape::Differences(a, rights) => {
                std::iter::once(*a).chain(rights.iter().copied()).collect()
            }
        }
    }
}

/// True when a union or intersection with this `smooth` takes a plain
/// minimum or maximum (the prepared node clamps `smooth` to ≥ 0).
fn sharp(smooth: f64) -> bool {
    smooth.is_nan() || smooth <= 0.0
}

/// The node that `n` stands for once unions and intersections of one
/// child are skipped.
fn through_single(mut n: &Node) -> &Node {
    loop {
        match n.kind() {
            NodeKind::Union { children, .. } | NodeKind::Intersection { children, .. }
                if children.len() == 1 =>
            {
                n = &children[0];
            }
            _ => return n,
        }
    }
}

/// The key that decides which nested nodes fold into a flat union or
/// intersection: `Some(true)` for a sharp, non-blending union,
/// `Some(false)` for such an intersection.
fn flat_key(n: &Node) -> Option<bool> {
    match n.kind() {
        NodeKind::Union { smooth, blend, .. } if sharp(*smooth) && !blend => Some(true),
        NodeKind::Intersection { smooth, blend, .. } if sharp(*smooth) && !blend => Some(false),
        _ => None,
    }
}

/// How `n` is prepared.
pub(super) fn shape(n: &Node) -> Shape<'_> {
    match n.kind() {
        NodeKind::Union { children, .. } | NodeKind::Intersection { children, .. } => {
            match children.len() {
                0 => Shape::Plain,
                1 => Shape::Same(through_single(&children[0])),
                _ => Shape::NAry(nary_operands(n, children)),
            }
        }
        NodeKind::Translate { child: Some(_), .. }
        | NodeKind::Rotate { child: Some(_), .. }
        | NodeKind::Scale { child: Some(_), .. } => moves(n),
        NodeKind::Offset { child: Some(_), .. } => offsets(n),
        // Identity only marks a frame in the script's tree, unless it
        // converts a scalar to fractions (then it is built as written).
        NodeKind::Identity { child: Some(c) }
            if crate::attribute::fraction_materials(n).is_empty() =>
        {
            Shape::Same(c)
        }
        NodeKind::Difference {
            smooth,
            left: Some(_),
            right: Some(_),
        } if sharp(*smooth) => differences(n),
        NodeKind::FGrade {
            child: Some(child), ..
        } => {
            let mut end = child;
            while let NodeKind::FGrade { child: Some(c), .. } = end.kind() {
                end = c;
            }
            Shape::Grade(end)
        }
        _ => Shape::Plain,
    }
}

/// The operands of a union or intersection with several children: each
/// child past single-child wrappers, and, for a sharp non-blending one,
/// the children of nested ones of the same kind in order, each once. A
/// nested one that carries attributes stays one operand: the attribute
/// evaluator then shares its prepared distance (not a second index of its
/// children) and the top union's walk names it as the child a point is in
/// (`attribute::hint`).
fn nary_operands<'a>(n: &'a Node, children: &'a [Node]) -> Vec<&'a Node> {
    let Some(key) = flat_key(n) else {
        return children.iter().map(through_single).collect();
    };
    let mut out = Vec::with_capacity(children.len());
    let mut seen = HashSet::new();
    let mut stack: Vec<&Node> = children.iter().rev().collect();
    while let Some(c) = stack.pop() {
        let c = through_single(c);
        if !seen.insert(c.ptr()) {
            continue;
        }
        match c.kind() {
            NodeKind::Union { children, .. } | NodeKind::Intersection { children, .. }
                if flat_key(c) == Some(key) && !children.is_empty() && c.attributes().is_none() =>
            {
                stack.extend(children.iter().rev());
            }
            _ => out.push(c),
        }
    }
    out
}

fn is_move(k: &NodeKind) -> bool {
    matches!(
        k,
        NodeKind::Translate { child: Some(_), .. }
            | NodeKind::Rotate { child: Some(_), .. }
            | NodeKind::Scale { child: Some(_), .. }
    )
}

/// The unary node's child (moves and offsets have one).
fn only_child(n: &Node) -> &Node {
    match n.kind().children().first() {
        Some(c) => c,
        None => n,
    }
}

fn moves(n: &Node) -> Shape<'_> {
    let mut chain = Vec::new();
    let mut cur = n;
    while is_move(cur.kind()) {
        chain.push(cur.kind());
        cur = only_child(cur);
    }
    if chain.len() < COMPOSE_MIN {
        return Shape::Plain;
    }
    Shape::Moves(chain, cur)
}

fn offsets(n: &Node) -> Shape<'_> {
    let mut distances = Vec::new();
    let mut cur = n;
    while let NodeKind::Offset {
        distance,
        child: Some(c),
    } = cur.kind()
    {
        distances.push(*distance);
        cur = c;
    }
    if distances.len() < COMPOSE_MIN {
        return Shape::Plain;
    }
    Shape::Offsets(distances, cur)
}

fn differences(n: &Node) -> Shape<'_> {
    let mut rights = Vec::new();
    let mut seen = HashSet::new();
    let mut levels = 0;
    let mut cur = n;
    while let NodeKind::Difference {
        smooth,
        left: Some(l),
        right: Some(r),
    } = cur.kind()
    {
        if !sharp(*smooth) {
            break;
        }
        if seen.insert(r.ptr()) {
            rights.push(r);
        }
        levels += 1;
        cur = through_single(l);
    }
    if levels < 2 {
        return Shape::Plain;
    }
    Shape::Differences(cur, rights)
}

/// One affine node for a chain of moves (outermost first) over `child`:
/// the query point goes through each move in turn, `q = m·p + t`, and the
/// distance is scaled by each Scale's `min |s|` (see `PNode::Scale`). The
/// box goes through them in the other order, as the nested nodes' would.
pub(super) fn compose_moves(chain: &[&NodeKind], child: &Prepared) -> (PNode, Aabb) {
    let (mut m, mut t, mut k) = (DMat3::IDENTITY, DVec3::ZERO, 1.0);
    for kind in chain {
        match kind {
            NodeKind::Translate { offset, .. } => t -= *offset,
            NodeKind::Rotate {
                pitch,
                yaw,
                roll,
                around,
                ..
            } => {
                let l = rotation(*pitch, *yaw, *roll).transpose();
                m = l * m;
                t = l * (t - *around) + *around;
            }
            NodeKind::Scale { factors, .. } => {
                let inv = DVec3::ONE / *factors;
                m = DMat3::from_diagonal(inv) * m;
                t *= inv;
                k *= factors.abs().min_element();
            }
            _ => {}
        }
    }
    let mut bbox = child.bbox;
    for kind in chain.iter().rev() {
        bbox = match kind {
            NodeKind::Translate { offset, .. } => Aabb::new(bbox.min + *offset, bbox.max + *offset),
            NodeKind::Rotate {
                pitch,
                yaw,
                roll,
                around,
                ..
            } => bbox.transformed(&rotation(*pitch, *yaw, *roll), *around),
            NodeKind::Scale { factors, .. } => bbox.scaled(*factors),
            _ => bbox,
        };
    }
    let node = PNode::Affine(Box::new(Affine {
        m,
        t,
        k,
        child: child.node.clone(),
    }));
    (node, bbox)
}

/// R = Rz(roll)·Ry(yaw)·Rx(pitch), degrees (pyvcad's convention for its
/// bounding box; we rotate the geometry by the same R, see docs/PYVCAD.md).
pub fn rotation(pitch: f64, yaw: f64, roll: f64) -> DMat3 {
    DMat3::from_rotation_z(roll.to_radians())
        * DMat3::from_rotation_y(yaw.to_radians())
        * DMat3::from_rotation_x(pitch.to_radians())
}
