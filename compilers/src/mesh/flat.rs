//! Flat regions of the contour: where the surface (or an interface) is
//! planar across many cubes, one triangulation of the region's outline
//! replaces the ~8 marching-tetrahedra triangles of every cube. A 10 mm
//! cube at 0.05 mm goes from 1.9 million triangles to a few thousand, with
//! the same vertices wherever the region meets the rest of the mesh.
//!
//! # Flat cubes
//! A cube is *flat* when its eight samples carry exactly two labels `x`
//! (the lower non-void one) and `y`, and the field `g` that places the cut
//! (the distance for void | inside, `f − c` for fraction ranges,
//! `f_y − f_x` for dominant materials; negative on `x`) is affine over the
//! cube: every edge difference along an axis equals that axis' mean
//! difference within `FLAT_TOL` of `|Δx| + |Δy| + |Δz|`. Its sign must
//! agree with the labels at every corner. Then every marching-tetrahedra
//! point of the cube lies on the plane `g = 0` and the cube's triangles
//! tile the polygon `{g = 0} ∩ cube`; where a sample lies on the plane
//! (`g = 0`), the contourer's clamp `T_MIN` moves the points next to it by
//! at most `T_MIN` voxels along their edges, the same in the merged and
//! the unmerged mesh (a face through a whole plane of samples stays
//! exactly flat, shifted by `T_MIN`).
//!
//! # Regions
//! Flat cubes with the same labels and the same unit normal, quantised to
//! `1/NORMAL_BINS` per component, that share a cut face form a region
//! (union-find, layer by layer). The key is compared exactly, so grouping
//! is transitive; a plane split across two bins only gives two regions.
//! The region's outline is the cut segments on faces it shares with any
//! other cube (or region), taken from the Kuhn split of those faces: the
//! same points, with the same keys, as the neighbours' triangles, so the
//! meshes stay closed. Points inside the region are dropped.
//!
//! # Triangulation
//! Each region's outline is triangulated in [`super::outline`]. A region
//! whose triangulation fails one of its checks is contoured cube by cube with
//! marching tetrahedra, so the output is never worse than without
//! merging. Its cubes' labels were kept, not their samples: the fallback
//! takes those again ([`SampleAt`]); its outline points keep the positions
//! its neighbours share, so it stays closed whatever the samples.

use glam::DVec3;
use rayon::prelude::*;
use volcad_core::round_i32;

use super::indexed::IndexedMesh;
use super::interface::{Cube, Interface, cut_field, front_back};
use super::outline::{ADDED, Triangulated, triangulate};
use super::vertex_keys::{FastMap, Tri};

/// Largest deviation of an edge difference from its axis mean, relative to
/// `|Δx| + |Δy| + |Δz|`: a sphere of radius `R` sampled at `h` deviates by
/// about `h / R`, so surfaces flatter than `R = 1000 h` count as planes.
const FLAT_TOL: f64 = 1e-3;
/// Normal quantisation per component.
const NORMAL_BINS: f64 = 1024.0;
/// Keys [`Regions::add_band`] remembers while interning a band's cubes.
const RECENT_KEYS: usize = 4;

/// What makes flat cubes one region.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(super) struct FlatKey {
    /// The lower non-void label (its triangles face `y`).
    pub x: u16,
    /// The other label (0 = void).
    pub y: u16,
    normal: [i32; 3],
}

/// A contouring band's flat cubes: row, column, key and the corners of
/// the key's `x` label (bit mask), with their samples kept for the
/// fallback.
#[derive(Default)]
pub(super) struct BandFlats {
    pub at: Vec<([usize; 2], FlatKey, u8)>,
    pub kept: KeptCubes,
}

impl BandFlats {
    pub fn with_capacity(cubes: usize, dims: [usize; 3]) -> Self {
        BandFlats {
            at: Vec::with_capacity(cubes),
            kept: KeptCubes::with_capacity(cubes, dims),
        }
    }
}

