//! The contourer's one-label path: each cube's marching-cubes loops (see
//! [`super::cube_loops`]) fanned into triangles. Within a band of rows,
//! each grid edge's point is placed once and found again by its edge's
//! slot, not by hashing its key: four cubes share each grid edge. A point
//! on an x or y edge of the layer's lower plane, placed by the layer
//! below, is taken from it as a vertex of the mesh ([`PlaneEdges`]).

use glam::DVec3;

use super::band_scratch::Stamped;
use super::contour::{BAND, Contourer, KEY_TYPES, LOOP_KEY, Scratch};
use super::cube_loops;
use super::interface::{Cube, corner_mask};
use super::kuhn::Pt;
use super::vertex_keys::{BandMesh, Tri, VRef};

impl Contourer {
    /// [`Contourer::contour_cube`] with one label: the cube's
    /// marching-cubes loops, each fanned into triangles.
    pub(super) fn loops_to_tris(&self, cube: &Cube, scratch: &mut Scratch, out: &mut Vec<Tri>) {
        for (n, l) in cube_loops::case(corner_mask(cube, 1)).iter().enumerate() {
            let refs = &mut scratch.refs;
            refs.clear();
            refs.extend(l.points.iter().map(|p| self.resolve(cube, 0, &[0; 4], *p)));
            let apex = match l.apex {
                Some(a) => a,
                None => {
                    refs.push(self.loop_centre(cube, n, refs));
                    refs.len() - 1
                }
            };
            for [a, i, j] in fan(l.points.len(), apex) {
                out.push(Tri {
                    label: 1,
                    v: [refs[a], refs[i], refs[j]],
                });
            }
        }
    }

    /// The point a loop without an apex is fanned from: the loop's
    /// centroid, a quarter of the way to the cube's centre (a loop on one
    /// face's four edges, a sheet across that face, has its centroid on the
    /// face, where the cube across may put its own).
    fn loop_centre(&self, cube: &Cube, n: usize, points: &[VRef]) -> VRef {
        let mid = (self.center(cube.base) + self.center(Self::corner(cube, 7))) * 0.5;
        let k = points.len() as f64;
        let mut c = DVec3::ZERO;
        for r in points {
            c += DVec3::from(r.pos.map(f64::from)) / k;
        }
        VRef {
            key: self.global(cube.base) * KEY_TYPES + LOOP_KEY + n as u64,
            pos: (c * 0.75 + mid * 0.25).as_vec3().to_array(),
        }
    }

    /// [`Self::contour_cube`]'s loops for one label, straight into the
    /// band's mesh: an edge point's position is computed only the first
    /// time the band uses it (four cubes share each grid edge), and the
    /// vertices come in the order `BandMesh::new` gives them (first use by
    /// a triangle corner).
    pub(super) fn loops_into(&self, cube: &Cube, scratch: &mut Scratch, band: &mut OneLabelBand) {
        for (n, l) in cube_loops::case(corner_mask(cube, 1)).iter().enumerate() {
            let k = l.points.len();
            if let Some(apex) = l.apex {
                // Each point is looked up once, in the order the fan's
                // corners first use them (the apex, then around the loop),
                // not once per corner.
                let mut v = [0u32; MAX_LOOP];
                for d in 0..k {
                    let m = (apex + d) % k;
                    v[m] = band.vertex(self, cube, l.points[m], None);
                }
                for t in fan(k, apex) {
                    band.mesh.tris.push((1, t.map(|m| v[m])));
                }
                continue;
            }
            // Rare: every point's position is needed for the centre.
            let refs = &mut scratch.refs;
            refs.clear();
            refs.extend(l.points.iter().map(|p| self.resolve(cube, 0, &[0; 4], *p)));
            let centre = self.loop_centre(cube, n, refs);
            let mut centre_at = None;
            for t in fan(k, k) {
                let v = t.map(|m| match l.points.get(m) {
                    Some(&p) => band.vertex(self, cube, p, Some(refs[m])),
                    None => *centre_at.get_or_insert_with(|| band.push(centre)),
                });
                band.mesh.tris.push((1, v));
            }
        }
    }
}

/// Most points in a marching-cubes loop: a cube has twelve edges.
const MAX_LOOP: usize = 12;

