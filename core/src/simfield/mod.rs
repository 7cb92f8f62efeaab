//! FEA results as a field: the paper's *SimulationField*, pyvcad's `PointMap`.
//!
//! A tetrahedral mesh (Abaqus/CalculiX `.inp`, `inp.rs`) carries nodal
//! values (CSV, `csv.rs`). Inside a tetrahedron every value is interpolated linearly
//! with the point's barycentric weights, `f(p) = Σ λi f(vi)` (exact for
//! linear elements such as C3D4), found by a walk from a coarse start grid with a BVH
//! fallback (`tet_bvh.rs`).
//! Displacements give the derived variable `len = |(dx, dy, dz)(p)|`: the
//! vector is interpolated first and its magnitude taken afterwards, as in
//! OpenVCAD (pyvcad 2.3.4). The mesh's outer surface (`boundary.rs`) is a
//! [`TriangleMesh`], which gives the field an exact signed distance.

mod boundary;
mod csv;
mod inp;
mod ranges;
mod tet_bvh;

#[cfg(test)]
mod tests;

use std::path::{Path, PathBuf};

use glam::DVec3;

use crate::aabb::Aabb;
use crate::interval::Interval;
use crate::trimesh::TriangleMesh;

use self::ranges::NodeRanges;
use self::tet_bvh::TetLocator;

/// Why a simulation field could not be loaded or built. File errors name
/// the file and 1-based line.
#[derive(Debug, thiserror::Error)]
pub enum SimFieldError {
    /// A file could not be read.
    #[error("{}: cannot read: {msg}", .path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The operating system's message.
        msg: String,
    },
    /// A malformed `.inp` line (field count, number, missing `TYPE=`).
    #[error("{}:{line}: {msg}", .path.display())]
    Inp {
        /// The `.inp` file.
        path: PathBuf,
        /// 1-based line.
        line: usize,
        /// What was expected and what was found.
        msg: String,
    },
    /// A node id defined twice.
    #[error("{}:{line}: node {id} is already defined at line {first_line}", .path.display())]
    DuplicateNode {
        /// The `.inp` file.
        path: PathBuf,
        /// Line of the second definition.
        line: usize,
        /// The node id.
        id: u64,
        /// Line of the first definition.
        first_line: usize,
    },
    /// An element refers to a node id that no `*NODE` block defines.
    #[error("{}:{line}: element {element} refers to node {node}, which is not defined", .path.display())]
    UnknownNode {
        /// The `.inp` file.
        path: PathBuf,
        /// Line of the element.
        line: usize,
        /// Element id.
        element: u64,
        /// The undefined node id.
        node: u64,
    },
    /// The `.inp` has no `*NODE` data.
    #[error("{}: no *NODE data found", .path.display())]
    NoNodes {
        /// The `.inp` file.
        path: PathBuf,
    },
    /// The `.inp` has no C3D4 or C3D10 element.
    #[error("{}: no tetrahedral elements (*ELEMENT, TYPE=C3D4 or C3D10) found{}", .path.display(),
        if .ignored.is_empty() { String::new() } else { format!("; ignored types: {}", .ignored) })]
    NoTets {
        /// The `.inp` file.
        path: PathBuf,
        /// Element types that were present but are not tetrahedra.
        ignored: String,
    },
    /// A tetrahedron with (almost) zero volume: barycentric weights would be
    /// meaningless.
    #[error("{}:{line}: element {element} is degenerate: volume {} (typical {})", .path.display(), volume_text(.volume), volume_text(.typical))]
    DegenerateTet {
        /// The `.inp` file.
        path: PathBuf,
        /// Line of the element.
        line: usize,
        /// Element id.
        element: u64,
        /// Its signed volume.
        volume: f64,
        /// Mean absolute volume of all tetrahedra.
        typical: f64,
    },
    /// A malformed CSV line (cell count, header).
    #[error("{}:{line}: {msg}", .path.display())]
    Csv {
        /// The CSV file.
        path: PathBuf,
        /// 1-based line.
        line: usize,
        /// What was expected and what was found.
        msg: String,
    },
    /// A CSV cell that is not a finite number (or not an integer node id).
    #[error("{}:{line}: column `{column}`: `{text}` is not a finite number", .path.display())]
    Number {
        /// The CSV file.
        path: PathBuf,
        /// 1-based line.
        line: usize,
        /// Column name.
        column: String,
        /// The cell.
        text: String,
    },
    /// A CSV row for a node id the mesh does not have.
    #[error("{}:{line}: node {id} is not in the mesh", .path.display())]
    UnknownCsvNode {
        /// The CSV file.
        path: PathBuf,
        /// 1-based line.
        line: usize,
        /// The node id.
        id: u64,
    },
    /// Two CSV rows for the same node.
    #[error("{}:{line}: node {id} already has a row at line {first_line}", .path.display())]
    DuplicateRow {
        /// The CSV file.
        path: PathBuf,
        /// Line of the second row.
        line: usize,
        /// The node id.
        id: u64,
        /// Line of the first row.
        first_line: usize,
    },
    /// A mesh node without a CSV row.
    #[error("{}: no row for node {id} (defined at .inp line {inp_line}); {missing} node(s) have no row", .path.display())]
    MissingRow {
        /// The CSV file.
        path: PathBuf,
        /// The first node id without a row.
        id: u64,
        /// Its line in the `.inp`.
        inp_line: usize,
        /// How many nodes have no row.
        missing: usize,
    },
    /// A CSV without node ids whose row count differs from the node count.
    #[error("{}:{line}: {rows} data rows for {nodes} mesh nodes (without a node_id column, row i is node i of the .inp)", .path.display())]
    RowCount {
        /// The CSV file.
        path: PathBuf,
        /// The first surplus row, or the last row when rows are missing.
        line: usize,
        /// Data rows found.
        rows: usize,
        /// Mesh nodes.
        nodes: usize,
    },
    /// Invalid arguments to [`SimField::from_parts`].
    #[error("{msg}")]
    Parts {
        /// What is wrong (tet or node index, column name).
        msg: String,
    },
}

