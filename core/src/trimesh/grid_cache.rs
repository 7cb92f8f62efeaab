//! Built distance grids kept on disk, so a second export of a design, or
//! the studio after a restart, reads a mesh's grids instead of building them.
//!
//! The candidate grid is most of a large mesh's load time (every surface
//! cell's exact distance and list). It depends on the triangles and the
//! build constants alone, so the file is named by a hash of the vertex
//! bits, the triangles as given, [`FORMAT`] and `candidates::SHAPE`, and
//! it is read while the mesh is built. Nothing read is trusted: the file
//! holds the mesh it was built from, compared exactly (a hash collision is
//! caught); checksums over every byte catch a torn or corrupted one; and
//! every length, index and list bound is checked against the mesh before
//! use. Any failure rebuilds and rewrites.
//!
//! Layout (little-endian): a preamble (magic, format, key, and the lengths
//! of the three sections), the head (the mesh, the coarse grid, the
//! candidate grid's shape), the candidate grid's records and items
//! (`u32`s), then each section's checksum. The arrays are read straight
//! into their vectors a megabyte at a time on every core, each block
//! hashed as it arrives, rather than the whole file read into one buffer
//! and then decoded, which copied every byte twice on one core.
//!
//! Writes go to a temporary name in the same folder and are renamed into
//! place (atomic on POSIX), so a reader never sees half a file; the folder
//! is trimmed to [`MAX_BYTES`], least recently used first (a hit touches
//! its file). A grid read back is the built one bit for bit, so exports do
//! not depend on whether the cache was warm.

use std::fs;
use std::io::{Read, Seek, SeekFrom, Write};
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
const FORMAT: u32 = 3;
/// Bytes before the head: magic, format, key, and the lengths of the head
/// (bytes) and of the records and items (`u32`s).
const PREAMBLE: usize = 8 + 4 + 8 + 3 * 8;
/// Bytes read and hashed apiece (see [`section_sum`]).
const BLOCK: usize = 1 << 20;
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

/// Where a mesh's grids are kept: the file named by the key of the mesh
/// as given (its vertices and triangles before any flip; the grids are a
/// function of them), in the cache folder.
pub(super) struct Slot {
    dir: PathBuf,
    path: PathBuf,
    key: u64,
}

/// The slot of the mesh with these `vertices` and `triangles` in `dir`;
/// none for small meshes (they build faster than a file is read).
pub(super) fn slot(vertices: &[DVec3], triangles: &[[u32; 3]], dir: Option<&Path>) -> Option<Slot> {
    let dir = dir.filter(|_| triangles.len() >= MIN_TRIANGLES)?;
    let key = key(vertices, triangles);
    Some(Slot {
        dir: dir.to_path_buf(),
        path: dir.join(format!("{key:016x}.grid")),
        key,
    })
}

/// Sets `mesh`'s coarse and candidate grids: from `read` (the slot's
/// file, read while the mesh was built) when it is a valid file for this
/// mesh, else built (and written to the slot).
pub(super) fn attach(mesh: &mut TriangleMesh, slot: Option<Slot>, read: Option<Sections>) {
    if let Some(slot) = &slot
        && let Some((coarse, cands)) = read.and_then(|r| decode(r, mesh))
    {
        mesh.coarse = coarse;
        mesh.candidates = cands;
        // Recently used: the trim keeps it (a failure only ages it).
        let _ = fs::File::options()
            .append(true)
            .open(&slot.path)
            .and_then(|f| f.set_modified(SystemTime::now()));
        return;
    }
    mesh.coarse = CoarseGrid::new(&mesh.bbox, mesh.triangles.len(), |p| {
        mesh.signed_distance(p)
    });
    mesh.candidates = CandidateGrid::new(mesh);
    if let Some(slot) = slot {
        // The cache only saves time: a full disk or a read-only home
        // leaves the export as it was.
        let _ = write(&slot, mesh).map(|()| trim(&slot.dir, MAX_BYTES));
    }
}

