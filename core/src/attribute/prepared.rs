//! The prepared attribute evaluator: a tree beside the prepared distance
//! tree, holding only the script nodes that carry an attribute or have one
//! below them, each with its compiled values, the move from its parent's
//! frame, and its own distance (which children contain a point; `d`).

use std::collections::{BTreeMap, HashMap};
use std::sync::Arc;

use super::moves::Move;
use super::{AttrSource, AttributeInfo, AttributeKind, Component, Resolver, names};
use crate::expr::{COORD_VARS, Expr};
use crate::material::MaterialId;
use crate::model::{PrepareError, SubDistance, SubPreparer, rotation};
use crate::node::{Node, NodeKind};

/// Coordinate slots before the node's own attributes in a math string.
pub(super) const COORD_SLOTS: usize = 9;
/// Most attributes one node may set (the math strings' 64 variables less
/// the 9 coordinates).
const MAX_OWN: usize = 64 - COORD_SLOTS;
/// Deepest attribute tree (the evaluation recurses once a level, as the
/// distance's does; see `model::prepare::MAX_DEPTH`).
const MAX_DEPTH: u32 = 500;

/// Every attribute of a prepared design, ready to evaluate.
pub struct Evaluator {
    pub(super) infos: Vec<AttributeInfo>,
    pub(super) root: Arc<ANode>,
    /// How the design's top union numbers the root's children, when the
    /// distance walk can hand over the child it found (`hint`).
    pub(super) hint: Option<super::hint::RootHint>,
}

impl std::fmt::Debug for Evaluator {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Evaluator")
            .field("attributes", &self.infos)
            .finish()
    }
}

/// One component of a prepared value.
#[derive(Clone)]
pub(super) enum PComp {
    Const(f64),
    Expr(Arc<Expr>),
}

/// Where a prepared attribute's values come from.
pub(super) enum OwnSrc {
    Comps(Vec<PComp>),
    Data {
        field: Arc<crate::simfield::SimField>,
        column: usize,
    },
    Points {
        cloud: Arc<super::PointCloud>,
        column: usize,
    },
    Image {
        map: Arc<super::ImageMap>,
        channel: Option<super::ImageChannel>,
    },
    Convert {
        /// Design index of the input attribute.
        from: usize,
        /// Its position in `ANode::own` when this node sets it.
        from_own: Option<usize>,
        map: PConv,
        /// Samples whose input was outside the table (clamped).
        clamped: std::sync::atomic::AtomicU64,
    },
}

/// A prepared conversion.
pub(super) enum PConv {
    Table(Arc<super::Table>),
    /// Slots: the coordinates, then the input value.
    Expr(Arc<Expr>),
    /// A mix of the fractions: `slots[i]`'s material has `values[i]`.
    Mix {
        reuss: bool,
        slots: Vec<usize>,
        values: Vec<f64>,
        materials: usize,
    },
}

