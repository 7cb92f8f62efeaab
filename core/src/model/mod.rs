//! The prepared model: what every consumer (viewport, compilers, CLI) samples.
//!
//! `Node tree → Model::prepare → Model` (immutable, `Send + Sync`), then
//! batches of points → distances and fractions into caller-owned buffers.
//!
//! Fractions are dense: a model uses few materials out of a table of many,
//! so `materials()` lists the ids it uses, ascending, and a point's fractions
//! are `k = materials().len()` numbers in that order.

mod derived;
mod distance_interval;
mod flatten;
mod fraction_bound;
mod fractions;
mod pnode;
pub mod polygon2d;
mod prepare;
pub(crate) mod sdf;
mod shapes;
mod strut_grid;
mod thin_gaps;
mod thin_sampled;
mod thinnest;
mod tpms;
mod union_index;

pub use thin_gaps::{Gap, StatedGaps};
use thin_sampled::SampledMemo;
pub use thin_sampled::{GAP_BAND, Sampled, SampledFeature};
pub use thinnest::{Feature, Thinnest};

#[cfg(test)]
pub(crate) mod tests;

use std::sync::Arc;
use std::time::{Duration, Instant};

use glam::DVec3;

use crate::aabb::Aabb;
use crate::interval::Interval;
use crate::material::{MaterialId, MaterialTable};
use crate::node::Node;
use pnode::PNode;

pub use flatten::rotation;

/// Check a `PolygonRevolve` half-profile as prepare will (for errors at
/// the script call): the reason it is refused, if it is.
pub(crate) fn check_revolve(
    vertices: &[DVec3],
    axis_start: DVec3,
    axis_end: DVec3,
    sweep_degrees: f64,
) -> Result<(), String> {
    shapes::Revolve::build(vertices, axis_start, axis_end, sweep_degrees).map(|_| ())
}

/// Most distinct materials one design may use (fractions live on the stack).
pub const MAX_MATERIALS: usize = 64;

/// Why a tree could not be prepared.
#[derive(Debug, Clone, thiserror::Error, PartialEq)]
#[error("{node}: {message}")]
pub struct PrepareError {
    /// The node, with the script line that made it.
    pub node: String,
    /// What is wrong and what would fix it.
    pub message: String,
}

/// A prepared design.
#[derive(Debug, Clone)]
pub struct Model {
    pub(crate) root: Arc<PNode>,
    bbox: Aabb,
    materials: Vec<MaterialId>,
    table: Arc<MaterialTable>,
    node_count: usize,
    prepare_time: Duration,
    varying: bool,
    averaging: bool,
    /// The attribute evaluator, only when some node carries an attribute
    /// (kept apart from `root` so distances and fractions never look at it).
    pub(crate) attrs: Option<Arc<crate::attribute::Evaluator>>,
    /// The sampled thin-feature estimate with the depth it was sampled to,
    /// made on first use and shared by clones (see
    /// [`Model::sampled_thinnest_below`]).
    sampled: Arc<std::sync::Mutex<Option<SampledMemo>>>,
    /// Results other crates derive from the model (see [`Model::derived`]).
    derived: derived::Derived,
}

/// The distance of one script subtree in its own frame (the attribute
/// evaluator asks which children contain a point, and its math strings'
/// `d`).
#[derive(Debug, Clone)]
pub(crate) struct SubDistance {
    node: Arc<PNode>,
    /// The subtree's box.
    pub(crate) bbox: Aabb,
}

impl SubDistance {
    /// Signed distance at `p`.
    #[inline]
    pub(crate) fn dist(&self, p: DVec3) -> f64 {
        self.node.dist(p)
    }

    /// True when `p` is inside.
    #[inline]
    pub(crate) fn contains(&self, p: DVec3) -> bool {
        self.node.contains(p)
    }

    /// Bounds of the distance over `b`.
    pub(crate) fn interval(&self, b: &Aabb) -> Interval {
        self.node.interval(b)
    }

