//! What the viewport shows: camera, mode, cut plane, per-material opacity,
//! overlays. Plain data, cheap to clone every frame.

use crate::camera::Camera;

/// How the volume is drawn.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ViewMode {
    /// Opaque lit surface coloured by the mixed material colour.
    Solid,
    /// Translucent accumulation through the part (see gradients inside);
    /// each material's density is scaled by its opacity.
    Volume,
    /// The surface where the fraction of model material `material_index`
    /// (index into `Model::materials()`) equals `level` (0..1), clipped to
    /// the part.
    Iso {
        /// Index into `Model::materials()`.
        material_index: usize,
        /// Fraction level, 0..1.
        level: f32,
    },
}

/// A cut plane perpendicular to an axis; the part on one side is removed
/// and the cut face shows the material colours inside.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CutPlane {
    /// 0 = x, 1 = y, 2 = z.
    pub axis: usize,
    /// Plane position along the axis (mm, world coordinates).
    pub offset: f32,
    /// Keep the part below the plane (`coord ≤ offset`); otherwise above.
    pub keep_below: bool,
}

impl CutPlane {
    /// Signed distance of `p` to the kept half-space (negative inside it).
    pub fn distance(&self, p: [f64; 3]) -> f64 {
        let c = p[self.axis.min(2)] - self.offset as f64;
        if self.keep_below { c } else { -c }
    }
}

/// Everything the viewport needs besides the baked volume.
#[derive(Clone, Debug, PartialEq)]
pub struct ViewSettings {
    /// The camera.
    pub camera: Camera,
    /// Drawing mode.
    pub mode: ViewMode,
    /// Optional cut plane.
    pub cut: Option<CutPlane>,
    /// Opacity per model material (index = position in
    /// `Model::materials()`); 0 hides the material, missing entries are 1.
    /// Solid and Iso modes only distinguish hidden (0) from shown (> 0);
    /// Volume mode scales density by it.
    pub material_opacity: Vec<f32>,
    /// Draw the model's bounding box edges.
    pub show_bbox: bool,
    /// Draw a ground grid under the part (z = bbox min).
    pub show_grid: bool,
    /// Draw an axis triad in the lower-left corner (x red, y green, z blue).
    pub show_axes: bool,
    /// Background colour, linear RGBA 0..1 (written as is to the target).
    pub background: [f32; 4],
    /// Share of the viewport's width and height that is ray-marched (0.05..1);
    /// below 1 the image is rendered smaller and upscaled. Use about 0.5 on a
    /// software renderer (lavapipe) or while the camera moves, 1 when still.
    pub render_scale: f32,
    /// Volume mode: multiplies the optical depth (1 = an average ray through
    /// a solid part keeps e^-1.5 of the light behind it; more shows the
    /// surface layers, less sees deeper).
    pub volume_density: f32,
}

impl Default for ViewSettings {
    fn default() -> Self {
        ViewSettings {
            camera: Camera::default(),
            mode: ViewMode::Solid,
            cut: None,
            material_opacity: Vec::new(),
            show_bbox: true,
            show_grid: true,
            show_axes: true,
            background: [0.13, 0.14, 0.16, 1.0],
            render_scale: 1.0,
            volume_density: 1.0,
        }
    }
}

impl ViewSettings {
    /// Settings with `camera` and no overlays (what tests and the CLI use).
    pub fn plain(camera: Camera) -> Self {
        ViewSettings {
            camera,
            show_bbox: false,
            show_grid: false,
            show_axes: false,
            ..Default::default()
        }
    }

    /// Opacity of model material `i` (1 when not listed).
    pub fn opacity(&self, i: usize) -> f32 {
        self.material_opacity
            .get(i)
            .copied()
            .unwrap_or(1.0)
            .clamp(0.0, 1.0)
    }
}
