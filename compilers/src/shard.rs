//! Sharded layer stacks: one export split into N equal layer ranges, run
//! as N tasks of a batch system (Slurm array, Kubernetes Indexed Job, GNU
//! parallel; recipes in `deploy/`), and merged into the folder the
//! single-machine export writes, byte for byte.
//!
//! `volcad export png DESIGN --shard K/N` writes the K-th (counting from 1)
//! of N equal layer ranges ([`Shard::layers`]: layers ⌊(K−1)·nz/N⌋ up to
//! ⌊K·nz/N⌋ − 1) under the whole stack's file names (global layer indices,
//! as `--layers` does). Its manifest is a `--layers` export's for that
//! range, plus `parameters.shard = {"index": K, "count": N}`.
//!
//! `volcad merge OUT SHARD_DIR...` ([`plan_merge`], then [`MergePlan::run`]
//! as a job) checks before any work that every folder is a finished export
//! of one layer-stack kind, tool version, design hash and parameters (seed
//! included) apart from the layer range; that the ranges tile `0..nz`
//! (naming missing and overlapping layers); and that every listed file is
//! there. It then copies the files and writes the manifest the single
//! export writes: files in layer order, counts and voxels summed, `layers`
//! the whole grid, no `shard`, notes rebuilt by the kind. Nothing in a
//! manifest differs by construction: timings ([`Summary::seconds`]) and the
//! thread count are never written.
//!
//! # Adding a layer-stack kind
//!
//! A kind whose output is a set of files per layer, named by global layer
//! index, each depending only on the design, the parameters and its layer
//! (error diffusion restarts from a fixed block below the range, see
//! `Diffuser::warmup_start`), shards as the PNG stack does:
//! 1. take `shard: Option<Shard>` in its parameters and resolve its layers
//!    with [`Shard::layers`] (refusing it together with `--layers`);
//! 2. write `parameters.layers = [start, end]`, `parameters.grid.dims`,
//!    `parameters.voxel_mm` and, for a shard, `parameters.shard =`
//!    [`Shard::to_json`];
//! 3. add a row to `KINDS` below: its manifest `kind` and the function
//!    that rebuilds its notes for the merged range (the PNG stack's is
//!    `png_stack::merged_notes`);
//! 4. let the CLI accept `--shard` for it (`app/src/cli/export.rs`).
//!
//! A kind whose output is one archive of whole-part products is not
//! sharded: a GCVF zip holds the whole part's `Mesh.stl` and `Zbuffer.png`
//! and whole-part voxel counts in `ConfigFile.xml`, which no shard can make
//! and a merge without the design cannot rebuild. Such kinds refuse
//! `--shard` with [`not_shardable`]'s message, which points to the PNG stack.

use std::fmt;
use std::ops::Range;
use std::path::{Component, Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use glam::DVec3;
use rayon::prelude::*;
use serde::Deserialize;
use serde_json::json;

use crate::job::{ExportError, JobContext, Summary};

/// The K-th (1-based `index`) of `count` equal layer ranges.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shard {
    /// K, from 1 to `count`.
    pub index: usize,
    /// N, the number of shards.
    pub count: usize,
}

impl fmt::Display for Shard {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

impl std::str::FromStr for Shard {
    type Err = ExportError;