    /// The scalar -> fractions conversion of the subtree's top node.
    pub(crate) fn fraction_source(&self) -> Option<Arc<crate::attribute::FractionSource>> {
        match &*self.node {
            PNode::AttrGrade { src, .. } => Some(src.clone()),
            _ => None,
        }
    }

    /// Fractions at `p` into `out` (the design's materials, dense).
    pub(crate) fn fractions(&self, p: DVec3, out: &mut [f64]) {
        out.fill(0.0);
        self.node.eval(p, out);
    }

    /// True when `other` is this very prepared node (not only an equal one).
    pub(crate) fn is(&self, other: &SubDistance) -> bool {
        Arc::ptr_eq(&self.node, &other.node)
    }

    /// When this is a sharp union whose children are distinct prepared
    /// nodes: for each child, the position in `parts` of the part that is
    /// it or, for a part that is itself a sharp union flattened into this
    /// one, holds it (`u32::MAX` for none); `None` when it is not such a
    /// union, some part is neither, or the parts are in another order.
    pub(crate) fn union_positions(&self, parts: &[&SubDistance]) -> Option<Vec<u32>> {
        let PNode::Union(u) = &*self.node else {
            return None;
        };
        if u.blend || u.smooth > 0.0 {
            return None;
        }
        let mut at: std::collections::HashMap<*const PNode, usize> =
            std::collections::HashMap::with_capacity(u.children.len());
        for (j, c) in u.children.iter().enumerate() {
            if at.insert(Arc::as_ptr(c), j).is_some() {
                return None;
            }
        }
        let mut of_child = vec![u32::MAX; u.children.len()];
        for (k, part) in parts.iter().enumerate() {
            let k = u32::try_from(k).ok()?;
            for j in flattened_into(&at, &part.node)? {
                if of_child[j] != u32::MAX {
                    return None;
                }
                of_child[j] = k;
            }
        }
        // The parts in the children's order, each a run of children: the
        // first child containing a point is in the first part containing it.
        let mut order = of_child.iter().filter(|&&k| k != u32::MAX);
        let mut last = order.next();
        for k in order {
            if last.is_some_and(|l| l > k) {
                return None;
            }
            last = Some(k);
        }
        Some(of_child)
    }
}

/// Positions among a union's children (`at`) of `part`: itself, or the
/// children of a sharp union that `flatten` read into that union (each
/// prepared once, so the same `Arc`s); `None` when neither.
fn flattened_into(
    at: &std::collections::HashMap<*const PNode, usize>,
    part: &Arc<PNode>,
) -> Option<Vec<usize>> {
    if let Some(&j) = at.get(&Arc::as_ptr(part)) {
        return Some(vec![j]);
    }
    match &**part {
        PNode::Union(p) if !p.blend && p.smooth <= 0.0 => p
            .children
            .iter()
            .map(|c| at.get(&Arc::as_ptr(c)).copied())
            .collect(),
        _ => None,
    }
}

/// Prepares the distances of script subtrees, sharing one cache.
pub(crate) struct SubPreparer(prepare::Preparer);

impl SubPreparer {
    /// The distance of the subtree `n`.
    pub(crate) fn distance(&mut self, n: &Node) -> Result<SubDistance, PrepareError> {
        let (node, bbox) = self.0.prepare(n)?;
        Ok(SubDistance { node, bbox })
    }
}

/// Points as structure of arrays (mm).
#[derive(Clone, Copy, Debug)]
pub struct Points<'a> {
    /// X coordinates.
    pub x: &'a [f64],
    /// Y coordinates.
    pub y: &'a [f64],
    /// Z coordinates.
    pub z: &'a [f64],
}

impl Points<'_> {
    /// Number of points.
    pub fn len(&self) -> usize {
        self.x.len()
    }

    /// True when there are no points.
    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }

    /// Point `i`.
    #[inline]
    pub fn get(&self, i: usize) -> DVec3 {
        DVec3::new(self.x[i], self.y[i], self.z[i])
    }
}

