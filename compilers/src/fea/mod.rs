//! FEA meshes for Abaqus/CalculiX (`.inp`).
//!
//! Two element kinds (the paper's FEA export):
//!
//! * **C3D8R bricks** on the shared voxel grid ([`bricks`]): one brick per
//!   voxel whose centre is inside, shared corner nodes.
//! * **C3D4 tetrahedra** by isosurface stuffing ([`tets`], Labelle & Shewchuk
//!   2007) on a graded Kuhn/bisection lattice ([`lattice`]) whose edge length
//!   follows the material heterogeneity ([`sizing`]):
//!   `L = min_cell + h (max_cell − min_cell)` or a math string of `h`.
//!
//! A design with a `modulus` attribute gets its elastic constants from the
//! fields instead ([`property_bins`]): `modulus`, `poissons_ratio` and
//! `density` at each element's centroid, grouped into a few elastic sets.
//! Otherwise every element gets **one** material, drawn from the fractions at its
//! centre with a counter-based generator keyed by the element (the voxel's
//! grid index for bricks, the element's index for tetrahedra), so the output
//! is the same bytes on any thread count. The deck ([`inp_writer`]) has a set,
//! section and `*ELASTIC` block per material, `NBOTTOM`/`NTOP` node sets, and
//! with [`StepParams`] a static step that runs as written. Results come back
//! through [`read_frd`] and [`write_result_csv`].

pub mod boundary;
pub mod bricks;
pub mod frd;
pub mod inp_writer;
pub mod lattice;
pub mod materials;
pub mod property_bins;
pub mod quality;
pub mod refine;
pub mod sizing;
pub mod solver;
pub mod tets;
pub mod topology;

use std::io::{BufWriter, Write};
use std::sync::atomic::AtomicBool;
use std::time::Instant;

use glam::DVec3;
use serde::Serialize;
use volcad_core::Model;
use volcad_core::material::VOID;
use volcad_core::model::MAX_MATERIALS;

pub use boundary::EndSets;
pub use frd::{
    CsvStats, FrdError, FrdResult, read_frd, read_inp_nodes, result_csv, write_result_csv,
};
pub use materials::{draw, elastic_materials};
pub use quality::{QualityReport, dihedral_range, signed_volume, tet_quality};
pub use sizing::{SizeRule, heterogeneity};
use tets::STUFF;

use crate::job::{ExportError, JobContext, Summary};
use crate::resources::run_with_threads;
use inp_writer::{Deck, MatOut};

/// Element kind.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum Element {
    /// 8-node bricks, reduced integration.
    C3D8R,
    /// 4-node tetrahedra.
    C3D4,
}

impl Element {
    /// Nodes per element.
    pub fn nodes_per_element(self) -> usize {
        match self {
            Element::C3D8R => 8,
            Element::C3D4 => 4,
        }
    }
}

/// How the tetrahedron edge length follows the heterogeneity `h`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub enum Sizing {
    /// `L = min_cell + h (max_cell − min_cell)`.
    Heterogeneity,
    /// A math string of `h` giving `L` in mm (clamped to `[min_cell, max_cell]`).
    Expr(String),
}

/// The static step appended by `--step`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct StepParams {
    /// Prescribed z displacement of the top nodes (mm), e.g. −0.5.
    pub top_displacement: f64,
}

/// FEA export parameters.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FeaParams {
    /// Element kind.
    pub element: Element,
    /// Brick size for C3D8R (mm).
    pub voxel: f64,
    /// Smallest tetrahedron edge length (mm), at h = 0; also the floor of the
    /// geometric refinement that keeps thin features (`refine.rs`).
    pub min_cell: f64,
    /// Largest tetrahedron edge length (mm), at h = 1 (pure material); the
    /// boundary of a pure region is refined where it curves or has a crease,
    /// down to a quarter of it.
    pub max_cell: f64,
    /// Sizing rule.
    pub sizing: Sizing,
    /// Seed of the material draw.
    pub seed: u64,
    /// Bins per property for designs with a `modulus` attribute
    /// (`None`: [`property_bins::DEFAULT_BINS`]; given for a design
    /// without `modulus`, an error).
    pub property_bins: Option<usize>,
    /// Append a ready static step.
    pub step: Option<StepParams>,
    /// How the `NBOTTOM` and `NTOP` node sets are chosen.
    pub ends: EndSets,
    /// Write a deck whose elements fall into several pieces (joined at
    /// edges or corners only, or apart), which is refused otherwise.
    pub allow_pieces: bool,
    /// Write a deck whose solve needs more memory than the machine has.
    pub force: bool,
    /// Memory (bytes) of the machine that will solve the deck (`None`:
    /// [`solver::machine_memory`]).
    #[serde(skip)]
    pub solver_memory: Option<u64>,
    /// Worker threads (`None`: all cores). The output does not depend on
    /// it, so the manifest does not record it either.
    #[serde(skip)]
    pub threads: Option<usize>,
}

