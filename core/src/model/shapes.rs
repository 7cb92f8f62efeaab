//! The primitives pyvcad 3 added (Cone, Torus, PolygonRevolve, tapered
//! Strut), prepared: closed-form distances in the style of Inigo Quilez's
//! "distance functions" (sdCone, sdTorus, sdCappedCone), and the section
//! argument for solids of revolution: the point nearest to `p` on a solid
//! revolved about an axis lies in the half-plane through the axis and `p`
//! (or on an end face of a partial sweep), so a 2D polygon distance in
//! (radial, axial) coordinates gives the exact 3D distance.

use glam::{DVec2, DVec3};

use super::sdf;
use crate::aabb::Aabb;
use crate::node::CapMode;

/// A capsule with precomputed terms.
#[derive(Clone, Copy, Debug)]
pub struct Capsule {
    pub a: DVec3,
    pub ab: DVec3,
    pub inv_ab2: f64,
    pub r: f64,
}

impl Capsule {
    pub fn new(a: DVec3, b: DVec3, r: f64) -> Self {
        let ab = b - a;
        let l2 = ab.length_squared();
        Self {
            a,
            ab,
            inv_ab2: if l2 > 0.0 { 1.0 / l2 } else { 0.0 },
            r,
        }
    }

    #[inline]
    pub fn dist(&self, p: DVec3) -> f64 {
        sdf::capsule(p, self.a, self.ab, self.inv_ab2, self.r)
    }

    /// Squared distance from `p` to the axis segment: `dist` is its square
    /// root minus `r`, computed the same way.
    #[inline]
    pub fn axis_dist2(&self, p: DVec3) -> f64 {
        sdf::segment_dist2(p, self.a, self.ab, self.inv_ab2)
    }

    pub fn bbox(&self) -> Aabb {
        let b = self.a + self.ab;
        Aabb::new(self.a.min(b), self.a.max(b)).expand(self.r)
    }
}

/// One prepared primitive of this module.
#[derive(Clone, Debug)]
pub enum Shape {
    Cone(Cone),
    Torus { major: f64, minor: f64 },
    Revolve(Box<Revolve>),
    Beam(Beam),
}

impl Shape {
    /// Signed distance: exact for the cone, torus and revolve; exact
    /// outside a tapered strut and a bound inside it (the union of its
    /// frustum and caps, each exact).
    #[inline]
    pub fn dist(&self, p: DVec3) -> f64 {
        match self {
            Shape::Cone(c) => c.dist(p),
            Shape::Torus { major, minor } => torus(p, *major, *minor),
            Shape::Revolve(r) => r.dist(p),
            Shape::Beam(b) => b.dist(p),
        }
    }

    /// A box holding every inside point.
    pub fn bbox(&self) -> Aabb {
        match self {
            Shape::Cone(c) => {
                let r = c.q.x;
                Aabb::new(DVec3::new(-r, -r, c.q.y), DVec3::new(r, r, 0.0))
            }
            Shape::Torus { major, minor } => {
                let e = DVec3::new(major + minor, major + minor, *minor);
                Aabb::new(-e, e)
            }
            Shape::Revolve(r) => r.bbox(),
            Shape::Beam(b) => b.bbox(),
        }
    }
}

/// Torus about the Z axis: `|(ρ − R, z)| − r` (Quilez, sdTorus).
#[inline]
pub fn torus(p: DVec3, major: f64, minor: f64) -> f64 {
    DVec2::new(DVec2::new(p.x, p.y).length() - major, p.z).length() - minor
}

/// Cone with its apex at the origin opening down −Z to its base disc at
/// z = −h (Quilez, sdCone with the base rim point `q = (h·tan α, −h)`).
#[derive(Clone, Copy, Debug)]
pub struct Cone {
    q: DVec2,
}

impl Cone {
    /// `angle`: aperture half-angle in radians (tan > 0), `height` > 0.
    pub fn new(angle: f64, height: f64) -> Self {
        Self {
            q: DVec2::new(height * angle.tan(), -height),
        }
    }

    #[inline]
    pub fn dist(&self, p: DVec3) -> f64 {
        let q = self.q;
        let w = DVec2::new(DVec2::new(p.x, p.y).length(), p.z);
        // Nearest point on the slanted side (apex to rim) and on the base.
        let a = w - q * (w.dot(q) / q.dot(q)).clamp(0.0, 1.0);
        let b = w - q * DVec2::new((w.x / q.x).clamp(0.0, 1.0), 1.0);
        let d = a.length_squared().min(b.length_squared());
        // q.y < 0: inside when below the side line and above the base.
        let s = (-(w.x * q.y - w.y * q.x)).max(-(w.y - q.y));
        if s < 0.0 { -d.sqrt() } else { d.sqrt() }
    }
}

