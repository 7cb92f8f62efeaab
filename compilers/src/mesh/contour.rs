//! Multi-label contouring: closed, outward-oriented meshes for every label
//! of a labelled voxel grid, sharing their interfaces exactly.
//!
//! # Method
//!
//! Samples sit at voxel centres; each carries a label (0 = void, 1..=L the
//! segments), a signed distance and interface values. Each cube between 8
//! neighbouring samples is split into six tetrahedra around its main
//! diagonal (the Kuhn / Freudenthal split: tet `π` has corners `0`,
//! `e_π1`, `e_π1 + e_π2`, `(1,1,1)`); the split of every cube face is the
//! same from both sides, so there are no ambiguous faces and no cracks
//! (this is marching *tetrahedra* inside each marching cube).
//!
//! Within one tet, a point is placed on every edge whose ends differ in
//! label: at `p = a + t (b − a)` with
//! * void | inside: `t = d_a / (d_a − d_b)` (the true surface, from the
//!   distances);
//! * segment `s` | `r` by ranges of a value `f` cut into `n` ranges:
//!   where `f` meets `c = (s + r + 1) / (2n)` (the shared range boundary when
//!   `|s − r| = 1`), `t = (c − f_a) / (f_b − f_a)`;
//! * dominant material `A` | `B`: where `f_A − f_B` changes sign;
//!
//! always computed from the edge's lower end, clamped to `[0.05, 0.95]`
//! (`T_MIN`: no sub-micron edges where the surface passes through a sample).
//! With two labels in the tet, the interface is the usual marching-tetrahedra
//! triangle or quad. With three or four, a point is added at the centroid of
//! the edge points of each three-label face and of the tet (of those next to
//! void alone when there are some, so the outer surface has no groove where
//! an interface meets it), and the
//! interface is the cone from the tet point over the curves on the faces
//! (straight between edge points on two-label faces, through the face point
//! on three-label faces). Each label's part of a tet is then a topological
//! ball and the parts tile the tet, so every label's mesh is a closed
//! 2-manifold and two labels share their interface triangles exactly (same
//! vertices, opposite orientation). Orientation is combinatorial (from the
//! tet's vertex order), never from a geometric test.
//!
//! Vertices are shared through keys on the grid elements they lie on
//! (edge, face or tet, by lowest corner index and direction), so each
//! label's mesh has every vertex once. Only the keys of two sample planes are
//! kept: memory is proportional to a plane plus the output.

use glam::DVec3;
use rayon::prelude::*;
use volcad_core::sampler::Grid;

use super::band_scratch::{Pool, Stamped};
use super::cube_loops;
use super::flat::{BandFlats, FlatMemo, Regions, SampleAt};
use super::indexed::IndexedMesh;
use super::interface::{Cube, Interface, corner_mask, cut_field, front_back};
use super::kuhn::{
    CUT_FACES, FACES, Pt, by_inclusion, chain, edge, face_cut, odd_one_out, tet_corners,
    two_label_cut,
};
use super::layer_dist::LayerDist;
use super::mixed::{around, mixed_cubes, push_mixed_from_bits};
use super::one_label::{LayerEdges, OneLabelBand, PlaneEdges};
pub use super::unevaluated::ExactAt;
use super::unevaluated::{CornerMemo, Layer};
use super::vertex_keys::{BandMesh, KeyMap, Tri, VRef};

/// One z plane of samples (`nx·ny` each, x fastest).
#[derive(Clone, Debug, Default)]
pub struct Plane {
    /// 0 = void, 1.. = label.
    pub label: Vec<u16>,
    /// Signed distance (mm): a layer of the sampled slab's buffer.
    pub dist: LayerDist,
    /// Interface values, `Interface::stride` per sample.
    pub value: Vec<f32>,
    /// One label's planes may carry their labels as bits too (bit `x % 64`
    /// of word `x / 64` of a row of `nx.div_ceil(64)` words set where the
    /// label is not 0), for the mixed-cube scan; empty otherwise.
    pub bits: Vec<u64>,
}

