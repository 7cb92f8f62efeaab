//! Built distance grids kept on disk, so a second export of a design, or
//! the studio after a restart, reads a mesh's grids instead of building them.
//!
//! The candidate grid is most of a large mesh's load time (every surface
//! cell's exact distance and list). It depends on the triangles and the
//! build constants alone, so the file is named by a hash of the vertex
//! bits, the triangles, [`FORMAT`] and `candidates::SHAPE`. Nothing read
//! is trusted: the file holds the mesh it was built from, compared exactly
//! (a hash collision is caught); a checksum over the whole file catches a
//! torn or corrupted one; and every length, index and list bound is checked
//! against the mesh before use. Any failure rebuilds and rewrites.
//!
//! Writes go to a temporary name in the same folder and are renamed into
//! place (atomic on POSIX), so a reader never sees half a file; the folder
//! is trimmed to [`MAX_BYTES`], least recently used first (a hit touches
//! its file). A grid read back is the built one bit for bit, so exports do
//! not depend on whether the cache was warm.

use std::fs;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::SystemTime;

use glam::DVec3;
use rayon::prelude::*;

use super::TriangleMesh;
use super::candidates::{self, CandidateGrid};
use super::certificate::Skips;
use super::coarse::CoarseGrid;
use crate::spatial::cells::CellLattice;

const MAGIC: &[u8; 8] = b"VCADGRID";
/// Bumped whenever the file layout or what the grids mean changes.
const FORMAT: u32 = 2;
/// Meshes with fewer triangles build faster than a file is found and read.
const MIN_TRIANGLES: usize = 1000;
/// Bound on the folder's size (the bunny's grids are about 23 MB: `ls -l` the
/// folder after `volcad export mesh assets/bench/bunny_mesh.rhai`).
const MAX_BYTES: u64 = 512 << 20;
/// Largest grid dimension accepted from a file (the builders stay far below).
const MAX_DIM: u64 = 1 << 16;

/// The cache folder: `$VOLCAD_CACHE_DIR` (empty or `off` disables it),
/// else `$XDG_CACHE_HOME/volcad`, else `~/.cache/volcad`, then
/// `mesh-grids`. Unit tests never touch the user's folder.
pub(super) fn dir() -> Option<PathBuf> {
    if cfg!(test) {
        return None;
    }
    let set = |k: &str| std::env::var_os(k).filter(|v| !v.is_empty());
    let base = match std::env::var_os("VOLCAD_CACHE_DIR") {
        Some(v) if v.is_empty() || v == "off" => return None,
        Some(v) => PathBuf::from(v),
        None => set("XDG_CACHE_HOME")
            .map(PathBuf::from)
            .or_else(|| set("HOME").map(|h| PathBuf::from(h).join(".cache")))?
            .join("volcad"),
    };
    Some(base.join("mesh-grids"))
}

/// Sets `mesh`'s coarse and candidate grids: read from `dir` when a valid
/// file is there, else built (and written there when `dir` is given).
pub(super) fn attach(mesh: &mut TriangleMesh, dir: Option<&Path>) {
    let slot = dir
        .filter(|_| mesh.triangles.len() >= MIN_TRIANGLES)
        .map(|d| d.join(format!("{:016x}.grid", key(mesh))));
    if let Some(path) = &slot
        && let Some((coarse, cands)) = read(path, mesh)
    {
        mesh.coarse = coarse;
        mesh.candidates = cands;
        // Recently used: the trim keeps it (a failure only ages it).
        let _ = fs::File::options()
            .append(true)
            .open(path)
            .and_then(|f| f.set_modified(SystemTime::now()));
        return;
    }
    mesh.coarse = CoarseGrid::new(&mesh.bbox, mesh.triangles.len(), |p| {
        mesh.signed_distance(p)
    });
    mesh.candidates = CandidateGrid::new(mesh);
    if let (Some(path), Some(d)) = (slot, dir) {
        // The cache only saves time: a full disk or a read-only home
        // leaves the export as it was.
        let _ = write(d, &path, mesh).map(|()| trim(d, MAX_BYTES));
    }
}

