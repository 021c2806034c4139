//! Polygonisation of a shape texture by its carrier's sample grid: vertices on the surface at
//! the samples (and, to meet a tolerance, at `k×k` points inside every sample cell), two
//! triangles per (sub)cell. The mesher's choice when the scene is one textured surface
//! (`mesh.rs`); marching tetrahedra would have to treat every sample line as a crease.
//!
//! **Error.** Over a (sub)cell the surface is the carrier displaced by a bilinear height
//! `a + bx + cy + dxy` (x, y in cell units); the two triangles interpolate it linearly, and
//! `|xy − L(x, y)| ≤ ¼` on each triangle, so the height of the mesh differs from the
//! surface's by at most `|d|/4` above the same carrier point — and d, the cell's twist
//! `h₀₀ − h₁₀ − h₀₁ + h₁₁`, shrinks as `1/k²` under a `k×k` subdivision. On a plane carrier
//! the displacement is along the one normal, so `|d|/(4k²)` bounds the distance both ways
//! (mesh → surface and surface → mesh). On a cylinder (wrapped around it, open at the ends)
//! and a sphere the triangles are also chords: a cell of
//! angular diagonal δ at radius ρ adds its sagitta `ρ(1 − cos(δ/2))`, shrinking as `1/k²` too,
//! and the mesher picks the least `k` whose sum of both terms is within the tolerance. The
//! two polar caps (half a row beyond the first and last sample rows, where the height is
//! clamped to the row's: no twist) get k rows of quads down to the row's heights on the polar
//! axis, chords as small as the cells'; `tests/library/freeform_mesh.rs` measures the Hausdorff
//! distance of both carriers.
//!
//! Preconditions: a compiled texture ([`Texture`]); a plane carrier is meshed over its grid's
//! rectangle and a cylinder over its length (beyond them the clamped surface goes on; the
//! mesher's box does not cut it), a sphere whole. The mesh never coarsens below the grid: a coarser grid is the texture's
//! `lod`. Output is deterministic (no threads).

use super::texture::{CarrierGeom, Texture};
use crate::error::{Error, Result};
use std::f64::consts::PI;

/// The largest subdivision of a sample cell per axis.
pub const MAX_SUBDIVISION: u32 = 64;
/// The most vertices a carrier-grid mesh may have.
const MAX_VERTICES: u64 = 1 << 28;

/// A carrier-grid mesh (the caller wraps it as `mesh::Mesh`).
pub struct GridMesh {
    pub positions: Vec<[f64; 3]>,
    /// Counter-clockwise seen from outside (above the heights).
    pub triangles: Vec<[u32; 3]>,
    /// Points per sample cell and axis.
    pub subdivision: u32,
    /// The largest distance between neighbouring vertices of the carrier (world units).
    pub spacing: f64,
}

