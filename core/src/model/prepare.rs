//! Script tree -> prepared tree: resolve materials to dense slots, compute
//! bounding boxes, build spatial indices, check what can only be checked
//! with the whole tree (missing children, unbounded tiles).

use crate::expr::ExprSet;
use std::collections::{BTreeSet, HashMap};
use std::sync::Arc;

use glam::{DMat3, DVec2, DVec3};

use super::pnode::{Capsule, Grade, LineCapsule, NAry, PNode, Prism, SimGrade, Slot};
use super::shapes::{Beam, Cone, Revolve, Shape};
use super::strut_grid::StrutGrid;
use super::tpms::Tpms;
use super::union_index::UnionIndex;
use super::{MAX_MATERIALS, PrepareError};
use crate::bounds::Aabb;
use crate::material::MaterialId;
use crate::node::{CapMode, Node, NodeKind};

/// Unions with at least this many sharp children get a spatial index.
const INDEX_MIN_CHILDREN: usize = 8;

pub(super) struct Preparer {
    slots: HashMap<MaterialId, Slot>,
    cache: HashMap<*const NodeKind, (Arc<PNode>, Aabb)>,
}

/// Every material id used in the tree, ascending.
pub(super) fn collect_materials(root: &Node) -> Vec<MaterialId> {
    let mut set = BTreeSet::new();
    let mut seen = std::collections::HashSet::new();
    let mut stack = vec![root];
    while let Some(n) = stack.pop() {
        if !seen.insert(n.ptr()) {
            continue;
        }
        set.extend(n.kind().own_materials().iter().copied());
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

    /// Prepare `n` (cached by identity, so shared subtrees are prepared once).
    pub(super) fn prepare(&mut self, n: &Node) -> Result<(Arc<PNode>, Aabb), PrepareError> {
        if let Some(hit) = self.cache.get(&n.ptr()) {
            return Ok(hit.clone());
        }
        // Identity only marks a frame in the script's tree: it prepares to
        // its child itself.
        if let NodeKind::Identity { child } = n.kind() {
            return self.child(n, child);
        }
        let out = self.build(n)?;
        let out = (Arc::new(out.0), out.1);
        self.cache.insert(n.ptr(), out.clone());
        Ok(out)
    }

    fn child(
        &mut self,
        parent: &Node,
        c: &Option<Node>,
    ) -> Result<(Arc<PNode>, Aabb), PrepareError> {
        match c {
            Some(c) => self.prepare(c),
            None => Err(err(
                parent,
                "has no child; give one in the constructor or with set_child",
            )),
        }
    }

    fn build(&mut self, n: &Node) -> Result<(PNode, Aabb), PrepareError> {
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
                (
                    PNode::Lattice {
                        grid: cell.and_then(|c| StrutGrid::new(&struts, c * 0.5).map(Box::new)),
                        struts,
                        r: *radius,
                        clip_h: cell.map(|c| c * 0.5),
                        m: self.slot(*material),
                    },
                    bbox,
                )
            }
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
            NodeKind::Union {
                smooth,
                blend,
                children,
            } => {
                let (nary, bbox) = self.nary(n, children, *smooth, *blend, true)?;
                (PNode::Union(Box::new(nary)), bbox.expand(smooth.max(0.0)))
            }
            NodeKind::Intersection {
                smooth,
                blend,
                children,
            } => {
                let (nary, _) = self.nary(n, children, *smooth, *blend, false)?;
                let bbox = nary
                    .boxes
                    .iter()
                    .fold(Aabb::EVERYTHING, |a, b| a.intersection(b));
                (PNode::Intersection(Box::new(nary)), bbox)
            }
            NodeKind::Difference {
                smooth,
                left,
                right,
            } => {
                let (a, ba) = self.child(n, left)?;
                let (b, _) = match right {
                    Some(r) => self.prepare(r)?,
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
            NodeKind::FGrade {
                exprs,
                materials,
                child,
                ..
            } => {
                too_many_expressions(n, exprs.len())?;
                let (c, b) = self.child(n, child)?;
                let used = exprs.iter().fold(0, |m, e| m | e.used_vars());
                let mats = materials.iter().map(|m| self.slot(*m)).collect();
                (
                    PNode::FGrade(Box::new(Grade {
                        exprs: exprs.clone(),
                        set: ExprSet::new(exprs.clone()),
                        mats,
                        used,
                        child: c,
                    })),
                    b,
                )
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
            kind => self.build_shape(n, kind)?,
        })
    }

    /// The nodes of `shapes` and the Mirror and Sum composites.
    fn build_shape(&mut self, n: &Node, kind: &NodeKind) -> Result<(PNode, Aabb), PrepareError> {
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
                let m = super::bound::reflection(*normal);
                (
                    PNode::Mirror {
                        point: *point,
                        normal: *normal,
                        child: c,
                    },
                    b.transformed(&m, *point),
                )
            }
            NodeKind::Sum { iso, children } => {
                if children.is_empty() {
                    return Err(err(
                        n,
                        "has no children; add some with add_child or pass a list",
                    ));
                }
                let mut nodes = Vec::with_capacity(children.len());
                let mut bbox = Aabb::EMPTY;
                for c in children {
                    let (p, b) = self.prepare(c)?;
                    nodes.push(p);
                    bbox = bbox.union(&b);
                }
                // Outside every child's box each dᵢ > 0, so Σdᵢ + iso ≤ 0
                // needs every dᵢ ≤ −iso: within −iso of every box.
                (
                    PNode::Sum {
                        iso: *iso,
                        children: nodes,
                    },
                    bbox.expand((-iso).max(0.0)),
                )
            }
            // Identity never gets here (`prepare` answers it with its
            // child); the other kinds are built in `build`.
            other => {
                return Err(err(
                    n,
                    &format!("{} cannot be prepared here", other.type_name()),
                ));
            }
        })
    }

    fn nary(
        &mut self,
        n: &Node,
        children: &[Node],
        smooth: f64,
        blend: bool,
        is_union: bool,
    ) -> Result<(NAry, Aabb), PrepareError> {
        if children.is_empty() {
            return Err(err(
                n,
                "has no children; add some with add_child or pass a list",
            ));
        }
        let mut nodes = Vec::with_capacity(children.len());
        let mut boxes = Vec::with_capacity(children.len());
        let mut bbox = Aabb::EMPTY;
        for c in children {
            let (p, b) = self.prepare(c)?;
            nodes.push(p);
            boxes.push(b);
            bbox = bbox.union(&b);
        }
        let lipschitz = smooth <= 0.0 && nodes.iter().all(|n| n.is_lipschitz());
        // 1-Lipschitz children are listed by `d(centre) − half diagonal`, so
        // queries can tighten it to `d(centre) − |p − centre|` (the slack).
        let index =
            (is_union && smooth <= 0.0 && children.len() >= INDEX_MIN_CHILDREN).then(|| {
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
        Ok((
            NAry {
                children: nodes,
                boxes,
                smooth: smooth.max(0.0),
                blend,
                index,
                capsules,
                fixed,
                lipschitz,
            },
            bbox,
        ))
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

/// R = Rz(roll)·Ry(yaw)·Rx(pitch), degrees (pyvcad's convention for its
/// bounding box; we rotate the geometry by the same R, see docs/PYVCAD.md).
pub fn rotation(pitch: f64, yaw: f64, roll: f64) -> DMat3 {
    DMat3::from_rotation_z(roll.to_radians())
        * DMat3::from_rotation_y(yaw.to_radians())
        * DMat3::from_rotation_x(pitch.to_radians())
}

/// A planar polygon (right-hand rule normal) extruded by `height` along the
/// normal (negative flips; `symmetric` centres it on the plane).
fn prism(vertices: &[DVec3], height: f64, symmetric: bool) -> Result<(Prism, Aabb), String> {
    if vertices.len() < 3 {
        return Err(format!("needs at least 3 vertices, got {}", vertices.len()));
    }
    // Newell's method: robust normal of a planar polygon, length = 2·area.
    let mut normal = DVec3::ZERO;
    for i in 0..vertices.len() {
        let (a, b) = (vertices[i], vertices[(i + 1) % vertices.len()]);
        normal += DVec3::new(
            (a.y - b.y) * (a.z + b.z),
            (a.z - b.z) * (a.x + b.x),
            (a.x - b.x) * (a.y + b.y),
        );
    }
    let scale = vertices
        .iter()
        .map(|v| (*v - vertices[0]).length())
        .fold(0.0, f64::max);
    if normal.length() <= 1e-12 * scale * scale || scale == 0.0 {
        return Err("vertices are collinear or repeated: the polygon has no area".into());
    }
    let nrm = normal.normalize();
    for (i, v) in vertices.iter().enumerate() {
        let off = (*v - vertices[0]).dot(nrm);
        if off.abs() > 1e-6 * scale.max(1.0) {
            return Err(format!(
                "vertex {i} is {off:.3e} mm off the polygon's plane: vertices must be coplanar"
            ));
        }
    }
    if height == 0.0 {
        return Err("height is 0".into());
    }
    let u = (vertices[1] - vertices[0]).normalize();
    let u = (u - nrm * u.dot(nrm)).normalize();
    let v = nrm.cross(u);
    let to_frame = DMat3::from_cols(u, v, nrm).transpose();
    let origin = vertices[0];
    let poly: Vec<DVec2> = vertices
        .iter()
        .map(|p| {
            let q = to_frame * (*p - origin);
            DVec2::new(q.x, q.y)
        })
        .collect();
    let (lo, hi) = if symmetric {
        (-height.abs() / 2.0, height.abs() / 2.0)
    } else if height > 0.0 {
        (0.0, height)
    } else {
        (height, 0.0)
    };
    let mut bbox = Aabb::EMPTY;
    for p in vertices {
        for w in [lo, hi] {
            let q = *p + nrm * w;
            bbox = bbox.union(&Aabb::new(q, q));
        }
    }
    Ok((
        Prism {
            to_frame,
            origin,
            poly,
            w_mid: (lo + hi) / 2.0,
            w_half: (hi - lo) / 2.0,
        },
        bbox,
    ))
}
