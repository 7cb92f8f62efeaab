//! Evaluating attributes at points and bounding them over boxes, and the
//! [`Model`] calls that do it.

use glam::DVec3;

use super::prepared::{ANode, COORD_SLOTS, Op, OwnSrc, PComp, PConv};
use super::{AttributeError, AttributeInfo, AttributeKind};
use crate::aabb::Aabb;
use crate::interval::Interval;
use crate::model::{Model, Points, sdf};

/// What an attribute query that writes into a caller's buffer returns.
type AttributeResult = Result<(), AttributeError>;

/// Most numbers of one value (a Vec4).
const MAX_WIDTH: usize = 4;

/// The children of a sharp pick, their grid, and whether the point is
/// known to be inside the picking node.
struct Near<'a> {
    children: &'a [std::sync::Arc<ANode>],
    grid: Option<&'a super::pick_grid::PickGrid>,
    inside: bool,
}

impl ANode {
    /// Attribute `idx` at `q` (this node's frame; `pw` the design point for
    /// messages) into `out`; false when nothing on or below this node
    /// defines it there.
    pub(super) fn eval(
        &self,
        idx: usize,
        q: DVec3,
        pw: DVec3,
        out: &mut [f64],
    ) -> Result<bool, AttributeError> {
        self.eval_at(idx, q, pw, out, false)
    }

    /// [`ANode::eval`] at a point known to be inside this node: a union
    /// here need not test that again (its whole distance) where no child
    /// with the attribute holds the point.
    pub(super) fn eval_inside(
        &self,
        idx: usize,
        q: DVec3,
        out: &mut [f64],
    ) -> Result<bool, AttributeError> {
        self.eval_at(idx, q, q, out, true)
    }

    /// This node's own value of `idx`, else what its children give
    /// (`inside`: q is known to be inside this node).
    fn eval_at(
        &self,
        idx: usize,
        q: DVec3,
        pw: DVec3,
        out: &mut [f64],
        inside: bool,
    ) -> Result<bool, AttributeError> {
        if let Some(pos) = self.own_of[idx] {
            self.own_value(pos as usize, q, pw, out)?;
            return Ok(true);
        }
        match &self.op {
            Op::Leaf => Ok(false),
            Op::Map(m, c) => c.eval(idx, m.apply(q), pw, out),
            Op::Pick {
                children, smooth, ..
            } if *smooth > 0.0 => blend_children(children, *smooth, idx, q, pw, out),
            Op::Pick { children, grid, .. } => {
                let near = Near {
                    children,
                    grid: grid.as_ref(),
                    inside,
                };
                self.pick_children(&near, idx, q, pw, out)
            }
        }
    }

    /// First child containing `q` that defines `idx`, or all of them folded
    /// by the node's resolver; where `q` is outside this node (in a smooth
    /// parent's fillet, or on a seam within rounding), the nearest child.
    fn pick_children(
        &self,
        near: &Near<'_>,
        idx: usize,
        q: DVec3,
        pw: DVec3,
        out: &mut [f64],
    ) -> Result<bool, AttributeError> {
        let (children, grid) = (near.children, near.grid);
        let r = self.resolver(idx);
        let first_only = matches!(r, super::Resolver::First);
        let mut tmp = [0.0; MAX_WIDTH];
        let tmp = &mut tmp[..out.len()];
        let mut found = false;
        // The children near q (a grid's list), else all, in child order.
        let list = grid.map(|g| g.candidates(q));
        for k in 0..list.map_or(children.len(), <[u32]>::len) {
            let c = &children[list.map_or(k, |l| l[k] as usize)];
            if !c.defines[idx] {
                continue;
            }
            if !c.dist.contains(q) {
                continue;
            }
            if !found {
                found = c.eval(idx, q, pw, out)?;
                if found && first_only {
                    return Ok(true);
                }
            } else if c.eval(idx, q, pw, tmp)? {
                r.fold(out, tmp);
            }
        }
        // Inside this node, a child without the attribute holds the point.
        if found || near.inside || self.dist.contains(q) {
            return Ok(found);
        }
        let nearest = children
            .iter()
            .filter(|c| c.defines[idx])
            .map(|c| (c.dist.dist(q), c))
            .min_by(|a, b| a.0.total_cmp(&b.0));
        match nearest {
            Some((_, c)) => c.eval(idx, q, pw, out),
            None => Ok(false),
        }
    }