/// Hash of the mesh and of everything that shapes its grids.
fn key(mesh: &TriangleMesh) -> u64 {
    let mut h = Hash::new();
    h.word(u64::from(FORMAT));
    candidates::SHAPE.iter().for_each(|c| h.word(c.to_bits()));
    h.word(mesh.vertices.len() as u64);
    mesh.vertices
        .iter()
        .for_each(|v| v.to_array().iter().for_each(|c| h.word(c.to_bits())));
    mesh.triangles.iter().for_each(|t| {
        h.word(u64::from(t[0]) | (u64::from(t[1]) << 32));
        h.word(u64::from(t[2]));
    });
    h.finish()
}

/// A 64-bit multiply-xorshift hash over words: fast on 16 MB, and only a
/// file name and a corruption check (contents are compared, not trusted).
struct Hash(u64);

impl Hash {
    fn new() -> Hash {
        Hash(0xcbf2_9ce4_8422_2325)
    }
    fn word(&mut self, w: u64) {
        self.0 = (self.0 ^ w).wrapping_mul(0x9e37_79b9_7f4a_7c15);
        self.0 ^= self.0 >> 29;
    }
    /// Hashes `b` as four interleaved lanes of words (each lane a chain
    /// of its own, so a file is hashed at several words a cycle instead of
    /// one word per multiply's latency), folded in at the end.
    fn bytes(&mut self, b: &[u8]) {
        let mut lanes = [Hash::new(), Hash(1), Hash(2), Hash(3)];
        let mut chunks = b.chunks_exact(32);
        for c in &mut chunks {
            for (lane, w) in lanes.iter_mut().zip(c.chunks_exact(8)) {
                lane.word(u64::from_le_bytes(w.try_into().unwrap_or_default()));
            }
        }
        let mut words = chunks.remainder().chunks_exact(8);
        for w in &mut words {
            lanes[0].word(u64::from_le_bytes(w.try_into().unwrap_or_default()));
        }
        lanes.iter().for_each(|l| self.word(l.finish()));
        let mut last = [0u8; 8];
        last[..words.remainder().len()].copy_from_slice(words.remainder());
        self.word(u64::from_le_bytes(last) ^ (b.len() as u64) << 56);
    }
    fn finish(&self) -> u64 {
        let x = self.0 ^ self.0 >> 31;
        x.wrapping_mul(0xbf58_476d_1ce4_e5b9) ^ x >> 27
    }
}

/// The file's bytes for `mesh`'s grids.
fn encode(mesh: &TriangleMesh) -> Vec<u8> {
    let mut w = Vec::with_capacity(
        64 + mesh
            .candidates
            .as_ref()
            .map_or(0, |g| 4 * (g.records.len() + g.items.len())),
    );
    w.extend_from_slice(MAGIC);
    put_u32(&mut w, FORMAT);
    put_u64(&mut w, key(mesh));
    put_u64(&mut w, mesh.vertices.len() as u64);
    mesh.vertices.iter().for_each(|v| put_vec(&mut w, *v));
    put_u64(&mut w, mesh.triangles.len() as u64);
    mesh.triangles
        .iter()
        .for_each(|t| t.iter().for_each(|&i| put_u32(&mut w, i)));
    match &mesh.coarse {
        None => w.push(0),
        Some(c) => {
            w.push(1);
            put_vec(&mut w, c.origin);
            put_f64(&mut w, c.cell);
            c.dims.iter().for_each(|&n| put_u64(&mut w, n as u64));
            put_u64(&mut w, c.d.len() as u64);
            c.d.iter().for_each(|&x| put_f64(&mut w, x));
        }
    }
    match &mesh.candidates {
        None => w.push(0),
        Some(g) => {
            w.push(1);
            put_vec(&mut w, g.cells.origin());
            put_vec(&mut w, g.cells.cell());
            g.cells
                .dims()
                .iter()
                .for_each(|&n| put_u64(&mut w, n as u64));
            for list in [&g.records, &g.items] {
                put_u64(&mut w, list.len() as u64);
                w.reserve(4 * list.len());
                list.iter().for_each(|&x| put_u32(&mut w, x));
            }
            put_u32(&mut w, g.slot_bits);
            put_u32(&mut w, g.q_shift);
            put_f64(&mut w, g.inv_unit);
            put_f64(&mut w, g.tiny);
        }
    }
    let mut h = Hash::new();
    h.bytes(&w);
    put_u64(&mut w, h.finish());
    w
}

fn put_u32(w: &mut Vec<u8>, x: u32) {
    w.extend_from_slice(&x.to_le_bytes());
}
fn put_u64(w: &mut Vec<u8>, x: u64) {
    w.extend_from_slice(&x.to_le_bytes());
}
fn put_f64(w: &mut Vec<u8>, x: f64) {
    put_u64(w, x.to_bits());
}
fn put_vec(w: &mut Vec<u8>, v: DVec3) {
    v.to_array().iter().for_each(|&x| put_f64(w, x));
}

