//! Designs nested a million levels deep prepare, evaluate, bound and drop
//! without overflowing a thread's stack (each test runs in a 2 MiB thread,
//! the default for spawned threads), and the chains that cannot be read
//! flat are refused with the depth and what to write instead.

// A test crate: its helper functions stop on a failed setup as its tests do.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::sync::Arc;

use volcad_core::expr::{COORD_VARS, Expr};
use volcad_core::interval::Interval;
use volcad_core::{Aabb, DVec3, MaterialTable, Model, Node, NodeKind};

const DEPTH: usize = 1_000_000;
const RED: u8 = 1;
const BLUE: u8 = 2;

/// Run `f` in a thread with a 2 MiB stack (what `std::thread::spawn` and
/// rayon's workers get).
fn small_stack(f: impl FnOnce() + Send + 'static) {
    std::thread::Builder::new()
        .stack_size(2 << 20)
        .spawn(f)
        .expect("spawn")
        .join()
        .expect("no panic");
}

fn table() -> Arc<MaterialTable> {
    Arc::new(MaterialTable::default_table())
}

fn sphere(c: DVec3, r: f64, m: u8) -> Node {
    Node::new(NodeKind::Sphere {
        center: c,
        radius: r,
        material: m,
    })
}

fn union(smooth: f64, children: Vec<Node>) -> Node {
    Node::new(NodeKind::Union {
        smooth,
        blend: false,
        children,
    })
}

/// Prepare `root` and check every walk at `p`, where the distance is
/// `want`; then drop the model and the tree.
fn exercise(root: Node, p: DVec3, want: f64) {
    let m = Model::prepare(&root, table()).expect("prepares");
    let d = m.distance(p);
    assert!((d - want).abs() < 1e-6, "distance {d}, want {want}");
    let (d2, fracs) = m.eval_point(p);
    assert_eq!(d, d2);
    if d <= 0.0 {
        let sum: f64 = fracs.iter().map(|f| f.1).sum();
        assert!((sum - 1.0).abs() < 1e-9, "fractions {fracs:?}");
    }
    let b = Aabb::from_center_size(p, DVec3::splat(0.01));
    let i = m.interval(&b);
    assert!(i.lo <= d && d <= i.hi, "{d} outside {i:?}");
    let mut bounds = vec![Interval::point(0.0); m.materials().len()];
    if m.fraction_bounds(&b, &mut bounds) && d <= 0.0 {
        for ((_, f), iv) in fracs.iter().zip(&bounds) {
            assert!(iv.lo <= *f && *f <= iv.hi, "{f} outside {iv:?}");
        }
    }
    m.constant_fractions(&b);
    // The thin-feature and gap walks of the exports' checks.
    m.thinnest_feature();
    m.stated_gaps(1.0);
    drop(m);
    drop(root);
}

/// The message of the prepare error of `root` (which must fail).
fn refused(root: &Node) -> String {
    Model::prepare(root, table())
        .expect_err("refused")
        .to_string()
}

#[test]
fn a_million_nested_sharp_unions() {
    small_stack(|| {
        let s = sphere(DVec3::new(3.0, 0.0, 0.0), 1.0, BLUE);
        let mut n = sphere(DVec3::ZERO, 1.0, RED);
        for _ in 0..DEPTH {
            n = union(0.0, vec![n, s.clone()]);
        }
        // Debug printing shows one level (the fields would recurse).
        let printed = format!("{n:?}");
        assert!(
            printed.contains("Union") && printed.len() < 200,
            "{printed}"
        );
        exercise(n.clone(), DVec3::new(3.0, 0.0, 0.0), -1.0);
        exercise(n, DVec3::ZERO, -1.0);
    });
}

#[test]
fn a_million_single_child_unions_and_intersections() {
    small_stack(|| {
        let mut n = sphere(DVec3::ZERO, 2.0, RED);
        for i in 0..DEPTH {
            let children = vec![n];
            n = if i.is_multiple_of(2) {
                union(0.5, children)
            } else {
                Node::new(NodeKind::Intersection {
                    smooth: 0.0,
                    blend: true,
                    children,
                })
            };
        }
        exercise(n, DVec3::new(1.0, 0.0, 0.0), -1.0);
    });
}

