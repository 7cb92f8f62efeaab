//! A `Prism` node's polygon brought into its own frame: the plane's normal
//! by Newell's method, the coplanarity check, and the extrusion's box.

use glam::{DMat3, DVec2, DVec3};

use crate::aabb::Aabb;
use crate::model::pnode::Prism;

/// A planar polygon (right-hand rule normal) extruded by `height` along the
/// normal (negative flips; `symmetric` centres it on the plane).
pub(super) fn prism(
    vertices: &[DVec3],
    height: f64,
    symmetric: bool,
) -> Result<(Prism, Aabb), String> {
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
