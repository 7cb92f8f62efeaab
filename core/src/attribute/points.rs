//! Scattered measurements as an attribute (`PointsField("temps.csv",
//! "temperature")`): a CSV of points, columns `x`, `y`, `z` and named value
//! columns, interpolated by inverse-distance weighting.
//!
//! A SimulationField interpolates inside its tetrahedra; scattered points
//! have no mesh, so a value is Shepard's inverse-distance weighting (D.
//! Shepard, "A two-dimensional interpolation function for
//! irregularly-spaced data", ACM national conference 1968) of the
//! [`NEIGHBOURS`] nearest points with power 2: `v(p) = Σ wᵢvᵢ / Σ wᵢ`,
//! `wᵢ = 1/|p − pᵢ|²`, and a data point's own value at the point itself.
//! The weights are positive, so every value lies within the column's range
//! (the interval bound). It is defined everywhere (no cut-off distance):
//! far from the data it tends to the mean of the nearest points. The
//! nearest points come from the 4-wide BVH of [`crate::spatial`], built
//! over the points as empty boxes.

use glam::DVec3;

use super::convert::csv_cells;
use crate::aabb::Aabb;
use crate::spatial::{bvh, wide::WideBvh};

/// Points each value is interpolated from (fewer when the file has fewer).
pub const NEIGHBOURS: usize = 8;

/// The points and value columns of a CSV.
#[derive(Debug)]
pub struct PointCloud {
    /// Value column names, in file order.
    names: Vec<String>,
    /// Points in the tree's slot order.
    pts: Vec<DVec3>,
    /// `values[slot * names.len() + column]`.
    values: Vec<f64>,
    /// Smallest and largest value of each column.
    ranges: Vec<(f64, f64)>,
    tree: WideBvh,
}

impl PointCloud {
    /// The points of CSV `text`: a header naming `x`, `y`, `z` (any case,
    /// any order) and one or more value columns, then one row of numbers a
    /// point; `#` lines and a byte-order mark are skipped. `what` names the
    /// file in errors, which give the line and column.
    pub(crate) fn parse(text: &str, what: &str) -> Result<PointCloud, String> {
        let mut rows = csv_cells(text);
        let Some((hl, header)) = rows.next() else {
            return Err(format!(
                "{what}: the file is empty; write a header such as x,y,z,temperature and a row a point"
            ));
        };
        let axis = |name: &str| {
            header
                .iter()
                .position(|c| c.eq_ignore_ascii_case(name))
                .ok_or_else(|| {
                    format!(
                        "{what}:{hl}: the header has no \"{name}\" column; it has {}; name the coordinate columns x, y and z",
                        header.join(", ")
                    )
                })
        };
        let xyz = [axis("x")?, axis("y")?, axis("z")?];
        let value_cols: Vec<usize> = (0..header.len()).filter(|c| !xyz.contains(c)).collect();
        if value_cols.is_empty() {
            return Err(format!(
                "{what}:{hl}: the header has only x, y, z; add a value column such as temperature"
            ));
        }
        let names: Vec<String> = value_cols.iter().map(|c| header[*c].to_owned()).collect();
        if let Some((i, n)) = names
            .iter()
            .enumerate()
            .find(|(i, n)| names[..*i].contains(n))
        {
            return Err(format!(
                "{what}:{hl}: column \"{n}\" appears twice (column {}); give each column its own name",
                value_cols[i] + 1
            ));
        }
        let mut pts = Vec::new();
        let mut values = Vec::new();
        for (line, cells) in rows {
            if cells.len() != header.len() {
                return Err(format!(
                    "{what}:{line}: {} cells, the header has {}; give every row one number per column",
                    cells.len(),
                    header.len()
                ));
            }
            let num = |c: usize| {
                cells[c]
                    .parse::<f64>()
                    .ok()
                    .filter(|v| v.is_finite())
                    .ok_or_else(|| {
                        format!(
                            "{what}:{line}: column {} (\"{}\") is {:?}, not a finite number",
                            c + 1,
                            header[c],
                            cells[c]
                        )
                    })
            };
            pts.push(DVec3::new(num(xyz[0])?, num(xyz[1])?, num(xyz[2])?));
            for c in &value_cols {
                values.push(num(*c)?);
            }
        }
        if pts.is_empty() {
            return Err(format!(
                "{what}: the header has no rows under it; add a row a point"
            ));
        }
        Ok(PointCloud::build(names, &pts, &values))
    }

    /// The cloud of `pts` with `values` (point after point), reordered
    /// into the tree's slots.
    fn build(names: Vec<String>, pts: &[DVec3], values: &[f64]) -> PointCloud {
        let k = names.len();
        let boxes: Vec<Aabb> = pts.iter().map(|p| Aabb::new(*p, *p)).collect();
        let (tree, order) = bvh::build(&boxes, 1);
        let tree = WideBvh::new(&tree);
        let mut ranges = vec![(f64::INFINITY, f64::NEG_INFINITY); k];
        for row in values.chunks_exact(k) {
            for (r, v) in ranges.iter_mut().zip(row) {
                *r = (r.0.min(*v), r.1.max(*v));
            }
        }
        PointCloud {
            names,
            pts: order.iter().map(|&i| pts[i as usize]).collect(),
            values: order
                .iter()
                .flat_map(|&i| values[i as usize * k..(i as usize + 1) * k].iter().copied())
                .collect(),
            ranges,
            tree,
        }
    }