    /// `K/N`, 1 ≤ K ≤ N.
    fn from_str(s: &str) -> Result<Self, ExportError> {
        let bad = |why: String| ExportError::param("--shard", format!("{s}: {why}"));
        let (k, n) = s.split_once('/').ok_or_else(|| {
            bad("expected K/N, the K-th of N equal layer ranges counting from 1 (e.g. 2/4)".into())
        })?;
        let number = |t: &str, what: &str| {
            t.trim().parse::<usize>().map_err(|_| {
                bad(format!(
                    "{what} {t:?} is not a whole number; expected K/N with 1 <= K <= N (e.g. 2/4)"
                ))
            })
        };
        let (index, count) = (number(k, "K")?, number(n, "N")?);
        if count == 0 {
            return Err(bad("N, the number of shards, must be at least 1".into()));
        }
        if index == 0 || index > count {
            return Err(bad(format!(
                "K counts from 1 to N: the first shard is 1/{count}, the last {count}/{count}"
            )));
        }
        Ok(Shard { index, count })
    }
}

impl Shard {
    /// This shard's layers of a grid of `nz`: ⌊(K−1)·nz/N⌋..⌊K·nz/N⌋, so the
    /// N ranges tile `0..nz` and differ in length by one at most. Refused
    /// when N > nz (a shard would hold no layer).
    pub fn layers(self, nz: usize) -> Result<Range<usize>, ExportError> {
        if self.count > nz {
            return Err(ExportError::param(
                "--shard",
                format!(
                    "{self}: the grid has {nz} layer(s), fewer than {} shards; use at most {nz} shards",
                    self.count
                ),
            ));
        }
        let at = |i: usize| (i as u128 * nz as u128 / self.count as u128) as usize;
        Ok(at(self.index - 1)..at(self.index))
    }

    /// `parameters.shard` in a shard's manifest.
    pub fn to_json(self) -> serde_json::Value {
        json!({ "index": self.index, "count": self.count })
    }
}

/// Why `volcad export KIND --shard` is refused for a kind that is not a
/// layer stack of per-layer files.
pub fn not_shardable(kind: &str) -> String {
    match kind {
        "gcvf" => "--shard does not apply to gcvf: a GCVF archive holds the whole part's mesh \
                   (Mesh.stl), z-buffer (Zbuffer.png) and voxel counts (ConfigFile.xml), which \
                   no shard can make, and a zip is not joined from parts; shard the PNG stack \
                   instead (`volcad export png --shard K/N`, then `volcad merge`)"
            .to_owned(),
        _ => format!(
            "--shard does not apply to `volcad export {kind}`, which is made from the whole \
             part at once; only layer stacks (png, vat) split into layer ranges"
        ),
    }
}

/// Rebuilds a stack's notes for a range and counts from one shard's
/// (`None` when the shard's notes are not the ones this version writes).
type MergedNotes = fn(&Part, &Range<usize>, &[(String, u64)]) -> Option<Vec<String>>;

/// A layer-stack kind that merges: its manifest `kind` and its notes.
struct StackKind {
    kind: &'static str,
    notes: MergedNotes,
}

const KINDS: &[StackKind] = &[
    StackKind {
        kind: "png",
        notes: crate::png_stack::merged_notes,
    },
    StackKind {
        kind: "vat",
        notes: crate::vat::merged_notes,
    },
];

/// One shard folder's manifest, as read.
pub struct Part {
    /// The folder.
    pub dir: PathBuf,
    /// The volcad version that wrote it.
    pub version: String,
    /// The design's hash.
    pub design_hash: String,
    /// The design's name, when the manifest records it.
    pub design: Option<String>,
    /// The manifest's summary.
    pub summary: Summary,
    /// Its layers.
    pub layers: Range<usize>,
    /// The whole grid's voxels per axis.
    pub dims: [usize; 3],
    /// Voxel size (mm).
    pub voxel: DVec3,
    /// Which shard it is (`None` for a `--layers` export).
    pub shard: Option<Shard>,
}

/// `manifest.json` as the job runner writes it.
#[derive(Deserialize)]
struct ManifestIn {
    tool: String,
    version: String,
    design_hash: String,
    #[serde(default)]
    design: Option<String>,
    #[serde(flatten)]
    summary: Summary,
}

/// The parameters every layer stack writes.
#[derive(Deserialize)]
struct StackParams {
    layers: [usize; 2],
    grid: GridParams,
    voxel_mm: [f64; 3],
    shard: Option<ShardParams>,
}

#[derive(Deserialize)]
struct GridParams {
    dims: [usize; 3],
}

#[derive(Deserialize)]
struct ShardParams {
    index: usize,
    count: usize,
}

/// `layer 5 is` or `layers 5..=9 are`, as `--layers` spells ranges.
fn span_is(r: &Range<usize>) -> String {
    if r.len() == 1 {
        format!("layer {} is", r.start)
    } else {
        format!("layers {}..={} are", r.start, r.end - 1)
    }
}

fn kind_of(kind: &str) -> Option<&'static StackKind> {
    KINDS.iter().find(|k| k.kind == kind)
}