    /// One of this node's own attributes at `q`.
    fn own_value(&self, pos: usize, q: DVec3, pw: DVec3, out: &mut [f64]) -> AttributeResult {
        let own = &self.own[pos];
        // Zeroing 64 slots is a 512-byte memset a sample: a constant reads
        // none, most nodes fit 16 (as `SimGrade::frac` does).
        if own.used == 0 {
            self.source_value(pos, q, pw, &[0.0; 64], out)?;
        } else if COORD_SLOTS + self.own.len() <= 16 {
            self.own_value_in::<16>(pos, q, pw, out)?;
        } else {
            self.own_value_in::<64>(pos, q, pw, out)?;
        }
        if let Some((lo, hi, unit)) = own.range
            && let Some(v) = out.iter().find(|v| own.refuses(**v))
        {
            {
                return Err(AttributeError {
                    node: self.describe.clone(),
                    message: format!(
                        "{} (\"{}\") gives {v} at ({}, {}, {}); it must be {}: keep the value in that range (clamp(...) in a math string)",
                        own.call,
                        own.name,
                        pw.x,
                        pw.y,
                        pw.z,
                        super::range_text(lo, hi, unit)
                    ),
                });
            }
        }
        Ok(())
    }

    /// [`ANode::own_value`] with `N` slots for the variables.
    #[inline(always)]
    fn own_value_in<const N: usize>(
        &self,
        pos: usize,
        q: DVec3,
        pw: DVec3,
        out: &mut [f64],
    ) -> Result<(), AttributeError> {
        let own = &self.own[pos];
        let mut slots = [0.0f64; N];
        slots[0] = q.x;
        slots[1] = q.y;
        slots[2] = q.z;
        crate::expr::fill_derived_coords_used(&mut slots, own.used);
        if own.used & (1 << 8) != 0 {
            slots[8] = self.dist.dist(q);
        }
        for &dep in &own.order {
            let mut v = [0.0];
            self.source_value(dep, q, pw, &slots, &mut v)?;
            slots[COORD_SLOTS + dep] = v[0];
        }
        self.source_value(pos, q, pw, &slots, out)
    }

    /// The values of own attribute `pos` with the variables in `slots`.
    #[inline]
    fn source_value(
        &self,
        pos: usize,
        q: DVec3,
        pw: DVec3,
        slots: &[f64],
        out: &mut [f64],
    ) -> AttributeResult {
        match &self.own[pos].src {
            OwnSrc::Comps(cs) => {
                for (o, c) in out.iter_mut().zip(cs) {
                    *o = match c {
                        PComp::Const(v) => *v,
                        PComp::Expr(e) => e.eval(slots),
                    };
                }
            }
            OwnSrc::Data { field, column } => {
                let mut buf = [0.0; 64];
                let n = (*column + 1).min(buf.len());
                out[0] = if field.sample(q, &mut buf[..n]) {
                    buf[*column]
                } else {
                    f64::NAN
                };
            }
            OwnSrc::Points { cloud, column } => out[0] = cloud.sample(q, *column),
            OwnSrc::Image { map, channel } => map.value(q, *channel, out),
            OwnSrc::Convert {
                from,
                from_own,
                map,
                clamped,
            } => {
                if let PConv::Mix {
                    reuss,
                    slots,
                    values,
                    materials,
                } = map
                {
                    let mut f = [0.0; crate::model::MAX_MATERIALS];
                    self.dist.fractions(q, &mut f[..*materials]);
                    let mut picked = [0.0; crate::model::MAX_MATERIALS];
                    for (p, s) in picked.iter_mut().zip(slots) {
                        *p = f[*s];
                    }
                    out[0] = super::convert::mix(*reuss, &picked[..slots.len()], values);
                    return Ok(());
                }
                let mut x = [f64::NAN];
                match from_own {
                    Some(j) => x[0] = slots[COORD_SLOTS + j],
                    // Not this node's own (else `from_own` names it): what
                    // the children give.
                    None => {
                        self.eval_at(*from, q, pw, &mut x, false)?;
                    }
                }
                out[0] = match map {
                    PConv::Table(t) if !x[0].is_nan() => {
                        let (y, outside) = t.lookup(x[0]);
                        if outside {
                            clamped.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                        }
                        y
                    }
                    PConv::Table(_) | PConv::Mix { .. } => f64::NAN,
                    PConv::Expr(e) => {
                        let mut s = [0.0; COORD_SLOTS + 1];
                        s[..COORD_SLOTS].copy_from_slice(&slots[..COORD_SLOTS]);
                        s[COORD_SLOTS] = x[0];
                        e.eval(&s)
                    }
                };
            }
        }
        Ok(())
    }