/// The unsigned distance from a point to a filled planar polygon whose
/// in-plane coordinates are `x`, out-of-plane offset `y`: the exact
/// distance to an end face of a partial revolve.
#[inline]
fn face_dist(v: &[DVec2], x: f64, h: f64, y: f64) -> f64 {
    let d2 = sdf::polygon_2d(DVec2::new(x, h), v);
    DVec2::new(d2.max(0.0), y).length()
}

/// A half-profile revolved about an axis.
#[derive(Clone, Debug)]
pub struct Revolve {
    /// Axis origin and unit direction.
    pub origin: DVec3,
    pub axis: DVec3,
    /// Unit radial direction of the profile's half-plane (angle 0), and
    /// `axis × e0` (angle 90°).
    pub e0: DVec3,
    pub e1: DVec3,
    /// Profile in (radial ≥ 0, axial) coordinates.
    pub poly: Vec<DVec2>,
    /// Per edge `i` (from vertex `i − 1` to `i`): false for an edge lying on
    /// the axis, which is inside the solid of a full revolution.
    pub surface: Vec<bool>,
    /// Sweep in radians, in (0, 2π].
    pub sweep: f64,
}

impl Revolve {
    #[inline]
    pub fn dist(&self, p: DVec3) -> f64 {
        let r = p - self.origin;
        let h = r.dot(self.axis);
        let (x0, x1) = (r.dot(self.e0), r.dot(self.e1));
        let rho = DVec2::new(x0, x1).length();
        let full = self.sweep >= std::f64::consts::TAU;
        let lateral = sdf::polygon_2d_surface(DVec2::new(rho, h), &self.poly, &self.surface);
        if full {
            return lateral;
        }
        let mut phi = x1.atan2(x0);
        if phi < 0.0 {
            phi += std::f64::consts::TAU;
        }
        let cap = |delta: f64| face_dist(&self.poly, rho * delta.cos(), h, rho * delta.sin());
        if phi <= self.sweep {
            if lateral >= 0.0 {
                lateral
            } else {
                -(-lateral).min(cap(phi)).min(cap(phi - self.sweep))
            }
        } else if phi - self.sweep < std::f64::consts::TAU - phi {
            cap(phi - self.sweep)
        } else {
            cap(phi - std::f64::consts::TAU)
        }
    }

    /// The box of the full revolution (a cylinder about the axis).
    pub fn bbox(&self) -> Aabb {
        let r = self.poly.iter().fold(0.0f64, |m, v| m.max(v.x));
        let (lo, hi) = self
            .poly
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| {
                (l.min(v.y), h.max(v.y))
            });
        let (a, b) = (self.origin + self.axis * lo, self.origin + self.axis * hi);
        // A disc of radius r normal to u spans r·√(1 − uᵢ²) along axis i.
        let e = (DVec3::ONE - self.axis * self.axis).max(DVec3::ZERO);
        let half = DVec3::new(e.x.sqrt(), e.y.sqrt(), e.z.sqrt()) * r;
        Aabb::new(a.min(b) - half, a.max(b) + half)
    }
}

/// A frustum from `a` (radius `ra`) to `b` (radius `rb`) with a cap at each
/// end, in the strut's own axial frame.
#[derive(Clone, Copy, Debug)]
pub struct Beam {
    pub a: DVec3,
    pub b: DVec3,
    /// Unit axis from `a` to `b`, and its length.
    pub u: DVec3,
    pub len: f64,
    pub ra: f64,
    pub rb: f64,
    pub cap_a: CapMode,
    pub cap_b: CapMode,
}

impl Beam {
    pub fn new(a: DVec3, b: DVec3, ra: f64, rb: f64, cap_a: CapMode, cap_b: CapMode) -> Self {
        let len = (b - a).length();
        Self {
            a,
            b,
            u: (b - a) / len,
            len,
            ra,
            rb,
            cap_a,
            cap_b,
        }
    }