#[test]
fn a_million_nested_intersections_and_differences() {
    small_stack(|| {
        let big = Node::new(NodeKind::RectPrism {
            center: DVec3::ZERO,
            size: DVec3::splat(100.0),
            material: BLUE,
        });
        let hole = sphere(DVec3::new(5.0, 0.0, 0.0), 1.0, BLUE);
        let mut n = sphere(DVec3::ZERO, 10.0, RED);
        for i in 0..DEPTH {
            n = if i.is_multiple_of(2) {
                Node::new(NodeKind::Intersection {
                    smooth: 0.0,
                    blend: false,
                    children: vec![n, big.clone()],
                })
            } else {
                Node::new(NodeKind::Difference {
                    smooth: 0.0,
                    left: Some(n),
                    right: Some(hole.clone()),
                })
            };
        }
        // Alternating kinds do not flatten: refused with the depth.
        let e = refused(&n);
        assert!(
            e.contains("levels deep") && e.contains("Union(false, parts)"),
            "{e}"
        );
        drop(n);

        // Ten holes, each made a hundred thousand times (equal leaves are
        // listed once).
        let mut n = sphere(DVec3::ZERO, 10.0, RED);
        for i in 0..DEPTH {
            let hole = sphere(DVec3::new(5.0, (i % 10) as f64, 0.0), 0.25, BLUE);
            n = Node::new(NodeKind::Difference {
                smooth: 0.0,
                left: Some(n),
                right: Some(hole),
            });
        }
        exercise(n, DVec3::new(5.0, 0.0, 0.0), 0.25);

        let mut n = sphere(DVec3::ZERO, 10.0, RED);
        for _ in 0..DEPTH {
            n = Node::new(NodeKind::Intersection {
                smooth: 0.0,
                blend: false,
                children: vec![n, big.clone()],
            });
        }
        exercise(n, DVec3::new(1.0, 0.0, 0.0), -9.0);
    });
}

#[test]
fn a_million_nested_grades() {
    small_stack(|| {
        let e = Arc::new(Expr::compile("0.5", &COORD_VARS).expect("expr"));
        let mut n = sphere(DVec3::ZERO, 1.0, RED);
        for _ in 0..DEPTH {
            n = Node::new(NodeKind::FGrade {
                exprs: vec![e.clone(), e.clone()],
                materials: vec![RED, BLUE],
                prob: false,
                child: Some(n),
            });
        }
        exercise(n, DVec3::ZERO, -1.0);
    });
}

#[test]
fn a_million_moves_of_each_kind() {
    small_stack(|| {
        let leaf = || sphere(DVec3::new(5.0, 0.0, 0.0), 1.0, RED);
        let mut n = leaf();
        for _ in 0..DEPTH {
            let offset = DVec3::new(1e-6, 0.0, 0.0);
            n = Node::new(NodeKind::Translate {
                offset,
                child: Some(n),
            });
        }
        exercise(n, DVec3::new(6.0, 0.0, 0.0), -1.0);

        // 0.36° a turn: a thousand full turns.
        let mut n = leaf();
        for _ in 0..DEPTH {
            n = Node::new(NodeKind::Rotate {
                pitch: 0.0,
                yaw: 0.0,
                roll: 0.36,
                around: DVec3::new(0.0, 0.0, 1.0),
                child: Some(n),
            });
        }
        exercise(n, DVec3::new(5.0, 0.0, 0.0), -1.0);

        let mut n = leaf();
        for i in 0..DEPTH {
            let s = if i.is_multiple_of(2) { 2.0 } else { 0.5 };
            n = Node::new(NodeKind::Scale {
                factors: DVec3::splat(s),
                child: Some(n),
            });
        }
        exercise(n, DVec3::new(5.0, 0.0, 0.0), -1.0);

        // All three in turn, against the nested nodes' mapping of the
        // point written out by hand (outermost first).
        let levels = DEPTH - DEPTH % 6;
        let scale = |i: usize| if i.is_multiple_of(2) { 2.0 } else { 0.5 };
        let mut n = leaf();
        for i in 0..levels {
            n = Node::new(match i % 3 {
                0 => NodeKind::Translate {
                    offset: DVec3::new(0.0, 0.0, 1e-6),
                    child: Some(n),
                },
                1 => NodeKind::Rotate {
                    pitch: 0.0,
                    yaw: 0.0,
                    roll: 180.0,
                    around: DVec3::ZERO,
                    child: Some(n),
                },
                _ => NodeKind::Scale {
                    factors: DVec3::splat(scale(i)),
                    child: Some(n),
                },
            });
        }
        let p = DVec3::new(5.0, 0.0, 0.5);
        let (mut q, mut k) = (p, 1.0);
        for i in (0..levels).rev() {
            match i % 3 {
                0 => q.z -= 1e-6,
                1 => q = DVec3::new(-q.x, -q.y, q.z),
                _ => {
                    q /= scale(i);
                    k *= scale(i);
                }
            }
        }
        let want = ((q - DVec3::new(5.0, 0.0, 0.0)).length() - 1.0) * k;
        exercise(n, p, want);

        let mut n = leaf();
        for _ in 0..DEPTH {
            n = Node::new(NodeKind::Offset {
                distance: 1e-6,
                child: Some(n),
            });
        }
        exercise(n, DVec3::new(5.0, 0.0, 0.0), -2.0);
    });
}

