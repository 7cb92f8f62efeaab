//! Fast generalised winding number.
//!
//! The generalised winding number of Jacobson, Kavan & Sorkine-Hornung,
//! "Robust inside-outside segmentation using generalized winding numbers"
//! (SIGGRAPH 2013) is `w(q) = Σ_t Ω_t(q) / 4π`, the signed solid angles of
//! all triangles seen from `q`. It is 1 inside and 0 outside a closed outward
//! mesh and degrades gracefully for holes, so `inside ⇔ w > 1/2`.
//!
//! The sum is evaluated hierarchically after Barill, Dickson, Schmidt, Levin
//! & Jacobson, "Fast winding numbers for soups and clouds" (SIGGRAPH 2018):
//! `Ω_t(q) = ∫_t n·(y − q)/|y − q|³ dA`, and for a BVH node whose triangles
//! lie within radius `r` of their area-weighted centre `p̃` with
//! `|p̃ − q| > β r` the integrand is Taylor-expanded about `x = p̃ − q`:
//!
//! * order 1 (dipole): `N·x/|x|³`, `N = Σ_t a_t n_t`;
//! * order 2: `tr(M)/|x|³ − 3 xᵀMx/|x|⁵`, `M = Σ_t a_t (c_t − p̃) n_tᵀ`
//!   (`c_t` the triangle centroid; exact because `y − p̃` is linear on `t`).
//!
//! Nodes closer than `β r` are opened; leaves that are still close are summed
//! exactly with [`solid_angle`]. With `β = 2` the relative error of a far
//! node is below about `(1/β)³`, far less than the 1/2 margin of the inside
//! test away from the surface, and exact near it.

use glam::DVec3;

use super::triangle::{Tri, solid_angle};
use crate::spatial::bvh::{BvhNode, MAX_DEPTH};

/// Accuracy parameter `β` of Barill et al. (their default is 2).
const BETA: f64 = 2.0;

/// Far-field expansion of one BVH node.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Expansion {
    /// Area-weighted centre `p̃`.
    center: DVec3,
    /// `(β r)²`: the query must be farther than this (squared) from `p̃`.
    far2: f64,
    /// `N = Σ a_t n_t` (half the sum of the cross products).
    normal: DVec3,
    /// `M = Σ a_t (c_t − p̃) n_tᵀ`, rows.
    m: [DVec3; 3],
    /// The node's triangle slots.
    range: [u32; 2],
}

/// Nodes with at most this many triangles are summed exactly when near.
const EXACT_BELOW: u32 = 4;

/// Per-node expansions, parallel to the BVH nodes.
#[derive(Clone, Debug)]
pub(crate) struct WindingTree {
    nodes: Vec<Expansion>,
}

impl WindingTree {
    /// Precomputes the expansions; `ranges[i]` are node `i`'s triangle slots
    /// in `tris`.
    pub fn new(ranges: &[[u32; 2]], tris: &[Tri]) -> WindingTree {
        let nodes = ranges
            .iter()
            .map(|&[lo, hi]| {
                let slice = &tris[lo as usize..hi as usize];
                let mut area = 0.0;
                let mut weighted = DVec3::ZERO;
                let mut normal = DVec3::ZERO;
                for t in slice {
                    let an = t.ab.cross(t.ac) * 0.5;
                    let a = an.length();
                    area += a;
                    weighted += (t.a + (t.ab + t.ac) / 3.0) * a;
                    normal += an;
                }
                let center = if area > 0.0 {
                    weighted / area
                } else {
                    slice.first().map_or(DVec3::ZERO, |t| t.a)
                };
                let mut m = [DVec3::ZERO; 3];
                let mut r2: f64 = 0.0;
                for t in slice {
                    let an = t.ab.cross(t.ac) * 0.5;
                    let d = t.a + (t.ab + t.ac) / 3.0 - center;
                    m[0] += an * d.x;
                    m[1] += an * d.y;
                    m[2] += an * d.z;
                    for c in t.corners() {
                        r2 = r2.max(c.distance_squared(center));
                    }
                }
                Expansion {
                    center,
                    far2: BETA * BETA * r2,
                    normal,
                    m,
                    range: [lo, hi],
                }
            })
            .collect();
        WindingTree { nodes }
    }

    /// Generalised winding number at `q` (see the module docs).
    pub fn evaluate(&self, bvh: &[BvhNode], tris: &[Tri], q: DVec3) -> f64 {
        let mut total = 0.0;
        let mut stack = [0u32; MAX_DEPTH + 2];
        let mut sp = 1;
        while sp > 0 {
            sp -= 1;
            let ni = stack[sp] as usize;
            let e = &self.nodes[ni];
            let x = e.center - q;
            let r2 = x.dot(x);
            if r2 > e.far2 {
                let r = r2.sqrt();
                let inv3 = 1.0 / (r2 * r);
                let inv5 = inv3 / r2;
                let trace = e.m[0].x + e.m[1].y + e.m[2].z;
                // xᵀ M x with M = Σ a (c − p̃) nᵀ: rows indexed by (c − p̃).
                let xmx = x.x * e.m[0].dot(x) + x.y * e.m[1].dot(x) + x.z * e.m[2].dot(x);
                total += e.normal.dot(x) * inv3 + trace * inv3 - 3.0 * xmx * inv5;
                continue;
            }
            let n = &bvh[ni];
            let [lo, hi] = e.range;
            if n.is_leaf() || hi - lo <= EXACT_BELOW {
                for t in &tris[lo as usize..hi as usize] {
                    let [a, b, c] = t.corners();
                    total += solid_angle(q, a, b, c);
                }
            } else {
                stack[sp] = n.first;
                stack[sp + 1] = n.first + 1;
                sp += 2;
            }
        }
        total / (4.0 * std::f64::consts::PI)
    }
}
