//! The cursor probe: an exact CPU ray cast against the model (not the baked
//! volume), for the "what is under the cursor" read-out.

use glam::{DVec3, Vec2};
use volcad_core::{MaterialId, Model};

use crate::camera::Camera;
use crate::settings::CutPlane;

/// What the probe ray hit.
#[derive(Clone, Debug, PartialEq)]
pub struct ProbeHit {
    /// The surface point (mm), just inside the part.
    pub point: DVec3,
    /// Distance from the ray origin to the point (mm).
    pub distance: f64,
    /// Material fractions at the point (non-zero ones, model order).
    pub fractions: Vec<(MaterialId, f64)>,
}

/// Sphere-trace `model` along the camera ray through `ndc` (−1..1, y up)
/// with the exact (lower-bound) distance, clipped by `cut` if given.
/// `None` when the ray misses.
pub fn probe(
    model: &Model,
    camera: &Camera,
    cut: Option<&CutPlane>,
    ndc: Vec2,
    aspect: f32,
) -> Option<ProbeHit> {
    let bbox = model.bbox();
    if bbox.is_empty() || !bbox.is_finite() {
        return None;
    }
    let (o, d) = camera.ray(ndc, aspect);
    let (o, d) = (o.as_dvec3(), d.as_dvec3().normalize());
    // Clip the ray to the (slightly grown) bounding box.
    let scale = bbox.size().max_element().max(1e-6);
    let b = bbox.expand(scale * 1e-3);
    let inv = d.recip();
    let t0 = (b.min - o) * inv;
    let t1 = (b.max - o) * inv;
    let tmin = t0.min(t1).max_element().max(0.0);
    let tmax = t0.max(t1).min_element();
    if tmin.is_nan() || tmax.is_nan() || tmin > tmax {
        return None;
    }
    let eps = scale * 1e-5;
    let sdf = |p: DVec3| {
        let m = model.distance(p);
        match cut {
            Some(c) => m.max(c.distance(p.to_array())),
            None => m,
        }
    };
    let mut t = tmin;
    for _ in 0..4096 {
        if t > tmax {
            return None;
        }
        let p = o + d * t;
        let dist = sdf(p);
        if dist <= eps {
            // Step until just inside so the fractions are defined.
            let mut tt = t;
            for _ in 0..64 {
                let p = o + d * tt;
                if sdf(p) <= 0.0 {
                    let (_, fr) = model.eval_point(p);
                    let fractions = fr.into_iter().filter(|(_, f)| *f > 0.0).collect();
                    return Some(ProbeHit {
                        point: p,
                        distance: tt,
                        fractions,
                    });
                }
                tt += eps;
            }
            t += eps;
            continue;
        }
        t += dist.max(eps);
    }
    None
}
