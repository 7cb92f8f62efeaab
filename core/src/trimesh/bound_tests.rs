//! Tests of the bounded distance queries: bounds and intervals hold the
//! exact distances, and a query that stops at a triangle within its radius
//! says no more than it proves.

use glam::DVec3;

use super::Probe;
use super::tests::{Rng, bunny};
use crate::aabb::Aabb;

#[test]
fn bound_and_interval_are_consistent() {
    let m = bunny();
    let mut rng = Rng::new(99);
    let region = m.bbox().expand(10.0);
    for _ in 0..500 {
        let p = rng.in_box(&region);
        let d = m.signed_distance(p);
        for max in [0.5, 2.0, 8.0] {
            let b = m.signed_distance_bound(p, max);
            assert_eq!(b < 0.0, d < 0.0, "{p} {d} {b}");
            if d.abs() < max {
                assert!((b - d).abs() < 1e-12, "{p} {d} {b}");
            } else {
                assert!(b.abs() >= max && b.abs() <= d.abs() + 1e-12, "{p} {d} {b}");
            }
        }
        let cell = Aabb::from_center_size(p, DVec3::new(1.0, 2.0, 0.5));
        let iv = m.interval(&cell);
        for _ in 0..4 {
            let q = rng.in_box(&cell);
            let dq = m.signed_distance(q);
            assert!(iv.lo <= dq && dq <= iv.hi);
        }
    }
    assert!(m.signed_distance(DVec3::NAN).is_nan());
    // Non-finite points are answered NaN by the fallback: the candidate
    // grid's lookup must reject them, also where the other coordinates
    // lie inside its box.
    let c = m.bbox.center();
    for bad in [
        DVec3::new(f64::NAN, c.y, c.z),
        DVec3::new(c.x, f64::NAN, c.z),
        DVec3::new(c.x, c.y, f64::INFINITY),
        DVec3::new(f64::NEG_INFINITY, c.y, c.z),
    ] {
        assert!(m.signed_distance(bad).is_nan(), "{bad}");
        assert!(m.distance(bad).is_nan(), "{bad}");
    }
}

#[test]
fn a_query_stopped_within_its_radius_bounds_the_distance() {
    let m = bunny();
    let mut rng = Rng::new(17);
    let region = m.bbox().expand(3.0);
    let (mut stopped, mut exact) = (0, 0);
    for _ in 0..4000 {
        let p = rng.in_box(&region);
        let d = m.signed_distance(p);
        for within in [0.1, 0.5, 2.0] {
            match m.signed_distance_unless_within(p, within) {
                // Some triangle at `u ≤ within`, so `|d| ≤ u`.
                Some(Probe::Within(u)) => {
                    stopped += 1;
                    assert!(u <= within && d.abs() <= u, "{p} {within}: {u} vs {d}");
                }
                // Otherwise the exact answer, bit for bit.
                Some(Probe::Exact(e)) => {
                    exact += 1;
                    assert_eq!(e.to_bits(), d.to_bits(), "{p} {within}");
                }
                // A cell without a list (far, or one whose list was too
                // long): the caller asks the other queries.
                None => {}
            }
        }
    }
    // Both answers occur.
    assert!(
        stopped > 100 && exact > 100,
        "{stopped} stopped, {exact} exact"
    );
}
