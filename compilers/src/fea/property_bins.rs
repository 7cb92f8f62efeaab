//! Elastic sets from property fields: the `modulus`, `poissons_ratio`
//! and `density` attributes at each element's centroid, quantised into a
//! few sets that each get their own `*MATERIAL` / `*ELASTIC` (and
//! `*DENSITY`).
//!
//! A solver input with one material per element would be exact but large
//! and slow to read; `N` equal-width bins over the field's range keep the
//! deck small while each element's modulus is off by at most half a bin
//! width. Each set is written with the mean of its elements' values (not
//! the bin's centre), so the set's total stiffness matches its elements'
//! sum: in a bar of springs in parallel that is exact, in series the error
//! is second order in the bin width. Elements whose Poisson ratio or
//! density differ by more than a bin of their own range land in separate
//! sets too, so a set is uniform in every property it writes.

use std::collections::BTreeMap;

use glam::DVec3;
use rayon::prelude::*;
use volcad_core::{Model, Points};

use super::FeaMesh;
use super::inp_writer::MatOut;
use crate::job::ExportError;

/// Default number of bins per property (`--property-bins`).
pub const DEFAULT_BINS: usize = 16;

/// The largest `--property-bins`: CalculiX reads any number of materials,
/// but more sets than this make a deck no smaller than one per element.
pub const MAX_BINS: usize = 4096;

/// The properties of every element (same order as the mesh).
#[derive(Clone, Debug, Default)]
pub struct ElementProps {
    /// Young's modulus (MPa) per element.
    pub modulus: Vec<f64>,
    /// Poisson ratio per element.
    pub poisson: Vec<f64>,
    /// Density (g/cm³) per element, when the design has `density`.
    pub density: Option<Vec<f64>>,
}

/// The elastic sets: a set per element and the sets' constants.
#[derive(Clone, Debug)]
pub struct Sets {
    /// Set of each element (the `slot` of its [`MatOut`]).
    pub set_of: Vec<u16>,
    /// One material per set, in ascending modulus.
    pub materials: Vec<MatOut>,
}

/// The bins of an element's modulus, Poisson ratio and density.
type BinKey = (usize, usize, usize);

/// The bin (0..n) of `v` on `[lo, hi]` in `n` equal widths; a range of
/// zero width is one bin.
fn bin(v: f64, lo: f64, hi: f64, n: usize) -> usize {
    if hi <= lo {
        return 0;
    }
    (((v - lo) / (hi - lo) * n as f64) as usize).min(n - 1)
}

fn range(v: &[f64]) -> (f64, f64) {
    v.iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
            (lo.min(*x), hi.max(*x))
        })
}

/// Group the elements into sets by their bins of modulus, Poisson ratio and
/// density (`n` bins over each property's range). Sets are numbered in
/// ascending bin order, so the result depends only on the values.
pub fn bin_elements(p: &ElementProps, n: usize) -> Sets {
    let n = n.clamp(1, MAX_BINS);
    let (e_lo, e_hi) = range(&p.modulus);
    let (nu_lo, nu_hi) = range(&p.poisson);
    let (d_lo, d_hi) = p.density.as_deref().map_or((0.0, 0.0), range);
    let key = |i: usize| {
        (
            bin(p.modulus[i], e_lo, e_hi, n),
            bin(p.poisson[i], nu_lo, nu_hi, n),
            p.density.as_ref().map_or(0, |d| bin(d[i], d_lo, d_hi, n)),
        )
    };
    // Sums per occupied key: count, Σ E, Σ ν, Σ ρ.
    let mut sums: BTreeMap<BinKey, (usize, f64, f64, f64)> = BTreeMap::new();
    for i in 0..p.modulus.len() {
        let s = sums.entry(key(i)).or_default();
        s.0 += 1;
        s.1 += p.modulus[i];
        s.2 += p.poisson[i];
        s.3 += p.density.as_ref().map_or(0.0, |d| d[i]);
    }
    let index: BTreeMap<BinKey, u16> = sums
        .keys()
        .enumerate()
        .map(|(i, k)| (*k, i as u16))
        .collect();
    let materials = sums
        .values()
        .enumerate()
        .map(|(i, &(count, e, nu, d))| {
            let c = count as f64;
            MatOut {
                slot: i as u16,
                name: format!("PROP_{}", i + 1),
                original: format!("property set {} ({count} elements)", i + 1),
                e: e / c,
                nu: nu / c,
                density: p.density.as_ref().map(|_| d / c),
            }
        })
        .collect();
    let set_of = (0..p.modulus.len()).map(|i| index[&key(i)]).collect();
    Sets { set_of, materials }
}