    #[inline]
    pub fn dist(&self, p: DVec3) -> f64 {
        let ap = p - self.a;
        let t = ap.dot(self.u);
        let rho = (ap - self.u * t).length();
        // The frustum's axial section is a symmetric trapezoid.
        let section = [
            DVec2::new(-self.ra, 0.0),
            DVec2::new(self.ra, 0.0),
            DVec2::new(self.rb, self.len),
            DVec2::new(-self.rb, self.len),
        ];
        let d = sdf::polygon_2d(DVec2::new(rho, t), &section);
        let da = cap(self.cap_a, rho, -t, self.ra);
        let db = cap(self.cap_b, rho, t - self.len, self.rb);
        d.min(da).min(db)
    }

    /// The box of the two end balls (it holds the frustum too).
    pub fn bbox(&self) -> Aabb {
        let ba = Aabb::new(self.a, self.a).expand(self.ra);
        let bb = Aabb::new(self.b, self.b).expand(self.rb);
        ba.union(&bb)
    }
}

/// Distance to an end cap of radius `r` at radial distance `rho` and axial
/// offset `t` beyond the end (outward positive); infinite for a flat end.
#[inline]
fn cap(mode: CapMode, rho: f64, t: f64, r: f64) -> f64 {
    match mode {
        CapMode::Butt => f64::INFINITY,
        CapMode::Sphere => DVec2::new(rho, t).length() - r,
        // The half ball {|q| ≤ r, t ≥ 0}: its flat disc faces the frustum.
        CapMode::HemiSphere if t >= 0.0 => (DVec2::new(rho, t).length() - r).max(-t),
        CapMode::HemiSphere => DVec2::new((rho - r).max(0.0), t).length(),
    }
}

impl Revolve {
    /// Check a half-profile (pyvcad 3's rules) and bring it into the
    /// axis frame.
    pub fn build(
        vertices: &[DVec3],
        axis_start: DVec3,
        axis_end: DVec3,
        sweep_degrees: f64,
    ) -> Result<Revolve, String> {
        if vertices.len() < 3 {
            return Err(format!("needs at least 3 vertices, got {}", vertices.len()));
        }
        if !(sweep_degrees > 0.0 && sweep_degrees <= 360.0) {
            return Err(format!(
                "sweep_degrees must be in (0, 360], got {sweep_degrees}"
            ));
        }
        let along = axis_end - axis_start;
        if along.length() == 0.0 || !along.is_finite() {
            return Err("axis_start and axis_end must be distinct finite points".into());
        }
        let axis = along.normalize();
        let scale = vertices
            .iter()
            .map(|v| (*v - axis_start).length())
            .fold(0.0, f64::max)
            .max(along.length());
        let tol = 1e-9 * scale.max(1.0);
        let radial = |v: DVec3| {
            let r = v - axis_start;
            r - axis * r.dot(axis)
        };
        let Some(e0) = vertices
            .iter()
            .map(|v| radial(*v))
            .find(|r| r.length() > tol)
            .map(|r| r.normalize())
        else {
            return Err("every vertex lies on the axis: the profile has no width".into());
        };
        let e1 = axis.cross(e0);
        let mut poly = Vec::with_capacity(vertices.len());
        for (i, v) in vertices.iter().enumerate() {
            let r = radial(*v);
            if r.dot(e1).abs() > 1e-6 * scale.max(1.0) {
                return Err(format!(
                    "vertex {i} is {:.3e} mm off the plane through the axis and vertex 0's side: the profile must lie in one plane with the axis",
                    r.dot(e1)
                ));
            }
            let x = r.dot(e0);
            if x < -tol {
                return Err(format!(
                    "vertex {i} is on the other side of the axis: a half-profile stays on one side"
                ));
            }
            poly.push(DVec2::new(x.max(0.0), (*v - axis_start).dot(axis)));
        }
        let area2 = (0..poly.len())
            .map(|i| poly[i].perp_dot(poly[(i + 1) % poly.len()]))
            .sum::<f64>();
        if area2.abs() <= 1e-12 * scale * scale {
            return Err("the profile's vertices are collinear: it has no area".into());
        }
        let n = poly.len();
        let surface = (0..n)
            .map(|i| {
                let j = (i + n - 1) % n;
                !(poly[i].x <= tol && poly[j].x <= tol)
            })
            .collect();
        Ok(Revolve {
            origin: axis_start,
            axis,
            e0,
            e1,
            poly,
            surface,
            sweep: if sweep_degrees >= 360.0 {
                std::f64::consts::TAU
            } else {
                sweep_degrees.to_radians()
            },
        })
    }
}