impl Default for FeaParams {
    fn default() -> Self {
        Self {
            element: Element::C3D4,
            voxel: 1.0,
            min_cell: 0.5,
            max_cell: 4.0,
            sizing: Sizing::Heterogeneity,
            seed: 0,
            property_bins: None,
            step: None,
            ends: EndSets::default(),
            allow_pieces: false,
            force: false,
            solver_memory: None,
            threads: None,
        }
    }
}

impl FeaParams {
    /// The smallest element size (mm) and the option that sets it.
    pub fn cell(&self) -> (f64, &'static str) {
        match self.element {
            Element::C3D8R => (self.voxel, "--voxel"),
            Element::C3D4 => (self.min_cell, "--min-cell"),
        }
    }

    /// The element size options with their values, for suggestions.
    pub fn size_options(&self) -> Vec<(&'static str, f64)> {
        match self.element {
            Element::C3D8R => vec![("--voxel", self.voxel)],
            Element::C3D4 => vec![("--min-cell", self.min_cell), ("--max-cell", self.max_cell)],
        }
    }
}

/// What an export would produce, from a coarse sampling (within a factor of
/// about two).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct FeaEstimate {
    /// Elements.
    pub elements: u64,
    /// Nodes.
    pub nodes: u64,
    /// Size of `model.inp` in bytes.
    pub file_bytes: u64,
}

/// A mesh with one material slot (index into `Model::materials()`) per element.
#[derive(Clone, Debug)]
pub struct FeaMesh {
    /// Element kind.
    pub element: Element,
    /// Node positions (0-based).
    pub nodes: Vec<DVec3>,
    /// Connectivity, `nodes_per_element` 0-based ids per element.
    pub conn: Vec<u32>,
    /// Material slot per element.
    pub mat: Vec<u16>,
    /// Tetrahedron quality (C3D4 only).
    pub quality: Option<QualityReport>,
    /// Free-form figures for the summary.
    pub notes: Vec<String>,
    /// Boundary faces and pieces, when the mesher found them on the way
    /// (bricks); otherwise [`topology::topology`] finds them.
    pub topology: Option<topology::Topology>,
}

impl FeaMesh {
    fn new(element: Element) -> Self {
        Self {
            element,
            nodes: Vec::new(),
            conn: Vec::new(),
            mat: Vec::new(),
            quality: None,
            notes: Vec::new(),
            topology: None,
        }
    }

    /// Number of elements.
    pub fn len(&self) -> usize {
        self.mat.len()
    }

    /// True without elements.
    pub fn is_empty(&self) -> bool {
        self.mat.is_empty()
    }

    /// Connectivity of element `e`.
    pub fn element_nodes(&self, e: usize) -> &[u32] {
        let n = self.element.nodes_per_element();
        &self.conn[e * n..(e + 1) * n]
    }

    /// A low estimate of the size of the `.inp` file of this mesh, for
    /// refusing up front a disk that cannot hold it: 20 bytes a node line
    /// and 4 + 3 a corner an element line (the files are larger, most of
    /// all for tetrahedra, whose coordinates take more digits).
    pub fn inp_bytes_at_least(&self) -> u64 {
        let corners = self.element.nodes_per_element() as u64;
        self.nodes.len() as u64 * 20 + self.len() as u64 * (4 + 3 * corners)
    }
}

/// Elements above which an export is refused (CalculiX needs far less).
pub const MAX_ELEMENTS: u64 = 50_000_000;

