//! The design tree as a script builds it.
//!
//! A [`Node`] is a cheap handle (`Arc`) to an immutable [`NodeKind`]; children
//! are shared, so a unit cell used by `Tile` or a strut used a thousand times
//! exists once. Building is cheap and does no geometry; [`crate::Model::prepare`]
//! turns the tree into an evaluator. Names and argument orders follow pyvcad
//! 2.x (pyvcad 2.3.4).

use std::sync::Arc;

use glam::DVec3;

use crate::expr::Expr;
use crate::material::MaterialId;

/// Where in the design script a node was made (1-based), for error messages.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Origin {
    /// Script line.
    pub line: u32,
    /// Script column.
    pub column: u32,
}

impl std::fmt::Display for Origin {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}:{}", self.line, self.column)
    }
}

/// Standard unit cells of [`NodeKind::GraphLattice`] (pyvcad's `LatticeType`,
/// plus `Octet`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum LatticeType {
    /// 4 body diagonals.
    BodyCenteredCubic,
    /// 12 face diagonals.
    FaceCenteredCubic,
    /// 12 cube edges.
    Cubic,
    /// Truncated octahedron (36 edges).
    KelvinCell,
    /// Octet truss: FCC face diagonals plus the octahedron joining face centres.
    Octet,
}

/// Triply periodic minimal surfaces (not in pyvcad 2.x).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum TpmsType {
    /// Schoen's gyroid: sin x cos y + sin y cos z + sin z cos x.
    Gyroid,
    /// Schwarz P: cos x + cos y + cos z.
    SchwarzP,
    /// Schwarz D (diamond).
    Diamond,
}

/// How a tapered strut's end is closed (pyvcad 3's `CapMode`, the 3MF
/// beam-lattice extension's `ST_CapMode`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum CapMode {
    /// A full sphere of the end's radius.
    Sphere,
    /// The outward half of that sphere.
    HemiSphere,
    /// Flat: the frustum ends in its disc.
    Butt,
}

/// A handle to a node of the design tree.
///
/// Dropping and debug-printing do not recurse: a script can nest a million
/// nodes (`n = Union(false, [n, s])` in a loop), and a recursive walk of
/// that depth overflows a thread's stack.
#[derive(Clone)]
pub struct Node {
    pub(crate) kind: Arc<NodeKind>,
    pub(crate) origin: Option<Origin>,
    /// Property fields set on this node (`set_attribute`); `None` for
    /// almost every node, so a handle stays three words.
    pub(crate) attrs: Option<Arc<crate::attribute::NodeAttributes>>,
}

