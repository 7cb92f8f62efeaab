//! The cursor pick: an exact CPU ray cast against the model (not the baked
//! volume), for the "what is under the cursor" read-out. It reads what the
//! picture draws: the cut plane removes its half, hidden materials (opacity
//! 0) and the iso mode's level decide which part of the inside is drawn, as
//! the shader's `region` does.

use glam::{DVec3, Vec2};
use volcad_core::{MaterialId, Model};

use crate::camera::Camera;
use crate::settings::{CutPlane, ViewMode, ViewSettings};

/// Which surface the pick ray stopped on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HitSurface {
    /// The part's outer surface.
    Part,
    /// The face the cut plane leaves.
    Cut,
    /// Inside the part, where the hidden materials give way to shown ones
    /// (or, in iso mode, where the fraction reaches the level).
    Region,
}

impl HitSurface {
    /// Words for the read-out.
    pub fn describe(self) -> &'static str {
        match self {
            HitSurface::Part => "on the part's surface",
            HitSurface::Cut => "on the cut face",
            HitSurface::Region => "inside the part, where shown materials begin",
        }
    }
}

/// What the pick ray hit.
#[derive(Clone, Debug, PartialEq)]
pub struct PickHit {
    /// The surface point (mm), just inside the part.
    pub point: DVec3,
    /// Distance from the ray origin to the point (mm).
    pub distance: f64,
    /// Material fractions at the point (non-zero ones, model order).
    pub fractions: Vec<(MaterialId, f64)>,
    /// Which surface it is.
    pub surface: HitSurface,
}

/// Which part of the inside the picture draws.
#[derive(Clone, Debug, PartialEq)]
enum Drawn {
    /// Everything inside the part.
    All,
    /// Where the shown materials (by position in `Model::materials()`)
    /// make up at least half of the mix.
    Shown(Vec<bool>),
    /// Where material `index`'s fraction is at least `level`.
    Iso { index: usize, level: f64 },
}

impl Drawn {
    fn from_settings(s: &ViewSettings, model: &Model) -> Drawn {
        match s.mode {
            ViewMode::Iso {
                material_index,
                level,
            } => Drawn::Iso {
                index: material_index,
                level: level as f64,
            },
            ViewMode::Solid | ViewMode::Volume => {
                let shown: Vec<bool> = (0..model.materials().len())
                    .map(|i| s.opacity(i) > 1e-3)
                    .collect();
                if shown.iter().all(|&v| v) {
                    Drawn::All
                } else {
                    Drawn::Shown(shown)
                }
            }
        }
    }

    /// `fracs` are the model's fractions in `Model::materials()` order.
    fn contains(&self, fracs: &[(MaterialId, f64)]) -> bool {
        match self {
            Drawn::All => true,
            Drawn::Shown(shown) => {
                let total: f64 = fracs.iter().map(|f| f.1).sum();
                let visible: f64 = fracs
                    .iter()
                    .zip(shown)
                    .filter(|(_, s)| **s)
                    .map(|(f, _)| f.1)
                    .sum();
                total > 0.0 && visible / total >= 0.5
            }
            Drawn::Iso { index, level } => fracs.get(*index).is_some_and(|f| f.1 >= *level),
        }
    }
}

/// Sphere-trace `model` along the camera ray through `ndc` (−1..1, y up)
/// with the exact (lower-bound) distance, clipped by `cut` if given; a model
/// whose value is not a distance bound is marched by its sign instead
/// (`sign_march`). Every material counts as drawn. `None` when the ray
/// misses.
pub fn pick(
    model: &Model,
    camera: &Camera,
    cut: Option<&CutPlane>,
    ndc: Vec2,
    aspect: f32,
) -> Option<PickHit> {
    march(model, camera, cut, &Drawn::All, ndc, aspect)
}

/// The pick as the picture drawn with `settings` shows the part: its
/// camera and cut plane, and only the materials it draws (hidden
/// materials are looked through; iso mode stops at the level's surface).
pub fn pick_drawn(
    model: &Model,
    settings: &ViewSettings,
    ndc: Vec2,
    aspect: f32,
) -> Option<PickHit> {
    let drawn = Drawn::from_settings(settings, model);
    march(
        model,
        &settings.camera,
        settings.cut.as_ref(),
        &drawn,
        ndc,
        aspect,
    )
}