/// Hash of a mesh's vertices and triangles and of everything that shapes
/// its grids.
fn key(vertices: &[DVec3], triangles: &[[u32; 3]]) -> u64 {
    let mut h = Hash::new();
    h.word(u64::from(FORMAT));
    candidates::SHAPE.iter().for_each(|c| h.word(c.to_bits()));
    h.word(vertices.len() as u64);
    vertices
        .iter()
        .for_each(|v| v.to_array().iter().for_each(|c| h.word(c.to_bits())));
    triangles.iter().for_each(|t| {
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

/// The file for `mesh`'s grids (keyed `key`): the preamble and head,
/// then the candidate grid's records and items, then the three sections'
/// checksums.
fn encode(mesh: &TriangleMesh, key: u64) -> Vec<u8> {
    let mut head = Vec::new();
    put_u64(&mut head, mesh.vertices.len() as u64);
    mesh.vertices.iter().for_each(|v| put_vec(&mut head, *v));
    put_u64(&mut head, mesh.triangles.len() as u64);
    mesh.triangles
        .iter()
        .for_each(|t| t.iter().for_each(|&i| put_u32(&mut head, i)));
    match &mesh.coarse {
        None => head.push(0),
        Some(c) => {
            head.push(1);
            put_vec(&mut head, c.origin);
            put_f64(&mut head, c.cell);
            c.dims.iter().for_each(|&n| put_u64(&mut head, n as u64));
            put_u64(&mut head, c.d.len() as u64);
            c.d.iter().for_each(|&x| put_f64(&mut head, x));
        }
    }
    let (records, items): (&[u32], &[u32]) = match &mesh.candidates {
        None => {
            head.push(0);
            (&[], &[])
        }
        Some(g) => {
            head.push(1);
            put_vec(&mut head, g.cells.origin());
            put_vec(&mut head, g.cells.cell());
            g.cells
                .dims()
                .iter()
                .for_each(|&n| put_u64(&mut head, n as u64));
            put_u32(&mut head, g.slot_bits);
            put_u32(&mut head, g.q_shift);
            put_f64(&mut head, g.inv_unit);
            put_f64(&mut head, g.tiny);
            (&g.records, &g.items)
        }
    };
    let mut w = Vec::with_capacity(PREAMBLE + head.len() + 4 * (records.len() + items.len()) + 24);
    w.extend_from_slice(MAGIC);
    put_u32(&mut w, FORMAT);
    put_u64(&mut w, key);
    for n in [head.len(), records.len(), items.len()] {
        put_u64(&mut w, n as u64);
    }
    w.extend_from_slice(&head);
    let mut sums = vec![section_sum(&w)];
    for list in [records, items] {
        let at = w.len();
        list.iter().for_each(|&x| put_u32(&mut w, x));
        sums.push(section_sum(&w[at..]));
    }
    sums.iter().for_each(|&x| put_u64(&mut w, x));
    w
}

/// A section's checksum: the hash of its [`BLOCK`]s' hashes and its
/// length, so that a reader hashes blocks on every core as they arrive.
fn section_sum(bytes: &[u8]) -> u64 {
    let blocks: Vec<u64> = bytes.par_chunks(BLOCK).map(block_sum).collect();
    fold_sums(&blocks, bytes.len())
}

fn block_sum(block: &[u8]) -> u64 {
    let mut h = Hash::new();
    h.bytes(block);
    h.finish()
}

fn fold_sums(blocks: &[u64], len: usize) -> u64 {
    let mut h = Hash::new();
    blocks.iter().for_each(|&b| h.word(b));
    h.word(len as u64);
    h.finish()
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

/// Writes `mesh`'s grids to the slot's file through a temporary file in
/// its folder.
fn write(slot: &Slot, mesh: &TriangleMesh) -> std::io::Result<()> {
    fs::create_dir_all(&slot.dir)?;
    let nanos = SystemTime::now()
        .duration_since(SystemTime::UNIX_EPOCH)
        .map_or(0, |d| d.subsec_nanos());
    let tmp = slot
        .dir
        .join(format!(".{}-{nanos}.tmp", std::process::id()));
    let done = fs::File::create(&tmp)
        .and_then(|mut f| f.write_all(&encode(mesh, slot.key)))
        .and_then(|()| fs::rename(&tmp, &slot.path));
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

/// A cache file's sections as read, each matching its checksum; whether
/// they describe the mesh is checked by [`decode`].
pub(super) struct Sections {
    /// The preamble and the head.
    head: Vec<u8>,
    records: Vec<u32>,
    items: Vec<u32>,
}

/// The slot's file, read a [`BLOCK`] at a time on every core straight into
/// its arrays (no copy of the whole file first), each block hashed as it
/// arrives; `None` when it is missing, of the wrong length or format, or
/// a checksum fails.
pub(super) fn load(slot: &Slot) -> Option<Sections> {
    let mut f = fs::File::open(&slot.path).ok()?;
    let len = f.metadata().ok()?.len();
    let mut pre = [0u8; PREAMBLE];
    f.read_exact(&mut pre).ok()?;
    let mut r = Reader { b: &pre, at: 0 };
    if r.take(8)? != MAGIC || r.u32()? != FORMAT || r.u64()? != slot.key {
        return None;
    }
    let (head, records, items) = (r.u64()?, r.u64()?, r.u64()?);
    let head = (PREAMBLE as u64).checked_add(head)?;
    let records_at = head;
    let items_at = records_at.checked_add(records.checked_mul(4)?)?;
    let sums_at = items_at.checked_add(items.checked_mul(4)?)?;
    if sums_at.checked_add(24)? != len {
        return None;
    }
    let mut sums = [0u8; 24];
    f.seek(SeekFrom::Start(sums_at)).ok()?;
    f.read_exact(&mut sums).ok()?;
    let sum = |i: usize| u64::from_le_bytes(sums[8 * i..8 * i + 8].try_into().unwrap_or_default());
    let path = &slot.path;
    let ((head, records), items) = rayon::join(
        || {
            rayon::join(
                || read_section::<u8>(path, 0, usize::try_from(head).ok()?, sum(0)),
                || read_section::<u32>(path, records_at, usize::try_from(records).ok()?, sum(1)),
            )
        },
        || read_section::<u32>(path, items_at, usize::try_from(items).ok()?, sum(2)),
    );
    Some(Sections {
        head: head?,
        records: records?,
        items: items?,
    })
}

/// `n` little-endian elements at byte `at` of the file at `path`, when
/// their checksum is `sum`. Each block is read through a handle of its
/// own (portable, and no shared file position); a file replaced or cut
/// short meanwhile fails a read or the checksum.
fn read_section<T: bytemuck::Pod + Send + Sync>(
    path: &Path,
    at: u64,
    n: usize,
    sum: u64,
) -> Option<Vec<T>> {
    let mut v = vec![T::zeroed(); n];
    let per = BLOCK / std::mem::size_of::<T>();
    let blocks: Option<Vec<u64>> = v
        .par_chunks_mut(per)
        .enumerate()
        .map(|(i, chunk)| {
            let bytes: &mut [u8] = bytemuck::cast_slice_mut(chunk);
            let mut f = fs::File::open(path).ok()?;
            f.seek(SeekFrom::Start(at + (i * BLOCK) as u64)).ok()?;
            f.read_exact(bytes).ok()?;
            Some(block_sum(bytes))
        })
        .collect();
    (fold_sums(&blocks?, n * std::mem::size_of::<T>()) == sum).then_some(v)
}

/// The grids of a file's `sections` when they were built for `mesh`;
/// nothing read is trusted.
fn decode(
    sections: Sections,
    mesh: &TriangleMesh,
) -> Option<(Option<CoarseGrid>, Option<CandidateGrid>)> {
    let Sections {
        head,
        mut records,
        mut items,
    } = sections;
    if cfg!(target_endian = "big") {
        records.iter_mut().for_each(|x| *x = u32::from_le(*x));
        items.iter_mut().for_each(|x| *x = u32::from_le(*x));
    }
    // (The preamble was checked by `load`, against this slot's key.)
    let mut r = Reader {
        b: &head,
        at: PREAMBLE,
    };
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
        0 if records.is_empty() && items.is_empty() => None,
        1 => Some(candidate_grid(&mut r, records, items, mesh)?),
        _ => return None,
    };
    (r.at == head.len()).then_some((coarse, cands))
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

fn candidate_grid(
    r: &mut Reader,
    records: Vec<u32>,
    items: Vec<u32>,
    mesh: &TriangleMesh,
) -> Option<CandidateGrid> {
    let (min, cell, dims) = (r.vec()?, r.vec()?, r.dims()?);
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