/// The key of a flat cube, or `None` (see the module docs).
pub(super) fn flat_key(voxel: DVec3, iface: Interface, cube: &Cube) -> Option<FlatKey> {
    let l0 = cube.label[0];
    let other = *cube.label.iter().find(|l| **l != l0)?;
    if cube.label.iter().any(|l| *l != l0 && *l != other) {
        return None;
    }
    let (x, y) = front_back(l0, other);
    // Next to void (the usual surface) the field is the distance.
    let g: [f64; 8] = if y == 0 {
        cube.dist.map(f64::from)
    } else {
        let mut g = [0.0; 8];
        for (k, g) in g.iter_mut().enumerate() {
            *g = cut_field(iface, x, y, cube.dist[k], cube.value[k])?;
        }
        g
    };
    // Per axis, the four corners with that axis' bit clear (ascending, so
    // the sums are those of a loop over 0..8).
    const LOW: [[usize; 4]; 3] = [[0, 2, 4, 6], [0, 1, 4, 5], [0, 1, 2, 3]];
    let mut mean = [0.0; 3];
    let mut diffs = [[0.0; 4]; 3];
    for (axis, (m, d)) in mean.iter_mut().zip(&mut diffs).enumerate() {
        let bit = 1usize << axis;
        for (k, &c) in LOW[axis].iter().enumerate() {
            d[k] = g[c | bit] - g[c];
            *m += d[k] / 4.0;
        }
    }
    let scale: f64 = mean.iter().map(|m| m.abs()).sum();
    // f32 storage of the samples (values near 1 for fractions).
    let raw = g.iter().fold(1.0f64, |a, v| a.max(v.abs()));
    let tol = FLAT_TOL * scale + 4e-7 * raw;
    let affine = mean
        .iter()
        .zip(&diffs)
        .all(|(m, d)| d.iter().all(|v| (v - m).abs() <= tol));
    // (`scale` is finite when the test holds: a non-finite sample makes an
    // axis' mean infinite or NaN, and its own difference then fails.)
    if !affine || scale <= 0.0 {
        return None;
    }
    // Which side holds `g = 0` exactly, as the labels put it: inside for
    // distances (d ≤ 0), the upper range for ranges (⌊f·n⌋), the lower slot
    // for dominant ties. Tested after the plane: most cubes of a curved
    // surface fail the test above, which has no branch per corner.
    let zero_is_x = !matches!((y, iface), (1.., Interface::Ranges { .. }));
    for (l, v) in cube.label.iter().zip(&g) {
        let ok = if *l == x {
            *v < 0.0 || (*v == 0.0 && zero_is_x)
        } else {
            *v > 0.0 || (*v == 0.0 && !zero_is_x)
        };
        if !ok || !v.is_finite() {
            return None;
        }
    }
    let n = DVec3::new(mean[0] / voxel.x, mean[1] / voxel.y, mean[2] / voxel.z).normalize();
    let q = n * NORMAL_BINS;
    Some(FlatKey {
        x,
        y,
        normal: [round_i32(q.x), round_i32(q.y), round_i32(q.z)],
    })
}

/// The last two answers of [`flat_key`] for cubes that touch void, by
/// their labels and distances: next to void the key is a function of
/// those alone (the interface values are not read), and along a flat face
/// neighbouring cubes repeat the same eight samples (a face parallel to a
/// grid plane everywhere; a row crossing two opposite faces alternates
/// between two). Two entries because of that alternation; computing the
/// key anew costs far more than comparing the samples.
#[derive(Default)]
pub(super) struct FlatMemo {
    seen: [Option<Remembered>; 2],
    next: usize,
}

/// A cube's labels, the bits of its distances, and its key.
type Remembered = ([u16; 8], [u32; 8], Option<FlatKey>);

impl FlatMemo {
    /// [`flat_key`] of `cube`, from the memo when it has the answer.
    pub fn key(&mut self, voxel: DVec3, iface: Interface, cube: &Cube) -> Option<FlatKey> {
        if !cube.label.contains(&0) {
            return flat_key(voxel, iface, cube);
        }
        let bits = cube.dist.map(f32::to_bits);
        for (label, dist, key) in self.seen.iter().flatten() {
            if *label == cube.label && *dist == bits {
                return *key;
            }
        }
        let key = flat_key(voxel, iface, cube);
        self.seen[self.next] = Some((cube.label, bits, key));
        self.next ^= 1;
        key
    }
}

/// Flat cubes kept for the fallback, gathered per band of rows in
/// parallel and handed to [`Regions`] whole (one growing array was copied
/// by `realloc` each time it grew, in the sequential joining pass).
///
/// A cube keeps its place and its labels in 8 bytes (its lowest corner's
/// index in the grid, below 2⁴⁴ voxels, shifted over a mask of the corners
/// carrying its key's label `x`), not its samples: the fallback is rare
/// (a region whose triangulation fails a check) and takes them again
/// through [`SampleAt`]. Keeping them would cost 32 bytes a cube with one
/// value a sample, 96 with three: fresh memory faulted in page by page on
/// every flat face.
#[derive(Default)]
pub(super) struct KeptCubes {
    cubes: Vec<u64>,
    /// The grid's samples along x and y.
    nx: usize,
    ny: usize,
}

