//! The memory CalculiX's direct solver (SPOOLES, the default of Debian's
//! `ccx` 2.20) takes for a static step on a deck, and the check that
//! refuses a deck the machine cannot solve.
//!
//! The factor of a 3D stiffness matrix in nested-dissection order holds
//! O(N^(4/3)) entries for N nodes (George 1973; the separators of a 3D mesh
//! have N^(2/3) nodes), which dominates the solver's peak. The constant is
//! fitted to ccx's peak resident memory (`/usr/bin/time -f %M`, one
//! thread) on cubes of unit bricks and of Kuhn tetrahedra, the most compact
//! shape and so the largest fill per node:
//!
//! | mesh | nodes | peak |
//! |---|---|---|
//! | 10³ C3D8R | 1,331 | 20.8 MB |
//! | 16³ C3D8R | 4,913 | 79.2 MB |
//! | 22³ C3D8R | 12,167 | 244 MB |
//! | 28³ C3D8R | 24,389 | 600 MB |
//! | 16³ × 6 C3D4 | 4,913 | 72.2 MB |
//! | 22³ × 6 C3D4 | 12,167 | 217 MB |
//!
//! `peak ≈ 12 MB + 830 B · N^(4/3)` is within 3 % of the brick rows and up
//! to 16 % above the others (a slender part fills less, so the estimate errs
//! high).

use crate::job::ExportError;
use crate::resources::human_bytes;
use crate::thin::size_above;

/// The environment variable giving the memory (MiB) of the machine that
/// will run the solver, when it is not this one.
pub const MEMORY_VAR: &str = "VOLCAD_SOLVER_MEMORY_MB";

const BASE: f64 = 12e6;
const PER_NODE: f64 = 830.0;

/// Estimated peak memory (bytes) of ccx's direct solver on `nodes` nodes.
pub fn solver_bytes(nodes: u64) -> u64 {
    (BASE + PER_NODE * (nodes as f64).powf(4.0 / 3.0)) as u64
}

/// The memory of the solving machine: [`MEMORY_VAR`] when set (an error
/// naming it when it is not a whole number of MiB), else this machine's
/// `MemTotal`, or `None` where unknown.
pub fn machine_memory() -> Result<Option<u64>, ExportError> {
    if let Some(v) = std::env::var_os(MEMORY_VAR) {
        let text = v.to_string_lossy();
        return match text.trim().parse::<u64>() {
            Ok(mb) if mb > 0 => Ok(Some(mb.saturating_mul(1 << 20))),
            _ => Err(ExportError::Other(format!(
                "{MEMORY_VAR}={text}: give the solving machine's memory as a whole number of MiB above 0"
            ))),
        };
    }
    let Ok(info) = std::fs::read_to_string("/proc/meminfo") else {
        return Ok(None);
    };
    Ok(info
        .lines()
        .find(|l| l.starts_with("MemTotal:"))
        .and_then(|l| l.split_whitespace().nth(1)?.parse::<u64>().ok())
        .map(|kib| kib * 1024))
}

/// The summary line for a deck of `nodes` nodes, or the refusal when the
/// solve needs more than `memory` and not `force`. `sizes` are the element
/// size options as given (`[("--min-cell", 0.5), ("--max-cell", 2.0)]`):
/// the error scales them to sizes that fit (nodes go as size⁻³, so the
/// solver's memory as size⁻⁴).
pub fn check_solver_memory(
    nodes: u64,
    memory: Option<u64>,
    force: bool,
    sizes: &[(&str, f64)],
) -> Result<String, ExportError> {
    let need = solver_bytes(nodes);
    let line = format!(
        "CalculiX's direct solver needs about {} for {nodes} nodes (fitted to ccx 2.20; a slender part takes less)",
        human_bytes(need)
    );
    let Some(memory) = memory else {
        return Ok(line);
    };
    if need <= memory {
        return Ok(format!(
            "{line}, within the {} of memory",
            human_bytes(memory)
        ));
    }
    if force {
        return Ok(format!(
            "warning: {line}, more than the {} of memory (written because of --force)",
            human_bytes(memory)
        ));
    }
    // Aim at 80 % of the memory, rounded up to two digits.
    let scale = (need as f64 / (0.8 * memory as f64)).powf(0.25);
    let fit: Vec<String> = sizes
        .iter()
        .map(|(option, v)| format!("{option} {}", size_above(v * scale)))
        .collect();
    let option = sizes.first().map_or("--voxel", |s| s.0);
    Err(ExportError::param(
        option,
        format!(
            "{line}, more than the {} of memory of the solving machine (set {MEMORY_VAR} for another machine); use larger elements, e.g. {}, or --force to write the deck anyway",
            human_bytes(memory),
            fit.join(" ")
        ),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fit_matches_the_measurements_and_refusal_names_sizes() {
        // (nodes, peak bytes) measured with ccx 2.20, see the module doc.
        for (n, peak) in [
            (1331u64, 20.8e6),
            (4913, 79.2e6),
            (12167, 244e6),
            (24389, 600e6),
            (4913, 72.2e6),
            (12167, 217e6),
        ] {
            let est = solver_bytes(n) as f64;
            assert!(
                est >= 0.97 * peak && est < 1.2 * peak,
                "{n}: {est} vs {peak}"
            );
        }
        let ok = check_solver_memory(1000, Some(1 << 30), false, &[("--voxel", 1.0)]).unwrap();
        assert!(ok.contains("within"), "{ok}");
        let e = check_solver_memory(
            3_000_000,
            Some(12 << 30),
            false,
            &[("--min-cell", 0.5), ("--max-cell", 2.0)],
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("--min-cell") && e.contains("--force"), "{e}");
        let forced =
            check_solver_memory(3_000_000, Some(12 << 30), true, &[("--voxel", 0.5)]).unwrap();
        assert!(forced.starts_with("warning:"), "{forced}");
    }
}
