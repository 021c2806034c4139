//! Pinhole camera shared by the GPU rasteriser and the CPU reference ray caster: the same
//! view-projection matrix (right-handed, y up, wgpu depth range 0..1) and, for the CPU, the ray
//! through each pixel centre of that projection.

use glam::{Mat4, Vec3, Vec4};
use serde::{Deserialize, Serialize};

/// Right-handed view matrix (glam 0.34 keeps these in `glam::camera`).
pub fn look_at(eye: Vec3, target: Vec3, up: Vec3) -> Mat4 {
    glam::camera::rh::view::look_at_mat4(eye, target, up)
}

/// Perspective projection for wgpu's clip space (depth 0..1, y up).
pub fn perspective(fov_y_rad: f32, aspect: f32, near: f32, far: f32) -> Mat4 {
    glam::camera::rh::proj::directx::perspective(fov_y_rad, aspect, near, far)
}

/// Orthographic projection for wgpu's clip space (depth 0..1, y up).
pub fn orthographic(left: f32, right: f32, bottom: f32, top: f32, near: f32, far: f32) -> Mat4 {
    glam::camera::rh::proj::directx::orthographic(left, right, bottom, top, near, far)
}

/// A perspective camera.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Camera {
    pub eye: Vec3,
    pub target: Vec3,
    pub up: Vec3,
    /// Vertical field of view in degrees.
    pub fov_y_deg: f32,
    pub near: f32,
    pub far: f32,
}

impl Camera {
    /// A camera in front of the bounds (looking along +z, as the Cornell box's published
    /// camera does), far enough back that the bounds fill the vertical field of view.
    pub fn framing(lo: Vec3, hi: Vec3, fov_y_deg: f32) -> Camera {
        let centre = (lo + hi) * 0.5;
        let ext = hi - lo;
        let half = 0.5 * ext.y.max(ext.x);
        let d = half / (0.5 * fov_y_deg.to_radians()).tan() * 1.05 + 0.5 * ext.z;
        let eye = Vec3::new(centre.x, centre.y, lo.z - (d - 0.5 * ext.z));
        let radius = ext.length().max(1e-6);
        Camera {
            eye,
            target: Vec3::new(centre.x, centre.y, centre.z),
            up: Vec3::Y,
            fov_y_deg,
            near: (radius * 1e-3).max(1e-6),
            far: (eye - centre).length() + 2.0 * radius,
        }
    }

    /// An orbit camera around `target`: `azimuth` degrees around +y from +z (0 = looking along
    /// −z... from the +z side), `elevation` degrees above the horizontal plane, at `distance`.
    pub fn orbit(
        target: Vec3,
        distance: f32,
        azimuth_deg: f32,
        elevation_deg: f32,
        fov_y_deg: f32,
    ) -> Camera {
        let (az, el) = (azimuth_deg.to_radians(), elevation_deg.to_radians());
        let dir = Vec3::new(az.sin() * el.cos(), el.sin(), az.cos() * el.cos());
        Camera {
            eye: target + dir * distance,
            target,
            up: Vec3::Y,
            fov_y_deg,
            near: (distance * 1e-3).max(1e-6),
            far: distance * 4.0,
        }
    }

    /// View matrix (world → camera).
    pub fn view(&self) -> Mat4 {
        look_at(self.eye, self.target, self.up)
    }

    /// Projection for an image `width`×`height` (wgpu clip space, depth 0..1).
    pub fn projection(&self, width: u32, height: u32) -> Mat4 {
        perspective(
            self.fov_y_deg.to_radians(),
            width as f32 / height.max(1) as f32,
            self.near,
            self.far,
        )
    }

    /// Projection × view.
    pub fn view_projection(&self, width: u32, height: u32) -> Mat4 {
        self.projection(width, height) * self.view()
    }

    /// The `--camera` argument that gives this camera back (eye, target, field of view; the up
    /// vector is +y there): `EX,EY,EZ,TX,TY,TZ,FOV`, shortest round-trip decimals.
    pub fn to_arg(&self) -> String {
        let [ex, ey, ez] = self.eye.to_array();
        let [tx, ty, tz] = self.target.to_array();
        format!("{ex},{ey},{ez},{tx},{ty},{tz},{}", self.fov_y_deg)
    }

    /// The world-space ray (origin, unit direction) through the centre of pixel (x, y), row 0
    /// at the top, matching the rasteriser's pixel centres.
    pub fn ray(&self, x: u32, y: u32, width: u32, height: u32) -> (Vec3, Vec3) {
        let inv = self.view_projection(width, height).inverse();
        let ndc_x = (x as f32 + 0.5) / width as f32 * 2.0 - 1.0;
        let ndc_y = 1.0 - (y as f32 + 0.5) / height as f32 * 2.0;
        let near = inv * Vec4::new(ndc_x, ndc_y, 0.0, 1.0);
        let far = inv * Vec4::new(ndc_x, ndc_y, 1.0, 1.0);
        let (near, far) = (near.truncate() / near.w, far.truncate() / far.w);
        (self.eye, (far - near).normalize())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ray_through_centre_pixel_hits_the_target_direction() {
        let c = Camera::framing(Vec3::ZERO, Vec3::ONE, 40.0);
        let (o, d) = c.ray(50, 50, 101, 101);
        assert!((d - (c.target - o).normalize()).length() < 1e-5);
    }

    #[test]
    fn projected_points_land_on_their_pixel() {
        let c = Camera::orbit(Vec3::new(1.0, 2.0, 3.0), 5.0, 30.0, 20.0, 50.0);
        let (w, h) = (64, 48);
        let vp = c.view_projection(w, h);
        for (x, y) in [(0, 0), (63, 47), (10, 30)] {
            let (o, d) = c.ray(x, y, w, h);
            let p = vp * (o + d * 4.0).extend(1.0);
            let px = (p.x / p.w * 0.5 + 0.5) * w as f32 - 0.5;
            let py = (0.5 - p.y / p.w * 0.5) * h as f32 - 0.5;
            assert!(
                (px - x as f32).abs() < 1e-2 && (py - y as f32).abs() < 1e-2,
                "{px} {py}"
            );
        }
    }
}