impl KeptCubes {
    /// Room for `cubes` cubes of a grid of `dims` samples.
    pub fn with_capacity(cubes: usize, [nx, ny, _]: [usize; 3]) -> Self {
        KeptCubes {
            cubes: Vec::with_capacity(cubes),
            nx,
            ny,
        }
    }

    /// Keep the flat cube with lowest corner `base` whose corners labelled
    /// with its key's `x` are `mask`.
    pub fn push(&mut self, [i, j, k]: [usize; 3], mask: u8) {
        let at = ((k * self.ny + j) * self.nx + i) as u64;
        self.cubes.push(at << 8 | u64::from(mask));
    }

    /// Cube `n`'s lowest corner and mask.
    fn get(&self, n: usize) -> ([usize; 3], u8) {
        let packed = self.cubes[n];
        let at = (packed >> 8) as usize;
        let base = [
            at % self.nx,
            at / self.nx % self.ny,
            at / (self.nx * self.ny),
        ];
        (base, packed as u8)
    }
}

/// A sample taken again for the fallback: the distance at grid sample
/// `[i, j, k]`, with its interface values written into the slice (the
/// contourer's stride of them, zero where the sample is void). Where the
/// planes' numbers were evaluated sample by sample these are the same
/// numbers, so the fallback gives marching tetrahedra's mesh exactly.
pub(super) type SampleAt<'a> = dyn Fn([usize; 3], &mut [f32]) -> f32 + 'a;

/// An outline edge: the flat cube that added it, its vertex keys and
/// their indices in label `x`'s and `y`'s meshes (`y` unused when void).
struct Edge {
    cube: u32,
    keys: [u64; 2],
    xi: [u32; 2],
    yi: [u32; 2],
}

/// One region at triangulation time.
struct Region {
    key: FlatKey,
    /// Its outline edges (indices into `Regions::edges`), and its cubes
    /// (ids) when it falls back.
    cubes: Vec<u32>,
    edges: Vec<u32>,
    /// The outline edges' vertices in label `x`'s mesh, gathered while the
    /// edges are read in order: triangulating read them by index, one
    /// cache miss an edge.
    outline: Vec<[u32; 2]>,
}

/// A [`FlatKey`] interned by [`Regions`]: equal ids, equal keys.
pub(super) type KeyId = u32;

/// Marching tetrahedra for one cube (the fallback).
pub(super) type CubeContour<'a> = dyn Fn(&Cube, &mut Vec<Tri>) + 'a;

/// All flat cubes of one contouring run, joined by union-find (ids in
/// creation order; a region's root is its lowest id). Cubes and edges sit
/// in flat arrays and are grouped by root only at the end, so joining is
/// a pointer update.
pub(super) struct Regions {
    parent: Vec<u32>,
    /// Each cube's key, interned: 4 bytes instead of 16 a cube, and one
    /// integer compare where neighbours are matched.
    keys: Vec<KeyId>,
    /// The distinct keys, by id, and their ids.
    table: Vec<FlatKey>,
    ids: FastMap<FlatKey, KeyId>,
    /// Kept cubes by band, with the id of each band's first cube.
    kept: Vec<(u32, KeptCubes)>,
    edges: Vec<Edge>,
    stride: usize,
    /// False: every region takes the fallback (tests compare the paths).
    pub triangulate: bool,
}

impl Regions {
    /// No regions yet; `stride` interface values per sample.
    pub fn new(stride: usize) -> Self {
        Self {
            parent: Vec::new(),
            keys: Vec::new(),
            table: Vec::new(),
            ids: FastMap::default(),
            kept: Vec::new(),
            edges: Vec::new(),
            stride,
            triangulate: true,
        }
    }