/// Most tetrahedra [`SimField::bounds`] gathers before giving up (a box
/// that large is too coarse for its bounds to decide anything).
pub(crate) const MAX_BOUND_TETS: usize = 512;

/// A tetrahedral mesh with nodal values, sampled by barycentric
/// interpolation. Immutable and `Sync`.
#[derive(Clone, Debug)]
pub struct SimField {
    nodes: Vec<DVec3>,
    tets: Vec<[u32; 4]>,
    /// Variable names: stored columns, then `len` if derived.
    names: Vec<String>,
    /// Stored values, node-major: `values[node * stride + column]`.
    values: Vec<f64>,
    /// Stored columns per node.
    stride: usize,
    /// Stored columns of dx, dy, dz when `len` is derived.
    len_from: Option<[usize; 3]>,
    locator: TetLocator,
    /// Nodal value ranges per tetrahedron and per node of the locator's
    /// tree, for `bounds` (none when the table would be too large).
    ranges: Option<NodeRanges>,
    boundary: TriangleMesh,
    warnings: Vec<String>,
}

/// A problem found by [`build`], before it is tied to a file and line.
enum BuildError {
    Degenerate {
        tet: usize,
        volume: f64,
        typical: f64,
    },
    Other(String),
}

impl SimField {
    /// Loads a tetrahedral `.inp` mesh and a nodal-results CSV.
    ///
    /// `.inp`: `*NODE` and `*ELEMENT, TYPE=C3D4` (or C3D10, corners used)
    /// blocks, keywords case-insensitive, `**` comments, node ids in any
    /// order; other blocks (sets, materials, steps) are skipped, other element
    /// types skipped with a warning. CSV: with a header, a `node_id` (or
    /// `id`, `node`) column maps rows to nodes and the other columns are
    /// values by name; headerless (pyvcad `PointMap`), rows `x,y,z,u,v,w` in
    /// node order, exposed as `x,y,z,dx,dy,dz`. Every node needs one row.
    pub fn load(inp: &Path, csv: &Path) -> Result<SimField, SimFieldError> {
        let mesh = inp::parse(inp)?;
        let (columns, csv_warnings) = csv::parse(csv, &mesh)?;
        let mut field =
            build(mesh.nodes.clone(), mesh.tets.clone(), columns).map_err(|e| match e {
                BuildError::Degenerate {
                    tet,
                    volume,
                    typical,
                } => SimFieldError::DegenerateTet {
                    path: inp.to_path_buf(),
                    line: mesh.elem_lines[tet],
                    element: mesh.elem_ids[tet],
                    volume,
                    typical,
                },
                BuildError::Other(msg) => SimFieldError::Parts { msg },
            })?;
        let mut warnings = mesh.warnings;
        warnings.extend(csv_warnings);
        warnings.append(&mut field.warnings);
        field.warnings = warnings;
        Ok(field)
    }

