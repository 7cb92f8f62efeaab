//! What a consumer reads from the samples, which decides what the sampler
//! may leave out: fractions, exact distances near the surface, voxels
//! whose fractions a bound settles.

use crate::interval::Interval;

/// A consumer's test on fraction bounds: true when every fraction vector
/// within them means the same to it (a mesh export's segment label).
pub type UniformTest<'a> = &'a (dyn Fn(&[Interval]) -> bool + Sync);

/// Who reads a [`Sampler`](super::Sampler)'s samples. Every consumer gets
/// each voxel's exact sign; what else it gets follows from what it reads:
///
/// - **distances**: consumers that interpolate distances along grid edges
///   (meshers, the viewport's shading) get the exact distance of every
///   voxel within one voxel diagonal of the surface; consumers that read
///   signs only let a tile settle as soon as its bound excludes zero,
///   which leaves fewer voxels to evaluate and changes no sign. A mesh
///   export's contouring does too, and gets `±∞` (the sign kept) in the
///   voxels it left within one voxel diagonal: the contourer evaluates
///   those where a cube it cuts has one as a corner (see
///   [`Consumer::MeshContour`]).
/// - **fractions**: filled per voxel (`k` values, zero outside), or not at
///   all (`Slab::k` is 0). A mesh export reads no outside voxel's
///   fractions: its slab keeps whatever they held before.
#[derive(Clone, Copy)]
pub enum Consumer<'a> {
    /// The studio's viewport bake: distances and fractions of every voxel,
    /// written voxel by voxel. Also the reference the other consumers'
    /// tests compare with.
    ViewportBake,
    /// A slice stack with a liquid keep-out (and its check that something
    /// is left): as [`Consumer::ViewportBake`], since the keep-out measures
    /// how deep each inside voxel lies.
    PngStackKeepOut,
    /// A surface contoured from distances alone (GCVF's outline mesh): no
    /// fractions.
    SurfaceContour,
    /// A mesh export's contouring, whose `test` says where a segment label
    /// is constant. Tiles settle as soon as their bound excludes zero, as
    /// for signs-only consumers; a value not evaluated that may lie within
    /// one voxel diagonal of the surface is written as `±∞` with its sign
    /// (an *unevaluated* voxel). The contourer reads distances only at the
    /// corners of cubes whose signs differ, and every such corner lies
    /// within one voxel diagonal of the surface: it evaluates the corners
    /// that hold `±∞` there, and gets what sampling them would have given.
    /// Most voxels that a margin of one diagonal evaluates are corners of
    /// no such cube. Inside, where the design's fractions vary, tiles keep
    /// the margin of one diagonal (see `Sampler::settle`). A solid tile whose fraction bounds, over the tile grown
    /// by one voxel on every side, pass `test` gets its centre's fractions
    /// in every voxel (one evaluation instead of one per voxel); growing
    /// the box makes every neighbour of such a voxel agree too, so the mesh
    /// is the same as with every voxel sampled. Such tiles (and those of a
    /// fixed mix) are reported as [`SolidRect`](super::SolidRect)s in
    /// `Slab::rects`, with their voxels' entries in `Slab::fracs` left
    /// unwritten; so are the entries of outside voxels (the labels read
    /// fractions inside only). Tiles are first tried as blocks through every layer of
    /// the slab: a block that is empty, or solid with one fraction vector,
    /// is filled in every layer from one analysis, its skipped voxels
    /// holding the block's (looser) interval end, whose sign is all a
    /// mesher reads there.
    MeshContour(UniformTest<'a>),
    /// A mesh export whose labels come from the distances' signs alone
    /// (one segment of a design whose mix is fixed): as
    /// [`Consumer::MeshContour`], without fractions (`Slab::k` is 0) or
    /// rectangles. The distances written are the same bits: with its mix
    /// fixed, `MeshContour` evaluates no fraction either, and settles the
    /// same tiles with the same margins.
    MeshContourSigns,
    /// A slice stack of a design with one material everywhere: signs only.
    PngStackSingle,
    /// An error-diffusion slice stack: signs and every voxel's fractions.
    PngStackDiffusion,
    /// A randomly dithered slice stack: signs, and fractions only where
    /// the picks need them. A solid tile whose fractions vary, and which
    /// `Model::fraction_bounds` can bound, is listed in `Slab::rects`
    /// (with `NaN` fractions, its voxels' entries in `Slab::fracs` not
    /// written) instead of one evaluation per voxel; the consumer
    /// evaluates them where its bounds leave a pick open. Where fractions are averages (`Blend`),
    /// so are the inside voxels of bounded tiles that a surface crosses.
    /// For a design whose fractions never vary
    /// (`Model::varying_fractions`) this is [`Consumer::PngStackDiffusion`].
    PngStackRandom,
    /// A full-colour slice stack: signs, and every voxel's fractions (the
    /// materials' colours mix by them where no `color` attribute is set).
    PngStackFullColor,
    /// An FEA brick mesh: a brick is kept by the sign at its centre and
    /// takes its fractions there.
    FeaBricks,
    /// A coarse size estimate (volume, mixed voxels, surface crossings):
    /// signs and fractions.
    Estimate,
}

