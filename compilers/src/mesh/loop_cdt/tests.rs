use super::*;
use spade::{ConstrainedDelaunayTriangulation, Triangulation};

/// A uniform number in [0, 1) from `(seed, i)`.
fn uniform(seed: u64, i: u64) -> f64 {
    (crate::dither::splitmix64(seed, i) >> 11) as f64 / (1u64 << 53) as f64
}

/// A loop of `n` ≥ 4 points around the origin, counter-clockwise (one
/// point in each of `n` equal sectors, so no gap reaches half a turn and
/// every point sees the origin), radii 0.5 to 1.5, and `inner` points
/// within 0.45 of the origin (inside it where its edges keep clear).
fn star(seed: u64, n: usize, inner: usize) -> Vec<Point2<f64>> {
    let angles: Vec<f64> = (0..n as u64)
        .map(|i| (i as f64 + 0.9 * uniform(seed, i)) / n as f64 * std::f64::consts::TAU)
        .collect();
    let mut pts: Vec<Point2<f64>> = angles
        .iter()
        .enumerate()
        .map(|(i, a)| {
            let r = 0.5 + uniform(seed ^ 0xABCD, i as u64);
            Point2::new(r * a.cos(), r * a.sin())
        })
        .collect();
    for i in 0..inner as u64 {
        let (a, r) = (
            uniform(seed ^ 7, i) * std::f64::consts::TAU,
            0.45 * uniform(seed ^ 9, i),
        );
        pts.push(Point2::new(r * a.cos(), r * a.sin()));
    }
    pts
}

/// Twice triangle `t`'s signed area (exact sign): positive when it turns
/// left.
fn turn(pts: &[Point2<f64>], t: [usize; 3]) -> f64 {
    let [a, b, c] = t.map(|i| Coord {
        x: pts[i].x,
        y: pts[i].y,
    });
    orient2d(a, b, c)
}

fn loop_edges(n: usize) -> Vec<[usize; 2]> {
    (0..n).map(|i| [i, (i + 1) % n]).collect()
}

fn area2(pts: &[Point2<f64>], edges: &[[usize; 2]]) -> f64 {
    edges
        .iter()
        .map(|[a, b]| pts[*a].x * pts[*b].y - pts[*b].x * pts[*a].y)
        .sum()
}

/// Triangles as sorted index triples, sorted.
fn canonical(tris: &[[usize; 3]]) -> Vec<[usize; 3]> {
    let mut out: Vec<[usize; 3]> = tris
        .iter()
        .map(|t| {
            let mut s = *t;
            s.sort_unstable();
            s
        })
        .collect();
    out.sort_unstable();
    out
}

/// spade's constrained Delaunay triangulation of a star-shaped loop
/// (around the origin), faces inside it only.
fn spade_cdt(pts: &[Point2<f64>], edges: &[[usize; 2]]) -> Vec<[usize; 3]> {
    let cdt = ConstrainedDelaunayTriangulation::<Point2<f64>>::bulk_load_cdt(
        pts.to_vec(),
        edges.to_vec(),
    )
    .expect("loads");
    let inside = |x: f64, y: f64| {
        // Crossing number of a ray along +x.
        let mut c = false;
        for &[a, b] in edges {
            let (p, q) = (pts[a], pts[b]);
            if (p.y > y) != (q.y > y) && x < p.x + (y - p.y) * (q.x - p.x) / (q.y - p.y) {
                c = !c;
            }
        }
        c
    };
    cdt.inner_faces()
        .map(|f| f.vertices().map(|v| v.fix().index()))
        .filter(|t| {
            let x = t.iter().map(|&i| pts[i].x).sum::<f64>() / 3.0;
            let y = t.iter().map(|&i| pts[i].y).sum::<f64>() / 3.0;
            inside(x, y)
        })
        .collect()
}