/// Read and check one shard folder's manifest.
fn read_part(dir: &Path) -> Result<Part, ExportError> {
    let shown = dir.display();
    if !dir.is_dir() {
        return Err(ExportError::Other(format!(
            "{shown}: not a folder; give the folders that `volcad export png --shard K/N --out DIR` wrote"
        )));
    }
    let path = dir.join("manifest.json");
    let text = std::fs::read_to_string(&path).map_err(|_| {
        ExportError::Other(format!(
            "{shown}: holds no readable manifest.json, so it is not a finished export (a shard \
             that failed or was interrupted leaves no folder: run that shard again)"
        ))
    })?;
    let m: ManifestIn = serde_json::from_str(&text).map_err(|e| {
        ExportError::Other(format!("{}: not a volcad manifest: {e}", path.display()))
    })?;
    if m.tool != "volcad" {
        return Err(ExportError::Other(format!(
            "{}: written by {:?}, not volcad",
            path.display(),
            m.tool
        )));
    }
    let names: Vec<&str> = KINDS.iter().map(|k| k.kind).collect();
    if kind_of(&m.summary.kind).is_none() {
        return Err(ExportError::Other(format!(
            "{shown}: a {} export; only layer stacks ({}) are sharded and merged",
            m.summary.kind,
            names.join(", ")
        )));
    }
    let p: StackParams = serde_json::from_value(m.summary.parameters.clone()).map_err(|e| {
        ExportError::Other(format!(
            "{}: parameters lack a layer stack's layers, grid or voxel size: {e}",
            path.display()
        ))
    })?;
    let [a, b] = p.layers;
    let nz = p.grid.dims[2];
    let shard = p.shard.map(|s| Shard {
        index: s.index,
        count: s.count,
    });
    let shard_ok = shard.is_none_or(|s| s.layers(nz).ok() == Some(a..b));
    if !(a < b && b <= nz && shard_ok) {
        return Err(ExportError::Other(format!(
            "{}: layers {a}..{b} are not a range of the grid's {nz} layers{}",
            path.display(),
            shard.map_or(String::new(), |s| format!(" that shard {s} holds"))
        )));
    }
    Ok(Part {
        dir: dir.to_owned(),
        version: m.version,
        design_hash: m.design_hash,
        design: m.design,
        summary: m.summary,
        layers: a..b,
        dims: p.grid.dims,
        voxel: DVec3::from_array(p.voxel_mm),
        shard,
    })
}

/// The parameters without what differs between the shards of one export.
fn shared_params(p: &Part) -> serde_json::Map<String, serde_json::Value> {
    let mut m = p
        .summary
        .parameters
        .as_object()
        .cloned()
        .unwrap_or_default();
    m.remove("layers");
    m.remove("shard");
    m
}

/// Refuse `b` unless it comes from the same export as `a` (version, kind,
/// design, parameters, materials), naming what differs.
fn check_same_export(a: &Part, b: &Part) -> Result<(), ExportError> {
    let (da, db) = (a.dir.display(), b.dir.display());
    let differ = |what: String| {
        Err(ExportError::Other(format!(
            "{db} and {da} are not shards of one export: {what}; export every shard with the \
             same design, --param values and options"
        )))
    };
    if a.version != b.version {
        return differ(format!(
            "volcad {} wrote {db}, {} wrote {da}",
            b.version, a.version
        ));
    }
    if a.summary.kind != b.summary.kind {
        return differ(format!(
            "{db} is a {} export, {da} a {}",
            b.summary.kind, a.summary.kind
        ));
    }
    if a.design_hash != b.design_hash {
        return differ(format!(
            "design hash {} differs from {} (another design or other --param values)",
            b.design_hash, a.design_hash
        ));
    }
    if a.design != b.design {
        let name = |d: &Option<String>| d.clone().unwrap_or_else(|| "no name".into());
        return differ(format!(
            "the design is {} in {db} and {} in {da}",
            name(&b.design),
            name(&a.design)
        ));
    }
    let (pa, pb) = (shared_params(a), shared_params(b));
    let mut keys: Vec<&String> = pa.keys().chain(pb.keys()).collect();
    keys.sort();
    keys.dedup();
    for k in keys {
        let (va, vb) = (pa.get(k), pb.get(k));
        if va != vb {
            let show = |v: Option<&serde_json::Value>| v.map_or("absent".into(), |v| v.to_string());
            return differ(format!(
                "{k} is {} in {db} but {} in {da}",
                show(vb),
                show(va)
            ));
        }
    }
    let names =
        |p: &Part| -> Vec<String> { p.summary.counts.iter().map(|c| c.0.clone()).collect() };
    if names(a) != names(b) || a.summary.unit != b.summary.unit {
        return differ(format!(
            "their materials differ ({} against {})",
            names(b).join(", "),
            names(a).join(", ")
        ));
    }
    Ok(())
}