    /// Bounds of scalar attribute `idx` over `b` (this node's frame):
    /// `None` when no value can occur there.
    pub(super) fn interval(&self, idx: usize, b: &Aabb) -> Option<Interval> {
        if let Some(pos) = self.own_of[idx] {
            return self.own_interval(pos as usize, b);
        }
        self.interval_below(idx, b)
    }

    fn interval_below(&self, idx: usize, b: &Aabb) -> Option<Interval> {
        match &self.op {
            Op::Leaf => None,
            Op::Map(m, c) => c.interval(idx, &m.apply_box(b)),
            Op::Pick {
                children, smooth, ..
            } => {
                let r = self.resolver(idx);
                let mut acc: Option<Interval> = None;
                for c in children.iter().filter(|c| c.defines[idx]) {
                    // A smooth union's fillet takes values from children
                    // that do not contain the point.
                    if *smooth <= 0.0 && c.dist.interval(b).lo > 0.0 {
                        continue;
                    }
                    let Some(i) = c.interval(idx, b) else {
                        continue;
                    };
                    acc = Some(match acc {
                        None => i,
                        // Any subset of the children may contain a point:
                        // the hull of each alone and of the fold so far.
                        Some(a) if *smooth <= 0.0 => a.union(i).union(r.fold_interval(a, i)),
                        // A smooth blend is a convex combination.
                        Some(a) => a.union(i),
                    });
                }
                acc
            }
        }
    }

    pub(super) fn own_interval(&self, pos: usize, b: &Aabb) -> Option<Interval> {
        let own = &self.own[pos];
        let mut slots = [Interval::EVERYTHING; 64];
        slots[0] = Interval::new(b.min.x, b.max.x);
        slots[1] = Interval::new(b.min.y, b.max.y);
        slots[2] = Interval::new(b.min.z, b.max.z);
        crate::expr::fill_derived_coord_intervals(&mut slots);
        if own.used & (1 << 8) != 0 {
            slots[8] = self.dist.interval(b);
        }
        for &dep in &own.order {
            slots[COORD_SLOTS + dep] = self.source_interval(dep, b, &slots)?;
        }
        self.source_interval(pos, b, &slots)
    }

    fn source_interval(&self, pos: usize, b: &Aabb, slots: &[Interval]) -> Option<Interval> {
        Some(match &self.own[pos].src {
            OwnSrc::Convert {
                from,
                from_own,
                map,
                ..
            } => {
                let x = match from_own {
                    Some(j) => slots[COORD_SLOTS + j],
                    None => self.interval_below(*from, b)?,
                };
                match map {
                    PConv::Table(t) => {
                        let (lo, hi) = t.output_range();
                        Interval::new(lo, hi)
                    }
                    PConv::Mix { .. } => Interval::EVERYTHING,
                    PConv::Expr(e) => {
                        let mut s = [Interval::EVERYTHING; COORD_SLOTS + 1];
                        s[..COORD_SLOTS].copy_from_slice(&slots[..COORD_SLOTS]);
                        s[COORD_SLOTS] = x;
                        e.eval_interval(&s)
                    }
                }
            }
            OwnSrc::Comps(cs) => match cs.first() {
                Some(PComp::Const(v)) => Interval::point(*v),
                Some(PComp::Expr(e)) => e.eval_interval(slots),
                None => Interval::EVERYTHING,
            },
            // Linear interpolation in a tetrahedron stays within its nodes'
            // values; outside the mesh the value is NaN (no sample).
            // Inverse-distance weights are positive: a convex combination.
            OwnSrc::Points { cloud, column } => {
                let (lo, hi) = cloud.range(*column);
                Interval::new(lo, hi)
            }
            // Bilinear weights are a convex combination of the pixels.
            OwnSrc::Image { map, channel } => {
                let (lo, hi) = map.range(channel.unwrap_or(super::ImageChannel::R));
                Interval::new(lo, hi)
            }
            OwnSrc::Data { field, column } => match field.variable_range(*column) {
                Some((lo, hi)) => Interval::new(lo, hi),
                None => Interval::EVERYTHING,
            },
        })
    }
}