    /// Builds a field from nodes, tetrahedra (node indices, any orientation)
    /// and named nodal columns (one value per node). Columns named `x`, `y`,
    /// `z` are coordinates: they are only compared with the nodes (a warning
    /// if they differ), not variables.
    pub fn from_parts(
        nodes: Vec<DVec3>,
        tets: Vec<[u32; 4]>,
        columns: Vec<(String, Vec<f64>)>,
    ) -> Result<SimField, SimFieldError> {
        build(nodes, tets, columns).map_err(|e| match e {
            BuildError::Degenerate {
                tet,
                volume,
                typical,
            } => SimFieldError::Parts {
                msg: format!(
                    "tet {tet} is degenerate: volume {} (typical {})",
                    volume_text(&volume),
                    volume_text(&typical)
                ),
            },
            BuildError::Other(msg) => SimFieldError::Parts { msg },
        })
    }

    /// Names usable as expression variables, in the order [`SimField::sample`]
    /// writes them: every value column except `x, y, z`, then `len` when
    /// `dx, dy, dz` exist (`len = |interpolated (dx, dy, dz)|`).
    pub fn variable_names(&self) -> Vec<String> {
        self.names.clone()
    }

    /// Number of variables ([`SimField::variable_names`]).
    pub fn variable_count(&self) -> usize {
        self.names.len()
    }

    /// The tetrahedron containing `p` and the barycentric weights of its
    /// four nodes (in the order the tetrahedron lists them), or `None`
    /// outside the mesh.
    pub fn locate(&self, p: DVec3) -> Option<(u32, [f64; 4])> {
        self.locator.locate(p).map(|(t, _, w)| (t, w))
    }

    /// Interpolates every variable at `p` into `out` (in
    /// [`SimField::variable_names`] order; a shorter `out` receives the first
    /// `out.len()` variables). Returns false, leaving `out` untouched, when
    /// `p` is outside the mesh.
    #[inline]
    pub fn sample(&self, p: DVec3, out: &mut [f64]) -> bool {
        let Some((_, nodes, w)) = self.locator.locate(p) else {
            return false;
        };
        let s = self.stride;
        let v = &self.values;
        let base = nodes.map(|i| i as usize * s);
        let interp = |c: usize| {
            w[0] * v[base[0] + c]
                + w[1] * v[base[1] + c]
                + w[2] * v[base[2] + c]
                + w[3] * v[base[3] + c]
        };
        for (c, o) in out.iter_mut().take(s).enumerate() {
            *o = interp(c);
        }
        if let (Some([x, y, z]), Some(o)) = (self.len_from, out.get_mut(s)) {
            *o = DVec3::new(interp(x), interp(y), interp(z)).length();
        }
        true
    }