/// Build the mesh (materials drawn) without writing anything. `progress`
/// gets (stage, done, total, fraction of the meshing).
pub fn build_mesh(
    model: &Model,
    p: &FeaParams,
    cancel: &AtomicBool,
    progress: &(dyn Fn(&str, u64, u64, f64) + Sync),
) -> Result<FeaMesh, ExportError> {
    match p.element {
        Element::C3D8R => {
            bricks::brick_mesh(model, p.voxel, p.seed, MAX_ELEMENTS, cancel, progress)
        }
        Element::C3D4 => tet_mesh(model, p, cancel, progress),
    }
}

fn size_rule(p: &FeaParams) -> Result<SizeRule, ExportError> {
    let expr = match &p.sizing {
        Sizing::Heterogeneity => None,
        Sizing::Expr(s) => Some(s.as_str()),
    };
    SizeRule::new(p.min_cell, p.max_cell, expr)
}

fn tet_mesh(
    model: &Model,
    p: &FeaParams,
    cancel: &AtomicBool,
    progress: &(dyn Fn(&str, u64, u64, f64) + Sync),
) -> Result<FeaMesh, ExportError> {
    let rule = size_rule(p)?;
    let mut lat = refine::lattice_for(model, &rule)?;
    let grading = refine::HetRefine { model, rule: &rule };
    let ok = lat.refine(&grading, |n| {
        progress("grading lattice", n as u64, 0, 0.1);
        n as u64 > 8 * MAX_ELEMENTS || cancel.load(std::sync::atomic::Ordering::Relaxed)
    });
    if !ok {
        if cancel.load(std::sync::atomic::Ordering::Relaxed) {
            return Err(ExportError::Cancelled);
        }
        return Err(ExportError::param(
            "--min-cell",
            format!(
                "the lattice passed {} tetrahedra; use a larger --min-cell",
                8 * MAX_ELEMENTS
            ),
        ));
    }
    progress(
        "stuffing",
        lat.tets.len() as u64,
        lat.tets.len() as u64,
        0.5,
    );
    let tm = tets::stuff(model, &lat, &STUFF, cancel).ok_or(ExportError::Cancelled)?;
    if tm.tets.len() as u64 > MAX_ELEMENTS {
        return Err(ExportError::param(
            "--min-cell",
            format!(
                "{} tetrahedra is more than {MAX_ELEMENTS}; use a larger --min-cell",
                tm.tets.len()
            ),
        ));
    }
    progress("drawing materials", 0, tm.tets.len() as u64, 0.8);
    let slots = tets::draw_materials(model, &tm, p.seed);
    let mut mesh = FeaMesh::new(Element::C3D4);
    let mut map = vec![u32::MAX; tm.nodes.len()];
    let mut quality = QualityReport::default();
    let mut void = 0usize;
    let mut volume = 0.0;
    for (t, s) in tm.tets.iter().zip(slots) {
        let Some(s) = s.filter(|s| model.materials()[*s] != VOID) else {
            void += 1;
            continue;
        };
        let corners = t.map(|i| tm.nodes[i as usize]);
        volume += signed_volume(&corners);
        quality.add(&corners);
        for &i in t {
            if map[i as usize] == u32::MAX {
                map[i as usize] = mesh.nodes.len() as u32;
                mesh.nodes.push(tm.nodes[i as usize]);
            }
            mesh.conn.push(map[i as usize]);
        }
        mesh.mat.push(s as u16);
    }
    mesh.notes.push(format!(
        "tetrahedra: {} from {} lattice tetrahedra; {} vertices warped onto the surface, {} edges cut; mesh volume {:.4} mm³",
        mesh.len(),
        lat.tets.len(),
        tm.warped,
        tm.cuts,
        volume
    ));
    if quality.count > 0 {
        mesh.notes.push(format!(
            "tet quality: dihedral angles {:.2}° … {:.2}° (guaranteed within [{}°, {}°]), smallest volume {:.3e} mm³",
            quality.min_dihedral_deg, quality.max_dihedral_deg, STUFF.min_angle, STUFF.max_angle, quality.min_volume
        ));
    }
    if tm.dropped > 0 {
        mesh.notes.push(format!("{} boundary elements outside the angle bounds were left out (the surface deviates there by up to one element)", tm.dropped));
    }
    if void > 0 {
        mesh.notes
            .push(format!("{void} elements drew void and were left out"));
    }
    mesh.quality = Some(quality);
    Ok(mesh)
}