/// The mesh of `t` within `tolerance`.
pub fn polygonise(t: &Texture, tolerance: f64) -> Result<GridMesh> {
    let k = subdivision(t, tolerance)?;
    let (w, h) = (t.width, t.height);
    let sphere = matches!(t.carrier, CarrierGeom::Sphere { .. });
    let wraps = !matches!(t.carrier, CarrierGeom::Plane { .. });
    let up = matches!(t.carrier, CarrierGeom::Cylinder { .. });
    // Vertex columns (x) and rows (y) in continuous sample coordinates.
    let cols = if wraps {
        w * k as usize
    } else {
        (w - 1) * k as usize + 1
    };
    let rows = (h - 1) * k as usize + 1;
    let count = cols as u64 * (rows as u64 + if sphere { 2 * k as u64 } else { 0 });
    if count > MAX_VERTICES {
        return Err(Error::knob(format!(
            "a mesh within {tolerance} needs {count} vertices ({k}x{k} per sample cell), more than {MAX_VERTICES}: raise the tolerance or the texture's lod"
        )));
    }
    let kf = k as f64;
    // Vertex rows in continuous sample y; on a sphere also k rows over each polar cap (half a
    // row to the pole, where the height is clamped to the first or last row's).
    let mut ys: Vec<f64> = (0..rows).map(|r| r as f64 / kf).collect();
    if sphere {
        let cap = |j: usize| 0.5 * j as f64 / kf;
        let north = (0..k as usize).map(|j| -0.5 + cap(j));
        let south = (1..=k as usize).map(|j| (h - 1) as f64 + cap(j));
        ys = north.chain(ys).chain(south).collect();
    }
    let mut positions = Vec::with_capacity(count as usize);
    for &y in &ys {
        for c in 0..cols {
            let x = c as f64 / kf;
            positions.push(t.point_at(x, y));
        }
    }
    let at = |r: usize, c: usize| (r * cols + c % cols) as u32;
    let mut triangles = Vec::with_capacity(2 * cols * ys.len());
    let across = if wraps { cols } else { cols - 1 };
    for r in 0..ys.len() - 1 {
        for c in 0..across {
            // a (x, y), b (x+1, y), c (x, y+1), d (x+1, y+1): counter-clockwise seen from
            // outside (u × v is the plane's normal; on a sphere x runs east and y south; on a
            // cylinder y runs up, so the turn is the other way).
            let (a, b, cc, d) = (at(r, c), at(r, c + 1), at(r + 1, c), at(r + 1, c + 1));
            if up {
                triangles.push([a, cc, b]);
                triangles.push([b, cc, d]);
            } else {
                triangles.push([a, b, cc]);
                triangles.push([b, d, cc]);
            }
        }
    }
    // Drop triangles with coincident corners (pole vertices of equal heights).
    triangles.retain(|t| {
        let [a, b, c] = t.map(|i| positions[i as usize]);
        a != b && b != c && a != c
    });
    let spacing = match t.carrier {
        CarrierGeom::Plane { scale, .. } => 1.0 / (kf * scale[0].min(scale[1])),
        CarrierGeom::Sphere { radius, .. } => radius * 2.0 * PI / (kf * w as f64),
        CarrierGeom::Cylinder {
            radius, scale_y, ..
        } => (radius * 2.0 * PI / w as f64).max(1.0 / scale_y) / kf,
    };
    Ok(GridMesh {
        positions,
        triangles,
        subdivision: k,
        spacing,
    })
}

/// The least `k` whose error bound (module header) is within `tolerance`.
fn subdivision(t: &Texture, tolerance: f64) -> Result<u32> {
    if !(tolerance.is_finite() && tolerance > 0.0) {
        return Err(Error::knob(format!(
            "mesh tolerance must be a positive finite number, got {tolerance}"
        )));
    }
    let (w, h) = (t.width, t.height);
    let s = |i: usize, j: usize| t.heights[j * w + i % w] as f64;
    let wraps = !matches!(t.carrier, CarrierGeom::Plane { .. });
    let across = if wraps { w } else { w - 1 };
    let mut twist = 0.0f64;
    for j in 0..h - 1 {
        for i in 0..across {
            twist = twist.max((s(i, j) - s(i + 1, j) - s(i, j + 1) + s(i + 1, j + 1)).abs());
        }
    }
    let sagitta = match t.carrier {
        CarrierGeom::Plane { .. } => 0.0,
        CarrierGeom::Sphere { radius, .. } => {
            let top = t.mip.max_height as f64;
            let (dx, dy) = (2.0 * PI / w as f64, PI / h as f64);
            let delta = (dx * dx + dy * dy).sqrt();
            (radius + top.max(0.0)) * (1.0 - (0.5 * delta).cos())
        }
        // Curved around the axis only: the chord over one column.
        CarrierGeom::Cylinder { radius, .. } => {
            let top = t.mip.max_height as f64;
            (radius + top.max(0.0)) * (1.0 - (PI / w as f64).cos())
        }
    };
    let e1 = 0.25 * twist + sagitta;
    let k = (e1 / tolerance).sqrt().ceil().max(1.0);
    if k > MAX_SUBDIVISION as f64 {
        return Err(Error::knob(format!(
            "a mesh within {tolerance} needs {k}x{k} vertices per sample cell (the cells' twist and curvature err by {e1:.3e}), more than {MAX_SUBDIVISION}x{MAX_SUBDIVISION}: raise the tolerance"
        )));
    }
    Ok(k as u32)
}