    /// Bounds of every variable (as [`SimField::sample`] orders them) at
    /// the points of `b` inside the mesh, into `out`: the nodal ranges over
    /// the tetrahedra whose boxes meet `b` (linear interpolation stays
    /// within them), and for `len` the magnitude of the component ranges.
    /// False when no tetrahedron or more than `MAX_BOUND_TETS` (512) meet
    /// `b`.
    pub fn bounds(&self, b: &Aabb, out: &mut [Interval]) -> bool {
        let s = self.stride;
        if s > 64 {
            return false;
        }
        let mut lo = [f64::INFINITY; 64];
        let mut hi = [f64::NEG_INFINITY; 64];
        let mut count = 0;
        let complete = match &self.ranges {
            // One row of the range table per tetrahedron that meets `b`,
            // and per tree node that lies within it (the same tetrahedra,
            // see `ranges`).
            Some(table) => self.locator.overlapping_nodes(b, |c| {
                count += table.count(c);
                table.merge(c, &mut lo[..s], &mut hi[..s]);
                count <= MAX_BOUND_TETS
            }),
            // No table (too large): each tetrahedron's nodal rows.
            None => self.locator.overlapping(b, |nodes| {
                count += 1;
                ranges::widen_by_tet(&self.values, s, nodes, &mut lo[..s], &mut hi[..s]);
                count <= MAX_BOUND_TETS
            }),
        };
        if !complete || count == 0 {
            return false;
        }
        let column = |c: usize| Interval::new(lo[c], hi[c]);
        for (c, o) in out.iter_mut().take(s).enumerate() {
            *o = column(c);
        }
        if let (Some([x, y, z]), Some(o)) = (self.len_from, out.get_mut(s)) {
            *o = (column(x).square() + column(y).square() + column(z).square()).sqrt();
        }
        true
    }

    /// Value of variable `var` at node `node` (`len` from the nodal vector).
    pub fn node_value(&self, node: usize, var: usize) -> Option<f64> {
        if node >= self.nodes.len() {
            return None;
        }
        let row = &self.values[node * self.stride..(node + 1) * self.stride];
        match (var < self.stride, self.len_from) {
            (true, _) => Some(row[var]),
            (false, Some([x, y, z])) if var == self.stride => {
                Some(DVec3::new(row[x], row[y], row[z]).length())
            }
            _ => None,
        }
    }

    /// Smallest and largest nodal value of variable `var`. Linear
    /// interpolation stays within this range; for `len` the maximum bounds
    /// the interpolated magnitude too (|Σλu| ≤ Σλ|u|), so `len/max` is in
    /// [0, 1] as the paper's grading functions expect.
    pub fn variable_range(&self, var: usize) -> Option<(f64, f64)> {
        (0..self.nodes.len())
            .map(|n| self.node_value(n, var))
            .try_fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                v.map(|v| (lo.min(v), hi.max(v)))
            })
    }

    /// Exact signed distance to the mesh boundary (faces used by exactly one
    /// tetrahedron), negative inside.
    pub fn signed_distance(&self, p: DVec3) -> f64 {
        self.boundary.signed_distance(p)
    }

    /// Conservative bounds of [`SimField::signed_distance`] over a box.
    pub fn interval(&self, b: &Aabb) -> Interval {
        self.boundary.interval(b)
    }

    /// The boundary surface (outward triangles) as a mesh.
    pub fn boundary_mesh(&self) -> &TriangleMesh {
        &self.boundary
    }

    /// Bounds of the tetrahedra.
    pub fn bbox(&self) -> Aabb {
        self.boundary.bbox()
    }

    /// Number of nodes (including nodes no tetrahedron uses).
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// Number of tetrahedra.
    pub fn tet_count(&self) -> usize {
        self.tets.len()
    }

    /// Node positions.
    pub fn nodes(&self) -> &[DVec3] {
        &self.nodes
    }

    /// Tetrahedra as node indices, as given.
    pub fn tets(&self) -> &[[u32; 4]] {
        &self.tets
    }

    /// Things worth telling the user (skipped element types, renamed
    /// columns, CSV coordinates that differ from the mesh, boundary problems).
    pub fn warnings(&self) -> Vec<String> {
        self.warnings.clone()
    }
}