    /// New one-cube regions, one per key, with the cubes `kept` (in the
    /// same order); returns the first id (the others follow).
    pub fn add_band(&mut self, keys: impl Iterator<Item = FlatKey>, kept: KeptCubes) -> u32 {
        let first = self.parent.len() as u32;
        // Runs of cubes share a key, and a row crosses few faces: the keys
        // met last are looked up without hashing (with one remembered, a
        // cube's side faces, met in turn along every row, hash each cube).
        let mut recent: [Option<(FlatKey, KeyId)>; RECENT_KEYS] = [None; RECENT_KEYS];
        let mut next_slot = 0;
        for key in keys {
            let id = match recent.iter().flatten().find(|(k, _)| *k == key) {
                Some(&(_, id)) => id,
                None => {
                    let next = self.table.len() as KeyId;
                    let id = *self.ids.entry(key).or_insert(next);
                    if id == next {
                        self.table.push(key);
                    }
                    recent[next_slot] = Some((key, id));
                    next_slot = (next_slot + 1) % RECENT_KEYS;
                    id
                }
            };
            self.parent.push(self.parent.len() as u32);
            self.keys.push(id);
        }
        debug_assert_eq!(
            self.parent.len() - first as usize,
            kept.cubes.len(),
            "one kept cube a key"
        );
        if !kept.cubes.is_empty() {
            self.kept.push((first, kept));
        }
        first
    }