/// Edge-point parameter clamp: keeps every point a twentieth of an edge off
/// the samples. Where the surface passes through a sample, the points of
/// its edges cluster around it; at 10⁻³ of a voxel their sub-micron edges
/// and needles stopped gmsh's boundary recovery (the surface moves by at
/// most this much of an edge there).
const T_MIN: f64 = 0.05;
/// Key type offsets: edges 1..=7 (direction mask), faces 8..=71, tets
/// 72..=77, loop centres 78..=81.
const FACE_KEY: u64 = 8;
const TET_KEY: u64 = 72;
/// Centre points of one-label loops (up to four a cube): 78..=81.
pub(super) const LOOP_KEY: u64 = 78;
pub(super) const KEY_TYPES: u64 = 128;

/// Rows of cubes a contouring task takes: fewer, larger tasks cost less
/// to schedule and allocate for than one per row (most rows of a solid
/// part hold two surface cubes).
pub(super) const BAND: usize = 8;

/// No flat cube here (layer tables of region ids).
const NOT_FLAT: u32 = u32::MAX;

/// Builds label meshes plane by plane.
pub struct Contourer {
    pub(super) grid: Grid,
    pub(super) iface: Interface,
    meshes: Vec<IndexedMesh>,
    /// Per label: key → vertex index, for keys based in the lower and the
    /// upper plane of the current cube layer (two or more labels; one
    /// label uses `edges`).
    maps: Vec<[KeyMap; 2]>,
    prev: Option<(usize, Plane)>,
    /// Merge flat regions (see [`super::flat`]); off: plain marching
    /// tetrahedra.
    merge: bool,
    /// One label: cubes are cut as marching cubes ([`cube_loops`]), with
    /// no face diagonals.
    one_label: bool,
    regions: Regions,
    /// Region id per cube of the previous layer, or [`NOT_FLAT`], and the
    /// cubes that have one.
    prev_flat: Vec<u32>,
    prev_list: Vec<(usize, u8)>,
    /// The layer table before that, reset to [`NOT_FLAT`] where it was set
    /// (a sparse reset), and an empty list: reused, so a layer does not
    /// allocate and fill a fresh table the size of a plane.
    spare_flat: Vec<u32>,
    spare_list: Vec<(usize, u8)>,
    /// Per band of rows, the triangles and flat cubes it made in the last
    /// layer: the next layer's buffers start at that size (plus an eighth),
    /// since growing them by doubling copies and faults in their memory
    /// again and again.
    band_sizes: Vec<(usize, usize)>,
    /// Edge slots of the one-label path and corner memos, lent to
    /// contouring tasks and given back.
    scratch_pool: Pool<(Stamped, CornerMemo)>,
    /// Corners evaluated by [`Self::flat_layer`], which reads cubes of the
    /// whole layer.
    layer_memo: CornerMemo,
    /// One label: the mesh's points on the layer's grid edges (see
    /// `one_label::LayerEdges`).
    edges: LayerEdges,
    /// Count only (an estimate's sampled layers): the bands' triangles so
    /// far, none numbered into meshes.
    counted: Option<usize>,
}

impl Contourer {
    /// A contourer for `labels` labels (1..=labels) on `grid`.
    pub fn new(grid: Grid, labels: usize, iface: Interface) -> Self {
        Self {
            grid,
            iface,
            meshes: vec![IndexedMesh::default(); labels],
            maps: (0..labels)
                .map(|_| [KeyMap::default(), KeyMap::default()])
                .collect(),
            prev: None,
            merge: true,
            one_label: labels == 1,
            regions: Regions::new(iface.stride()),
            prev_flat: Vec::new(),
            prev_list: Vec::new(),
            spare_flat: Vec::new(),
            spare_list: Vec::new(),
            band_sizes: Vec::new(),
            scratch_pool: Pool::default(),
            layer_memo: CornerMemo::default(),
            edges: LayerEdges::default(),
            counted: None,
        }
    }

    /// Count the triangles pushed ([`Self::triangles`]) and build no
    /// meshes: an estimate needs the count, not the sequential numbering.
    pub(super) fn counting_only(mut self) -> Self {
        self.counted = Some(0);
        self
    }