/// What a node is. Parameters are as the script gave them; validation of
/// values happens in the constructors in [`crate::script`] and at prepare.
#[derive(Clone, Debug)]
#[allow(missing_docs)]
pub enum NodeKind {
    /// Exact `|p − c| − r`.
    Sphere {
        center: DVec3,
        radius: f64,
        material: MaterialId,
    },
    /// Box with full side lengths `size` (exact Euclidean distance).
    RectPrism {
        center: DVec3,
        size: DVec3,
        material: MaterialId,
    },
    /// Z-axis capped cylinder centred at `center`.
    Cylinder {
        center: DVec3,
        radius: f64,
        height: f64,
        material: MaterialId,
    },
    /// Capsule between `a` and `b`.
    Strut {
        a: DVec3,
        b: DVec3,
        radius: f64,
        material: MaterialId,
    },
    /// Planar polygon extruded along its normal.
    PolygonExtrude {
        vertices: Vec<DVec3>,
        height: f64,
        symmetric: bool,
        material: MaterialId,
    },
    /// Implicit function of a math string, clipped to its box.
    Function {
        expr: Arc<Expr>,
        material: MaterialId,
        min: DVec3,
        max: DVec3,
    },
    /// Sheet TPMS with wall thickness, unbounded (intersect it with a shape).
    Tpms {
        kind: TpmsType,
        cell: DVec3,
        thickness: f64,
        material: MaterialId,
    },
    /// Struts of a unit cell (or a custom edge list), clipped to the cell box.
    GraphLattice {
        edges: Vec<(DVec3, DVec3)>,
        cell: Option<DVec3>,
        radius: f64,
        material: MaterialId,
    },
    /// `child(p − offset)`.
    Translate { offset: DVec3, child: Option<Node> },
    /// Rotation by pitch (X), yaw (Y), roll (Z) degrees about `around`.
    Rotate {
        pitch: f64,
        yaw: f64,
        roll: f64,
        around: DVec3,
        child: Option<Node>,
    },
    /// Scale about the origin.
    Scale { factors: DVec3, child: Option<Node> },
    /// Min of children; `smooth` > 0 rounds the seams; `blend` averages materials.
    Union {
        smooth: f64,
        blend: bool,
        children: Vec<Node>,
    },
    /// Max of children.
    Intersection {
        smooth: f64,
        blend: bool,
        children: Vec<Node>,
    },
    /// `max(a, −b)`.
    Difference {
        smooth: f64,
        left: Option<Node>,
        right: Option<Node>,
    },
    /// Grow (positive) or shrink (negative) by `distance`.
    Offset { distance: f64, child: Option<Node> },
    /// Hollow with wall `thickness` (either sign, inward).
    Shell { thickness: f64, child: Option<Node> },
    /// Periodic repetition of the child; cell from the child's box if `None`.
    Tile {
        cell: Option<DVec3>,
        child: Option<Node>,
    },
    /// Material fractions from math strings over the child's geometry.
    FGrade {
        exprs: Vec<Arc<Expr>>,
        materials: Vec<MaterialId>,
        prob: bool,
        child: Option<Node>,
    },
    /// Average of the child's fractions over a neighbourhood of `radius`.
    Blend { radius: f64, child: Option<Node> },
    /// A triangle mesh as signed distance (mesh import).
    Mesh {
        mesh: Arc<crate::trimesh::TriangleMesh>,
        material: MaterialId,
    },
    /// An FEA result field driving fractions (SimulationField).
    SimulationField {
        field: Arc<crate::simfield::SimField>,
        exprs: Vec<Arc<Expr>>,
        materials: Vec<MaterialId>,
    },
    /// Cone with its apex at the origin opening down −Z: aperture half-angle
    /// `angle` (radians), base disc at z = −height.
    Cone {
        angle: f64,
        height: f64,
        material: MaterialId,
    },
    /// Torus about the Z axis at the origin: ring radius `major`, tube
    /// radius `minor`.
    Torus {
        major: f64,
        minor: f64,
        material: MaterialId,
    },
    /// A planar half-profile revolved about the axis from `axis_start` to
    /// `axis_end` by `sweep_degrees` (right-hand rule about that direction).
    PolygonRevolve {
        vertices: Vec<DVec3>,
        axis_start: DVec3,
        axis_end: DVec3,
        sweep_degrees: f64,
        material: MaterialId,
    },
    /// Strut with a radius and a cap at each end (a frustum between `a` and
    /// `b`); pyvcad's name is `Strut` too.
    TaperedStrut {
        a: DVec3,
        b: DVec3,
        radius_a: f64,
        radius_b: f64,
        cap_a: CapMode,
        cap_b: CapMode,
        material: MaterialId,
    },
    /// Reflection of the child across the plane through `point` with unit
    /// `normal`.
    Mirror {
        point: DVec3,
        normal: DVec3,
        child: Option<Node>,
    },
    /// The child unchanged: a frame of its own for the expressions above it.
    Identity { child: Option<Node> },
    /// `Σ dᵢ + iso`; fractions of the first child containing the point.
    Sum { iso: f64, children: Vec<Node> },
    /// Text outlines (laid out and flattened by `crate::text`) extruded by
    /// `depth` centred on z = 0.
    Text {
        text: String,
        shape: Arc<crate::model::polygon2d::Polygon2d>,
        depth: f64,
        material: MaterialId,
    },
}