#[test]
fn random_loops_match_spades_triangulation() {
    for seed in 0..300u64 {
        let n = 4 + (seed as usize * 7) % 120;
        let inner = if seed % 3 == 0 {
            (seed as usize) % 9
        } else {
            0
        };
        let pts = star(seed, n, inner);
        let edges = loop_edges(n);
        let a2 = area2(&pts, &edges);
        let ours =
            triangulate(&pts, &edges, n, a2).unwrap_or_else(|| panic!("seed {seed}: refused"));
        for t in &ours {
            assert!(turn(&pts, *t) > 0.0, "seed {seed}: {t:?} turns right");
        }
        // Inner points outside a loop of few points are left out.
        assert!(
            ours.len() >= n - 2 && ours.len() <= n - 2 + 2 * inner,
            "seed {seed}"
        );
        assert_eq!(
            canonical(&ours),
            canonical(&spade_cdt(&pts, &edges)),
            "seed {seed}"
        );
        // Clockwise, the same triangles.
        let rev: Vec<[usize; 2]> = edges.iter().map(|[a, b]| [*b, *a]).collect();
        let cw = triangulate(&pts, &rev, n, -a2).expect("clockwise");
        assert_eq!(canonical(&cw), canonical(&ours), "seed {seed}");
    }
}

/// A comb: a straight bottom, and a top of `teeth` notches of random
/// depth (most of its points reflex), counter-clockwise; then `inner`
/// random points in its box (those outside it are left out by both).
fn comb(seed: u64, teeth: usize, inner: usize) -> (Vec<Point2<f64>>, usize) {
    let w = teeth as f64;
    let mut pts = vec![Point2::new(0.0, 0.0), Point2::new(w, 0.0)];
    for i in (0..teeth).rev() {
        let x = i as f64 + uniform(seed, i as u64) * 0.3;
        pts.push(Point2::new(x + 0.7, 3.0));
        pts.push(Point2::new(
            x + 0.35,
            0.3 + 2.5 * uniform(seed ^ 5, i as u64),
        ));
    }
    pts.push(Point2::new(0.0, 3.0));
    let n = pts.len();
    for i in 0..inner as u64 {
        pts.push(Point2::new(
            w * uniform(seed ^ 11, i),
            3.0 * uniform(seed ^ 13, i),
        ));
    }
    (pts, n)
}

#[test]
fn combs_match_spades_triangulation() {
    for seed in 0..100u64 {
        let (pts, n) = comb(seed, 2 + seed as usize % 60, (seed as usize * 5) % 40);
        let edges = loop_edges(n);
        let a2 = area2(&pts, &edges);
        let ours = triangulate(&pts, &edges, n, a2).unwrap_or_else(|| panic!("seed {seed}"));
        assert_eq!(
            canonical(&ours),
            canonical(&spade_cdt(&pts, &edges)),
            "seed {seed}"
        );
    }
}

#[test]
fn a_box_face_with_collinear_points_is_tiled() {
    // A 30 × 5 rectangle with a point at every unit: all but four points
    // collinear, most quads cocircular.
    let mut pts = Vec::new();
    (0..30).for_each(|i| pts.push(Point2::new(f64::from(i), 0.0)));
    (0..5).for_each(|j| pts.push(Point2::new(30.0, f64::from(j))));
    (0..30).for_each(|i| pts.push(Point2::new(f64::from(30 - i), 5.0)));
    (0..5).for_each(|j| pts.push(Point2::new(0.0, f64::from(5 - j))));
    let n = pts.len();
    let edges = loop_edges(n);
    let tris = triangulate(&pts, &edges, n, area2(&pts, &edges)).expect("tiled");
    assert_eq!(tris.len(), n - 2);
    let sum: f64 = tris
        .iter()
        .map(|t| {
            let o = turn(&pts, *t);
            assert!(o > 0.0, "{t:?}");
            o
        })
        .sum();
    assert_eq!(sum, 2.0 * 150.0);
}