    /// Turn flat-region merging on (the default) or off.
    pub fn with_flat_merge(mut self, merge: bool) -> Self {
        self.merge = merge;
        self
    }

    /// Merge flat regions but contour each with its fallback (tests).
    pub(super) fn with_fallback_only(mut self) -> Self {
        self.regions.triangulate = false;
        self
    }

    /// Add plane `z` (planes come in order from 0); contours the cube layer
    /// between it and the previous plane, and hands that previous plane
    /// back for its buffers to be reused. `exact` evaluates the corners of
    /// cut cubes that the sampler left unevaluated.
    ///
    /// # Panics
    /// If a plane is skipped or has the wrong size.
    pub fn push_plane(&mut self, z: usize, plane: Plane, exact: ExactAt) -> Option<Plane> {
        let layer = self.grid.dims[0] * self.grid.dims[1];
        assert!(
            plane.label.len() == layer && plane.dist.len() == layer,
            "plane size"
        );
        assert_eq!(
            plane.value.len(),
            layer * self.iface.stride(),
            "plane values"
        );
        let Some((pz, lo)) = self.prev.take() else {
            assert_eq!(z, 0, "planes must start at 0");
            self.prev = Some((z, plane));
            return None;
        };
        assert_eq!(pz + 1, z, "planes must come in order");
        let ny = self.grid.dims[1];
        // Rows in parallel, each with its vertices deduplicated per label;
        // then one sequential pass numbers each new vertex in its label's
        // mesh (a lookup per row vertex, not per triangle corner).
        let rows = ny.saturating_sub(1);
        let sizes = &self.band_sizes;
        let layer = Layer {
            lo: &lo,
            hi: &plane,
            exact,
        };
        if self.one_label {
            self.edges.fit(self.grid.dims);
        }
        let below = self.edges.below();
        let bands: Vec<(BandMesh, BandFlats, (usize, usize))> = (0..rows.div_ceil(BAND))
            .into_par_iter()
            .map_init(
                || self.scratch_pool.lend(),
                |scratch, b| {
                    let js = b * BAND..((b + 1) * BAND).min(rows);
                    let hint = sizes
                        .get(b)
                        .map_or((0, 0), |&(t, f)| (t + t / 8, f + f / 8));
                    let (slots, memo) = &mut **scratch;
                    memo.begin(pz, js.start, BAND + 1, self.grid.dims[0]);
                    let (mesh, flats) = self.band(pz, js, layer, hint, (slots, below), memo);
                    let made = (mesh.tris.len(), flats.at.len());
                    (mesh, flats, made)
                },
            )
            .collect();
        self.band_sizes = bands.iter().map(|b| b.2).collect();
        if let Some(n) = &mut self.counted {
            *n += bands.iter().map(|b| b.0.tris.len()).sum::<usize>();
            self.prev = Some((z, plane));
            return Some(lo);
        }
        let mut global = Vec::new();
        if self.one_label {
            self.edges.begin_upper(self.grid.dims);
        }
        for (row, _, _) in &bands {
            global.clear();
            for &(label, key, pos) in &row.verts {
                global.push(self.index_of(pz, label, VRef { key, pos }));
            }
            for &(label, t) in &row.tris {
                self.meshes[label as usize - 1]
                    .triangles
                    .push(t.map(|i| PlaneEdges::index(i, &global)));
            }
        }
        if self.merge {
            let flats: Vec<BandFlats> = bands.into_iter().map(|r| r.1).collect();
            self.flat_layer(pz, layer, flats);
        }
        for m in &mut self.maps {
            m.swap(0, 1);
            m[1].clear();
        }
        self.edges.next_layer();
        self.prev = Some((z, plane));
        Some(lo)
    }

    /// Triangles made so far (flat regions are triangulated by `finish`).
    pub fn triangles(&self) -> usize {
        self.counted.unwrap_or(0) + self.meshes.iter().map(|m| m.triangles.len()).sum::<usize>()
    }

