//! The first view of a mesh scene: the framing from the front ([`Camera::framing`]) when it
//! sees into the scene (the Cornell box through its open side), else a viewpoint inside it.
//!
//! - **Does the framing see in?** Rays through the central half of the framing view (9×9) find
//!   their first surfaces. When the median of their depths behind the bounding box's near face is
//!   more than a quarter of the box's depth and fewer than a quarter of them meet the back of a
//!   surface, the view looks into the scene and is kept. A closed room (its walls' backs face
//!   the camera) or a building seen from outside (Sponza's outer wall) stops the rays at the
//!   near face.
//! - **Where inside?** Candidate eyes on a 12×6×12 grid through the bounds, each sending
//!   [`DIRECTIONS`] rays over the sphere (a Fibonacci lattice). A candidate is inside the scene
//!   when at most one ray in eight meets the back of a surface (it is not inside a wall, under a
//!   floor or behind a closed room's wall, where about half do) and at least half meet the front
//!   of one (it is enclosed, not above the roofs). Among those the most open wins: the largest mean distance
//!   to the first surface (the middle of the largest room). Ties go to the first in grid order.
//! - **Looking where?** Along the horizontal direction (of 32) with the longest free distance
//!   to a surface's front, pitched down by 10° to show the floor, with a 70° field of view.
//!
//! Scenes are y-up (the player's cameras are). Rays honour alpha masks: a viewpoint behind
//! foliage sees through its cut-out texels. Deterministic: fixed directions, fixed grid.

use super::camera::Camera;
use crate::raytrace::visibility::{Hit, Visibility};
use crate::raytrace::Frame;
use crate::scene::Scene;
use glam::{DVec3, Vec3};

/// Rays per candidate eye.
pub const DIRECTIONS: usize = 64;
/// Rays of a candidate eye that may meet the back of a surface: open meshes (a lamp shade, a
/// curtain modelled one-sided) show their backs from inside a room; an eye inside a wall or
/// under a floor sees backs in about half its directions.
pub const MAX_BACKS: usize = DIRECTIONS / 8;
/// Vertical field of view of an inside view, degrees.
pub const INSIDE_FOV_DEG: f32 = 70.0;
/// Vertical field of view of the framing view, degrees (the Cornell box's published camera).
pub const FRAMING_FOV_DEG: f32 = 39.3077;

/// Which view [`first_view`] chose.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ViewKind {
    /// The framing from the front sees into the scene.
    Framing,
    /// A viewpoint inside the scene.
    Inside,
}

/// The first camera for `scene` and how it was chosen. A scene with no triangles gets the
/// framing of its (empty) bounds.
pub fn first_view(scene: &Scene) -> (Camera, ViewKind) {
    let (lo, hi) = scene.bounds();
    let framing = Camera::framing(lo, hi, FRAMING_FOV_DEG);
    if scene.triangles.is_empty() || !(hi - lo).is_finite() {
        return (framing, ViewKind::Framing);
    }
    let tracer = Tracer::new(scene, lo, hi);
    if sees_in(&tracer, &framing, lo, hi) {
        return (framing, ViewKind::Framing);
    }
    match inside_eye(&tracer, lo, hi) {
        Some(eye) => (inside_camera(&tracer, eye, lo, hi), ViewKind::Inside),
        None => (framing, ViewKind::Framing),
    }
}

/// The scene's triangles in a BVH, in world units relative to the bounds' corner.
struct Tracer {
    vis: Visibility,
    frame: Frame,
}

impl Tracer {
    fn new(scene: &Scene, lo: Vec3, hi: Vec3) -> Self {
        let frame = Frame {
            origin: lo.as_dvec3(),
            scale: 1.0,
        };
        let all: Vec<u32> = (0..scene.triangles.len() as u32).collect();
        let extent = (hi - lo).max_element().max(1e-6) as f64;
        let vis = Visibility::with_build(
            scene,
            &all,
            &frame,
            extent,
            obvhs::BvhBuildParams::fast_build(),
        );
        Tracer { vis, frame }
    }

    /// The first surface along `dir` (unit) from the world point `from`.
    fn first(&self, from: Vec3, dir: Vec3) -> Option<Hit> {
        let o = (from.as_dvec3() - self.frame.origin) / self.frame.scale;
        self.vis.closest_hit(o, dir.as_dvec3().normalize())
    }
}