#[test]
fn chains_that_do_not_flatten_are_refused_with_the_depth() {
    small_stack(|| {
        let s = sphere(DVec3::new(3.0, 0.0, 0.0), 1.0, BLUE);
        let mut smooth = sphere(DVec3::ZERO, 1.0, RED);
        let mut blends = sphere(DVec3::ZERO, 1.0, RED);
        let mut shells = sphere(DVec3::ZERO, 1.0, RED);
        for _ in 0..DEPTH {
            smooth = union(0.5, vec![smooth, s.clone()]);
            blends = Node::new(NodeKind::Blend {
                radius: 0.1,
                child: Some(blends),
            });
            shells = Node::new(NodeKind::Shell {
                thickness: 0.1,
                child: Some(shells),
            });
        }
        for n in [smooth, blends, shells] {
            let e = refused(&n);
            assert!(e.contains("nested 501 levels deep"), "{e}");
            assert!(e.contains("Union(false, parts)"), "{e}");
        }
    });
}

#[test]
fn the_deepest_design_allowed_evaluates_in_a_small_stack() {
    small_stack(|| {
        // Nodes that do not flatten, in turn: a sharp union over a shell,
        // a blending intersection, a smooth union, and a move.
        let s = sphere(DVec3::new(0.0, 0.0, 1.0), 0.5, BLUE);
        let big = Node::new(NodeKind::RectPrism {
            center: DVec3::ZERO,
            size: DVec3::splat(100.0),
            material: RED,
        });
        let mut n = sphere(DVec3::ZERO, 2.0, RED);
        let mut levels = 1;
        while levels < 500 {
            n = Node::new(match levels % 4 {
                0 => NodeKind::Union {
                    smooth: 0.0,
                    blend: false,
                    children: vec![n, s.clone()],
                },
                1 => NodeKind::Shell {
                    thickness: 50.0,
                    child: Some(n),
                },
                2 => NodeKind::Intersection {
                    smooth: 0.0,
                    blend: true,
                    children: vec![n, big.clone()],
                },
                _ => NodeKind::Translate {
                    offset: DVec3::ZERO,
                    child: Some(n),
                },
            });
            levels += 1;
        }
        let m = Model::prepare(&n, table()).expect("500 levels are allowed");
        let p = DVec3::new(0.5, 0.0, 0.0);
        let d = m.distance(p);
        assert!(d < 0.0, "{d}");
        let (_, fracs) = m.eval_point(p);
        assert!(!fracs.is_empty());
        let b = Aabb::from_center_size(p, DVec3::splat(0.01));
        let i = m.interval(&b);
        assert!(i.lo <= d && d <= i.hi);
        let mut bounds = vec![Interval::point(0.0); m.materials().len()];
        m.fraction_bounds(&b, &mut bounds);
        m.constant_fractions(&b);

        // One more level is refused.
        let e = refused(&union(0.0, vec![n, s.clone()]));
        assert!(e.contains("nested 501 levels deep"), "{e}");
    });
}