/// One attribute a node sets.
pub(super) struct Own {
    pub name: String,
    pub src: OwnSrc,
    /// Positions (in `ANode::own`) of the scalar attributes its math
    /// strings read, in an order where each comes after those it reads.
    pub order: Vec<usize>,
    /// Variables read by it and by `order` (bit i: slot i).
    pub used: u64,
    /// `(min, max, unit)` for a common name.
    pub range: Option<(f64, f64, &'static str)>,
    /// "set_attribute at line 4:3", for errors.
    pub call: String,
}

impl Own {
    /// True where `v` lies outside the common name's range.
    pub fn refuses(&self, v: f64) -> bool {
        self.range.is_some_and(|(lo, hi, _)| v < lo || v > hi)
    }
}

/// How a node passes a point to its children.
pub(super) enum Op {
    Leaf,
    Map(Move, Arc<ANode>),
    Pick {
        children: Vec<Arc<ANode>>,
        smooth: f64,
        /// Which children may hold a point (sharp unions of many).
        grid: Option<super::pick_grid::PickGrid>,
    },
}

/// A prepared node with attributes on or below it.
pub(super) struct ANode {
    pub describe: String,
    pub own: Vec<Own>,
    /// Position in `own` of each design attribute this node sets.
    pub own_of: Vec<Option<u16>>,
    /// True for each design attribute this node or one below it sets.
    pub defines: Vec<bool>,
    pub resolvers: Vec<(usize, Resolver)>,
    pub dist: SubDistance,
    /// The node's scalar -> fractions conversion (for its warning).
    pub grade: Option<Arc<super::FractionSource>>,
    pub op: Op,
    depth: u32,
}

impl ANode {
    /// The resolver this node names for attribute `idx`.
    pub fn resolver(&self, idx: usize) -> &Resolver {
        self.resolvers
            .iter()
            .find(|(i, _)| *i == idx)
            .map_or(&Resolver::First, |(_, r)| r)
    }
}

fn err(n: &Node, message: String) -> PrepareError {
    PrepareError {
        node: n.describe(),
        message,
    }
}

fn call(o: Option<crate::node::Origin>) -> String {
    match o {
        Some(o) => format!("set_attribute at line {o}"),
        None => "set_attribute".into(),
    }
}

type Key = (*const NodeKind, usize);

fn key(n: &Node) -> Key {
    (n.ptr(), n.attrs_ptr())
}

/// Every node of the tree once (shared subtrees once), parents first.
fn distinct_nodes(root: &Node) -> Vec<&Node> {
    let mut seen = std::collections::HashSet::new();
    let mut out = Vec::new();
    let mut stack = vec![root];
    while let Some(n) = stack.pop() {
        if seen.insert(key(n)) {
            out.push(n);
            stack.extend(n.kind().children().into_iter().rev());
        }
    }
    out
}

impl Evaluator {
    /// The evaluator of the design `root`, or `None` when no node carries
    /// an attribute.
    pub(crate) fn build(
        root: &Node,
        materials: &[MaterialId],
        sub: SubPreparer,
    ) -> Result<Option<Evaluator>, PrepareError> {
        let nodes = distinct_nodes(root);
        if nodes.iter().all(|n| n.attributes().is_none()) {
            return Ok(None);
        }
        let infos = collect_infos(&nodes)?;
        let index: HashMap<&str, usize> = infos
            .iter()
            .enumerate()
            .map(|(i, a)| (a.name.as_str(), i))
            .collect();
        let mut b = Builder {
            materials,
            infos: &infos,
            index,
            sub,
            done: HashMap::new(),
            exprs: HashMap::new(),
        };
        let root = b.tree(root)?;
        let root = root.ok_or_else(|| err(root_node(&nodes), "has no attributes".into()))?;
        Ok(Some(Evaluator {
            infos,
            root,
            hint: None,
        }))
    }
}

fn root_node<'a>(nodes: &[&'a Node]) -> &'a Node {
    nodes[0]
}

/// The design's attributes, sorted by name; one type per name.
fn collect_infos(nodes: &[&Node]) -> Result<Vec<AttributeInfo>, PrepareError> {
    let mut kinds: BTreeMap<&str, (AttributeKind, &Node, Option<crate::node::Origin>)> =
        BTreeMap::new();
    for n in nodes {
        let Some(a) = n.attributes() else { continue };
        for d in &a.defs {
            match kinds.get(d.name.as_str()) {
                Some((k, first, o)) if *k != d.kind => {
                    return Err(err(
                        n,
                        format!(
                            "{} sets \"{}\" to a {}, but {} ({}) set it to a {}; an attribute has one type in a design",
                            call(d.origin),
                            d.name,
                            d.kind.name(),
                            first.describe(),
                            call(*o),
                            k.name()
                        ),
                    ));
                }
                Some(_) => {}
                None => {
                    kinds.insert(&d.name, (d.kind, n, d.origin));
                }
            }
        }
    }
    let infos: Vec<AttributeInfo> = kinds
        .iter()
        .map(|(name, (kind, ..))| AttributeInfo {
            name: (*name).to_owned(),
            kind: *kind,
        })
        .collect();
    for n in nodes {
        let Some(a) = n.attributes() else { continue };
        for (name, _, o) in &a.resolvers {
            if !kinds.contains_key(name.as_str()) {
                let have: Vec<&str> = kinds.keys().copied().collect();
                return Err(err(
                    n,
                    format!(
                        "set_attribute_conflict_resolver{} names \"{name}\", which no node sets; the design has: {}",
                        o.map(|o| format!(" at line {o}")).unwrap_or_default(),
                        have.join(", ")
                    ),
                ));
            }
        }
    }
    Ok(infos)
}