/// Estimate the export's size from a coarse sampling of the model.
pub fn estimate_fea(model: &Model, p: &FeaParams) -> Result<FeaEstimate, ExportError> {
    let b = crate::design::bounded_box(model)?;
    const N: usize = 24;
    let step = b.size() / N as f64;
    let cell = step.x * step.y * step.z;
    let k = model.materials().len();
    let mut f = [0.0f64; MAX_MATERIALS];
    let (elements, nodes_per, elem_bytes) = match p.element {
        Element::C3D8R => {
            let g = bricks::grid(model, p.voxel)?;
            let mut inside = 0usize;
            for_samples(N, |u| {
                inside += usize::from(model.distance(b.min + u * b.size()) <= 0.0)
            });
            (
                (g.count() as f64 * inside as f64 / (N * N * N) as f64).round() as u64,
                1.15,
                60,
            )
        }
        Element::C3D4 => {
            // A crude density first, to pick a scale at which the real
            // lattice is cheap; then grade that coarser lattice and count
            // its tetrahedra with the centroid inside, times scale³.
            let rule = size_rule(p)?;
            let mut crude = 0.0;
            for_samples(N, |u| {
                if model.eval_into(b.min + u * b.size(), &mut f[..k]) <= 0.0 {
                    let l = rule.length(heterogeneity(&f[..k]));
                    crude += cell / (l * l * l / 60.0);
                }
            });
            let mut scale = 1.0f64;
            while crude / scale.powi(3) > 50_000.0 {
                scale *= 2.0;
            }
            let coarse = rule.scaled(scale);
            let mut lat = refine::lattice_for(model, &coarse)?;
            lat.refine(
                &refine::HetRefine {
                    model,
                    rule: &coarse,
                },
                |_| false,
            );
            let inside = lat
                .tets
                .iter()
                .filter(|t| model.distance(lat.corners(t).iter().sum::<DVec3>() * 0.25) <= 0.0)
                .count();
            ((inside as f64 * scale.powi(3)).round() as u64, 0.22, 36)
        }
    };
    let nodes = (elements as f64 * nodes_per).ceil() as u64;
    Ok(FeaEstimate {
        elements,
        nodes,
        file_bytes: elements * elem_bytes + nodes * 48 + 512,
    })
}

fn for_samples(n: usize, mut f: impl FnMut(DVec3)) {
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                f((DVec3::new(i as f64, j as f64, k as f64) + 0.5) / n as f64);
            }
        }
    }
}

/// The `--step` displacement against the part's height `h` (mm): a number,
/// and smaller than `h` (a top moved by the whole height has crushed the
/// part or doubled it, far outside the small strains of a linear static
/// step); a note past a tenth of `h`, and for 0 (the solution is zero).
fn check_step(d: f64, h: f64, notes: &mut Vec<String>) -> Result<(), ExportError> {
    if !d.is_finite() {
        return Err(ExportError::param(
            "--step",
            format!("the top displacement must be a number of mm, got {d}"),
        ));
    }
    if d.abs() >= h {
        return Err(ExportError::param(
            "--step",
            format!(
                "{d} mm is not smaller than the part's height ({h:.4} mm); a linear static step needs small strains (a few percent of the height)"
            ),
        ));
    }
    if d == 0.0 {
        notes.push(
            "--step 0: the top is held in place, so every displacement and stress is 0".into(),
        );
    } else if d.abs() > 0.1 * h {
        notes.push(format!(
            "--step {d} mm is {:.0} % of the part's height ({h:.4} mm): a linear static step assumes small strains, so the result is only indicative",
            100.0 * d.abs() / h
        ));
    }
    Ok(())
}