/// The sampler's options that follow from a [`Consumer`].
#[derive(Clone, Copy)]
pub(super) struct Needs<'a> {
    /// Fractions are filled.
    pub fracs: bool,
    /// Tiles settle once their bound excludes zero, not one voxel
    /// diagonal beyond it.
    pub signs_only: bool,
    /// The consumer's uniformity test on solid tiles.
    pub uniform: Option<UniformTest<'a>>,
    /// Solid tiles of one fraction vector go to `Slab::rects`.
    pub solid_rects: bool,
    /// Tiles are first tried as blocks through every layer.
    pub blocks: bool,
    /// Bounded varying fractions are left `NaN`.
    pub lazy: bool,
    /// Voxels beyond the margin may hold a bound from a neighbour's value
    /// (see `leaf`): consumers that read exact values only within the
    /// margin. Not the viewport bake (the reference), the keep-out (which
    /// reads how deep inside voxels lie) or GCVF's outline.
    pub lipschitz_skip: bool,
    /// Values written without evaluation within one voxel diagonal of zero
    /// are `±∞` (see [`Consumer::MeshContour`]).
    pub unevaluated_near: bool,
    /// Outside voxels' fractions are written (zero); false where the
    /// consumer never reads them (most of an imported mesh's box is
    /// outside, and zeroing is a store per voxel and material).
    pub outside_fracs: bool,
}

impl<'a> Consumer<'a> {
    /// What the sampler must write for this consumer.
    pub(super) fn needs(self) -> Needs<'a> {
        let plain = Needs {
            fracs: true,
            signs_only: false,
            uniform: None,
            solid_rects: false,
            blocks: false,
            lazy: false,
            lipschitz_skip: false,
            unevaluated_near: false,
            outside_fracs: true,
        };
        let signs = Needs {
            signs_only: true,
            lipschitz_skip: true,
            ..plain
        };
        let contour = Needs {
            blocks: true,
            unevaluated_near: true,
            outside_fracs: false,
            ..signs
        };
        match self {
            Consumer::ViewportBake | Consumer::PngStackKeepOut => plain,
            Consumer::SurfaceContour => Needs {
                fracs: false,
                ..plain
            },
            Consumer::MeshContour(test) => Needs {
                uniform: Some(test),
                solid_rects: true,
                ..contour
            },
            Consumer::MeshContourSigns => Needs {
                fracs: false,
                ..contour
            },
            Consumer::PngStackSingle => Needs {
                fracs: false,
                ..signs
            },
            Consumer::PngStackDiffusion
            | Consumer::PngStackFullColor
            | Consumer::FeaBricks
            | Consumer::Estimate => signs,
            Consumer::PngStackRandom => Needs {
                lazy: true,
                ..signs
            },
        }
    }
}
