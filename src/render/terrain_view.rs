//! The first view of a height map: a low oblique look at its most rugged part, from the side
//! where the sun shows the most relief.
//!
//! - **Where**: the map is cut into 8 blocks along its longer side (square blocks); the highest
//!   point of the block with the largest height range is the target (Puget Sound: Mount
//!   Rainier's summit).
//! - **From how far and how high**: [`DISTANCE_PER_BLOCK`] block widths from the target, 20°
//!   above it (higher where the ground under the line of sight would come within 5 % of the
//!   distance of it) — close enough that the air's in-scattering does not veil the near ground (at
//!   Puget Sound's 20 km blocks the eye is 9 km away), low enough that slopes face the eye.
//! - **From which side**: of 8 azimuths, the one where the sun's shading of the block varies
//!   most as seen from the eye: the standard deviation of Lambert's cosine over the block's
//!   texels, each weighted by how squarely it faces the eye (its projected area; occlusion is
//!   left out). Side light from the eye's left or right usually wins, as a cartographer would
//!   choose; a sun straight behind the eye flattens the relief and loses.
//!
//! Terrain world space is the player's: x east (columns), y up (heights × exaggeration),
//! z south (rows). Deterministic; ties go to the first azimuth from north, clockwise.

use super::camera::Camera;
use crate::heightmap::HeightMap;
use crate::terrain::hard::relief::lambert;
use crate::terrain::sun::Sun;
use glam::{DVec3, Vec3};

/// Eye distance from the target in block widths.
pub const DISTANCE_PER_BLOCK: f64 = 0.45;
/// Elevation of the eye above the target, degrees.
pub const ELEVATION_DEG: f64 = 20.0;
/// Vertical field of view, degrees.
pub const FOV_DEG: f32 = 45.0;

/// The first camera for `map` drawn with heights × `exaggeration` under `sun`.
pub fn relief_view(map: &HeightMap, sun: &Sun, exaggeration: f32) -> Camera {
    let (w, h) = (map.width, map.height);
    let bs = (w.max(h) / 8).max(1);
    let e = exaggeration as f64;
    // The most rugged block.
    let mut best = (f32::NEG_INFINITY, 0usize, 0usize);
    for r0 in (0..h).step_by(bs) {
        for c0 in (0..w).step_by(bs) {
            let (lo, hi) =
                block(map, c0, r0, bs).fold((f32::INFINITY, f32::NEG_INFINITY), |a, i| {
                    let v = map.heights[i];
                    (a.0.min(v), a.1.max(v))
                });
            if hi - lo > best.0 {
                best = (hi - lo, c0, r0);
            }
        }
    }
    let (_, c0, r0) = best;
    let cells: Vec<usize> = block(map, c0, r0, bs).collect();
    let top = cells.iter().copied().fold(cells[0], |a, i| {
        if map.heights[i] > map.heights[a] {
            i
        } else {
            a
        }
    });
    let [cx, cy] = map.cell_size;
    let world = |c: f64, r: f64, z: f64| DVec3::new((c + 0.5) * cx, z * e, (r + 0.5) * cy);
    let target = world((top % w) as f64, (top / w) as f64, map.heights[top] as f64);
    let dist = DISTANCE_PER_BLOCK * bs as f64 * cx.max(cy);
    let el = ELEVATION_DEG.to_radians();
    // Azimuth a (clockwise from north) → world offset: east = +x, north = −z.
    let eye_at = |a: f64| {
        let a = a.to_radians();
        target + DVec3::new(a.sin() * el.cos(), el.sin(), -a.cos() * el.cos()) * dist
    };
    let lam = lambert(map, sun);
    // Sample at most ~128² texels of the block.
    let step = (bs / 128).max(1);
    let samples: Vec<usize> = cells
        .iter()
        .copied()
        .filter(|&i| (i % w - c0) % step == 0 && (i / w - r0) % step == 0)
        .collect();
    let mut choice = (f64::NEG_INFINITY, 0.0);
    for k in 0..8 {
        let a = 45.0 * k as f64;
        let eye = eye_at(a);
        let (mut sw, mut s1, mut s2) = (0.0, 0.0, 0.0);
        for &i in &samples {
            let (c, r) = (i % w, i / w);
            let (dzdx, dzdn) = map.gradient(c, r);
            // The displayed (exaggerated) surface's normal in world space (z south).
            let n = DVec3::new(-e * dzdx, 1.0, e * dzdn).normalize();
            let p = world(c as f64, r as f64, map.heights[i] as f64);
            let facing = n.dot((eye - p).normalize());
            if facing > 0.0 {
                let v = lam[i] as f64;
                sw += facing;
                s1 += facing * v;
                s2 += facing * v * v;
            }
        }
        let score = if sw > 0.0 {
            (s2 / sw - (s1 / sw).powi(2)).max(0.0)
        } else {
            0.0
        };
        if score > choice.0 {
            choice = (score, a);
        }
    }
    let mut eye = eye_at(choice.1);
    // Raise the eye until the ground under its line of sight to the target (the first 90 % of
    // it) stays below it by 5 % of the distance: no slope fills the foreground.
    let ground = |p: DVec3| {
        let (c, r) = (p.x / cx - 0.5, p.z / cy - 0.5);
        (c >= 0.0 && r >= 0.0 && (c as usize) < w && (r as usize) < h)
            .then(|| map.at(c as usize, r as usize) as f64 * e)
    };
    let margin = 0.05 * dist;
    for k in 0..=57 {
        let t = k as f64 / 64.0;
        if let Some(g) = ground(eye + (target - eye) * t) {
            eye.y = eye.y.max((g + margin - target.y * t) / (1.0 - t));
        }
    }
    let size = (w as f64 * cx).max(h as f64 * cy);
    Camera {
        eye: eye.as_vec3(),
        target: target.as_vec3(),
        up: Vec3::Y,
        fov_y_deg: FOV_DEG,
        near: (dist * 1e-3) as f32,
        far: (2.0 * size + dist) as f32,
    }
}

/// Texel indices of the block of side `bs` at (c0, r0), clipped to the map.
fn block(map: &HeightMap, c0: usize, r0: usize, bs: usize) -> impl Iterator<Item = usize> + '_ {
    let (w, h) = (map.width, map.height);
    (r0..(r0 + bs).min(h)).flat_map(move |r| (c0..(c0 + bs).min(w)).map(move |c| r * w + c))
}
