//! The FEA deck's plan: its estimate line, the size that must resolve thin
//! features, and the solver-memory question.

use volcad_core::Model;

use super::{Assessment, Opt, Severity, Verdict};
use crate::fea::solver::{check_solver_memory, machine_memory, solver_bytes};
use crate::fea::{self, Element, FeaParams};
use crate::job::{ExportError, JobContext, Summary};
use crate::resources::human_bytes;

/// The deck's size, and for bricks the solver-memory question: asked when
/// even half the estimated nodes would not fit the solving machine (the
/// estimate is within a factor of about two; the export checks the exact
/// count before writing). Tetrahedra are asked by the export itself: their
/// estimate grades a coarse lattice, not the mesh.
pub(super) fn estimate(model: &Model, p: &FeaParams) -> Result<Assessment, ExportError> {
    let est = fea::estimate_fea(model, p)?;
    let mut verdicts = Vec::new();
    if p.element == Element::C3D8R {
        let memory = match p.solver_memory {
            Some(m) => Some(m),
            None => machine_memory()?,
        };
        if let Err(e) = check_solver_memory(est.nodes / 2, memory, false, &p.size_options()) {
            verdicts.push(Verdict::from_error(Severity::Ask, &e));
        }
    }
    Ok(Assessment {
        text: format!(
            "about {} elements, {} nodes, {} .inp, {} for CalculiX's solver",
            est.elements,
            est.nodes,
            human_bytes(est.file_bytes),
            human_bytes(solver_bytes(est.nodes))
        ),
        disk_bytes: None,
        verdicts,
    })
}

/// Bricks resolve by their size, tetrahedra by their smallest cell.
pub(super) fn cell(p: &FeaParams) -> (f64, Opt) {
    let (size, flag) = p.cell();
    (size, Opt::from_flag(flag))
}

pub(super) fn run(model: &Model, p: &FeaParams, ctx: &JobContext) -> Result<Summary, ExportError> {
    fea::export_fea(model, p, ctx)
}