    /// Index in `label`'s mesh of vertex `v` (added when new), for the
    /// cube layer above plane `pz`.
    fn index_of(&mut self, pz: usize, label: u16, v: VRef) -> u32 {
        let l = label as usize - 1;
        let plane_len = (self.grid.dims[0] * self.grid.dims[1]) as u64;
        let sample = v.key / KEY_TYPES;
        // The key's sample lies in plane pz or pz + 1 (slot 0 or 1): a
        // compare, where dividing by the plane's length was a hardware
        // division a vertex.
        let rel = sample - pz as u64 * plane_len;
        let slot = usize::from(rel >= plane_len);
        let mesh = &mut self.meshes[l];
        let add = || {
            mesh.vertices.push(v.pos);
            (mesh.vertices.len() - 1) as u32
        };
        if !self.one_label {
            return *self.maps[l][slot].entry(v.key).or_insert_with(add);
        }
        let at = (rel - slot as u64 * plane_len) as usize;
        self.edges.find_or(slot, at, v.key % KEY_TYPES, add)
    }

    /// The meshes, label 1 first (flat regions triangulated now; a region
    /// that falls back to marching tetrahedra takes its cubes' samples
    /// again from `samples`).
    pub fn finish(mut self, samples: &SampleAt) -> Vec<IndexedMesh> {
        let regions = std::mem::replace(&mut self.regions, Regions::new(0));
        let mut meshes = std::mem::take(&mut self.meshes);
        let contour = |cube: &Cube, out: &mut Vec<Tri>| {
            let mut scratch = Scratch::default();
            self.contour_cube(cube, &mut scratch, out);
        };
        regions.finish(&mut meshes, &contour, samples);
        meshes
    }

    /// Triangles of the cubes in rows `js` between planes `z` and `z + 1`,
    /// over the band's own vertices, and the band's flat cubes (left for
    /// [`Self::flat_layer`]).
    fn band(
        &self,
        z: usize,
        js: std::ops::Range<usize>,
        layer: Layer,
        (tris, flat): (usize, usize),
        (slots, below): (&mut Stamped, &PlaneEdges),
        corners: &mut CornerMemo,
    ) -> (BandMesh, BandFlats) {
        let nx = self.grid.dims[0];
        let mut out = Vec::with_capacity(if self.one_label { 0 } else { tris });
        let mut one = self
            .one_label
            .then(|| OneLabelBand::new(js.start, nx, tris, slots, below));
        let mut flats = BandFlats::with_capacity(flat, self.grid.dims);
        let mut scratch = Scratch::default();
        let mut memo = FlatMemo::default();
        let (lo, hi) = (layer.lo, layer.hi);
        let (words, bits) = (nx.div_ceil(64), !lo.bits.is_empty() && !hi.bits.is_empty());
        let mut xs = Vec::new();
        for j in js {
            xs.clear();
            if bits {
                push_mixed_from_bits(around(&lo.bits, &hi.bits, j, words), nx, &mut xs);
            } else {
                xs.extend(mixed_cubes(around(&lo.label, &hi.label, j, nx)));
            }
            for &i in &xs {
                let cube = self.cube([i, j, z], layer, corners);
                if self.merge
                    && let Some(key) = memo.key(self.grid.voxel, self.iface, &cube)
                {
                    let mask = corner_mask(&cube, key.x);
                    flats.at.push(([j, i], key, mask));
                    flats.kept.push(cube.base, mask);
                    continue;
                }
                match &mut one {
                    Some(one) => self.loops_into(&cube, &mut scratch, one),
                    None => self.contour_cube(&cube, &mut scratch, &mut out),
                }
            }
        }
        let mesh = match one {
            Some(one) => one.mesh,
            None => BandMesh::new(out),
        };
        (mesh, flats)
    }