/// Validates the parts and builds the locator and boundary.
fn build(
    nodes: Vec<DVec3>,
    tets: Vec<[u32; 4]>,
    columns: Vec<(String, Vec<f64>)>,
) -> Result<SimField, BuildError> {
    let other = |m: String| BuildError::Other(m);
    if tets.is_empty() {
        return Err(other("no tetrahedra".into()));
    }
    if let Some(i) = nodes.iter().position(|n| !n.is_finite()) {
        return Err(other(format!("node {i} is not finite: {}", nodes[i])));
    }
    for (t, tet) in tets.iter().enumerate() {
        if let Some(&i) = tet.iter().find(|&&i| i as usize >= nodes.len()) {
            return Err(other(format!(
                "tet {t} refers to node {i}, but there are only {} nodes",
                nodes.len()
            )));
        }
    }
    let mut warnings = Vec::new();
    let (mut names, stored, coords) = value_columns(columns, nodes.len())?;
    check_coordinates(&nodes, &coords, &mut warnings);

    // Degenerate tetrahedra: |V| ≤ 1e−12 · mean |V|.
    let volumes: Vec<f64> = tets
        .iter()
        .map(|t| tet_bvh::signed_volume(t.map(|i| nodes[i as usize])))
        .collect();
    let typical = volumes.iter().map(|v| v.abs()).sum::<f64>() / volumes.len() as f64;
    if let Some(tet) = volumes.iter().position(|v| v.abs() <= 1e-12 * typical) {
        return Err(BuildError::Degenerate {
            tet,
            volume: volumes[tet],
            typical,
        });
    }
    let inverted = volumes.iter().filter(|&&v| v < 0.0).count();
    if inverted > 0 {
        warnings.push(format!(
            "{inverted} inverted tetrahedra (negative volume) were reoriented"
        ));
    }

    let find = |n: &str| names.iter().position(|x| x.eq_ignore_ascii_case(n));
    let len_from = match (find("dx"), find("dy"), find("dz"), find("len")) {
        (Some(x), Some(y), Some(z), None) => Some([x, y, z]),
        (Some(_), Some(_), Some(_), Some(_)) => {
            warnings.push("a `len` column exists, so |(dx, dy, dz)| is not derived".into());
            None
        }
        _ => None,
    };
    let stride = stored.len();
    let mut values = vec![0.0; nodes.len() * stride];
    for (c, col) in stored.iter().enumerate() {
        for (n, v) in col.iter().enumerate() {
            values[n * stride + c] = *v;
        }
    }
    if len_from.is_some() {
        names.push("len".into());
    }
    if stride > csv::MAX_VALUE_COLUMNS {
        return Err(other(format!(
            "{stride} value columns besides x, y, z; at most {} are supported",
            csv::MAX_VALUE_COLUMNS
        )));
    }

    // The boundary surface (its candidate grid is built in parallel) and
    // the tetrahedra's tree (sequential) at once: the tree's build no
    // longer waits for the surface's.
    let (surface, mut locator) = rayon::join(
        || {
            let b = boundary::extract(&nodes, &tets);
            let overused = b.overused_faces;
            TriangleMesh::from_triangles(b.vertices, b.triangles).map(|m| (m, overused))
        },
        || TetLocator::unstarted(&nodes, &tets),
    );
    let (boundary, overused) = surface.map_err(|e| other(format!("boundary surface: {e}")))?;
    if overused > 0 {
        warnings.push(format!(
            "{overused} faces are shared by more than two tetrahedra (non-conforming mesh)"
        ));
    }
    warnings.extend(
        boundary
            .warnings()
            .into_iter()
            .map(|w| format!("boundary surface: {w}")),
    );
    locator.start_walks(&boundary);
    let ranges = NodeRanges::new(&locator, &values, stride);
    Ok(SimField {
        nodes,
        tets,
        names,
        values,
        stride,
        len_from,
        locator,
        ranges,
        boundary,
        warnings,
    })
}

