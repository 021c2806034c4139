//! The f64 pinhole camera of the freeform casters and the view-pyramid cells it spans.
//!
//! A pixel's ray is `eye + z·(f + X·r + Y·u)` with z the view depth, (f, r, u) the camera's
//! forward, right and up unit vectors and (X, Y) the screen position scaled by the half-angle
//! tangents. Depth is searched on a logarithmic scale `s = ln z`: a cell `[s₀, s₁]` under a tile
//! of angular size θ is about cubic when `s₁ − s₀ ≈ θ`, at every distance.

use super::bounds::Cell;
use crate::scene::freeform::FreeformCamera;
use glam::DVec3;

/// A camera for an image of `width`×`height` pixels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct View {
    pub eye: [f64; 3],
    pub forward: [f64; 3],
    pub right: [f64; 3],
    pub up: [f64; 3],
    pub tan_x: f64,
    pub tan_y: f64,
    pub width: u32,
    pub height: u32,
    pub near: f64,
    pub far: f64,
}

impl View {
    /// The view of `camera` (or the default camera) for an image of `width`×`height`.
    pub fn new(camera: &FreeformCamera, width: u32, height: u32) -> View {
        let eye = DVec3::from(camera.eye);
        let target = DVec3::from(camera.target);
        let dist = (target - eye).length();
        let f = (target - eye).normalize();
        let world_up = if f.y.abs() > 0.999 {
            DVec3::Z
        } else {
            DVec3::Y
        };
        let r = f.cross(world_up).normalize();
        let u = r.cross(f);
        let tan_y = (0.5 * camera.fov.to_radians()).tan();
        View {
            eye: eye.into(),
            forward: f.into(),
            right: r.into(),
            up: u.into(),
            tan_x: tan_y * width as f64 / height as f64,
            tan_y,
            width,
            height,
            near: camera.near.unwrap_or(dist * 1e-3),
            far: camera.far.unwrap_or(dist * 1e3),
        }
    }

    /// Screen X at a horizontal pixel-edge coordinate (0 = left edge, `width` = right).
    pub fn screen_x(&self, ex: f64) -> f64 {
        (ex / self.width as f64 * 2.0 - 1.0) * self.tan_x
    }

    /// Screen Y at a vertical pixel-edge coordinate (0 = top edge).
    pub fn screen_y(&self, ey: f64) -> f64 {
        (1.0 - ey / self.height as f64 * 2.0) * self.tan_y
    }

    /// The (not normalised, forward component 1) direction at screen (X, Y).
    pub fn direction(&self, x: f64, y: f64) -> [f64; 3] {
        std::array::from_fn(|k| self.forward[k] + x * self.right[k] + y * self.up[k])
    }

    /// The unit ray direction through the centre of pixel (px, py), and the factor from view
    /// depth to distance along it.
    pub fn pixel_ray(&self, px: u32, py: u32) -> ([f64; 3], f64) {
        let d = self.direction(
            self.screen_x(px as f64 + 0.5),
            self.screen_y(py as f64 + 0.5),
        );
        let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        (d.map(|v| v / len), len)
    }

    /// The log-depth size of a cell under one pixel (its angular size).
    pub fn pixel_angle(&self) -> f64 {
        2.0 * self.tan_y / self.height as f64
    }

    /// The cell over screen `[x0, x1] × [y0, y1]` (screen units) and log depths `[s0, s1]`.
    pub fn cell(&self, x: [f64; 2], y: [f64; 2], s: [f64; 2]) -> Cell {
        let (z0, z1) = (s[0].exp(), s[1].exp());
        let (zc, zr) = (0.5 * (z0 + z1), 0.5 * (z1 - z0));
        let (xc, xr) = (0.5 * (x[0] + x[1]), 0.5 * (x[1] - x[0]));
        let (yc, yr) = (0.5 * (y[0] + y[1]), 0.5 * (y[1] - y[0]));
        let dc = self.direction(xc, yc);
        let (r, u) = (self.right, self.up);
        Cell {
            c: std::array::from_fn(|k| self.eye[k] + zc * dc[k]),
            v: [
                dc.map(|v| zr * v),
                r.map(|v| zc * xr * v),
                u.map(|v| zc * yr * v),
                r.map(|v| zr * xr * v),
                u.map(|v| zr * yr * v),
            ],
        }
    }
}

/// The cell of a line `o + t·d`, `t ∈ [t0, t1]` (a ray segment: one noise symbol).
pub fn line_cell(o: [f64; 3], d: [f64; 3], t0: f64, t1: f64) -> Cell {
    let (tc, tr) = (0.5 * (t0 + t1), 0.5 * (t1 - t0));
    Cell {
        c: std::array::from_fn(|k| o[k] + tc * d[k]),
        v: [d.map(|v| tr * v), [0.0; 3], [0.0; 3], [0.0; 3], [0.0; 3]],
    }
}