/// The triangles `(apex, i, j)` of the fan over a loop of `k` points from
/// `apex`: the loop's own points skip it and its two neighbours; an added
/// centre (`apex == k`) closes the whole loop.
fn fan(k: usize, apex: usize) -> impl Iterator<Item = [usize; 3]> {
    let steps = if apex == k { k } else { k - 2 };
    let first = if apex == k { 0 } else { apex + 1 };
    (0..steps).map(move |d| [apex, (first + d) % k, (first + d + 1) % k])
}

/// One band's mesh as the one-label path builds it: an edge point is found
/// by its edge's slot, not by hashing its key.
pub(super) struct OneLabelBand<'a> {
    pub mesh: BandMesh,
    /// First row of cubes.
    j0: usize,
    nx: usize,
    /// Vertex index per grid edge of the band: two planes of `BAND + 1`
    /// rows, three directions.
    slots: &'a mut Stamped,
    /// The mesh's vertices on the lower plane's x and y edges.
    below: &'a PlaneEdges,
}

impl<'a> OneLabelBand<'a> {
    pub fn new(
        j0: usize,
        nx: usize,
        tris: usize,
        slots: &'a mut Stamped,
        below: &'a PlaneEdges,
    ) -> Self {
        slots.begin(2 * (BAND + 1) * nx * 3);
        OneLabelBand {
            mesh: BandMesh {
                verts: Vec::with_capacity(tris / 2),
                tris: Vec::with_capacity(tris),
            },
            j0,
            nx,
            slots,
            below,
        }
    }

    /// Index of point `p` of `cube` (placed now when new, or given as
    /// `placed`); an edge point is looked up by its edge's slot.
    fn vertex(&mut self, c: &Contourer, cube: &Cube, p: Pt, placed: Option<VRef>) -> u32 {
        let Pt::Edge(a, b) = p else {
            // (Marching-cubes loops hold edge points only.)
            return self.push(placed.unwrap_or_else(|| c.resolve(cube, 0, &[0; 4], p)));
        };
        let [i, j, _] = cube.base;
        let (ci, cj, ck) = (
            i + usize::from(a & 1),
            j + usize::from(a >> 1 & 1) - self.j0,
            usize::from(a >> 2 & 1),
        );
        let dir = (b & !a).trailing_zeros() as usize;
        let s = ((ck * (BAND + 1) + cj) * self.nx + ci) * 3 + dir;
        if let Some(v) = self.slots.get(s) {
            return v;
        }
        if ck == 0
            && dir < 2
            && let Some(v) = self.below.get(ci, cj + self.j0, self.nx, dir)
        {
            self.slots.set(s, v);
            return v;
        }
        let r = placed.unwrap_or_else(|| c.resolve(cube, 0, &[0; 4], p));
        let v = self.push(r);
        self.slots.set(s, v);
        v
    }

    fn push(&mut self, r: VRef) -> u32 {
        self.mesh.verts.push((1, r.key, r.pos));
        (self.mesh.verts.len() - 1) as u32
    }
}

/// Marks a triangle corner that is a vertex of the mesh already (its index
/// in the mesh), not one of the band's new vertices.
const KNOWN: u32 = 1 << 31;

/// The one-label mesh's vertices on the grid edges of the current cube
/// layer, by edge: every one-label point lies on a grid edge (or is a
/// loop's centre, which only its cube uses), so the contourer finds a
/// point's vertex here by index, with no key map.
#[derive(Default)]
pub(super) struct LayerEdges {
    /// The x and y edges of the lower plane (placed by the layer below)
    /// and of the upper plane.
    planes: [PlaneEdges; 2],
    /// The z edges between them, by the edge's lower sample.
    z: Stamped,
}

impl LayerEdges {
    /// Sized for planes of `dims`, keeping the lower plane's vertices.
    pub fn fit(&mut self, dims: [usize; 3]) {
        self.planes[0].fit(dims);
    }

    /// The lower plane's x and y edges.
    pub fn below(&self) -> &PlaneEdges {
        &self.planes[0]
    }

    /// Nothing set yet on the upper plane and the z edges.
    pub fn begin_upper(&mut self, dims: [usize; 3]) {
        self.planes[1].begin(dims);
        self.z.begin(dims[0] * dims[1]);
    }