impl Model {
    /// Prepare `root` with the material table its script used.
    pub fn prepare(root: &Node, table: Arc<MaterialTable>) -> Result<Model, PrepareError> {
        let start = Instant::now();
        let materials = prepare::collect_materials(root);
        let mut p = prepare::Preparer::new(&materials)?;
        // Structural errors (missing children) first: they explain an
        // empty material list too.
        let (root_p, bbox) = p.prepare(root)?;
        if materials.is_empty() {
            return Err(PrepareError {
                node: root.describe(),
                message: "the design has no material".into(),
            });
        }
        // The attribute evaluator reuses the preparer's cache: each node's
        // distance is prepared once for both.
        let top = SubDistance {
            node: root_p.clone(),
            bbox,
        };
        let attrs = crate::attribute::Evaluator::build(root, &materials, SubPreparer(p))?
            .map(|a| Arc::new(a.with_root_hint(&top)));
        Ok(Model {
            attrs,
            varying: root_p.varying_fractions(),
            averaging: root_p.averages_fractions(),
            root: root_p,
            bbox,
            materials,
            table,
            node_count: root.count_nodes(),
            prepare_time: start.elapsed(),
            sampled: Arc::default(),
            derived: derived::Derived::default(),
        })
    }

    /// Bounding box (may be infinite for an unclipped Tile or TPMS).
    pub fn bbox(&self) -> Aabb {
        self.bbox
    }

    /// The material ids the design can return, ascending (fraction order).
    pub fn materials(&self) -> &[MaterialId] {
        &self.materials
    }

    /// The material table the design was written against.
    pub fn table(&self) -> &MaterialTable {
        &self.table
    }

    /// The same design written against `table` (same ids: a printer's
    /// names and colours for the design's materials).
    pub fn with_table(mut self, table: Arc<MaterialTable>) -> Model {
        self.table = table;
        self.derived = derived::Derived::default();
        self
    }

    /// `make()`, computed once per `key` and result type for this model
    /// and its clones: for results that depend on the model and `key`
    /// alone (another crate's look at the design, by voxel size). At most
    /// a few are kept, the oldest dropped first.
    pub fn derived<K, T>(&self, key: K, make: impl FnOnce() -> T) -> T
    where
        K: PartialEq + Send + Sync + 'static,
        T: Clone + Send + Sync + 'static,
    {
        self.derived.get_or(key, make)
    }

    /// The shared table.
    pub fn table_arc(&self) -> Arc<MaterialTable> {
        self.table.clone()
    }

    /// Distinct nodes in the script's tree.
    pub fn node_count(&self) -> usize {
        self.node_count
    }

    /// How long `prepare` took.
    pub fn prepare_time(&self) -> Duration {
        self.prepare_time
    }

    /// True when [`Model::distance`] is 1-Lipschitz, so a sphere tracer may
    /// step by it; false when a node's value is not a distance (a math
    /// string `Function`, a TPMS sheet, a `Tile` of anything but a
    /// mirror-symmetric lattice clipped to its cell), where a renderer must
    /// find the surface by the sign of the value instead.
    pub fn distance_is_bound(&self) -> bool {
        self.root.is_lipschitz()
    }

    /// Signed distance at `p` (negative inside; inside ⇔ ≤ 0).
    #[inline]
    pub fn distance(&self, p: DVec3) -> f64 {
        self.root.dist(p)
    }

    /// Distance at `p`, and fractions into `fracs` (length `materials().len()`;
    /// all zero outside).
    #[inline]
    pub fn eval_into(&self, p: DVec3, fracs: &mut [f64]) -> f64 {
        fracs.fill(0.0);
        self.root.eval(p, fracs)
    }

    /// Fractions at `p` into `fracs`, for a point already known to be inside
    /// (samplers filling a solid tile): skips the distance, which for a mesh
    /// or an FEA field deep inside the part is the expensive half.
    #[inline]
    pub fn fractions_inside(&self, p: DVec3, fracs: &mut [f64]) {
        fracs.fill(0.0);
        self.root.frac(p, fracs);
    }