/// A smooth union's children folded in order with the weight its smooth
/// minimum gives the value so far (pyvcad's `h` with k' = 4k, as
/// [`sdf::smooth_min`]): `h = clamp(½ + ½(d_b − d_a)/4k, 0, 1)`,
/// `v = h·v_a + (1 − h)·v_b`.
fn blend_children(
    children: &[std::sync::Arc<ANode>],
    k: f64,
    idx: usize,
    q: DVec3,
    pw: DVec3,
    out: &mut [f64],
) -> Result<bool, AttributeError> {
    let mut tmp = [0.0; MAX_WIDTH];
    let tmp = &mut tmp[..out.len()];
    let mut acc_d: Option<f64> = None;
    for c in children.iter().filter(|c| c.defines[idx]) {
        let e = c.dist.dist(q);
        match acc_d {
            None => {
                if c.eval(idx, q, pw, out)? {
                    acc_d = Some(e);
                }
            }
            Some(d) => {
                if c.eval(idx, q, pw, tmp)? {
                    let h = (0.5 + 0.5 * (e - d) / (4.0 * k)).clamp(0.0, 1.0);
                    for (o, t) in out.iter_mut().zip(tmp.iter()) {
                        *o = h * *o + (1.0 - h) * *t;
                    }
                    acc_d = Some(sdf::smooth_min(d, e, k));
                }
            }
        }
    }
    Ok(acc_d.is_some())
}

impl Model {
    /// Every attribute any node of the design carries, sorted by name.
    pub fn attributes(&self) -> &[AttributeInfo] {
        self.attrs.as_ref().map_or(&[], |a| &a.infos)
    }

    /// The index of attribute `name` in [`Model::attributes`].
    pub fn attribute_index(&self, name: &str) -> Option<usize> {
        self.attributes().iter().position(|a| a.name == name)
    }

    /// The index of attribute `name`, or an error that lists the
    /// attributes the design has (for exports that need one).
    pub fn require_attribute(&self, name: &str) -> Result<usize, AttributeError> {
        self.attribute_index(name).ok_or_else(|| AttributeError {
            node: "design".into(),
            message: format!(
                "has no attribute \"{name}\"; it has {}; set it with node.set_attribute(\"{name}\", value)",
                if self.attributes().is_empty() {
                    "none".to_owned()
                } else {
                    self.attributes()
                        .iter()
                        .map(|a| a.name.as_str())
                        .collect::<Vec<_>>()
                        .join(", ")
                }
            ),
        })
    }

    fn attribute_checked(&self, index: usize, out_len: usize, points: usize) -> AttributeResult {
        let Some(info) = self.attributes().get(index) else {
            return Err(AttributeError {
                node: "design".into(),
                message: format!(
                    "has {} attributes; there is no attribute {index}",
                    self.attributes().len()
                ),
            });
        };
        let want = info.kind.width() * points;
        if out_len != want {
            return Err(AttributeError {
                node: "design".into(),
                message: format!(
                    "attribute \"{}\" needs {want} numbers for {points} points, the buffer has {out_len}",
                    info.name
                ),
            });
        }
        Ok(())
    }

