//! One walk of the design's top union for the distance, the fractions and
//! the attributes.
//!
//! Why: a union's attribute goes to the first child containing the point
//! (unless it names a resolver), and the distance walk of a sharp union
//! already finds that child to write its fractions (`NAry::union_eval`,
//! through the union's index of lower bounds). Asking the attribute tree
//! again tests the children near the point once more: on the bunny
//! lattice, whose 3,286 struts each set a modulus, that second search cost
//! more than the fractions of per-strut FGrades. When the design's top node
//! is a sharp union whose children carrying attributes are children of the
//! prepared union in the same order (or nested unions spliced into it, each
//! a run of its children), the attribute is read from the child the
//! distance walk found: no containment test at all. A union that carries an
//! attribute itself is not spliced (`model::flatten`), so a lattice graded
//! as a whole is one child here and shares its prepared distance.
//!
//! The child found is the one whose distance is ≤ 0 first in child order;
//! the attribute tree's own search asks each child `contains`, which for a
//! mesh is a winding test, not the sign of its distance. The two may differ
//! at points within rounding of a mesh's surface; this path follows the
//! fractions, so a point's attribute and material come from one child.

use glam::DVec3;

use super::prepared::{ANode, Evaluator, Op};
use super::{AttributeError, Resolver};
use crate::model::{Model, SubDistance};

/// The children of the top union, as the distance walk numbers them.
pub(super) struct RootHint {
    /// Per child of the prepared union: its position among the attribute
    /// tree's children, `u32::MAX` where it carries no attribute.
    pub(super) of_child: Vec<u32>,
    /// Per attribute: the last child (prepared union's numbering) that
    /// defines it; a point whose first containing child is at or after it
    /// has no value from a later child.
    pub(super) last: Vec<Option<u32>>,
    /// Per attribute: the root neither sets it nor names a resolver for
    /// it, so the first child containing a point gives it.
    pub(super) first_wins: Vec<bool>,
}

impl Evaluator {
    /// The evaluator with its hint for the design's top node `top` (the
    /// prepared root), when the attribute tree's root is that node and a
    /// sharp union the hint can follow.
    pub(crate) fn with_root_hint(mut self, top: &SubDistance) -> Evaluator {
        self.hint = root_hint(&self.root, top);
        self
    }

    /// Attribute `idx` at design point `p` inside the part, where `first`
    /// is the top union's first child containing `p` (`usize::MAX` when
    /// unknown): false where no node defines it there.
    #[inline]
    pub(super) fn eval_first(
        &self,
        idx: usize,
        p: DVec3,
        first: usize,
        out: &mut [f64],
    ) -> Result<bool, AttributeError> {
        let root = &self.root;
        if let Some(h) = &self.hint
            && first != usize::MAX
            && h.first_wins[idx]
            && let Op::Pick { children, .. } = &root.op
        {
            // Children before `first` do not contain p; `first` does.
            if let Some(&k) = h.of_child.get(first)
                && let Some(c) = children.get(k as usize)
                && c.defines[idx]
                && c.eval_inside(idx, p, out)?
            {
                return Ok(true);
            }
            if h.last[idx].is_none_or(|l| l as usize <= first) {
                return Ok(false);
            }
        }
        root.eval_inside(idx, p, out)
    }
}

fn root_hint(root: &ANode, top: &SubDistance) -> Option<RootHint> {
    if !root.dist.is(top) {
        return None;
    }
    let Op::Pick {
        children, smooth, ..
    } = &root.op
    else {
        return None;
    };
    if *smooth > 0.0 {
        return None;
    }
    let parts: Vec<&SubDistance> = children.iter().map(|c| &c.dist).collect();
    let of_child = top.union_positions(&parts)?;
    let mut last = vec![None; root.defines.len()];
    for (j, &k) in of_child.iter().enumerate() {
        let Some(c) = children.get(k as usize) else {
            continue;
        };
        for (l, d) in last.iter_mut().zip(&c.defines) {
            if *d {
                *l = u32::try_from(j).ok();
            }
        }
    }
    let first_wins = (0..root.defines.len())
        .map(|i| root.own_of[i].is_none() && matches!(root.resolver(i), Resolver::First))
        .collect();
    Some(RootHint {
        of_child,
        last,
        first_wins,
    })
}

impl Model {
    /// Distance at `p` and fractions into `fracs`, as [`Model::eval_into`],
    /// and the attributes `wanted` (indices into [`Model::attributes`])
    /// into `values`, each its width, one after another: NaN outside the
    /// part or where no node defines one. A sharp union at the top of the
    /// design is walked once for both: its attribute is read from the child
    /// whose fractions were written.
    pub fn eval_with_attributes(
        &self,
        p: DVec3,
        fracs: &mut [f64],
        wanted: &[usize],
        values: &mut [f64],
    ) -> Result<f64, AttributeError> {
        self.check_wanted(wanted, 1, values.len())?;
        fracs.fill(0.0);
        let (d, first) = self.root.eval_first(p, fracs);
        let mut at = 0;
        for &i in wanted {
            let w = self.attributes()[i].kind.width();
            let o = &mut values[at..at + w];
            at += w;
            let found = match &self.attrs {
                Some(a) if d <= 0.0 => a.eval_first(i, p, first, o)?,
                _ => false,
            };
            if !found {
                o.fill(f64::NAN);
            }
        }
        Ok(d)
    }

    /// The numbers a point of `wanted` takes, checked against a buffer of
    /// `len` for `points` points.
    pub(super) fn check_wanted(
        &self,
        wanted: &[usize],
        points: usize,
        len: usize,
    ) -> Result<usize, AttributeError> {
        let mut need = 0;
        for &i in wanted {
            let Some(info) = self.attributes().get(i) else {
                return Err(AttributeError {
                    node: "design".into(),
                    message: format!(
                        "has {} attributes; there is no attribute {i}",
                        self.attributes().len()
                    ),
                });
            };
            need += info.kind.width();
        }
        if len != need * points {
            return Err(AttributeError {
                node: "design".into(),
                message: format!(
                    "the {} attributes asked for need {need} numbers a point, {} for {points} points; the buffer has {len}",
                    wanted.len(),
                    need * points
                ),
            });
        }
        Ok(need)
    }
}