    /// Convenience: distance and (material id, fraction) pairs at one point;
    /// empty outside. Allocates; use the batch calls in loops.
    pub fn eval_point(&self, p: DVec3) -> (f64, Vec<(MaterialId, f64)>) {
        let mut f = vec![0.0; self.materials.len()];
        let d = self.eval_into(p, &mut f);
        let pairs = if d <= 0.0 {
            self.materials.iter().copied().zip(f).collect()
        } else {
            Vec::new()
        };
        (d, pairs)
    }

    /// Distances for a batch of points into `dist` (same length).
    pub fn distance_batch(&self, pts: Points<'_>, dist: &mut [f64]) {
        assert_eq!(dist.len(), pts.len(), "distance buffer length");
        for (i, d) in dist.iter_mut().enumerate() {
            *d = self.root.dist(pts.get(i));
        }
    }

    /// Distances and fractions for a batch: `dist[i]`, and
    /// `fracs[i*k .. (i+1)*k]` with `k = materials().len()` (zero outside).
    pub fn eval_batch(&self, pts: Points<'_>, dist: &mut [f64], fracs: &mut [f32]) {
        let k = self.materials.len();
        assert_eq!(dist.len(), pts.len(), "distance buffer length");
        assert_eq!(fracs.len(), pts.len() * k, "fraction buffer length");
        let mut f = [0.0f64; MAX_MATERIALS];
        for i in 0..pts.len() {
            let d = self.eval_into(pts.get(i), &mut f[..k]);
            dist[i] = d;
            for (o, v) in fracs[i * k..(i + 1) * k].iter_mut().zip(&f[..k]) {
                *o = *v as f32;
            }
        }
    }

    /// A conservative interval of the distance over box `b`: every point of
    /// `b` has a distance inside it. `lo > 0`: empty; `hi < 0`: full.
    pub fn interval(&self, b: &Aabb) -> Interval {
        self.root.interval(b)
    }

    /// False when every part has fractions that do not depend on the point
    /// (no grading with a variable, no FEA field, no `Blend`): the design's
    /// fractions are then piecewise constant, and bounding them over a box
    /// helps no one (the bunny lattice: 3,286 struts of fixed mixes).
    pub fn varying_fractions(&self) -> bool {
        self.varying
    }

    /// True when some part's fractions are averages over many samples (a
    /// `Blend`): evaluating them costs far more than bounding them, so
    /// samplers bound them even in tiles that a surface crosses.
    pub fn averages_fractions(&self) -> bool {
        self.averaging
    }

    /// Bounds of the fractions at every inside point of `b` into `out`
    /// (one per material of [`Self::materials`]); false when the design has
    /// a node without a cheap bound (a blending union, a smooth union with
    /// a graded child near `b`, a growing `Offset` of a graded part, a union
    /// with many children overlapping `b`, an FEA field with many
    /// tetrahedra in `b`).
    pub fn fraction_bounds(&self, b: &Aabb, out: &mut [Interval]) -> bool {
        out.fill(fraction_bound::ZERO);
        self.root.frac_bounds(b, out)
    }

    /// The axes along which the fractions of inside points may vary
    /// (`PNode::fraction_axes`): bounds of the fractions over a run of
    /// voxels along an axis they do not vary along hold for every such run.
    pub fn fraction_axes(&self) -> [bool; 3] {
        self.root.fraction_axes()
    }

    /// The fractions every inside point has, into `out` (as an evaluation
    /// writes them), when they do not depend on the point at all (one
    /// material, or a grade of constants); false otherwise.
    pub fn fixed_fractions(&self, out: &mut [f64]) -> bool {
        out.fill(0.0);
        match self.root.fixed_fractions() {
            Some(f) => {
                f.write(out);
                true
            }
            None => false,
        }
    }

    /// True when the fractions are the same at every inside point of `b`
    /// (samplers then evaluate one point and fill the rest).
    pub fn constant_fractions(&self, b: &Aabb) -> bool {
        self.root.constant_fractions(b)
    }
}