    /// Attribute `index` at `p` into `out` (its width): NaN outside the
    /// part or where no node defines it.
    pub fn attribute_at(&self, index: usize, p: DVec3, out: &mut [f64]) -> AttributeResult {
        self.attribute_checked(index, out.len(), 1)?;
        self.attribute_unchecked(index, p, out, false)
    }

    /// [`Model::attribute_at`] at a point the caller knows is inside the
    /// part (its distance from [`Model::eval_into`] is ≤ 0): skips the
    /// inside test, a second distance evaluation.
    pub fn attribute_inside(&self, index: usize, p: DVec3, out: &mut [f64]) -> AttributeResult {
        self.attribute_checked(index, out.len(), 1)?;
        self.attribute_unchecked(index, p, out, true)
    }

    #[inline]
    fn attribute_unchecked(
        &self,
        index: usize,
        p: DVec3,
        out: &mut [f64],
        inside: bool,
    ) -> AttributeResult {
        let Some(a) = &self.attrs else {
            return Ok(());
        };
        let found = if inside {
            a.root.eval_inside(index, p, out)?
        } else if a.hint.is_some() {
            // One walk of the top union finds the child holding p (`hint`).
            let (d, first) = self.root.dist_first(p);
            d <= 0.0 && a.eval_first(index, p, first, out)?
        } else {
            self.root.contains(p) && a.root.eval(index, p, p, out)?
        };
        if found {
            return Ok(());
        }
        out.fill(f64::NAN);
        Ok(())
    }

    /// Attribute `index` at every point into `out` (`width` numbers a
    /// point, point after point); the first range error stops it.
    pub fn attribute_batch(
        &self,
        index: usize,
        pts: Points<'_>,
        out: &mut [f64],
    ) -> AttributeResult {
        self.attribute_checked(index, out.len(), pts.len())?;
        let w = self.attributes()[index].kind.width();
        for (i, o) in out.chunks_exact_mut(w).enumerate() {
            self.attribute_unchecked(index, pts.get(i), o, false)?;
        }
        Ok(())
    }

    /// Bounds of scalar attribute `index` over the inside points of `b`
    /// where a node defines it; `None` for a Vec3/Vec4 attribute, an
    /// index out of range, or when no inside point of `b` has a value.
    pub fn attribute_interval(&self, index: usize, b: &Aabb) -> Option<Interval> {
        let a = self.attrs.as_ref()?;
        if a.infos.get(index)?.kind != AttributeKind::Scalar || self.root.interval(b).lo > 0.0 {
            return None;
        }
        a.root.interval(index, b)
    }
}

impl Model {
    /// One line per conversion whose table clamped samples so far ("Convert
    /// to \"modulus\" (set_attribute at line 4:9): 12 samples of ... outside
    /// the table were clamped to its ends"), for the caller to warn with
    /// after sampling.
    pub fn attribute_warnings(&self) -> Vec<String> {
        let Some(a) = &self.attrs else {
            return Vec::new();
        };
        let mut out = Vec::new();
        let mut seen = std::collections::HashSet::new();
        let mut stack = vec![&a.root];
        while let Some(n) = stack.pop() {
            if !seen.insert(std::sync::Arc::as_ptr(n)) {
                continue;
            }
            out.extend(n.grade.as_ref().and_then(|g| g.warning()));
            for o in &n.own {
                if let OwnSrc::Convert {
                    from,
                    map: PConv::Table(t),
                    clamped,
                    ..
                } = &o.src
                {
                    let k = clamped.load(std::sync::atomic::Ordering::Relaxed);
                    if k > 0 {
                        let (lo, hi) = t.input_range();
                        out.push(format!(
                            "{}: Convert to \"{}\": {k} samples of \"{}\" outside the table's {lo}..{hi} were clamped to its ends",
                            n.describe, o.name, a.infos[*from].name
                        ));
                    }
                }
            }
            match &n.op {
                Op::Leaf => {}
                Op::Map(_, c) => stack.push(c),
                Op::Pick { children, .. } => stack.extend(children.iter()),
            }
        }
        out
    }
}