/// True when the median depth of the framing view's central rays behind the bounds' near face
/// exceeds a quarter of the bounds' depth (rays that meet nothing count as seeing through) and
/// fewer than a quarter of them meet the back of a surface (a closed room's wall).
fn sees_in(t: &Tracer, cam: &Camera, lo: Vec3, hi: Vec3) -> bool {
    let near_face = lo.z - cam.eye.z;
    let depth = hi.z - lo.z;
    let n = 9u32;
    let (mut behind, mut backs) = (Vec::new(), 0u32);
    for j in 0..n {
        for i in 0..n {
            // Pixels 40, 48, …, 104 of 144: the central half of a square image.
            let (x, y) = (4 * n + 8 * i + 4, 4 * n + 8 * j + 4);
            let (eye, dir) = cam.ray(x, y, 16 * n, 16 * n);
            let hit = t.first(eye, dir);
            backs += u32::from(hit.is_some_and(|h| !h.front));
            behind.push(hit.map_or(f32::INFINITY, |h| h.t * dir.z) - near_face);
        }
    }
    behind.sort_by(f32::total_cmp);
    4 * backs < n * n && behind[behind.len() / 2] > 0.25 * depth
}

/// `k` of [`DIRECTIONS`] unit directions evenly over the sphere (a Fibonacci lattice).
fn sphere_direction(k: usize) -> Vec3 {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    let y = 1.0 - 2.0 * (k as f64 + 0.5) / DIRECTIONS as f64;
    let r = (1.0 - y * y).sqrt();
    let phi = golden * k as f64;
    DVec3::new(r * phi.cos(), y, r * phi.sin()).as_vec3()
}

/// The most open candidate eye inside the scene, if any.
fn inside_eye(t: &Tracer, lo: Vec3, hi: Vec3) -> Option<Vec3> {
    let (nx, ny, nz) = (12, 6, 12);
    let mut best: Option<(f32, Vec3)> = None;
    for j in 0..ny {
        for k in 0..nz {
            for i in 0..nx {
                let f = Vec3::new(
                    (i as f32 + 0.5) / nx as f32,
                    (j as f32 + 0.5) / ny as f32,
                    (k as f32 + 0.5) / nz as f32,
                );
                let eye = lo + (hi - lo) * f;
                if let Some(open) = openness(t, eye) {
                    if best.is_none_or(|(b, _)| open > b) {
                        best = Some((open, eye));
                    }
                }
            }
        }
    }
    best.map(|(_, e)| e)
}

/// The mean distance to the first surface from `eye` over the sphere, or None when `eye` is not
/// inside the scene (more than [`MAX_BACKS`] rays meet a surface's back, or fewer than half
/// meet a front).
fn openness(t: &Tracer, eye: Vec3) -> Option<f32> {
    let (mut fronts, mut backs, mut sum) = (0usize, 0usize, 0.0f32);
    for k in 0..DIRECTIONS {
        match t.first(eye, sphere_direction(k)) {
            Some(h) if !h.front => {
                backs += 1;
                if backs > MAX_BACKS {
                    return None;
                }
            }
            Some(h) => {
                fronts += 1;
                sum += h.t;
            }
            None => {}
        }
    }
    (2 * fronts >= DIRECTIONS).then(|| sum / fronts as f32)
}

/// Looking from `eye` along the horizontal direction with the longest free distance to a
/// surface's front, pitched down 10°.
fn inside_camera(t: &Tracer, eye: Vec3, lo: Vec3, hi: Vec3) -> Camera {
    let mut best = (0.0f32, Vec3::Z);
    for a in 0..32 {
        let phi = (a as f32) * std::f32::consts::TAU / 32.0;
        let dir = Vec3::new(phi.sin(), 0.0, -phi.cos());
        if let Some(h) = t.first(eye, dir) {
            if h.front && h.t > best.0 {
                best = (h.t, dir);
            }
        }
    }
    let pitch = (-10f32).to_radians();
    let dir = best.1 * pitch.cos() + Vec3::Y * pitch.sin();
    let radius = (hi - lo).length().max(1e-6);
    Camera {
        eye,
        target: eye + dir * best.0.max(radius * 0.1),
        up: Vec3::Y,
        fov_y_deg: INSIDE_FOV_DEG,
        near: (radius * 1e-3).max(1e-6),
        far: 2.0 * radius,
    }
}