    /// Register one layer's flat cubes: join them with flat neighbours of
    /// the same key (left, front, below) and give each region the cut
    /// segments of its faces shared with anything else. Faces towards the
    /// next layer are settled when that layer comes.
    fn flat_layer(&mut self, pz: usize, layer: Layer, flats: Vec<BandFlats>) {
        let [nx, ny, _] = self.grid.dims;
        let mut memo = std::mem::take(&mut self.layer_memo);
        memo.begin(pz, 0, ny, nx);
        let (cw, ch) = (nx - 1, ny - 1);
        let mut cur = std::mem::take(&mut self.spare_flat);
        if cur.len() != cw * ch {
            cur = vec![NOT_FLAT; cw * ch];
        }
        // (cube, corners labelled x as a bit mask)
        let mut list = std::mem::take(&mut self.spare_list);
        for band in flats {
            let first = self
                .regions
                .add_band(band.at.iter().map(|a| a.1), band.kept);
            for (id, &([j, i], _, mask)) in (first..).zip(&band.at) {
                cur[j * cw + i] = id;
                list.push((j * cw + i, mask));
            }
        }
        if self.prev_flat.len() != cur.len() {
            self.prev_flat = vec![NOT_FLAT; cur.len()];
        }
        for &(c, mask) in &list {
            let (i, j) = (c % cw, c / cw);
            let id = cur[c];
            let key = self.regions.key_id(id);
            let mut cube = None;
            // Only the faces the cut crosses (two to four of the five), in
            // the order left, right, front, back, below.
            let mut cuts = CUT_FACES[mask as usize];
            while cuts != 0 {
                let f = cuts.trailing_zeros() as usize;
                cuts &= cuts - 1;
                let (axis, side) = (f >> 1, (f & 1) as u8);
                let nb = match f {
                    0 if i > 0 => cur[c - 1],
                    1 if i + 1 < cw => cur[c + 1],
                    2 if j > 0 => cur[c - cw],
                    3 if j + 1 < ch => cur[c + cw],
                    4 => self.prev_flat[c],
                    _ => NOT_FLAT,
                };
                if nb != NOT_FLAT && self.regions.key_id(nb) == key {
                    if side == 0 {
                        self.regions.union(id, nb);
                    }
                    continue;
                }
                let cube = cube.get_or_insert_with(|| self.cube([i, j, pz], layer, &mut memo));
                self.outline(pz, id, cube, axis, side, false);
            }
        }
        // Top faces of the layer below, against this layer's cubes.
        let below = std::mem::take(&mut self.prev_list);
        for &(c, mask) in &below {
            let id = self.prev_flat[c];
            if !face_cut(mask, 2, 1)
                || (cur[c] != NOT_FLAT && self.regions.key_id(cur[c]) == self.regions.key_id(id))
            {
                continue;
            }
            let cube = self.cube([c % cw, c / cw, pz], layer, &mut memo);
            self.outline(pz, id, &cube, 2, 0, true);
        }
        let mut old = std::mem::replace(&mut self.prev_flat, cur);
        for &(c, _) in &below {
            old[c] = NOT_FLAT;
        }
        self.spare_flat = old;
        self.spare_list = below;
        self.spare_list.clear();
        self.prev_list = list;
        self.layer_memo = memo;
    }

    /// Add the cut of `cube`'s face (`axis`, `side`) to region `id`'s
    /// outline, oriented as seen from `cube` (or from the cube across the
    /// face when `reverse`).
    fn outline(&mut self, pz: usize, id: u32, cube: &Cube, axis: usize, side: u8, reverse: bool) {
        let key = self.regions.key(id);
        if self.one_label {
            for (a, b) in cube_loops::face_segments(corner_mask(cube, key.x), axis, side) {
                let (a, b) = if reverse { (b, a) } else { (a, b) };
                let r = [a, b].map(|p| self.resolve(cube, 0, &[0; 4], p));
                let xi = r.map(|r| self.index_of(pz, key.x, r));
                self.regions.add_edge(id, r.map(|r| r.key), xi, [0; 2]);
            }
            return;
        }
        for perm in 0..6 {
            let v = tet_corners(perm);
            let lab = v.map(|m| cube.label[m as usize]);
            for f in FACES {
                let corners = f.map(|i| v[i]);
                if corners.iter().any(|m| m >> axis & 1 != side) {
                    continue;
                }
                let Some(odd) = odd_one_out(corners, f.map(|i| lab[i])) else {
                    continue;
                };
                let Some(&(_, mut a, mut b)) = two_label_cut(odd).iter().find(|c| c.0 == key.x)
                else {
                    continue;
                };
                if reverse {
                    std::mem::swap(&mut a, &mut b);
                }
                let (ra, rb) = (
                    self.resolve(cube, perm, &v, a),
                    self.resolve(cube, perm, &v, b),
                );
                let xi = [ra, rb].map(|r| self.index_of(pz, key.x, r));
                let yi = if key.y == 0 {
                    [0; 2]
                } else {
                    [ra, rb].map(|r| self.index_of(pz, key.y, r))
                };
                self.regions.add_edge(id, [ra.key, rb.key], xi, yi);
            }
        }
    }