#[test]
fn loops_it_cannot_take_are_refused() {
    let p = |v: &[[f64; 2]]| {
        v.iter()
            .map(|q| Point2::new(q[0], q[1]))
            .collect::<Vec<_>>()
    };
    let refuse = |pts: &[Point2<f64>], outline: usize| {
        let edges = loop_edges(outline);
        triangulate(pts, &edges, outline, area2(pts, &edges)).is_none()
    };
    // A pentagram turns left at every point but winds twice.
    let star: Vec<[f64; 2]> = (0..5)
        .map(|k| {
            let a = std::f64::consts::TAU * (2 * k) as f64 / 5.0;
            [a.cos(), a.sin()]
        })
        .collect();
    assert!(refuse(&p(&star), 5), "pentagram");
    // A figure eight, and a loop touching itself at a point.
    assert!(
        refuse(&p(&[[0., 0.], [2., 2.], [2., 0.], [0., 2.]]), 4),
        "eight"
    );
    let touching = [[0., 0.], [4., 0.], [4., 4.], [2., 0.], [0., 4.]];
    assert!(refuse(&p(&touching), 5), "touching");
    // A spike folding back along itself.
    assert!(
        refuse(&p(&[[0., 0.], [4., 0.], [2., 0.], [2., 2.]]), 4),
        "spike"
    );
    // An inner point on the outline, or on an outline point.
    let square = [[0., 0.], [2., 0.], [2., 2.], [0., 2.]];
    let mut on_edge = square.to_vec();
    on_edge.push([1., 0.]);
    assert!(refuse(&p(&on_edge), 4), "on the outline");
    let mut on_point = square.to_vec();
    on_point.push([2., 2.]);
    assert!(refuse(&p(&on_point), 4), "on a point");
    // Not one loop: two squares.
    let two: Vec<Point2<f64>> = p(&[
        [0., 0.],
        [1., 0.],
        [1., 1.],
        [0., 1.],
        [5., 0.],
        [6., 0.],
        [6., 1.],
        [5., 1.],
    ]);
    let edges = vec![
        [0, 1],
        [1, 2],
        [2, 3],
        [3, 0],
        [4, 5],
        [5, 6],
        [6, 7],
        [7, 4],
    ];
    assert!(triangulate(&two, &edges, 8, 4.0).is_none(), "two loops");
}

#[test]
fn inner_points_split_triangles_or_are_left_out() {
    let mut pts: Vec<Point2<f64>> = [[0., 0.], [4., 0.], [4., 4.], [0., 4.]]
        .iter()
        .map(|q| Point2::new(q[0], q[1]))
        .collect();
    // On the square's diagonal (an inner edge of any triangulation of
    // it), strictly inside, and outside.
    pts.push(Point2::new(2.0, 2.0));
    pts.push(Point2::new(1.0, 2.5));
    pts.push(Point2::new(9.0, 9.0));
    let edges = loop_edges(4);
    let tris = triangulate(&pts, &edges, 4, 32.0).expect("triangulated");
    assert_eq!(tris.len(), 6, "{tris:?}");
    assert!(tris.iter().all(|t| !t.contains(&6)), "the outside point");
    let sum: f64 = tris.iter().map(|t| turn(&pts, *t)).sum();
    assert_eq!(sum, 32.0);
}

#[test]
fn the_circle_test_says_yes_only_where_the_exact_one_does() {
    let c = |x: f64, y: f64| Coord { x, y };
    let (a, b, cc) = (c(0.0, 0.0), c(1.0, 0.0), c(1.0, 1.0));
    // Strictly inside, strictly outside, and on the circle of a unit square.
    assert!(surely_in_circle(a, b, cc, c(0.5, 0.9)));
    assert!(!surely_in_circle(a, b, cc, c(-0.5, 1.5)));
    assert!(!surely_in_circle(a, b, cc, c(0.0, 1.0)));
    // Near the circle the filter may abstain, but never disagrees with
    // the exact determinant's sign; points this near give both a yes and
    // an abstention where the exact test says inside.
    let (mut yes, mut abstained) = (0, 0);
    for i in 0..2000u64 {
        let t = uniform(3, i) * std::f64::consts::TAU;
        let r = std::f64::consts::FRAC_1_SQRT_2 * (1.0 + (uniform(5, i) - 0.5) * 1e-14);
        let d = c(0.5 + r * t.cos(), 0.5 + r * t.sin());
        let exact = robust::incircle(a, b, cc, d) > 0.0;
        if surely_in_circle(a, b, cc, d) {
            assert!(exact, "{d:?}");
            yes += 1;
        } else if exact {
            abstained += 1;
        }
    }
    assert!(yes > 0 && abstained > 0, "{yes} yes, {abstained} abstained");
}