    /// Kept cube `id` with its samples taken again into `buf`.
    fn kept_cube<'b>(&self, id: u32, samples: &SampleAt, buf: &'b mut Vec<f32>) -> Cube<'b> {
        let band = self.kept.partition_point(|(first, _)| *first <= id) - 1;
        let (first, kept) = &self.kept[band];
        let (base, mask) = kept.get((id - first) as usize);
        let key = self.key(id);
        let s = self.stride;
        buf.clear();
        buf.resize(8 * s, 0.0);
        let mut dist = [0.0; 8];
        for (c, d) in dist.iter_mut().enumerate() {
            let at = std::array::from_fn(|a| base[a] + (c >> a & 1));
            *d = samples(at, &mut buf[c * s..(c + 1) * s]);
        }
        let buf = &**buf;
        Cube {
            base,
            label: std::array::from_fn(|c| if mask >> c & 1 == 1 { key.x } else { key.y }),
            dist,
            value: std::array::from_fn(|c| &buf[c * s..(c + 1) * s]),
        }
    }

    /// The key of cube `id` (the same for its whole region).
    pub fn key(&self, id: u32) -> FlatKey {
        self.table[self.keys[id as usize] as usize]
    }

    /// The interned key of cube `id`: equal for equal keys.
    pub fn key_id(&self, id: u32) -> KeyId {
        self.keys[id as usize]
    }

    /// Join the regions of `a` and `b` (the lower root stays).
    pub fn union(&mut self, a: u32, b: u32) {
        // Most joins on a flat face are of cubes already in one region
        // whose parents agree (a cube joined to its left neighbour's root,
        // and its front neighbour pointing there too): settled unfound.
        if self.parent[a as usize] == self.parent[b as usize] {
            return;
        }
        crate::union_find::join(&mut self.parent, a, b);
    }

    /// Add an outline edge to the region of cube `id`: vertex keys and
    /// their indices in `x`'s mesh (and `y`'s, ignored when `y` is void).
    pub fn add_edge(&mut self, id: u32, keys: [u64; 2], xi: [u32; 2], yi: [u32; 2]) {
        self.edges.push(Edge {
            cube: id,
            keys,
            xi,
            yi,
        });
    }

    /// Triangulate every region into `meshes` (label `l` in `meshes[l − 1]`),
    /// falling back to `contour` over samples taken again from `samples`
    /// for regions that fail the checks.
    pub fn finish(mut self, meshes: &mut [IndexedMesh], contour: &CubeContour, samples: &SampleAt) {
        // A region's root is its lowest id, so the roots in ascending order
        // list the regions in order of their first cube, without a pass
        // that finds every cube's root: only edges need theirs, and cubes
        // only in a region that falls back (gathered below).
        let n = self.parent.len() as u32;
        let roots: Vec<u32> = (0..n)
            .filter(|&id| self.parent[id as usize] == id)
            .collect();
        let mut regions: Vec<Region> = roots
            .iter()
            .map(|&r| Region {
                key: self.key(r),
                cubes: Vec::new(),
                edges: Vec::new(),
                outline: Vec::new(),
            })
            .collect();
        // Each edge's region on every core (roots read without shortening
        // paths), then the edges dealt out in order into lists sized first.
        let region_of: Vec<u32> = {
            let parent = &self.parent;
            self.edges
                .par_iter()
                .map(|e| {
                    let r = crate::union_find::root(parent, e.cube);
                    roots.binary_search(&r).map_or(u32::MAX, |s| s as u32)
                })
                .collect()
        };
        let mut sizes = vec![0usize; regions.len()];
        for &s in region_of.iter().filter(|&&s| s != u32::MAX) {
            sizes[s as usize] += 1;
        }
        for (r, &n) in regions.iter_mut().zip(&sizes) {
            r.edges.reserve_exact(n);
            r.outline.reserve_exact(n);
        }
        for (e, &s) in region_of.iter().enumerate() {
            if let Some(r) = regions.get_mut(s as usize) {
                r.edges.push(e as u32);
                r.outline.push(self.edges[e].xi);
            }
        }
        let tris: Vec<Option<Triangulated>> = {
            let meshes = &*meshes;
            regions
                .par_iter()
                .map(|r| {
                    let verts = &meshes[r.key.x as usize - 1].vertices;
                    self.triangulate
                        .then(|| triangulate(r.key.normal, r.outline.iter().copied(), verts))
                        .flatten()
                })
                .collect()
        };
        if tris.iter().any(Option::is_none) {
            for id in 0..n {
                let r = crate::union_find::find(&mut self.parent, id);
                if let Ok(s) = roots.binary_search(&r)
                    && tris[s].is_none()
                {
                    regions[s].cubes.push(id);
                }
            }
        }
        // The meshes grow once, not by doubling (each doubling copies the
        // mesh and faults in fresh pages).
        let mut more = vec![(0usize, 0usize); meshes.len()];
        for (r, t) in regions.iter().zip(&tris) {
            let Some(t) = t else { continue };
            for label in [r.key.x as usize, r.key.y as usize] {
                if label > 0 {
                    more[label - 1].0 += t.added.len();
                    more[label - 1].1 += t.tris.len();
                }
            }
        }
        for (m, (v, t)) in meshes.iter_mut().zip(more) {
            m.vertices.reserve(v);
            m.triangles.reserve(t);
        }
        let mut scratch = Vec::new();
        for (r, t) in regions.iter().zip(tris) {
            let (x, y) = (r.key.x as usize - 1, r.key.y as usize);
            match t {
                Some(Triangulated { tris, added }) => {
                    // Added inner points go to both labels' meshes.
                    let base = meshes[x].vertices.len() as u32;
                    meshes[x].vertices.extend(&added);
                    let t: Vec<[u32; 3]> = tris
                        .into_iter()
                        .map(|t| t.map(|i| if i >= ADDED { base + i - ADDED } else { i }))
                        .collect();
                    if y != 0 {
                        let mut to_y: FastMap<u32, u32> = r
                            .edges
                            .iter()
                            .map(|e| &self.edges[*e as usize])
                            .flat_map(|e| [(e.xi[0], e.yi[0]), (e.xi[1], e.yi[1])])
                            .collect();
                        let base_y = meshes[y - 1].vertices.len() as u32;
                        meshes[y - 1].vertices.extend(&added);
                        to_y.extend((0..added.len() as u32).map(|k| (base + k, base_y + k)));
                        let my = &mut meshes[y - 1].triangles;
                        my.extend(t.iter().map(|[a, b, c]| [to_y[a], to_y[c], to_y[b]]));
                    }
                    meshes[x].triangles.extend(t);
                }
                None => self.fallback(r, meshes, contour, samples, &mut scratch),
            }
        }
    }

    /// Marching tetrahedra over the region's kept cubes; outline vertices
    /// keep their indices, inner ones are added.
    fn fallback(
        &self,
        r: &Region,
        meshes: &mut [IndexedMesh],
        contour: &CubeContour,
        samples: &SampleAt,
        tris: &mut Vec<Tri>,
    ) {
        let (x, y) = (r.key.x, r.key.y);
        let mut map: FastMap<(u16, u64), u32> = FastMap::default();
        for e in r.edges.iter().map(|e| &self.edges[*e as usize]) {
            for k in 0..2 {
                map.insert((x, e.keys[k]), e.xi[k]);
                if y != 0 {
                    map.insert((y, e.keys[k]), e.yi[k]);
                }
            }
        }
        let mut buf = Vec::new();
        for &c in &r.cubes {
            let cube = self.kept_cube(c, samples, &mut buf);
            tris.clear();
            contour(&cube, tris);
            for t in tris.iter() {
                let mesh = &mut meshes[t.label as usize - 1];
                let idx = t.v.map(|v| {
                    *map.entry((t.label, v.key)).or_insert_with(|| {
                        mesh.vertices.push(v.pos);
                        (mesh.vertices.len() - 1) as u32
                    })
                });
                mesh.triangles.push(idx);
            }
        }
    }
}

#[cfg(test)]
mod tests;