    /// The vertex of the point keyed `kind` (see [`Contourer::resolve`])
    /// at sample `at` of the lower (`plane` 0) or upper (1) plane, or
    /// `add()`'s, remembered there.
    pub fn find_or(
        &mut self,
        plane: usize,
        at: usize,
        kind: u64,
        add: impl FnOnce() -> u32,
    ) -> u32 {
        match kind {
            1 | 2 => self.planes[plane].find_or(at, kind as usize - 1, add),
            4 => {
                debug_assert_eq!(plane, 0, "a z edge starts on the lower plane");
                self.z.find_or(at, add)
            }
            _ => add(),
        }
    }

    /// The upper plane becomes the next layer's lower plane.
    pub fn next_layer(&mut self) {
        self.planes.swap(0, 1);
    }
}

/// The one-label mesh's vertices on the x and y grid edges of one plane, by
/// edge. Each such edge is shared by the cube layers below and above the
/// plane: the layer below places its point, and the layer above takes that
/// vertex from here rather than placing the point again and finding its
/// key in the contourer's map. (What is found is what the map holds for
/// the key: the vertices, their order and the triangles do not change.)
#[derive(Default)]
pub(super) struct PlaneEdges(Stamped);

impl PlaneEdges {
    /// Sized for planes of `dims`, keeping what is set.
    pub fn fit(&mut self, [nx, ny, _]: [usize; 3]) {
        if self.0.slots() != 2 * nx * ny {
            self.0.begin(2 * nx * ny);
        }
    }

    /// A new plane of `dims`, nothing set.
    pub fn begin(&mut self, [nx, ny, _]: [usize; 3]) {
        self.0.begin(2 * nx * ny);
    }

    /// The vertex on the edge from sample `at` (index in the plane) along
    /// x (`dir` 0) or y (1), or `add()`'s, remembered there.
    pub fn find_or(&mut self, at: usize, dir: usize, add: impl FnOnce() -> u32) -> u32 {
        let v = self.0.find_or(at * 2 + dir, add);
        debug_assert!(v < KNOWN, "vertex index {v}");
        v
    }

    /// The vertex on the edge from sample `(i, j)` along x (`dir` 0) or y
    /// (1), marked as known.
    pub fn get(&self, i: usize, j: usize, nx: usize, dir: usize) -> Option<u32> {
        self.0.get((j * nx + i) * 2 + dir).map(|v| v | KNOWN)
    }

    /// A band triangle's corner `i` as a mesh index: a known vertex's own,
    /// or the index `band` gives the band's new vertex `i`.
    pub fn index(i: u32, band: &[u32]) -> u32 {
        if i & KNOWN != 0 {
            i & !KNOWN
        } else {
            band[i as usize]
        }
    }
}

#[cfg(test)]
mod tests {
    use volcad_core::bench::XorShift;
    use volcad_core::sampler::Grid;

    use super::*;
    use crate::mesh::interface::Interface;

    /// Two bands of random cubes (every one of the 256 corner cases many
    /// times, with loops that need a centre): the band path gives exactly
    /// the mesh that deduplicating the triangle path's output gives, the
    /// same vertices in the same order and the same triangles.
    #[test]
    fn the_band_path_matches_deduplicating_the_triangle_path() {
        let nx = 40;
        let grid = Grid {
            origin: DVec3::new(-1.0, 2.0, 0.5),
            voxel: DVec3::new(0.5, 0.4, 0.3),
            dims: [nx, 2 * BAND + 1, 2],
        };
        let c = Contourer::new(grid, 1, Interface::Midpoint);
        let mut rng = XorShift::new(11);
        let mut slots = Stamped::default();
        let mut centres = 0;
        for j0 in [0, BAND] {
            // Corner samples of this band: labels and distances whose
            // sign agrees with the label (inside at or below zero).
            let corners = |rng: &mut XorShift| -> ([u16; 8], [f32; 8]) {
                let mut label = [0; 8];
                let mut dist = [0.0; 8];
                for (l, d) in label.iter_mut().zip(&mut dist) {
                    *l = u16::from(rng.next_f64() < 0.5);
                    let mag = (rng.next_f64() * 0.4 + 0.01) as f32;
                    *d = if *l == 1 { -mag } else { mag };
                }
                (label, dist)
            };
            let mut below = PlaneEdges::default();
            below.fit(grid.dims);
            let mut band = OneLabelBand::new(j0, nx, 0, &mut slots, &below);
            let mut tris = Vec::new();
            let mut scratch = Scratch::default();
            for j in j0..j0 + BAND {
                for i in 0..nx - 1 {
                    let (label, dist) = corners(&mut rng);
                    let cube = Cube {
                        base: [i, j, 0],
                        label,
                        dist,
                        value: [&[]; 8],
                    };
                    let mask = corner_mask(&cube, 1);
                    centres += cube_loops::case(mask)
                        .iter()
                        .filter(|l| l.apex.is_none())
                        .count();
                    c.loops_into(&cube, &mut scratch, &mut band);
                    c.loops_to_tris(&cube, &mut scratch, &mut tris);
                }
            }
            let want = BandMesh::new(tris);
            assert_eq!(band.mesh.tris, want.tris, "band at row {j0}");
            let bits = |v: &[(u16, u64, [f32; 3])]| -> Vec<(u16, u64, [u32; 3])> {
                v.iter()
                    .map(|&(l, k, p)| (l, k, p.map(f32::to_bits)))
                    .collect()
            };
            assert_eq!(bits(&band.mesh.verts), bits(&want.verts), "band at {j0}");
        }
        assert!(centres > 0, "no loop without an apex was drawn");
    }

