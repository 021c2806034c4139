//! A mesh for per-vertex light: the scene with every triangle longer than a limit split into a
//! regular m × m grid, and the transfer weights of every corner of it by the corners' own rule
//! ([`super::corners::PointTransfer`]).
//!
//! Why: light interpolated between a mesh's vertices can only vary where the mesh has vertices.
//! The Cornell box has four per wall, and its walls came out 40–72 % darker in the player than
//! Mitsuba measures while the radiosity solution itself was within 4 % (docs/radiosity.md). Split
//! to about a voxel and a half, the interpolated light follows the patches. Triangles already
//! short enough keep their corner lists from the bake; degenerate ones stay as they are (empty
//! lists). Splits of neighbouring triangles need not match (T-junctions): the mesh is drawn,
//! never traced.

use super::corners::PointTransfer;
use super::{PatchLists, PatchSet};
use crate::scene::Scene;
use glam::DVec3;
use rayon::prelude::*;

/// Most sub-triangles along an edge.
pub const MAX_SPLIT: usize = 64;

/// Longest edge of the display mesh the player draws, in voxels.
pub const DISPLAY_EDGE_VOXELS: f64 = 1.5;

/// [`display_mesh`] with edges up to [`DISPLAY_EDGE_VOXELS`]: the mesh the player draws.
pub fn display_mesh_of(scene: &Scene, set: &PatchSet) -> (Scene, PatchLists) {
    display_mesh(scene, set, DISPLAY_EDGE_VOXELS * set.voxel_size)
}

/// The display mesh of `scene` (voxelized as `set`) with no edge longer than `max_edge` (scene
/// units; at most [`MAX_SPLIT`] steps per edge), and its per-corner transfer lists.
pub fn display_mesh(scene: &Scene, set: &PatchSet, max_edge: f64) -> (Scene, PatchLists) {
    let split: Vec<usize> = (0..scene.triangles.len())
        .map(|t| {
            let c = scene.corners(t);
            let longest = (0..3)
                .map(|k| (c[(k + 1) % 3] - c[k]).length() as f64)
                .fold(0.0, f64::max);
            ((longest / max_edge).ceil() as usize).clamp(1, MAX_SPLIT)
        })
        .collect();
    let degenerate: std::collections::BTreeSet<usize> = scene.degenerate_triangles().collect();
    if split.iter().all(|&m| m == 1) {
        return (scene.clone(), set.corners.clone());
    }
    let transfer = PointTransfer::new(scene, set);
    // Per scene triangle: sub-triangle corner positions and their lists.
    type Part = (Vec<[f32; 3]>, Vec<Vec<(u32, f32)>>);
    let parts: Vec<Part> = (0..scene.triangles.len())
        .into_par_iter()
        .map(|t| {
            let m = if degenerate.contains(&t) { 1 } else { split[t] };
            let own = |k: usize| {
                let (p, w) = set.corners.list(3 * t + k);
                p.iter().copied().zip(w.iter().copied()).collect::<Vec<_>>()
            };
            if m == 1 {
                let pos = scene.triangles[t].map(|v| scene.positions[v as usize]);
                return (pos.to_vec(), (0..3).map(own).collect());
            }
            let c =
                scene.triangles[t].map(|v| DVec3::from(scene.positions[v as usize].map(f64::from)));
            let grid = |i: usize, j: usize| {
                let (u, v) = (i as f64 / m as f64, j as f64 / m as f64);
                (c[0] + (c[1] - c[0]) * u + (c[2] - c[0]) * v).as_vec3()
            };
            // Weights once per grid vertex (the scene's own corners keep the bake's lists).
            let mut weights = std::collections::HashMap::new();
            let mut at = |i: usize, j: usize| -> ([f32; 3], Vec<(u32, f32)>) {
                let p = grid(i, j);
                let w = weights
                    .entry((i, j))
                    .or_insert_with(|| match (i, j) {
                        (0, 0) => own(0),
                        (i, 0) if i == m => own(1),
                        (0, j) if j == m => own(2),
                        _ => transfer.weights(scene, t, p),
                    })
                    .clone();
                (p.to_array(), w)
            };
            let (mut pos, mut lists) = (Vec::new(), Vec::new());
            for i in 0..m {
                for j in 0..m - i {
                    let mut tri = vec![at(i, j), at(i + 1, j), at(i, j + 1)];
                    if i + j + 1 < m {
                        tri.extend([at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)]);
                    }
                    for (p, w) in tri {
                        pos.push(p);
                        lists.push(w);
                    }
                }
            }
            (pos, lists)
        })
        .collect();
    let mut out = Scene {
        objects: scene.objects.clone(),
        materials: scene.materials.clone(),
        lights: scene.lights.clone(),
        ..Default::default()
    };
    let mut all_lists = Vec::new();
    for (t, (pos, lists)) in parts.into_iter().enumerate() {
        for corners in pos.chunks_exact(3) {
            let base = out.positions.len() as u32;
            out.positions.extend_from_slice(corners);
            out.triangles.push([base, base + 1, base + 2]);
            out.triangle_material.push(scene.triangle_material[t]);
            out.triangle_object.push(scene.triangle_object[t]);
        }
        all_lists.extend(lists);
    }
    (out, PatchLists::from_lists(all_lists))
}