    pub(super) fn global(&self, c: [usize; 3]) -> u64 {
        let [nx, ny, _] = self.grid.dims;
        ((c[2] * ny + c[1]) * nx + c[0]) as u64
    }

    pub(super) fn center(&self, c: [usize; 3]) -> DVec3 {
        self.grid.center(c[0], c[1], c[2])
    }

    /// Edge parameter from corner `a` (the lower) to `b`.
    fn crossing(&self, cube: &Cube, a: u8, b: u8) -> f64 {
        let (a, b) = (a as usize, b as usize);
        let (la, lb) = (cube.label[a], cube.label[b]);
        let cut = |c: usize| cut_field(self.iface, la, lb, cube.dist[c], cube.value[c]);
        let t = match (cut(a), cut(b)) {
            (Some(ga), Some(gb)) => ga / (ga - gb),
            _ => 0.5,
        };
        if t.is_finite() {
            t.clamp(T_MIN, 1.0 - T_MIN)
        } else {
            0.5
        }
    }

    fn edge_pos(&self, cube: &Cube, a: u8, b: u8) -> DVec3 {
        let (pa, pb) = (
            self.center(Self::corner(cube, a)),
            self.center(Self::corner(cube, b)),
        );
        pa + (pb - pa) * self.crossing(cube, a, b)
    }

    /// Where a point joining three or four labels goes (a three-label
    /// face's or a tet's): the centroid of the cut `edges`' points, or,
    /// when some of them end in void, of those alone. Those lie on the
    /// outer surface, so the rim where an interface meets it stays on that
    /// surface; the centroid of every point lies inside the part and cut a
    /// groove along each interface's rim.
    fn junction(&self, cube: &Cube, edges: impl Iterator<Item = (u8, u8)>) -> DVec3 {
        let (mut all, mut n) = (DVec3::ZERO, 0.0);
        let (mut outer, mut m) = (DVec3::ZERO, 0.0);
        for (a, b) in edges {
            let p = self.edge_pos(cube, a, b);
            all += p;
            n += 1.0;
            if cube.label[a as usize] == 0 || cube.label[b as usize] == 0 {
                outer += p;
                m += 1.0;
            }
        }
        if m > 0.0 { outer / m } else { all / n }
    }