    /// A random field over several layers and bands, contoured plane by
    /// plane: the vertices a layer takes from the one below
    /// ([`PlaneEdges`]) leave the mesh exactly what deduplicating every
    /// cube's triangles by key gives, the same vertices in the same order
    /// and the same triangles.
    #[test]
    fn layers_take_their_lower_plane_vertices_from_below() {
        let [nx, ny, nz] = [12, 2 * BAND + 4, 6];
        let grid = Grid {
            origin: DVec3::new(0.5, -1.0, 2.0),
            voxel: DVec3::new(0.3, 0.5, 0.4),
            dims: [nx, ny, nz],
        };
        let mut rng = XorShift::new(5);
        let border = |i: usize, j: usize, k: usize| {
            i == 0 || j == 0 || k == 0 || i + 1 == nx || j + 1 == ny || k + 1 == nz
        };
        // Inside or outside at random, never exactly zero; the grid's
        // outer layer outside, as `contour_field` labels it.
        let mut values = vec![0.0f32; nx * ny * nz];
        for (v, d) in values.iter_mut().enumerate() {
            let (i, j, k) = (v % nx, v / nx % ny, v / (nx * ny));
            let mag = (rng.next_f64() * 0.4 + 0.01) as f32;
            *d = if !border(i, j, k) && rng.next_f64() < 0.5 {
                -mag
            } else {
                mag
            };
        }
        let c = Contourer::new(grid, 1, Interface::Midpoint).with_flat_merge(false);
        let mesh = crate::mesh::field::contour_field(c, &grid, &values);
        let c = Contourer::new(grid, 1, Interface::Midpoint);
        let mut tris = Vec::new();
        let mut scratch = Scratch::default();
        for k in 0..nz - 1 {
            for j in 0..ny - 1 {
                for i in 0..nx - 1 {
                    let at = |m: usize| {
                        let (a, b, e) = (i + (m & 1), j + (m >> 1 & 1), k + (m >> 2 & 1));
                        values[(e * ny + b) * nx + a]
                    };
                    let dist: [f32; 8] = std::array::from_fn(at);
                    let cube = Cube {
                        base: [i, j, k],
                        label: dist.map(|d| u16::from(d <= 0.0)),
                        dist,
                        value: [&[]; 8],
                    };
                    c.loops_to_tris(&cube, &mut scratch, &mut tris);
                }
            }
        }
        let want = BandMesh::new(tris);
        let bits = |p: [f32; 3]| p.map(f32::to_bits);
        let got: Vec<_> = mesh.vertices.iter().map(|p| bits(*p)).collect();
        let expected: Vec<_> = want.verts.iter().map(|v| bits(v.2)).collect();
        assert_eq!(got, expected, "vertices");
        let expected: Vec<[u32; 3]> = want.tris.iter().map(|t| t.1).collect();
        assert_eq!(mesh.triangles, expected, "triangles");
        assert!(mesh.is_watertight(), "{:?}", mesh.edge_report());
    }
}
