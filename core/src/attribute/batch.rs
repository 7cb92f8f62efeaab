//! [`Model::eval_with_attributes`] for a batch of points into the caller's
//! buffers.
//!
//! Why: a math string evaluated point by point pays the tape's dispatch
//! (a jump and a register round trip an instruction) at every point; an
//! FGrade's fractions pay the same, so a graded attribute cost as much as
//! its FGrade twin. Here the points whose value comes from one math string
//! of the coordinates (the child of the top union that the distance walk
//! found sets it: the hint's case) are gathered per compiled tape and run
//! through [`Expr::eval_batch`] (one dispatch per 64 points, the arithmetic
//! in vector lanes), bit for bit what [`Expr::eval`] gives. Every other
//! point takes the one-point path.

use std::sync::Arc;

use glam::DVec3;

use super::AttributeError;
use super::prepared::{ANode, Evaluator, Op, OwnSrc, PComp};
use crate::expr::Expr;
use crate::model::Model;

/// Points of one batch whose value is one tape's: the tape, a node that
/// sets it (for the attribute's range) and the positions (in the batch) of
/// its points.
type Group<'a> = (&'a Arc<Expr>, &'a ANode, Vec<usize>);

impl ANode {
    /// The math string of the coordinates alone (x, y, z: no other
    /// attribute, no `d`, not affine) that gives this node's own `idx`.
    fn coordinate_tape(&self, idx: usize) -> Option<&Arc<Expr>> {
        let own = &self.own[self.own_of[idx]? as usize];
        let OwnSrc::Comps(cs) = &own.src else {
            return None;
        };
        let [PComp::Expr(e)] = cs.as_slice() else {
            return None;
        };
        // Affine strings have their own per-point form (another rounding).
        let coords_only = own.used & !0b111 == 0 && own.order.is_empty();
        (coords_only && !e.is_affine()).then_some(e)
    }

    /// True where `own_value` refuses `v` as this node's own `idx`.
    fn out_of_range(&self, idx: usize, v: f64) -> bool {
        self.own_of[idx].is_some_and(|pos| self.own[pos as usize].refuses(v))
    }
}

impl Evaluator {
    /// The tape that gives `idx` at a point whose first containing child of
    /// the top union is `first`, where [`Evaluator::eval_first`] would read
    /// that child's own math string of the coordinates.
    fn batch_tape(&self, idx: usize, first: usize) -> Option<(&Arc<Expr>, &ANode)> {
        let h = self.hint.as_ref()?;
        if !h.first_wins[idx] {
            return None;
        }
        let Op::Pick { children, .. } = &self.root.op else {
            return None;
        };
        let c = children.get(*h.of_child.get(first)? as usize)?;
        Some((c.coordinate_tape(idx)?, c))
    }
}

impl Model {
    /// [`Model::eval_with_attributes`] at every point of `pts`: distances
    /// into `dists`, fractions into `fracs` (its materials' count a point)
    /// and the attributes `wanted` into `values` (their widths a point),
    /// the same numbers bit for bit. An error is the first failing point's.
    pub fn eval_with_attributes_batch(
        &self,
        pts: &[DVec3],
        dists: &mut [f64],
        fracs: &mut [f64],
        wanted: &[usize],
        values: &mut [f64],
    ) -> Result<(), AttributeError> {
        let need = self.check_wanted(wanted, pts.len(), values.len())?;
        let k = self.materials().len();
        if dists.len() != pts.len() || fracs.len() != k * pts.len() {
            return Err(AttributeError {
                node: "design".into(),
                message: format!(
                    "{} points need {} distances and {} fractions; the buffers have {} and {}",
                    pts.len(),
                    pts.len(),
                    k * pts.len(),
                    dists.len(),
                    fracs.len()
                ),
            });
        }
        let mut firsts = vec![usize::MAX; pts.len()];
        for (i, p) in pts.iter().enumerate() {
            let f = &mut fracs[i * k..(i + 1) * k];
            f.fill(0.0);
            (dists[i], firsts[i]) = self.root.eval_first(*p, f);
        }
        let (Some(a), true) = (&self.attrs, need > 0) else {
            values.fill(f64::NAN);
            return Ok(());
        };
        let mut at = 0;
        for &idx in wanted {
            let w = self.attributes()[idx].kind.width();
            let batch = Batch {
                a,
                pts,
                dists,
                firsts: &firsts,
                need,
                at,
                w,
            };
            if batch.attribute(idx, values).is_err() {
                // The first failing point in order, as one point at a time
                // finds it.
                return self.first_error(pts, wanted, need);
            }
            at += w;
        }
        Ok(())
    }