/// Sphere tracing outside the part; inside a part whose point is not
/// drawn, fixed steps of about a thousandth of the part's size until the
/// drawn region begins (then bisection to the boundary) or the ray leaves
/// the part.
fn march(
    model: &Model,
    camera: &Camera,
    cut: Option<&CutPlane>,
    drawn: &Drawn,
    ndc: Vec2,
    aspect: f32,
) -> Option<PickHit> {
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
    let inside_step = (scale * 1e-3).max(eps);
    let cut_d = |p: DVec3| cut.map_or(f64::NEG_INFINITY, |c| c.distance(p.to_array()));
    let sdf = |p: DVec3| model.distance(p).max(cut_d(p));
    if !model.distance_is_bound() {
        return sign_march(model, cut, &sdf, o, d, (tmin, tmax), scale);
    }
    let at = |t: f64| o + d * t;
    // The last point inside the part that was not drawn, if the ray is
    // walking through hidden material.
    let mut hidden_since: Option<f64> = None;
    let mut t = tmin;
    for _ in 0..65_536 {
        if t > tmax {
            return None;
        }
        let dist = sdf(at(t));
        if dist > eps {
            hidden_since = None;
            t += dist;
            continue;
        }
        // Step until just inside so the fractions are defined.
        let Some(tt) = (0..64)
            .map(|k| t + k as f64 * eps)
            .find(|&tt| sdf(at(tt)) <= 0.0)
        else {
            t += 64.0 * eps;
            continue;
        };
        let (_, fr) = model.eval_point(at(tt));
        if !drawn.contains(&fr) {
            hidden_since = Some(tt);
            t = tt + inside_step;
            continue;
        }
        let (tt, fr, surface) = match hidden_since {
            None => {
                let p = at(tt);
                let surface = if cut_d(p) >= model.distance(p) {
                    HitSurface::Cut
                } else {
                    HitSurface::Part
                };
                (tt, fr, surface)
            }
            Some(lo) => {
                let (tt, fr) = bisect(lo, tt, 20, |t| {
                    let p = at(t);
                    let (dm, fr) = model.eval_point(p);
                    (dm.max(cut_d(p)) <= 0.0 && drawn.contains(&fr)).then_some(fr)
                })
                .unwrap_or((tt, fr));
                (tt, fr, HitSurface::Region)
            }
        };
        return Some(PickHit {
            point: at(tt),
            distance: tt,
            fractions: fr.into_iter().filter(|(_, f)| *f > 0.0).collect(),
            surface,
        });
    }
    None
}

/// The first `t` in `(lo, hi]` where `drawn_at` answers (it does at `hi`,
/// not at `lo`), to 2^−`steps` of the interval, with its answer.
fn bisect<T>(
    mut lo: f64,
    mut hi: f64,
    steps: u32,
    drawn_at: impl Fn(f64) -> Option<T>,
) -> Option<(f64, T)> {
    let mut best = None;
    for _ in 0..steps {
        let mid = 0.5 * (lo + hi);
        match drawn_at(mid) {
            Some(v) => {
                hi = mid;
                best = Some(v);
            }
            None => lo = mid,
        }
    }
    best.map(|v| (hi, v))
        .or_else(|| drawn_at(hi).map(|v| (hi, v)))
}

/// The hit at `point` of a sign march (hidden materials are not looked
/// through there: such fields are rare and the march is coarse already).
fn hit_at(model: &Model, cut: Option<&CutPlane>, point: DVec3, distance: f64) -> PickHit {
    let (dm, fr) = model.eval_point(point);
    let on_cut = cut.is_some_and(|c| c.distance(point.to_array()) >= dm);
    PickHit {
        point,
        distance,
        fractions: fr.into_iter().filter(|(_, f)| *f > 0.0).collect(),
        surface: if on_cut {
            HitSurface::Cut
        } else {
            HitSurface::Part
        },
    }
}

/// Steps per bounding-box size of the sign march: four per voxel of the
/// viewport's finest bake (256 along the longest side), so the pick finds
/// every feature the viewport draws.
const SIGN_STEPS: f64 = 1024.0;

/// The first sign change of `sdf` along `o + t·d`, t in `span`: fixed steps
/// of 1/[`SIGN_STEPS`] of the box size, then bisection to the inside end of
/// the crossing (what the viewport draws from the redistanced bake).
fn sign_march(
    model: &Model,
    cut: Option<&CutPlane>,
    sdf: &dyn Fn(DVec3) -> f64,
    o: DVec3,
    d: DVec3,
    span: (f64, f64),
    scale: f64,
) -> Option<PickHit> {
    let (tmin, tmax) = span;
    let step = scale / SIGN_STEPS;
    if sdf(o + d * tmin) <= 0.0 {
        return Some(hit_at(model, cut, o + d * tmin, tmin));
    }
    let mut prev = tmin;
    while prev < tmax {
        let t = (prev + step).min(tmax);
        if sdf(o + d * t) <= 0.0 {
            let (b, ()) = bisect(prev, t, 48, |m| (sdf(o + d * m) <= 0.0).then_some(()))?;
            return Some(hit_at(model, cut, o + d * b, b));
        }
        prev = t;
    }
    None
}
