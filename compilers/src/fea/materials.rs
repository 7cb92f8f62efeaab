//! Materials per element: the seeded draw and the elastic constants.

use volcad_core::Model;
use volcad_core::material::VOID;

use super::inp_writer::{self, MatOut};
use crate::job::ExportError;

/// SplitMix64's finaliser (Steele, Lea & Flood 2014): a bijective 64-bit mix,
/// used as a counter-based generator (Salmon et al. 2011): the n-th number
/// is `mix(seed ^ mix(n))`, independent of evaluation order.
#[inline]
fn mix(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// Draw one material slot from `fracs` (weights, need not sum to one) with
/// the uniform number for `(seed, key)`; `None` when all weights are zero.
pub fn draw(fracs: &[f64], seed: u64, key: u64) -> Option<usize> {
    let sum: f64 = fracs.iter().filter(|f| **f > 0.0).sum();
    if sum.is_nan() || sum <= 0.0 {
        return None;
    }
    let u = (mix(seed ^ mix(key)) >> 11) as f64 * (1.0 / (1u64 << 53) as f64) * sum;
    let mut acc = 0.0;
    let mut last = None;
    for (i, f) in fracs.iter().enumerate() {
        if *f > 0.0 {
            acc += f;
            last = Some(i);
            if u < acc {
                return last;
            }
        }
    }
    last
}

/// The elastic constants of every material the model uses, or an error
/// naming the first that lacks them. ν = 0.5 (incompressible, e.g. Agilus30)
/// makes λ = Eν/((1+ν)(1−2ν)) infinite, so it is written as 0.49 with a note.
pub fn elastic_materials(model: &Model) -> Result<(Vec<MatOut>, Vec<String>), ExportError> {
    let table = model.table();
    let mut out = Vec::new();
    let mut notes = Vec::new();
    let mut taken = Vec::new();
    for (slot, &id) in model.materials().iter().enumerate() {
        if id == VOID {
            continue;
        }
        let name = table.name(id);
        let mat = table.get(id).ok_or_else(|| {
            ExportError::Other(format!(
                "material id {id} is not in table {}",
                table.origin()
            ))
        })?;
        let missing = |what: &str, key: &str| {
            ExportError::Other(format!(
                "material \"{name}\" (id {id}) in material table {} has no {what}; the FEA export writes *ELASTIC for every material, so add \"{key}\" to that entry (or use a table with elastic properties, e.g. j750_materials())",
                table.origin()
            ))
        };
        let e = mat
            .youngs_modulus_mpa
            .ok_or_else(|| missing("Young's modulus", "youngs_modulus_mpa"))?;
        let mut nu = mat
            .poisson_ratio
            .ok_or_else(|| missing("Poisson ratio", "poisson_ratio"))?;
        if !(e.is_finite() && e > 0.0) {
            return Err(ExportError::Other(format!(
                "material \"{name}\" in material table {}: Young's modulus must be > 0 MPa, got {e}",
                table.origin()
            )));
        }
        if !(nu > -1.0 && nu <= 0.5) {
            return Err(ExportError::Other(format!(
                "material \"{name}\" in material table {}: Poisson ratio must be in (−1, 0.5], got {nu}",
                table.origin()
            )));
        }
        if nu >= 0.5 - 1e-9 {
            notes.push(format!("{name}: Poisson ratio {nu} (incompressible) written as 0.49; linear elements lock near 0.5"));
            nu = 0.49;
        }
        let written = inp_writer::sanitize(name, &mut taken);
        out.push(MatOut {
            slot: slot as u16,
            name: written,
            original: name.to_string(),
            e,
            nu,
            density: None,
        });
    }
    Ok((out, notes))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn draw_follows_the_fractions() {
        let f = [0.25, 0.0, 0.75];
        let mut n = [0usize; 3];
        for key in 0..40_000 {
            n[draw(&f, 7, key).unwrap()] += 1;
        }
        assert_eq!(n[1], 0);
        assert!((n[2] as f64 / 40_000.0 - 0.75).abs() < 0.01, "{n:?}");
        assert_eq!(draw(&[0.0, 0.0], 1, 1), None);
        assert_eq!(draw(&[1.0], 1, 1), Some(0));
        // Same key, same answer; another seed, another stream.
        assert_eq!(draw(&f, 7, 99), draw(&f, 7, 99));
        assert_ne!(
            (0..64).map(|k| draw(&f, 1, k)).collect::<Vec<_>>(),
            (0..64).map(|k| draw(&f, 2, k)).collect::<Vec<_>>()
        );
    }
}