/// Refuse a mesh in several pieces (elements joined through faces) unless
/// `allow`: a piece held at an edge or a corner, or not at all, has no
/// stiffness there, and the solver's answer for it means nothing.
fn check_pieces(pieces: &[usize], allow: bool, option: &str) -> Result<Vec<String>, ExportError> {
    if pieces.len() <= 1 {
        return Ok(vec![
            "pieces: 1 (every element joined to the rest through faces)".into(),
        ]);
    }
    let total: usize = pieces.iter().sum();
    let what = format!(
        "the elements form {} pieces that share no face (the largest holds {:.1} % of the elements; the rest touch it only at edges or corners, or not at all), so the solver's answer for them means nothing",
        pieces.len(),
        100.0 * pieces[0] as f64 / total as f64
    );
    if !allow {
        return Err(ExportError::param(
            option,
            format!(
                "{what}; use a smaller {option} (the summary of `volcad export mesh` names the size that resolves the design), or --allow-pieces to write the deck anyway"
            ),
        ));
    }
    Ok(vec![format!(
        "warning: {what} (written because of --allow-pieces)"
    )])
}

/// True when the elastic constants come from the design's `modulus`
/// field; `--property-bins` out of range, or given for a design without
/// `modulus`, is an error (listing the attributes it has).
fn check_property_bins(model: &Model, bins: Option<usize>) -> Result<bool, ExportError> {
    if let Some(n) = bins {
        if !(1..=property_bins::MAX_BINS).contains(&n) {
            return Err(ExportError::param(
                "--property-bins",
                format!("must be 1 to {}, got {n}", property_bins::MAX_BINS),
            ));
        }
        model
            .require_attribute("modulus")
            .map_err(|e| ExportError::param("--property-bins", e.to_string()))?;
    }
    Ok(model.attribute_index("modulus").is_some())
}

/// The materials the deck writes, and each element's set in `mesh.mat`:
/// sets binned from the design's `modulus` field when it has one (the
/// elements' slots replaced by set numbers), else the table's materials
/// that some element uses.
fn element_materials(
    model: &Model,
    p: &FeaParams,
    mesh: &mut FeaMesh,
    materials: Vec<MatOut>,
    notes: &mut Vec<String>,
) -> Result<Vec<MatOut>, ExportError> {
    Ok(match property_bins::element_props(model, mesh)? {
        Some(props) => {
            let bins = p.property_bins.unwrap_or(property_bins::DEFAULT_BINS);
            let mut sets = property_bins::bin_elements(&props, bins);
            notes.extend(property_bins::cap_poisson(&mut sets));
            notes.push(format!(
                "elastic sets from the modulus field: {} sets ({bins} bins per property over modulus {:.6} … {:.6} MPa), each with the mean of its elements' centroid values",
                sets.materials.len(),
                sets.materials.first().map_or(0.0, |m| m.e),
                sets.materials.last().map_or(0.0, |m| m.e),
            ));
            mesh.mat = sets.set_of;
            sets.materials
        }
        None => materials
            .into_iter()
            .filter(|m| mesh.mat.contains(&m.slot))
            .collect(),
    })
}

/// Elements per written material, by the material's table name.
fn material_counts(used: &[MatOut], mesh: &FeaMesh) -> Vec<(String, u64)> {
    used.iter()
        .map(|m| {
            (
                m.original.clone(),
                mesh.mat.iter().filter(|s| **s == m.slot).count() as u64,
            )
        })
        .collect()
}

/// [`build_mesh`] on `p.threads` worker threads (default: rayon's pool),
/// reporting its progress as the first nine tenths of the job's.
fn mesh_on_threads(model: &Model, p: &FeaParams, ctx: &JobContext) -> Result<FeaMesh, ExportError> {
    let progress = |stage: &str, done: u64, total: u64, frac: f64| {
        ctx.progress(stage, done, total, "elements", frac * 0.9)
    };
    run_with_threads(p.threads, || {
        build_mesh(model, p, ctx.cancel_flag(), &progress)
    })
}