struct Builder<'a> {
    materials: &'a [MaterialId],
    infos: &'a [AttributeInfo],
    index: HashMap<&'a str, usize>,
    sub: SubPreparer,
    done: HashMap<Key, Option<Arc<ANode>>>,
    /// Math strings compiled so far, by source and variable list: nodes
    /// that set the same string (a lattice's 3,286 struts) share one tape.
    exprs: HashMap<(String, String), PComp>,
}

impl Builder<'_> {
    /// The attribute tree of `root`: children before parents, in a loop
    /// with its own stack (script trees may be far deeper than the limit
    /// where they carry no attribute).
    fn tree(&mut self, root: &Node) -> Result<Option<Arc<ANode>>, PrepareError> {
        let mut stack = vec![(root, false)];
        while let Some((n, ready)) = stack.pop() {
            if self.done.contains_key(&key(n)) {
                continue;
            }
            if ready {
                let a = self.node(n)?;
                self.done.insert(key(n), a);
                continue;
            }
            stack.push((n, true));
            for c in n.kind().children().into_iter().rev() {
                stack.push((c, false));
            }
        }
        Ok(self.done.get(&key(root)).cloned().flatten())
    }

    fn child(&self, c: &Option<Node>) -> Option<Arc<ANode>> {
        c.as_ref()
            .and_then(|c| self.done.get(&key(c)).cloned().flatten())
    }

    fn node(&mut self, n: &Node) -> Result<Option<Arc<ANode>>, PrepareError> {
        let op = self.op(n)?;
        let has_own = n.attributes().is_some_and(|a| !a.defs.is_empty());
        if matches!(op, Op::Leaf) && !has_own {
            return Ok(None);
        }
        let count = self.infos.len();
        let (own, own_of) = self.own(n)?;
        let mut defines: Vec<bool> = own_of.iter().map(Option::is_some).collect();
        let mut depth = 1;
        let mut below = |c: &ANode| {
            for (d, c) in defines.iter_mut().zip(&c.defines) {
                *d |= *c;
            }
            depth = depth.max(c.depth + 1);
        };
        match &op {
            Op::Leaf => {}
            Op::Map(_, c) => below(c),
            Op::Pick { children, .. } => children.iter().for_each(|c| below(c)),
        }
        if depth > MAX_DEPTH {
            return Err(err(
                n,
                format!(
                    "has attributes {depth} levels below it, more than the {MAX_DEPTH} an evaluation can follow; set the attribute on a node higher up"
                ),
            ));
        }
        let resolvers = n
            .attributes()
            .map(|a| {
                a.resolvers
                    .iter()
                    .filter_map(|(name, r, _)| {
                        self.index.get(name.as_str()).map(|i| (*i, r.clone()))
                    })
                    .collect()
            })
            .unwrap_or_default();
        debug_assert_eq!(defines.len(), count);
        let dist = self.sub.distance(n)?;
        Ok(Some(Arc::new(ANode {
            grade: dist.fraction_source(),
            describe: n.describe(),
            own,
            own_of,
            defines,
            resolvers,
            dist,
            op,
            depth,
        })))
    }

    /// How `n` passes points to the children that carry attributes.
    // Its arms take the same node fields apart as the geometry's
    // `Preparer::build` (core/src/model/prepare.rs) and look alike, but
    // build a point move, not a distance node.
    fn op(&mut self, n: &Node) -> Result<Op, PrepareError> {
        let map = |m: Move, c: Option<Arc<ANode>>| c.map_or(Op::Leaf, |c| Op::Map(m, c));
        Ok(match n.kind() {
            NodeKind::Translate { offset, child } => {
                map(Move::Translate(*offset), self.child(child))
            }
            NodeKind::Rotate {
                pitch,
                yaw,
                roll,
                around,
                child,
            } => map(
                Move::Rotate {
                    to_local: rotation(*pitch, *yaw, *roll).transpose(),
                    around: *around,
                },
                self.child(child),
            ),
            NodeKind::Scale { factors, child } => map(Move::Scale(*factors), self.child(child)),
            NodeKind::Mirror {
                point,
                normal,
                child,
            } => map(
                Move::Mirror {
                    point: *point,
                    normal: *normal,
                },
                self.child(child),
            ),
            NodeKind::Tile { cell, child } => {
                let Some(c) = self.child(child) else {
                    return Ok(Op::Leaf);
                };
                let cell = match cell {
                    Some(cell) => *cell,
                    None => c.dist.bbox.size(),
                };
                Op::Map(Move::Tile(cell), c)
            }
            NodeKind::Offset { child, .. }
            | NodeKind::Shell { child, .. }
            | NodeKind::FGrade { child, .. }
            | NodeKind::Blend { child, .. }
            | NodeKind::Identity { child } => map(Move::Same, self.child(child)),
            NodeKind::Difference { left, .. } => map(Move::Same, self.child(left)),
            NodeKind::Union {
                smooth, children, ..
            } => self.pick(children, *smooth),
            NodeKind::Intersection { children, .. } | NodeKind::Sum { children, .. } => {
                self.pick(children, 0.0)
            }
            _ => Op::Leaf,
        })
    }

    fn pick(&self, children: &[Node], smooth: f64) -> Op {
        let children: Vec<Arc<ANode>> = children
            .iter()
            .filter_map(|c| self.done.get(&key(c)).cloned().flatten())
            .collect();
        if children.is_empty() {
            Op::Leaf
        } else {
            Op::Pick {
                grid: (smooth <= 0.0)
                    .then(|| super::pick_grid::PickGrid::build(&children))
                    .flatten(),
                children,
                smooth,
            }
        }
    }

    /// The node's own attributes compiled, and their positions by design
    /// attribute index.
    #[allow(clippy::type_complexity)]
    fn own(&mut self, n: &Node) -> Result<(Vec<Own>, Vec<Option<u16>>), PrepareError> {
        let mut own_of = vec![None; self.infos.len()];
        let Some(a) = n.attributes() else {
            return Ok((Vec::new(), own_of));
        };
        if a.defs.len() > MAX_OWN {
            return Err(err(
                n,
                format!(
                    "sets {} attributes; at most {MAX_OWN} fit on one node",
                    a.defs.len()
                ),
            ));
        }
        // Variables: the coordinates, then each own scalar by position
        // (other kinds get a name no math string can spell).
        let mut vars: Vec<String> = COORD_VARS.iter().map(|v| v.to_string()).collect();
        for d in &a.defs {
            vars.push(match d.kind {
                AttributeKind::Scalar => d.name.clone(),
                _ => format!("#{}", d.name),
            });
        }
        let var_refs: Vec<&str> = vars.iter().map(String::as_str).collect();
        let vars_key = vars.join("\u{1f}");
        let mut own = Vec::with_capacity(a.defs.len());
        for (pos, d) in a.defs.iter().enumerate() {
            own_of[self.index[d.name.as_str()]] = Some(pos as u16);
            let src = match &d.source {
                AttrSource::Components(cs) => OwnSrc::Comps(
                    cs.iter()
                        .map(|c| self.compile(n, d, c, (&var_refs, &vars_key)))
                        .collect::<Result<_, _>>()?,
                ),
                AttrSource::Data { field, column, .. } => OwnSrc::Data {
                    field: field.clone(),
                    column: *column,
                },
                AttrSource::Points { cloud, column } => OwnSrc::Points {
                    cloud: cloud.clone(),
                    column: *column,
                },
                AttrSource::Image { map, channel } => OwnSrc::Image {
                    map: map.clone(),
                    channel: *channel,
                },
                AttrSource::Convert { from, map } => self.convert(n, a, d, from, map)?,
            };
            own.push(Own {
                name: d.name.clone(),
                src,
                order: Vec::new(),
                used: 0,
                range: names::range(&d.name),
                call: call(d.origin),
            });
        }
        super::order::order_dependencies(n, &mut own)?;
        Ok((own, own_of))
    }
}

