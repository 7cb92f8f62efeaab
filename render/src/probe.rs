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
/// with the exact (lower-bound) distance, clipped by `cut` if given; a model
/// whose value is not a distance bound is marched by its sign instead
/// ([`sign_march`]). `None` when the ray misses.
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
    if !model.distance_is_bound() {
        return sign_march(model, &sdf, o, d, (tmin, tmax), scale);
    }
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
                    return Some(hit_at(model, p, tt));
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

fn hit_at(model: &Model, point: DVec3, distance: f64) -> ProbeHit {
    let (_, fr) = model.eval_point(point);
    ProbeHit {
        point,
        distance,
        fractions: fr.into_iter().filter(|(_, f)| *f > 0.0).collect(),
    }
}

/// Steps per bounding-box size of the sign march: four per voxel of the
/// viewport's finest bake (256 along the longest side), so the probe finds
/// every feature the viewport draws.
const SIGN_STEPS: f64 = 1024.0;

/// The first sign change of `sdf` along `o + t·d`, t in `span`: fixed steps
/// of 1/[`SIGN_STEPS`] of the box size, then bisection to the inside end of
/// the crossing (what the viewport draws from the redistanced bake).
fn sign_march(
    model: &Model,
    sdf: &dyn Fn(DVec3) -> f64,
    o: DVec3,
    d: DVec3,
    span: (f64, f64),
    scale: f64,
) -> Option<ProbeHit> {
    let (tmin, tmax) = span;
    let step = scale / SIGN_STEPS;
    if sdf(o + d * tmin) <= 0.0 {
        return Some(hit_at(model, o + d * tmin, tmin));
    }
    let mut prev = tmin;
    while prev < tmax {
        let t = (prev + step).min(tmax);
        if sdf(o + d * t) <= 0.0 {
            let (mut a, mut b) = (prev, t);
            for _ in 0..48 {
                let m = 0.5 * (a + b);
                if sdf(o + d * m) <= 0.0 {
                    b = m;
                } else {
                    a = m;
                }
            }
            return Some(hit_at(model, o + d * b, b));
        }
        prev = t;
    }
    None
}