/// Writes `mesh`'s grids to `path` through a temporary file in `dir`.
fn write(dir: &Path, path: &Path, mesh: &TriangleMesh) -> std::io::Result<()> {
    fs::create_dir_all(dir)?;
    let nanos = SystemTime::now()
        .duration_since(SystemTime::UNIX_EPOCH)
        .map_or(0, |d| d.subsec_nanos());
    let tmp = dir.join(format!(".{}-{nanos}.tmp", std::process::id()));
    let done = fs::File::create(&tmp)
        .and_then(|mut f| f.write_all(&encode(mesh)))
        .and_then(|()| fs::rename(&tmp, path));
    if done.is_err() {
        let _ = fs::remove_file(&tmp);
    }
    done
}

/// Removes the least recently used files until `dir` holds at most
/// `max_bytes` (temporary files of crashed writers older than an hour too).
pub(super) fn trim(dir: &Path, max_bytes: u64) {
    let Ok(entries) = fs::read_dir(dir) else {
        return;
    };
    let now = SystemTime::now();
    let mut files: Vec<(SystemTime, u64, PathBuf)> = Vec::new();
    for e in entries.flatten() {
        let (path, Ok(meta)) = (e.path(), e.metadata()) else {
            continue;
        };
        let when = meta.modified().unwrap_or(SystemTime::UNIX_EPOCH);
        match path.extension().and_then(|x| x.to_str()) {
            Some("grid") => files.push((when, meta.len(), path)),
            Some("tmp") if now.duration_since(when).is_ok_and(|a| a.as_secs() > 3600) => {
                let _ = fs::remove_file(&path);
            }
            _ => {}
        }
    }
    let mut total: u64 = files.iter().map(|f| f.1).sum();
    files.sort();
    for (_, len, path) in files {
        if total <= max_bytes {
            break;
        }
        if fs::remove_file(&path).is_ok() {
            total -= len;
        }
    }
}

/// The grids in `path` when it is a valid file for `mesh`.
fn read(path: &Path, mesh: &TriangleMesh) -> Option<(Option<CoarseGrid>, Option<CandidateGrid>)> {
    let bytes = fs::read(path).ok()?;
    let (body, sum) = bytes.split_at_checked(bytes.len().checked_sub(8)?)?;
    let sum = u64::from_le_bytes(sum.try_into().ok()?);
    // The checksum beside the decoding, which trusts nothing either: what
    // it built is dropped unless the checksum holds.
    let (intact, grids) = rayon::join(
        || {
            let mut h = Hash::new();
            h.bytes(body);
            h.finish() == sum
        },
        || decode(body, mesh),
    );
    grids.filter(|_| intact)
}

/// Parses and checks a file's body (its checksum is checked beside this).
fn decode(body: &[u8], mesh: &TriangleMesh) -> Option<(Option<CoarseGrid>, Option<CandidateGrid>)> {
    let mut r = Reader { b: body, at: 0 };
    if r.take(8)? != MAGIC || r.u32()? != FORMAT || r.u64()? != key(mesh) {
        return None;
    }
    // The mesh it was built from, exactly.
    if r.u64()? != mesh.vertices.len() as u64 || mesh.vertices.iter().any(|v| r.vec() != Some(*v)) {
        return None;
    }
    if r.u64()? != mesh.triangles.len() as u64
        || mesh
            .triangles
            .iter()
            .any(|t| t.iter().any(|&i| r.u32() != Some(i)))
    {
        return None;
    }
    let coarse = match r.u8()? {
        0 => None,
        1 => Some(coarse(&mut r)?),
        _ => return None,
    };
    let cands = match r.u8()? {
        0 => None,
        1 => Some(candidate_grid(&mut r, mesh)?),
        _ => return None,
    };
    (r.at == body.len()).then_some((coarse, cands))
}

fn coarse(r: &mut Reader) -> Option<CoarseGrid> {
    let origin = r.vec()?;
    let cell = r.f64()?;
    let dims = r.dims()?;
    let d = r.f64s()?;
    let ok = origin.is_finite() && cell.is_finite() && cell > 0.0;
    (ok && d.len() == dims.iter().product::<usize>()).then(|| CoarseGrid {
        origin,
        cell,
        inv_cell: 1.0 / cell,
        dims,
        d,
    })
}