impl Builder<'_> {
    /// A `Convert` of `from`: a scalar of the design.
    fn convert(
        &self,
        n: &Node,
        a: &super::NodeAttributes,
        d: &super::AttrDef,
        from: &str,
        map: &super::ConvMap,
    ) -> Result<OwnSrc, PrepareError> {
        if let super::ConvMap::Mix { reuss, values } = map {
            return self.mix(n, *reuss, values);
        }
        let Some(&idx) = self.index.get(from) else {
            let have: Vec<&str> = self.infos.iter().map(|i| i.name.as_str()).collect();
            return Err(err(
                n,
                format!(
                    "converts \"{from}\", which no node sets; the design has: {}",
                    have.join(", ")
                ),
            ));
        };
        if self.infos[idx].kind != AttributeKind::Scalar {
            return Err(err(
                n,
                format!(
                    "converts \"{from}\", a {}; Convert reads a number attribute",
                    self.infos[idx].kind.name()
                ),
            ));
        }
        let map = match map {
            super::ConvMap::Table(t) => PConv::Table(t.clone()),
            super::ConvMap::Mix { .. } => {
                return Err(err(n, "mixes fractions (a bug in volcad)".into()));
            }
            super::ConvMap::Expr(s) => {
                let mut vars: Vec<&str> = COORD_VARS.to_vec();
                vars.push(from);
                let e = Expr::compile(s, &vars).map_err(|e| {
                    err(
                        n,
                        format!(
                            "Convert to \"{}\": {e}; the math string reads x y z rho phic r theta phis d and \"{from}\"",
                            d.name
                        ),
                    )
                })?;
                PConv::Expr(Arc::new(e))
            }
        };
        Ok(OwnSrc::Convert {
            from: idx,
            from_own: a.defs.iter().position(|o| o.name == from),
            map,
            clamped: Default::default(),
        })
    }
}