/// Value columns (names and values) and coordinate columns (by axis) of
/// `columns`, each checked: one finite value per node, a unique name.
type Sorted = (Vec<String>, Vec<Vec<f64>>, [Option<Vec<f64>>; 3]);

/// Sorts `columns` (`nodes` values each) into value and coordinate
/// columns, refusing wrong lengths, repeated names and non-finite values.
fn value_columns(columns: Vec<(String, Vec<f64>)>, nodes: usize) -> Result<Sorted, BuildError> {
    let other = |m: String| BuildError::Other(m);
    let mut names: Vec<String> = Vec::new();
    let mut stored: Vec<Vec<f64>> = Vec::new();
    let mut coords: [Option<Vec<f64>>; 3] = [None, None, None];
    for (name, vals) in columns {
        if vals.len() != nodes {
            return Err(other(format!(
                "column `{name}` has {} values for {nodes} nodes",
                vals.len(),
            )));
        }
        if name.is_empty() || names.iter().any(|n| n.eq_ignore_ascii_case(&name)) {
            return Err(other(format!("column name `{name}` is empty or repeated")));
        }
        if let Some(i) = vals.iter().position(|v| !v.is_finite()) {
            return Err(other(format!(
                "column `{name}`: value of node {i} is not finite"
            )));
        }
        match coordinate_axis(&name) {
            Some(a) => coords[a] = Some(vals),
            None => {
                names.push(name);
                stored.push(vals);
            }
        }
    }
    Ok((names, stored, coords))
}

/// The axis of a coordinate column (`x`, `y`, `z` in any case): compared
/// with the nodes, never a variable.
fn coordinate_axis(name: &str) -> Option<usize> {
    ["x", "y", "z"]
        .iter()
        .position(|a| name.eq_ignore_ascii_case(a))
}

/// Warns when CSV coordinates disagree with the mesh nodes by more than
/// 1e−4 of the mesh size (a CSV that belongs to another mesh or node order).
fn check_coordinates(nodes: &[DVec3], coords: &[Option<Vec<f64>>; 3], warnings: &mut Vec<String>) {
    let bbox = nodes
        .iter()
        .fold(Aabb::EMPTY, |b, &p| b.union(&Aabb::new(p, p)));
    let tol = 1e-4 * bbox.size().length().max(1e-300);
    let mut worst = 0.0f64;
    let mut count = 0;
    for (n, p) in nodes.iter().enumerate() {
        let mut d2 = 0.0;
        for (a, c) in coords.iter().enumerate() {
            if let Some(c) = c {
                d2 += (c[n] - p[a]).powi(2);
            }
        }
        let d = d2.sqrt();
        if d > tol {
            count += 1;
            worst = worst.max(d);
        }
    }
    if count > 0 {
        warnings.push(format!(
            "CSV coordinates differ from the mesh nodes at {count} nodes (up to {worst:.4}); rows may belong to another mesh or node order"
        ));
    }
}

/// A tetrahedron's volume for an error message: four significant digits in
/// plain notation where that reads well (`13.14 mm³`), scientific for the
/// tiny volumes of near-degenerate elements (`2.500e-12 mm³`), `0 mm³`.
fn volume_text(v: &f64) -> String {
    let a = v.abs();
    if a == 0.0 {
        "0 mm³".to_string()
    } else if (1e-3..1e6).contains(&a) {
        let decimals = (3 - a.log10().floor() as i32).max(0) as usize;
        format!("{v:.decimals$} mm³")
    } else {
        format!("{v:.3e} mm³")
    }
}