/// Refuse shards whose layers leave gaps in `0..nz` or overlap, naming the
/// layers (and, for shards of N, the missing shards). `parts` are sorted
/// by their first layer.
fn check_tiling(parts: &[Part]) -> Result<(), ExportError> {
    let nz = parts[0].dims[2];
    let counts: Vec<Shard> = parts.iter().filter_map(|p| p.shard).collect();
    if let Some(w) = counts.windows(2).find(|w| w[0].count != w[1].count) {
        return Err(ExportError::Other(format!(
            "shard {} and shard {} come from splits into {} and {} shards; merge the shards of one split",
            w[0], w[1], w[0].count, w[1].count
        )));
    }
    let n = counts.first().map(|s| s.count);
    let mut problems = Vec::new();
    let missing = |gap: Range<usize>, problems: &mut Vec<String>| {
        let which: Vec<String> = n
            .map(|n| {
                (1..=n)
                    .map(|index| Shard { index, count: n })
                    .filter(|s| {
                        s.layers(nz)
                            .is_ok_and(|r| r.start < gap.end && gap.start < r.end)
                    })
                    .map(|s| format!("shard {s}"))
                    .collect()
            })
            .unwrap_or_default();
        let hint = if which.is_empty() {
            String::new()
        } else {
            format!(" ({}: not given, or not finished)", which.join(", "))
        };
        problems.push(format!("{} missing{hint}", span_is(&gap)));
    };
    let mut end = 0;
    let mut owner: Option<&Part> = None;
    for p in parts {
        if p.layers.start > end {
            missing(end..p.layers.start, &mut problems);
        } else if p.layers.start < end
            && let Some(o) = owner
        {
            problems.push(format!(
                "{} in both {} and {}",
                span_is(&(p.layers.start..end.min(p.layers.end))),
                o.dir.display(),
                p.dir.display()
            ));
        }
        if p.layers.end > end {
            end = p.layers.end;
            owner = Some(p);
        }
    }
    if end < nz {
        missing(end..nz, &mut problems);
    }
    if problems.is_empty() {
        return Ok(());
    }
    Err(ExportError::Other(format!(
        "the shards do not tile the grid's {nz} layers (0..={}) once each: {}",
        nz - 1,
        problems.join("; ")
    )))
}

/// `rel` as a path inside a shard folder: plain names only (a manifest
/// naming `../x` or `/x` is refused, never followed).
fn inside(dir: &Path, rel: &str) -> Option<PathBuf> {
    let p = Path::new(rel);
    p.components()
        .all(|c| matches!(c, Component::Normal(_)))
        .then(|| dir.join(p))
}

/// What a merge will do, checked before any work.
pub struct MergePlan {
    /// The shards' design hash (the merged manifest's).
    pub design_hash: String,
    /// The shards' design name (the merged manifest's).
    pub design: Option<String>,
    /// The merged manifest's summary.
    pub summary: Summary,
    /// Number of shard folders.
    pub shards: usize,
    /// Bytes to copy.
    pub bytes: u64,
    copies: Vec<(PathBuf, String)>,
    dirs: Vec<PathBuf>,
}