impl Builder<'_> {
    /// A conversion from the fractions: each material's dense slot.
    fn mix(
        &self,
        n: &Node,
        reuss: bool,
        values: &[(MaterialId, f64)],
    ) -> Result<OwnSrc, PrepareError> {
        let mut slots = Vec::with_capacity(values.len());
        for (id, _) in values {
            let Some(s) = self.materials.iter().position(|m| m == id) else {
                return Err(err(
                    n,
                    format!(
                        "mixes a value for material {id}, which the design does not use; it uses {:?}",
                        self.materials
                    ),
                ));
            };
            slots.push(s);
        }
        Ok(OwnSrc::Convert {
            from: usize::MAX,
            from_own: None,
            map: PConv::Mix {
                reuss,
                slots,
                values: values.iter().map(|v| v.1).collect(),
                materials: self.materials.len(),
            },
            clamped: Default::default(),
        })
    }
}

impl Builder<'_> {
    /// Component `c` of `d`, with the variables `vars` (and their cache
    /// key): a math string compiled once per source and variable list.
    fn compile(
        &mut self,
        n: &Node,
        d: &super::AttrDef,
        c: &Component,
        (vars, vars_key): (&[&str], &str),
    ) -> Result<PComp, PrepareError> {
        let s = match c {
            Component::Const(v) => return Ok(PComp::Const(*v)),
            Component::Text(s) => s,
        };
        let key = (s.clone(), vars_key.to_owned());
        if let Some(p) = self.exprs.get(&key) {
            return Ok(p.clone());
        }
        let p = match Expr::compile(s, vars) {
            Ok(e) => match e.constant() {
                Some(v) => PComp::Const(v),
                None => PComp::Expr(Arc::new(e)),
            },
            Err(e) => {
                return Err(err(
                    n,
                    format!(
                        "{} (\"{}\"): {e}; a math string reads x y z rho phic r theta phis d and the node's other number attributes by name",
                        call(d.origin),
                        d.name
                    ),
                ));
            }
        };
        self.exprs.insert(key, p.clone());
        Ok(p)
    }
}