    /// The value column names, in file order.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.pts.len()
    }

    /// True when there are no points (never for a parsed cloud).
    pub fn is_empty(&self) -> bool {
        self.pts.is_empty()
    }

    /// Smallest and largest value of `column`.
    pub fn range(&self, column: usize) -> (f64, f64) {
        self.ranges[column]
    }

    /// The interpolated value of `column` at `p`.
    pub fn sample(&self, p: DVec3, column: usize) -> f64 {
        // The nearest points so far, by squared distance, ascending.
        let mut near = [(f64::INFINITY, 0u32); NEIGHBOURS];
        let mut count = 0usize;
        self.tree.nearest(p, f64::INFINITY, |slot, _| {
            let d2 = self.pts[slot as usize].distance_squared(p);
            if count < NEIGHBOURS || d2 < near[count - 1].0 {
                let mut j = count.min(NEIGHBOURS - 1);
                while j > 0 && near[j - 1].0 > d2 {
                    near[j] = near[j - 1];
                    j -= 1;
                }
                near[j] = (d2, slot);
                count = (count + 1).min(NEIGHBOURS);
            }
            // The search keeps only boxes nearer than the farthest kept.
            if count == NEIGHBOURS {
                near[NEIGHBOURS - 1].0
            } else {
                f64::INFINITY
            }
        });
        let k = self.names.len();
        let value = |slot: u32| self.values[slot as usize * k + column];
        if near[0].0 == 0.0 {
            return value(near[0].1);
        }
        let (mut sw, mut swv) = (0.0, 0.0);
        for (d2, slot) in &near[..count] {
            let w = 1.0 / d2;
            sw += w;
            swv += w * value(*slot);
        }
        swv / sw
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn at_a_data_point_its_value_and_between_the_weighted_mean() {
        let c = PointCloud::parse("x,y,z,t\n0,0,0,10\n2,0,0,30\n", "t.csv").unwrap();
        assert_eq!(c.sample(DVec3::ZERO, 0), 10.0);
        assert_eq!(c.sample(DVec3::new(2.0, 0.0, 0.0), 0), 30.0);
        assert_eq!(c.sample(DVec3::new(1.0, 0.0, 0.0), 0), 20.0);
        // At x = 0.5: weights 1/0.25 = 4 and 1/2.25; (40 + 30/2.25) / (4 + 1/2.25).
        let want = (4.0 * 10.0 + 30.0 / 2.25) / (4.0 + 1.0 / 2.25);
        assert!((c.sample(DVec3::new(0.5, 0.0, 0.0), 0) - want).abs() < 1e-12);
        assert_eq!(c.range(0), (10.0, 30.0));
    }

    /// Brute force over every point, the same formula.
    fn brute(pts: &[(DVec3, f64)], p: DVec3) -> f64 {
        let mut d: Vec<(f64, f64)> = pts
            .iter()
            .map(|(q, v)| (q.distance_squared(p), *v))
            .collect();
        d.sort_by(|a, b| a.0.total_cmp(&b.0));
        let near = &d[..NEIGHBOURS.min(d.len())];
        let sw: f64 = near.iter().map(|(d2, _)| 1.0 / d2).sum();
        near.iter().map(|(d2, v)| v / d2).sum::<f64>() / sw
    }

    #[test]
    fn the_tree_finds_the_same_neighbours_as_brute_force() {
        let mut rng = crate::xorshift::XorShift::new(7);
        let mut text = String::from("temperature,Z,X,Y\n");
        let mut pts = Vec::new();
        for _ in 0..300 {
            let q = DVec3::new(
                rng.next_f64() * 20.0,
                rng.next_f64() * 10.0,
                rng.next_f64() * 5.0,
            );
            let v = 20.0 + q.x * q.x - q.y;
            text += &format!("{v},{},{},{}\n", q.z, q.x, q.y);
            pts.push((q, v));
        }
        let c = PointCloud::parse(&text, "t.csv").unwrap();
        assert_eq!(c.names(), ["temperature"]);
        for _ in 0..200 {
            let p = DVec3::new(
                rng.next_f64() * 24.0 - 2.0,
                rng.next_f64() * 12.0 - 1.0,
                rng.next_f64() * 7.0 - 1.0,
            );
            let (got, want) = (c.sample(p, 0), brute(&pts, p));
            assert!(
                (got - want).abs() <= 1e-9 * want.abs(),
                "{p}: {got} vs {want}"
            );
        }
    }

    #[test]
    fn repeated_points_and_one_point() {
        let c = PointCloud::parse("x,y,z,t\n1,1,1,5\n1,1,1,7\n1,1,1,9\n", "t.csv").unwrap();
        // Equal weights away from the point: the mean.
        assert!((c.sample(DVec3::ZERO, 0) - 7.0).abs() < 1e-12);
        let c =
            PointCloud::parse("\u{feff}# probe readings\nx,y,z,t\n1,2,3,42\n", "t.csv").unwrap();
        assert_eq!(c.sample(DVec3::new(9.0, 9.0, 9.0), 0), 42.0);
    }

    #[test]
    fn bad_files_say_where() {
        for (text, says) in [
            ("", "t.csv: the file is empty"),
            (
                "x,y,t\n1,2,3\n",
                "t.csv:1: the header has no \"z\" column; it has x, y, t",
            ),
            (
                "x,y,z,t\n1,2,3,4\n1,2,oops,4\n",
                "t.csv:3: column 3 (\"z\") is \"oops\"",
            ),
            ("x,y,z,t\n1,2,3\n", "t.csv:2: 3 cells, the header has 4"),
            ("x,y,z,t\n", "no rows"),
            ("x,y,z\n1,2,3\n", "only x, y, z"),
            ("x,y,z,t,t\n1,2,3,4,5\n", "\"t\" appears twice"),
            ("x,y,z,t\n1,2,3,inf\n", "column 4 (\"t\")"),
        ] {
            let e = PointCloud::parse(text, "t.csv").unwrap_err();
            assert!(e.contains(says), "{text:?}: {e}");
        }
    }
}