/// Read and check the shard folders `dirs` and plan their merge; every
/// refusal comes here, before any file is written.
pub fn plan_merge(dirs: &[PathBuf]) -> Result<MergePlan, ExportError> {
    if dirs.is_empty() {
        return Err(ExportError::Other("give at least one shard folder".into()));
    }
    let mut parts = dirs
        .iter()
        .map(|d| read_part(d))
        .collect::<Result<Vec<_>, _>>()?;
    let this = env!("CARGO_PKG_VERSION");
    if parts[0].version != this {
        return Err(ExportError::Other(format!(
            "{}: written by volcad {}; this is volcad {this}: merge with the version that wrote the shards",
            parts[0].dir.display(),
            parts[0].version
        )));
    }
    for p in &parts[1..] {
        check_same_export(&parts[0], p)?;
    }
    parts.sort_by_key(|p| (p.layers.start, p.layers.end));
    check_tiling(&parts)?;
    let mut copies = Vec::new();
    let mut bytes = 0u64;
    for p in &parts {
        let mut absent = Vec::new();
        for f in &p.summary.files {
            match inside(&p.dir, f).and_then(|src| Some((std::fs::metadata(&src).ok()?, src))) {
                Some((m, src)) if m.is_file() => {
                    bytes += m.len();
                    copies.push((src, f.clone()));
                }
                _ => absent.push(f.as_str()),
            }
        }
        if !absent.is_empty() {
            return Err(ExportError::Other(format!(
                "{}: {} file(s) its manifest lists are missing or not plain files inside it ({}{}); export that shard again",
                p.dir.display(),
                absent.len(),
                absent[..absent.len().min(3)].join(", "),
                if absent.len() > 3 { ", …" } else { "" }
            )));
        }
    }
    let summary = merged_summary(&parts)?;
    Ok(MergePlan {
        design_hash: parts[0].design_hash.clone(),
        design: parts[0].design.clone(),
        summary,
        shards: parts.len(),
        bytes,
        copies,
        dirs: parts.into_iter().map(|p| p.dir).collect(),
    })
}

/// The whole stack's summary from its shards (sorted, tiling the grid).
fn merged_summary(parts: &[Part]) -> Result<Summary, ExportError> {
    let first = &parts[0];
    let nz = first.dims[2];
    let mut counts = first.summary.counts.clone();
    for p in &parts[1..] {
        for (t, (_, c)) in counts.iter_mut().zip(&p.summary.counts) {
            t.1 = t.1.saturating_add(*c);
        }
    }
    // Rebuilt key by key, so the order is the shard's whatever map serde_json uses.
    let mut parameters = serde_json::Map::new();
    for (k, v) in first.summary.parameters.as_object().into_iter().flatten() {
        let v = match k.as_str() {
            "shard" => continue,
            "layers" => json!([0, nz]),
            _ => v.clone(),
        };
        parameters.insert(k.clone(), v);
    }
    let kind = kind_of(&first.summary.kind).map(|k| k.notes);
    let notes = kind.and_then(|f| f(first, &(0..nz), &counts)).ok_or_else(|| {
        ExportError::Other(format!(
            "{}/manifest.json: its notes are not the ones volcad {} writes (was it edited?); export that shard again",
            first.dir.display(),
            first.version
        ))
    })?;
    Ok(Summary {
        kind: first.summary.kind.clone(),
        files: parts
            .iter()
            .flat_map(|p| p.summary.files.iter().cloned())
            .collect(),
        counts,
        units: parts.iter().map(|p| p.summary.units).sum(),
        unit: first.summary.unit.clone(),
        parameters: serde_json::Value::Object(parameters),
        notes,
        seconds: 0.0,
    })
}

/// `p` made absolute with its links resolved, as far as it exists.
fn resolved(p: &Path) -> PathBuf {
    let abs = std::path::absolute(p).unwrap_or_else(|_| p.to_owned());
    let mut rest = Vec::new();
    let mut base = abs.as_path();
    loop {
        if let Ok(c) = base.canonicalize() {
            return rest.iter().rev().fold(c, |acc: PathBuf, n| acc.join(n));
        }
        match (base.parent(), base.file_name()) {
            (Some(parent), Some(name)) => {
                rest.push(name.to_owned());
                base = parent;
            }
            _ => return abs,
        }
    }
}