/// Points per batch of attribute evaluation.
const CHUNK: usize = 4096;

/// Attribute `index` (a scalar) at every point, in parallel batches; the
/// first failing batch (lowest index) reports, so the message does not
/// depend on the thread count.
fn scalar_at(model: &Model, index: usize, pts: &[DVec3]) -> Result<Vec<f64>, ExportError> {
    let mut out = vec![f64::NAN; pts.len()];
    let failed = out
        .par_chunks_mut(CHUNK)
        .zip(pts.par_chunks(CHUNK))
        .enumerate()
        .filter_map(|(c, (o, p))| {
            let x: Vec<f64> = p.iter().map(|q| q.x).collect();
            let y: Vec<f64> = p.iter().map(|q| q.y).collect();
            let z: Vec<f64> = p.iter().map(|q| q.z).collect();
            let pts = Points {
                x: &x,
                y: &y,
                z: &z,
            };
            model.attribute_batch(index, pts, o).err().map(|e| (c, e))
        })
        .min_by_key(|(c, _)| *c);
    match failed {
        Some((_, e)) => Err(ExportError::Other(e.to_string())),
        None => Ok(out),
    }
}

/// Attribute `name` at every element: at its centroid, or where the
/// centroid has no value (a boundary element whose centre lies just
/// outside), the mean of its corners' values; an element with neither is
/// an error naming it.
fn per_element(
    model: &Model,
    name: &str,
    mesh: &FeaMesh,
    centroids: &[DVec3],
) -> Result<Vec<f64>, ExportError> {
    let index = model
        .require_attribute(name)
        .map_err(|e| ExportError::Other(e.to_string()))?;
    let mut v = scalar_at(model, index, centroids)?;
    for (e, x) in v.iter_mut().enumerate() {
        if x.is_nan() {
            let corners: Vec<DVec3> = mesh
                .element_nodes(e)
                .iter()
                .map(|n| mesh.nodes[*n as usize])
                .collect();
            let at = scalar_at(model, index, &corners)?;
            let set: Vec<f64> = at.into_iter().filter(|a| !a.is_nan()).collect();
            if set.is_empty() {
                return Err(element_error(
                    e,
                    centroids[e],
                    &format!(
                        "no node sets \"{name}\" there; set it on every part that has elements (or on the root, which its children inherit)"
                    ),
                ));
            }
            *x = set.iter().sum::<f64>() / set.len() as f64;
        }
    }
    Ok(v)
}

/// An error about element `e` (0-based; named 1-based, as the deck numbers
/// it) at its centroid `c`.
fn element_error(e: usize, c: DVec3, what: &str) -> ExportError {
    ExportError::Other(format!(
        "element {} at ({:.4}, {:.4}, {:.4}) mm: {what}",
        e + 1,
        c.x,
        c.y,
        c.z
    ))
}