/// The pattern of every unary node (one optional child slot), binding the
/// slot to `$child`: one list for [`NodeKind::children`] and
/// [`NodeKind::child_slot`], so a new unary node is added in one place.
macro_rules! unary_kinds {
    ($child:ident) => {
        NodeKind::Translate { $child, .. }
            | NodeKind::Rotate { $child, .. }
            | NodeKind::Scale { $child, .. }
            | NodeKind::Offset { $child, .. }
            | NodeKind::Shell { $child, .. }
            | NodeKind::Tile { $child, .. }
            | NodeKind::FGrade { $child, .. }
            | NodeKind::Blend { $child, .. }
            | NodeKind::Mirror { $child, .. }
            | NodeKind::Identity { $child }
    };
}

impl NodeKind {
    /// pyvcad's class name of this node (for messages and `volcad info`).
    pub fn type_name(&self) -> &'static str {
        match self {
            NodeKind::Sphere { .. } => "Sphere",
            NodeKind::RectPrism { .. } => "RectPrism",
            NodeKind::Cylinder { .. } => "Cylinder",
            NodeKind::Strut { .. } => "Strut",
            NodeKind::PolygonExtrude { .. } => "PolygonExtrude",
            NodeKind::Function { .. } => "Function",
            NodeKind::Tpms { .. } => "TPMS",
            NodeKind::GraphLattice { .. } => "GraphLattice",
            NodeKind::Translate { .. } => "Translate",
            NodeKind::Rotate { .. } => "Rotate",
            NodeKind::Scale { .. } => "Scale",
            NodeKind::Union { .. } => "Union",
            NodeKind::Intersection { .. } => "Intersection",
            NodeKind::Difference { .. } => "Difference",
            NodeKind::Offset { .. } => "Offset",
            NodeKind::Shell { .. } => "Shell",
            NodeKind::Tile { .. } => "Tile",
            NodeKind::FGrade { .. } => "FGrade",
            NodeKind::Blend { .. } => "Blend",
            NodeKind::Mesh { .. } => "Mesh",
            NodeKind::SimulationField { .. } => "SimulationField",
            NodeKind::Cone { .. } => "Cone",
            NodeKind::Torus { .. } => "Torus",
            NodeKind::PolygonRevolve { .. } => "PolygonRevolve",
            NodeKind::TaperedStrut { .. } => "Strut",
            NodeKind::Mirror { .. } => "Mirror",
            NodeKind::Identity { .. } => "Identity",
            NodeKind::Sum { .. } => "Sum",
            NodeKind::Text { .. } => "Text",
        }
    }

    /// The material ids this node itself assigns (a leaf's material, or an
    /// FGrade's / SimulationField's list); not its children's.
    pub fn own_materials(&self) -> &[MaterialId] {
        match self {
            NodeKind::Sphere { material, .. }
            | NodeKind::RectPrism { material, .. }
            | NodeKind::Cylinder { material, .. }
            | NodeKind::Strut { material, .. }
            | NodeKind::PolygonExtrude { material, .. }
            | NodeKind::Function { material, .. }
            | NodeKind::Tpms { material, .. }
            | NodeKind::GraphLattice { material, .. }
            | NodeKind::Mesh { material, .. }
            | NodeKind::Cone { material, .. }
            | NodeKind::Torus { material, .. }
            | NodeKind::PolygonRevolve { material, .. }
            | NodeKind::TaperedStrut { material, .. }
            | NodeKind::Text { material, .. } => std::slice::from_ref(material),
            NodeKind::FGrade { materials, .. } | NodeKind::SimulationField { materials, .. } => {
                materials
            }
            _ => &[],
        }
    }

    /// The children, in order (missing optional children are skipped).
    pub fn children(&self) -> Vec<&Node> {
        match self {
            unary_kinds!(child) => child.iter().collect(),
            NodeKind::Union { children, .. }
            | NodeKind::Intersection { children, .. }
            | NodeKind::Sum { children, .. } => children.iter().collect(),
            NodeKind::Difference { left, right, .. } => left.iter().chain(right.iter()).collect(),
            _ => Vec::new(),
        }
    }

    /// Mutable access to the single child slot of a unary node.
    pub(crate) fn child_slot(&mut self) -> Option<&mut Option<Node>> {
        match self {
            unary_kinds!(child) => Some(child),
            _ => None,
        }
    }
}