    /// Key and position of a point of tet `perm` (corners `v`).
    pub(super) fn resolve(&self, cube: &Cube, perm: usize, v: &[u8; 4], p: Pt) -> VRef {
        let (key, pos) = match p {
            Pt::Edge(a, b) => {
                let key = self.global(Self::corner(cube, a)) * KEY_TYPES + u64::from(b & !a);
                (key, self.edge_pos(cube, a, b))
            }
            Pt::Face(a, b, c) => {
                let key = self.global(Self::corner(cube, a)) * KEY_TYPES
                    + FACE_KEY
                    + u64::from(b ^ a) * 8
                    + u64::from(c ^ a);
                (
                    key,
                    self.junction(cube, [(a, b), (b, c), (a, c)].into_iter()),
                )
            }
            Pt::Tet => {
                let key = self.global(cube.base) * KEY_TYPES + TET_KEY + perm as u64;
                let edges = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)]
                    .into_iter()
                    .map(|(x, y)| by_inclusion(v[x], v[y]))
                    .filter(|&(a, b)| cube.label[a as usize] != cube.label[b as usize]);
                (key, self.junction(cube, edges))
            }
        };
        VRef {
            key,
            pos: pos.as_vec3().to_array(),
        }
    }

    /// Contour one cube into `out`: as marching cubes with one label, tet
    /// by tet with more.
    fn contour_cube(&self, cube: &Cube, scratch: &mut Scratch, out: &mut Vec<Tri>) {
        if !self.one_label {
            for perm in 0..6 {
                self.tet(cube, perm, scratch, out);
            }
            return;
        }
        self.loops_to_tris(cube, scratch, out);
    }

    /// Contour tet `perm` of `cube` into `out` (`scratch`: buffers reused
    /// from tet to tet, so the hot loop does not allocate).
    fn tet(&self, cube: &Cube, perm: usize, scratch: &mut Scratch, out: &mut Vec<Tri>) {
        let v = tet_corners(perm);
        let lab = v.map(|m| cube.label[m as usize]);
        if lab.iter().all(|l| *l == lab[0]) {
            return;
        }
        let mut distinct = [lab[0]; 4];
        let mut nd = 1;
        for l in &lab[1..] {
            if !distinct[..nd].contains(l) {
                distinct[nd] = *l;
                nd += 1;
            }
        }
        // Oriented curve segments on the faces, per label: (label, from, to)
        // with the label's region on the left seen from outside the tet.
        let Scratch {
            segs,
            mine,
            ring,
            refs,
        } = scratch;
        segs.clear();
        for f in FACES {
            let [u, w, x] = f.map(|i| v[i]);
            let [lu, lw, lx] = f.map(|i| lab[i]);
            if lu == lw && lw == lx {
                continue;
            }
            match odd_one_out([u, w, x], [lu, lw, lx]) {
                Some(odd) => segs.extend(two_label_cut(odd)),
                None => {
                    let (a, b) = by_inclusion(u, w);
                    let (b, c) = by_inclusion(b, x);
                    let (a, b) = by_inclusion(a, b);
                    let face = Pt::Face(a, b, c);
                    for (o, p, s, lo) in [(u, x, w, lu), (w, u, x, lw), (x, w, u, lx)] {
                        segs.push((lo, edge(p, o), face));
                        segs.push((lo, face, edge(o, s)));
                    }
                }
            }
        }
        let res = |p: Pt| self.resolve(cube, perm, &v, p);
        if nd == 2 {
            // One interface: chain the first non-void label's segments into
            // a loop and fan it; the other label gets the reverse.
            let (x, y) = front_back(distinct[0], distinct[1]);
            mine.clear();
            mine.extend(segs.iter().filter(|s| s.0 == x).map(|s| (s.1, s.2)));
            if chain(mine, ring) {
                refs.clear();
                refs.extend(ring.iter().map(|p| res(*p)));
                for i in 1..refs.len() - 1 {
                    let t = [refs[0], refs[i], refs[i + 1]];
                    out.push(Tri { label: x, v: t });
                    if y != 0 {
                        out.push(Tri {
                            label: y,
                            v: [t[0], t[2], t[1]],
                        });
                    }
                }
                return;
            }
            debug_assert!(false, "two-label tet without a single loop: {lab:?}");
        }
        let apex = res(Pt::Tet);
        for &(l, a, b) in segs.iter() {
            if l != 0 {
                out.push(Tri {
                    label: l,
                    v: [res(a), res(b), apex],
                });
            }
        }
    }
}

/// Buffers one row's tets reuse.
#[derive(Default)]
pub(super) struct Scratch {
    /// Oriented curve segments on the tet's faces: (label, from, to).
    segs: Vec<(u16, Pt, Pt)>,
    /// One label's segments.
    mine: Vec<(Pt, Pt)>,
    /// Their loop.
    ring: Vec<Pt>,
    /// The loop's vertices.
    pub refs: Vec<VRef>,
}