/// Mesh `model` and write `<staging>/model.inp` (see the module doc).
pub fn export_fea(model: &Model, p: &FeaParams, ctx: &JobContext) -> Result<Summary, ExportError> {
    let start = Instant::now();
    let by_props = check_property_bins(model, p.property_bins)?;
    let (materials, mut notes) = if by_props {
        (Vec::new(), Vec::new())
    } else {
        elastic_materials(model)?
    };
    let (element_size, size_option) = p.cell();
    notes.extend(crate::thin::thin_feature_notes(
        model,
        element_size,
        size_option,
    ));
    if let Some(s) = &p.step {
        check_step(s.top_displacement, model.bbox().size().z, &mut notes)?;
    }
    let mut mesh = mesh_on_threads(model, p, ctx)?;
    ctx.check_cancel()?;
    let known = mesh.topology.take();
    if mesh.is_empty() {
        return Err(ExportError::Other("the mesh has no elements: the design is empty at this element size (try a smaller --voxel or --max-cell)".into()));
    }
    let used = element_materials(model, p, &mut mesh, materials, &mut notes)?;
    notes.push(solver::check_solver_memory(
        mesh.nodes.len() as u64,
        match p.solver_memory {
            Some(m) => Some(m),
            None => solver::machine_memory()?,
        },
        p.force,
        &p.size_options(),
    )?);
    let (mut bottom, mut top) = boundary::end_sets(&mesh.nodes, &p.ends, element_size)?;
    if bottom.ids.len() < 3 || top.ids.len() < 3 {
        notes.push(format!("warning: NBOTTOM has {} and NTOP {} nodes; fewer than 3 leaves rigid-body modes under the --step boundary conditions", bottom.ids.len(), top.ids.len()));
    }
    notes.extend(mesh.notes.iter().cloned());
    notes.push(format!(
        "{} nodes, {} elements",
        mesh.nodes.len(),
        mesh.len(),
    ));
    let counts = material_counts(&used, &mesh);
    let kind = match mesh.element {
        Element::C3D8R => "C3D8R",
        Element::C3D4 => "C3D4",
    };
    let deck = Deck {
        mesh: &mesh,
        materials: &used,
        title: format!("Volcad Studio FEA export: {} {kind} elements, {} nodes, {} materials; units mm, N, MPa", mesh.len(), mesh.nodes.len(), used.len()),
        comments: std::iter::once(if by_props {
            format!("volcad-compilers {}; design {}; elastic sets from the design's modulus field at the element centroids", env!("CARGO_PKG_VERSION"), ctx.design_hash)
        } else {
            format!("volcad-compilers {}; design {}; one material per element, drawn from the fractions at its centre (seed {})", env!("CARGO_PKG_VERSION"), ctx.design_hash, p.seed)
        })
            .chain(notes.iter().cloned())
            .collect(),
        bottom: &bottom.ids,
        top: &top.ids,
        step: p.step.map(|s| s.top_displacement),
    };
    crate::resources::check_disk(
        mesh.inp_bytes_at_least(),
        ctx.folder(),
        "larger elements (--voxel, or --min-cell and --max-cell for tetrahedra)",
    )?;
    ctx.progress("writing model.inp", 0, mesh.len() as u64, "elements", 0.92);
    let path = ctx.staging().join("model.inp");
    // The faces' checks (pieces, set areas, footprint) run while the deck
    // is written: the writer is one core's work. A deck refused for its
    // pieces is then removed with the staging folder.
    let write = || {
        let file = std::fs::File::create(&path).map_err(|e| ExportError::io(&path, e))?;
        let mut w = BufWriter::with_capacity(1 << 20, file);
        inp_writer::write(&mut w, &deck)
            .and_then(|_| w.flush())
            .map_err(|e| ExportError::io(&path, e))
    };
    let faces = || {
        let topo = known.unwrap_or_else(|| topology::topology(&mesh));
        let footprint = boundary::footprint(&mesh.nodes, &topo.boundary);
        (topo, footprint)
    };
    let (written, (topo, footprint)) = rayon::join(write, faces);
    written?;
    notes.extend(check_pieces(&topo.pieces, p.allow_pieces, size_option)?);
    bottom.measure(&mesh.nodes, &topo.boundary);
    top.measure(&mesh.nodes, &topo.boundary);
    let zspan = boundary::z_span(&mesh.nodes);
    notes.extend(boundary::notes(&bottom, &top, footprint, zspan));
    ctx.progress(
        "done",
        mesh.len() as u64,
        mesh.len() as u64,
        "elements",
        1.0,
    );
    Ok(Summary {
        kind: "fea".into(),
        files: vec!["model.inp".into()],
        counts,
        units: mesh.len() as u64,
        unit: "elements".into(),
        parameters: serde_json::to_value(p).unwrap_or_default(),
        notes,
        seconds: start.elapsed().as_secs_f64(),
    })
}