/// The properties of every element of `mesh` from the design's `modulus`,
/// `poissons_ratio` and `density`; `None` when the design has no
/// `modulus`. Without `poissons_ratio` each element takes the Poisson ratio
/// of its drawn material from the material table.
pub fn element_props(model: &Model, mesh: &FeaMesh) -> Result<Option<ElementProps>, ExportError> {
    if model.attribute_index("modulus").is_none() {
        return Ok(None);
    }
    let centroids: Vec<DVec3> = (0..mesh.len())
        .map(|e| {
            let n = mesh.element_nodes(e);
            n.iter().map(|i| mesh.nodes[*i as usize]).sum::<DVec3>() / n.len() as f64
        })
        .collect();
    let modulus = per_element(model, "modulus", mesh, &centroids)?;
    if let Some((e, m)) = modulus.iter().enumerate().find(|(_, m)| **m <= 0.0) {
        return Err(element_error(
            e,
            centroids[e],
            &format!("modulus {m} MPa; the FEA export needs a modulus > 0"),
        ));
    }
    let poisson = if model.attribute_index("poissons_ratio").is_some() {
        per_element(model, "poissons_ratio", mesh, &centroids)?
    } else {
        table_poisson(model, mesh)?
    };
    let density = match model.attribute_index("density") {
        Some(_) => Some(per_element(model, "density", mesh, &centroids)?),
        None => None,
    };
    Ok(Some(ElementProps {
        modulus,
        poisson,
        density,
    }))
}

/// The Poisson ratio of each element's drawn material, from the table.
fn table_poisson(model: &Model, mesh: &FeaMesh) -> Result<Vec<f64>, ExportError> {
    let table = model.table();
    let per_slot: Vec<Option<f64>> = model
        .materials()
        .iter()
        .map(|id| table.get(*id).and_then(|m| m.poisson_ratio))
        .collect();
    mesh.mat
        .iter()
        .map(|s| {
            per_slot[*s as usize].ok_or_else(|| {
                let id = model.materials()[*s as usize];
                ExportError::Other(format!(
                    "the design sets \"modulus\" but not \"poissons_ratio\", and material \"{}\" (id {id}) in material table {} has no Poisson ratio; set node.set_attribute(\"poissons_ratio\", 0.3) (or the material's value) beside the modulus",
                    table.name(id),
                    table.origin()
                ))
            })
        })
        .collect()
}

/// Poisson ratios at 0.5 (incompressible) written as 0.49, as for
/// materials (λ = Eν/((1+ν)(1−2ν)) is infinite at 0.5); the note, if any.
pub fn cap_poisson(sets: &mut Sets) -> Option<String> {
    let n = sets
        .materials
        .iter_mut()
        .filter(|m| m.nu >= 0.5 - 1e-9)
        .map(|m| m.nu = 0.49)
        .count();
    (n > 0).then(|| format!("{n} property sets with Poisson ratio 0.5 (incompressible) written as 0.49; linear elements lock near 0.5"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bins_split_the_range_and_average_their_members() {
        // Modulus 100..=200 in steps of 10, ν fixed: 4 bins of width 25.
        let modulus: Vec<f64> = (0..=10).map(|i| 100.0 + 10.0 * i as f64).collect();
        let p = ElementProps {
            poisson: vec![0.3; modulus.len()],
            modulus,
            density: None,
        };
        let s = bin_elements(&p, 4);
        assert_eq!(s.set_of, vec![0, 0, 0, 1, 1, 2, 2, 2, 3, 3, 3]);
        let e: Vec<f64> = s.materials.iter().map(|m| m.e).collect();
        assert_eq!(e, vec![110.0, 135.0, 160.0, 190.0]);
        assert!(
            s.materials
                .iter()
                .all(|m| m.nu == 0.3 && m.density.is_none())
        );
        // One value everywhere: one set; more bins than values: one set per value.
        let one = ElementProps {
            modulus: vec![5.0; 3],
            poisson: vec![0.4; 3],
            density: Some(vec![1.2; 3]),
        };
        let s1 = bin_elements(&one, 16);
        assert_eq!(s1.materials.len(), 1);
        assert_eq!(s1.materials[0].density, Some(1.2));
        assert_eq!(bin_elements(&p, 1000).materials.len(), 11);
        // A second property splits a modulus bin.
        let mut two = p.clone();
        two.poisson[0] = 0.45;
        assert_eq!(bin_elements(&two, 4).materials.len(), 5);
    }
}