impl MergePlan {
    /// Refuse an output folder that is, holds or lies in a shard folder:
    /// replacing it would destroy the shards being read.
    pub fn check_destination(&self, out: &Path) -> Result<(), ExportError> {
        let o = resolved(out);
        for d in &self.dirs {
            let r = resolved(d);
            if o.starts_with(&r) || r.starts_with(&o) {
                return Err(ExportError::param(
                    "OUT",
                    format!(
                        "{} would replace shard folder {} (or a folder holding it); give a new folder",
                        out.display(),
                        d.display()
                    ),
                ));
            }
        }
        Ok(())
    }

    /// Copy the shards' files into `ctx.staging()`; the job runner writes
    /// the manifest from the returned summary.
    pub fn run(self, ctx: &JobContext) -> Result<Summary, ExportError> {
        let mut folders: Vec<&Path> = self
            .copies
            .iter()
            .filter_map(|(_, rel)| Path::new(rel).parent())
            .filter(|p| !p.as_os_str().is_empty())
            .collect();
        folders.sort();
        folders.dedup();
        for f in folders {
            let dir = ctx.staging().join(f);
            std::fs::create_dir_all(&dir).map_err(|e| ExportError::io(&dir, e))?;
        }
        let done = AtomicU64::new(0);
        let total = self.copies.len() as u64;
        self.copies.par_iter().try_for_each(|(src, rel)| {
            ctx.check_cancel()?;
            let dest = ctx.staging().join(rel);
            std::fs::copy(src, &dest).map_err(|e| ExportError::io(&dest, e))?;
            let n = done.fetch_add(1, Ordering::Relaxed) + 1;
            ctx.progress("merging", n, total, "files", n as f64 / total.max(1) as f64);
            Ok(())
        })?;
        Ok(self.summary)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn shard(s: &str) -> Result<Shard, String> {
        s.parse::<Shard>().map_err(|e| e.to_string())
    }

    #[test]
    fn shards_parse_and_tile_the_grid_in_near_equal_ranges() {
        assert_eq!(shard("2/4"), Ok(Shard { index: 2, count: 4 }));
        assert_eq!(shard(" 1 / 1 "), Ok(Shard { index: 1, count: 1 }));
        for nz in [1, 7, 20, 186, 100_003] {
            for n in [1, 2, 3, 4, 7].into_iter().filter(|n| *n <= nz) {
                let mut next = 0;
                for index in 1..=n {
                    let r = Shard { index, count: n }.layers(nz).unwrap();
                    assert_eq!(r.start, next, "{index}/{n} of {nz}");
                    assert!(r.len() == nz / n || r.len() == nz / n + 1);
                    next = r.end;
                }
                assert_eq!(next, nz);
            }
        }
        let e = Shard { index: 1, count: 8 }
            .layers(5)
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "--shard: 1/8: the grid has 5 layer(s), fewer than 8 shards; use at most 5 shards"
        );
        for (s, msg) in [
            (
                "0/3",
                "K counts from 1 to N: the first shard is 1/3, the last 3/3",
            ),
            ("4/3", "K counts from 1 to N"),
            ("3", "expected K/N"),
            ("1/x", "N \"x\" is not a whole number"),
            ("-1/3", "K \"-1\" is not a whole number"),
            ("1/0", "must be at least 1"),
        ] {
            let e = shard(s).unwrap_err();
            assert!(e.starts_with(&format!("--shard: {s}: ")), "{e}");
            assert!(e.contains(msg), "{s}: {e}");
        }
    }

    #[test]
    fn only_plain_relative_names_are_copied() {
        let d = Path::new("/x");
        assert_eq!(
            inside(d, "a/slice_0.png"),
            Some(PathBuf::from("/x/a/slice_0.png"))
        );
        assert_eq!(inside(d, "../y"), None);
        assert_eq!(inside(d, "/etc/passwd"), None);
        assert_eq!(inside(d, "a/./b"), Some(PathBuf::from("/x/a/b")));
    }

    #[test]
    fn gcvf_is_refused_with_its_reason() {
        assert!(not_shardable("gcvf").contains("Mesh.stl"));
        assert!(not_shardable("fea").contains("`volcad export fea`"));
    }
}