    /// The first point of `pts` whose attributes fail, by the one-point path.
    fn first_error(
        &self,
        pts: &[DVec3],
        wanted: &[usize],
        need: usize,
    ) -> Result<(), AttributeError> {
        let mut f = vec![0.0; self.materials().len()];
        let mut v = vec![0.0; need];
        for p in pts {
            self.eval_with_attributes(*p, &mut f, wanted, &mut v)?;
        }
        Ok(())
    }
}

/// One attribute of a batch whose distance walk is done.
struct Batch<'a> {
    a: &'a Evaluator,
    pts: &'a [DVec3],
    dists: &'a [f64],
    firsts: &'a [usize],
    /// Numbers a point in `values`, and this attribute's offset and width.
    need: usize,
    at: usize,
    w: usize,
}

impl Batch<'_> {
    /// Attribute `idx` at every point into its columns of `values`.
    fn attribute(&self, idx: usize, values: &mut [f64]) -> Result<(), AttributeError> {
        let mut groups: Vec<Group<'_>> = Vec::new();
        let hint = self.a.hint.as_ref().filter(|h| h.first_wins[idx]);
        for (i, p) in self.pts.iter().enumerate() {
            let o = &mut values[i * self.need + self.at..][..self.w];
            let first = self.firsts[i];
            // Outside, or in a child without attributes after the last that
            // defines it (the bunny's body): no value, as `eval_first` says.
            let none_after = |h: &super::hint::RootHint| {
                h.of_child.get(first) == Some(&u32::MAX)
                    && h.last[idx].is_none_or(|l| l as usize <= first)
            };
            if self.dists[i] > 0.0 || hint.is_some_and(none_after) {
                o.fill(f64::NAN);
                continue;
            }
            if self.w == 1
                && let Some((e, node)) = self.a.batch_tape(idx, first)
            {
                match groups.iter_mut().find(|(g, _, _)| Arc::ptr_eq(g, e)) {
                    Some((_, _, list)) => list.push(i),
                    None => groups.push((e, node, vec![i])),
                }
                continue;
            }
            if !self.a.eval_first(idx, *p, first, o)? {
                o.fill(f64::NAN);
            }
        }
        for (e, node, list) in &groups {
            self.run_tape(idx, (e, node), list, values)?;
        }
        Ok(())
    }

    /// Tape `e` at the points `list` (positions in the batch); a value out
    /// of the attribute's range is refused by the one-point path.
    fn run_tape(
        &self,
        idx: usize,
        (e, node): (&Expr, &ANode),
        list: &[usize],
        values: &mut [f64],
    ) -> Result<(), AttributeError> {
        let coord = |c: usize| -> Vec<f64> { list.iter().map(|&i| self.pts[i][c]).collect() };
        let (x, y, z) = (coord(0), coord(1), coord(2));
        let mut out = vec![0.0; list.len()];
        e.eval_batch(&[&x, &y, &z], &mut out);
        for (&i, v) in list.iter().zip(out) {
            let o = &mut values[i * self.need + self.at];
            // Every node of the group sets `idx`: one name, one range.
            if node.out_of_range(idx, v) {
                // Its error, with the node, point and value.
                self.a
                    .eval_first(idx, self.pts[i], self.firsts[i], std::slice::from_mut(o))?;
            }
            *o = v;
        }
        Ok(())
    }
}