impl Node {
    /// A node with no script origin.
    pub fn new(kind: NodeKind) -> Self {
        Self {
            kind: Arc::new(kind),
            origin: None,
            attrs: None,
        }
    }

    /// A node made at `origin` in a script.
    pub fn with_origin(kind: NodeKind, origin: Option<Origin>) -> Self {
        Self {
            kind: Arc::new(kind),
            origin,
            attrs: None,
        }
    }

    /// What this node is.
    pub fn kind(&self) -> &NodeKind {
        &self.kind
    }

    /// Where the script made it.
    pub fn origin(&self) -> Option<Origin> {
        self.origin
    }

    /// "FGrade (line 3:12)" or "FGrade", for error messages.
    pub fn describe(&self) -> String {
        match self.origin {
            Some(o) => format!("{} (made at line {})", self.kind.type_name(), o),
            None => self.kind.type_name().to_owned(),
        }
    }

    /// Number of distinct nodes in the tree (shared subtrees count once).
    pub fn count_nodes(&self) -> usize {
        let mut seen = std::collections::HashSet::new();
        let mut stack = vec![self];
        while let Some(n) = stack.pop() {
            if seen.insert(Arc::as_ptr(&n.kind)) {
                stack.extend(n.kind.children());
            }
        }
        seen.len()
    }

    /// Mutable access for builder methods (`add_child`, `set_child`): copy on
    /// write, so other handles to the same node are not changed.
    pub(crate) fn kind_mut(&mut self) -> &mut NodeKind {
        Arc::make_mut(&mut self.kind)
    }

    /// The attributes set on this node, if any.
    pub fn attributes(&self) -> Option<&crate::attribute::NodeAttributes> {
        self.attrs.as_deref()
    }

    /// The attributes for `set_attribute` to change (copy on write, as
    /// `Node::kind_mut`).
    pub fn attributes_mut(&mut self) -> &mut crate::attribute::NodeAttributes {
        Arc::make_mut(self.attrs.get_or_insert_with(Default::default))
    }

    /// Identity of the attribute set (0 for none), beside [`Node::ptr`].
    pub(crate) fn attrs_ptr(&self) -> usize {
        self.attrs.as_ref().map_or(0, |a| Arc::as_ptr(a) as usize)
    }

    /// The identity of the shared node (for caches during prepare).
    pub(crate) fn ptr(&self) -> *const NodeKind {
        Arc::as_ptr(&self.kind)
    }
}

/// Moves the children out of `kind` into `out` when this is its last
/// handle (so they are dropped from the caller's loop, not from inside
/// this node's drop).
fn take_children(kind: &mut Arc<NodeKind>, out: &mut Vec<Node>) {
    let Some(k) = Arc::get_mut(kind) else {
        return;
    };
    if let Some(slot) = k.child_slot() {
        out.extend(slot.take());
        return;
    }
    match k {
        NodeKind::Union { children, .. } | NodeKind::Intersection { children, .. } => {
            out.append(children)
        }
        NodeKind::Difference { left, right, .. } => {
            out.extend(left.take());
            out.extend(right.take());
        }
        _ => {}
    }
}

impl Drop for Node {
    fn drop(&mut self) {
        let mut pending = Vec::new();
        take_children(&mut self.kind, &mut pending);
        while let Some(mut n) = pending.pop() {
            take_children(&mut n.kind, &mut pending);
            // `n` now holds no children: its own drop does not descend.
        }
    }
}

impl std::fmt::Debug for Node {
    /// One level: the type, where it was made and how many children (the
    /// children's own fields would recurse as deep as the tree).
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Node")
            .field("type", &self.kind.type_name())
            .field("origin", &self.origin)
            .field("children", &self.kind.children().len())
            .finish()
    }
}