fn candidate_grid(r: &mut Reader, mesh: &TriangleMesh) -> Option<CandidateGrid> {
    let (min, cell, dims) = (r.vec()?, r.vec()?, r.dims()?);
    let (records, items) = (r.u32s()?, r.u32s()?);
    let (slot_bits, q_shift) = (r.u32()?, r.u32()?);
    let (inv_unit, tiny) = (r.f64()?, r.f64()?);
    let positive = |x: f64| x.is_finite() && x > 0.0;
    let lattice_ok = min.is_finite() && cell.cmpgt(DVec3::ZERO).all() && cell.is_finite();
    if !lattice_ok || !positive(inv_unit) || !positive(tiny) {
        return None;
    }
    // The layout this mesh's build gives (see `CandidateGrid::new`).
    let want_slot_bits = (usize::BITS - (mesh.tris.len().max(2) - 1).leading_zeros()).min(31);
    let certified = candidates::certified(slot_bits);
    let want_q = slot_bits
        + if certified {
            super::certificate::BITS
        } else {
            0
        };
    if slot_bits != want_slot_bits || q_shift != want_q {
        return None;
    }
    let cells = CellLattice::new(min, cell, dims);
    if records.len() != cells.slots() + 1 {
        return None;
    }
    // Lists ascend and end at the items' end; sides are 0, 1 or 2; slots
    // name triangles of this mesh.
    const START_MASK: u32 = (1 << 30) - 1;
    let ascending = records
        .par_windows(2)
        .all(|w| w[0] & START_MASK <= w[1] & START_MASK && w[0] >> 30 <= 2);
    let end = records.last().map(|&x| x & START_MASK) as Option<u32>;
    let slot_mask = (1u32 << slot_bits) - 1;
    let slots_ok = items
        .par_iter()
        .all(|&i| ((i & slot_mask) as usize) < mesh.tris.len());
    if !(ascending && end == Some(items.len() as u32) && slots_ok) {
        return None;
    }
    Some(CandidateGrid {
        cells,
        records,
        items,
        slot_bits,
        q_shift,
        skips: Skips::new(slot_bits, certified),
        inv_unit,
        tiny,
    })
}

/// Bounds-checked little-endian reads; `None` past the end.
struct Reader<'a> {
    b: &'a [u8],
    at: usize,
}

impl Reader<'_> {
    fn take(&mut self, n: usize) -> Option<&[u8]> {
        let s = self.b.get(self.at..self.at.checked_add(n)?)?;
        self.at += n;
        Some(s)
    }
    fn u8(&mut self) -> Option<u8> {
        Some(self.take(1)?[0])
    }
    fn u32(&mut self) -> Option<u32> {
        Some(u32::from_le_bytes(self.take(4)?.try_into().ok()?))
    }
    fn u64(&mut self) -> Option<u64> {
        Some(u64::from_le_bytes(self.take(8)?.try_into().ok()?))
    }
    fn f64(&mut self) -> Option<f64> {
        Some(f64::from_bits(self.u64()?))
    }
    fn vec(&mut self) -> Option<DVec3> {
        Some(DVec3::new(self.f64()?, self.f64()?, self.f64()?))
    }
    fn dims(&mut self) -> Option<[usize; 3]> {
        let mut d = [0; 3];
        for x in &mut d {
            let n = self.u64()?;
            if !(1..=MAX_DIM).contains(&n) {
                return None;
            }
            *x = n as usize;
        }
        Some(d)
    }
    /// A length, then that many elements of `size` bytes (the length is
    /// checked against the bytes left before anything is allocated).
    fn array(&mut self, size: usize) -> Option<&[u8]> {
        let n = usize::try_from(self.u64()?).ok()?;
        self.take(n.checked_mul(size)?)
    }
    fn u32s(&mut self) -> Option<Vec<u32>> {
        let b = self.array(4)?;
        Some(
            b.par_chunks_exact(4)
                .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
                .collect(),
        )
    }
    fn f64s(&mut self) -> Option<Vec<f64>> {
        let b = self.array(8)?;
        Some(
            b.chunks_exact(8)
                .map(|c| f64::from_bits(u64::from_le_bytes(c.try_into().unwrap_or_default())))
                .collect(),
        )
    }
}

#[cfg(test)]
#[path = "grid_cache_tests.rs"]
mod tests;
