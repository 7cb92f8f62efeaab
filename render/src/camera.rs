//! The orbit camera: a target point, a distance and two angles (z is up).
//!
//! The eye sits at `target + distance · (cos pitch cos yaw, cos pitch sin yaw,
//! sin pitch)`. The screen's right vector depends on yaw only, so the Top and
//! Bottom views (pitch ±90°) are well defined: x to the right, y up (Top).

use glam::{Mat4, Vec2, Vec3};
use volcad_core::Aabb;

/// The standard views of the View menu.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum StandardView {
    /// From the front-right, above (yaw −60°, pitch 30°).
    Iso,
    /// Looking down −z: x right, y up.
    Top,
    /// Looking along +y (from −y): x right, z up.
    Front,
    /// Looking along −x (from +x): y right, z up.
    Side,
    /// Looking up +z from below: x right, y down.
    Bottom,
}

/// An orbit camera (angles in radians, lengths in mm).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// The point the camera orbits and looks at.
    pub target: Vec3,
    /// Eye to target (mm). In orthographic mode it sets the visible height:
    /// `2 · distance · tan(fov_y / 2)`.
    pub distance: f32,
    /// Angle of the eye around z, from +x (radians).
    pub yaw: f32,
    /// Elevation of the eye above the xy plane, clamped to ±90° (radians).
    pub pitch: f32,
    /// Vertical field of view (radians).
    pub fov_y: f32,
    /// Parallel projection instead of perspective.
    pub orthographic: bool,
}

/// Radians of orbit per pixel of drag.
const ORBIT_PER_PIXEL: f32 = 0.008;

impl Default for Camera {
    fn default() -> Self {
        Camera::fit(
            &Aabb::new(glam::DVec3::splat(-10.0), glam::DVec3::splat(10.0)),
            StandardView::Iso,
        )
    }
}

impl Camera {
    /// A camera looking at `bbox` from `view`, far enough that the box's
    /// bounding sphere fits the view (perspective, 35° field of view).
    pub fn fit(bbox: &Aabb, view: StandardView) -> Camera {
        let (target, radius) = if bbox.is_empty() || !bbox.is_finite() {
            (Vec3::ZERO, 10.0)
        } else {
            (
                bbox.center().as_vec3(),
                (bbox.half_diagonal() as f32).max(1e-3),
            )
        };
        let d = std::f32::consts::PI / 180.0;
        let (yaw, pitch) = match view {
            StandardView::Iso => (-60.0 * d, 30.0 * d),
            StandardView::Top => (-90.0 * d, 90.0 * d),
            StandardView::Front => (-90.0 * d, 0.0),
            StandardView::Side => (0.0, 0.0),
            StandardView::Bottom => (-90.0 * d, -90.0 * d),
        };
        let fov_y = 35.0 * d;
        let mut cam = Camera {
            target,
            distance: 1.0,
            yaw,
            pitch,
            fov_y,
            orthographic: false,
        };
        cam.frame(radius);
        cam
    }

    /// Set the distance so a sphere of `radius` around the target fits.
    pub fn frame(&mut self, radius: f32) {
        self.distance = radius / (self.fov_y * 0.5).sin() * 1.02;
    }

    /// Unit vector from the target to the eye.
    pub fn back(&self) -> Vec3 {
        let (sy, cy) = self.yaw.sin_cos();
        let (sp, cp) = self.pitch.sin_cos();
        Vec3::new(cp * cy, cp * sy, sp)
    }

    /// The eye position.
    pub fn eye(&self) -> Vec3 {
        self.target + self.back() * self.distance
    }

    /// Orthonormal camera basis: (right, up, forward).
    pub fn basis(&self) -> (Vec3, Vec3, Vec3) {
        let (sy, cy) = self.yaw.sin_cos();
        let right = Vec3::new(-sy, cy, 0.0);
        let forward = -self.back();
        let up = right.cross(forward).normalize();
        (right, up, forward)
    }

    /// Half the visible height at the target's depth (mm).
    pub fn half_height_at_target(&self) -> f32 {
        self.distance * (self.fov_y * 0.5).tan()
    }

    /// Orbit by a mouse drag of `dx, dy` pixels (drag right turns the model
    /// right; drag down looks from higher up).
    pub fn orbit(&mut self, dx: f32, dy: f32) {
        self.yaw -= dx * ORBIT_PER_PIXEL;
        self.yaw = self.yaw.rem_euclid(std::f32::consts::TAU);
        self.pitch = (self.pitch + dy * ORBIT_PER_PIXEL)
            .clamp(-std::f32::consts::FRAC_PI_2, std::f32::consts::FRAC_PI_2);
    }

    /// Pan by a drag of `dx, dy` pixels in a viewport `viewport_h` pixels
    /// high: the point under the cursor follows it (at the target's depth).
    pub fn pan(&mut self, dx: f32, dy: f32, viewport_h: f32) {
        let (right, up, _) = self.basis();
        let mm_per_px = 2.0 * self.half_height_at_target() / viewport_h.max(1.0);
        self.target += (-right * dx + up * dy) * mm_per_px;
    }

    /// Zoom: multiply the distance by `factor` (< 1 zooms in), keeping the
    /// point under the cursor (`cursor_ndc` in −1..1, y up) fixed on the
    /// target's depth plane. `aspect` is width / height.
    pub fn zoom_to(&mut self, factor: f32, cursor_ndc: Vec2, aspect: f32) {
        let factor = factor.clamp(1e-3, 1e3);
        let (right, up, _) = self.basis();
        let h = self.half_height_at_target();
        let under = self.target + right * (cursor_ndc.x * h * aspect) + up * (cursor_ndc.y * h);
        self.target += (under - self.target) * (1.0 - factor);
        self.distance = (self.distance * factor).max(1e-4);
    }

    /// World → clip matrix (wgpu conventions: depth 0..1, y up).
    pub fn view_proj(&self, aspect: f32) -> Mat4 {
        let (_, up, forward) = self.basis();
        let view = glam::camera::rh::view::look_to_mat4(self.eye(), forward, up);
        let near = (self.distance * 1e-3).max(1e-4);
        let far = self.distance * 100.0;
        let proj = if self.orthographic {
            let h = self.half_height_at_target();
            glam::camera::rh::proj::directx::orthographic(-h * aspect, h * aspect, -h, h, near, far)
        } else {
            glam::camera::rh::proj::directx::perspective(self.fov_y, aspect.max(1e-6), near, far)
        };
        proj * view
    }

    /// The ray through `ndc` (−1..1, y up): (origin, unit direction).
    pub fn ray(&self, ndc: Vec2, aspect: f32) -> (Vec3, Vec3) {
        let (right, up, forward) = self.basis();
        let h = (self.fov_y * 0.5).tan();
        if self.orthographic {
            let hh = self.half_height_at_target();
            let origin = self.eye() + right * (ndc.x * hh * aspect) + up * (ndc.y * hh);
            (origin, forward)
        } else {
            let dir = (forward + right * (ndc.x * h * aspect) + up * (ndc.y * h)).normalize();
            (self.eye(), dir)
        }
    }
}
