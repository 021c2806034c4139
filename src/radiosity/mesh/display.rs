//! A mesh for per-vertex light: the scene with every triangle longer than a limit split into a
//! regular m × m grid, and the transfer weights of every corner of it by the corners' own rule
//! ([`crate::radiosity::patches::corners::PointTransfer`]).
//!
//! Why: light interpolated between a mesh's vertices can only vary where the mesh has vertices.
//! The Cornell box has four per wall, and its walls came out 40–72 % darker in the player than
//! Mitsuba measures while the radiosity solution itself was within 4 % (docs/radiosity.md). Split
//! to about a voxel and a half, the interpolated light follows the patches. Triangles already
//! short enough keep their corner lists from the bake; degenerate ones stay as they are (empty
//! lists). Splits of neighbouring triangles need not match (T-junctions): the mesh is drawn,
//! never traced.

use crate::radiosity::patches::corners::PointTransfer;
use crate::radiosity::{PatchLists, PatchSet};
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
/// units; at most [`MAX_SPLIT`] steps per edge) times the edge of the smallest patch cell the
/// triangle feeds ([`crate::radiosity::patches::corners::patch_cells`]: 1 on a uniform grid, down to 2^−max_level
/// where adaptive patches refined a voxel), and its per-corner transfer lists.
pub fn display_mesh(scene: &Scene, set: &PatchSet, max_edge: f64) -> (Scene, PatchLists) {
    let cells = crate::radiosity::patches::corners::patch_cells(set);
    let split: Vec<usize> = (0..scene.triangles.len())
        .map(|t| {
            if scene.is_degenerate(t) {
                return 1;
            }
            let finest = set
                .triangle_patches
                .list(t)
                .0
                .iter()
                .map(|&j| cells[j as usize].1)
                .fold(1.0, f64::min);
            let max_edge = max_edge * finest;
            let c = scene.corners(t);
            let longest = (0..3)
                .map(|k| (c[(k + 1) % 3] - c[k]).length() as f64)
                .fold(0.0, f64::max);
            ((longest / max_edge).ceil() as usize).clamp(1, MAX_SPLIT)
        })
        .collect();
    if split.iter().all(|&m| m == 1) {
        return (scene.clone(), set.corners.clone());
    }
    let vis = set.visibility(scene);
    let transfer = PointTransfer::with_cells(scene, set, &vis, cells);
    // Per scene triangle: its sub-triangles' corner positions and lists, three per sub-triangle.
    // Texture coordinates ride along (empty when the scene has none).
    type Part = (Vec<[f32; 3]>, Vec<[f32; 2]>, Vec<Vec<(u32, f32)>>);
    let has_uv = !scene.uvs.is_empty();
    let parts: Vec<Part> = (0..scene.triangles.len())
        .into_par_iter()
        .map(|t| {
            let m = split[t];
            let own = |k: usize| {
                let (p, w) = set.corners.list(3 * t + k);
                p.iter().copied().zip(w.iter().copied()).collect::<Vec<_>>()
            };
            let tri_uv = has_uv.then(|| scene.triangles[t].map(|v| scene.uvs[v as usize]));
            if m == 1 {
                let pos = scene.triangles[t].map(|v| scene.positions[v as usize]);
                let uv = tri_uv.map(|t| t.to_vec()).unwrap_or_default();
                return (pos.to_vec(), uv, (0..3).map(own).collect());
            }
            // The grid vertices (i, j), i + j ≤ m, at barycentric (1 − (i + j)/m, i/m, j/m),
            // row by row; the scene's own corners keep the bake's lists.
            let c =
                scene.triangles[t].map(|v| DVec3::from(scene.positions[v as usize].map(f64::from)));
            let on = transfer.on_triangle(scene, t);
            let row = |i: usize| i * (m + 1) - i * (i.saturating_sub(1)) / 2;
            let index = |i: usize, j: usize| row(i) + j;
            let mut verts = Vec::with_capacity(row(m) + 1);
            for i in 0..=m {
                for j in 0..=m - i {
                    let (u, v) = (i as f64 / m as f64, j as f64 / m as f64);
                    let p = (c[0] + (c[1] - c[0]) * u + (c[2] - c[0]) * v).as_vec3();
                    let uv = tri_uv.map(|t| {
                        let (u, v) = (u as f32, v as f32);
                        [0, 1].map(|k| t[0][k] + (t[1][k] - t[0][k]) * u + (t[2][k] - t[0][k]) * v)
                    });
                    let w = match (i, j) {
                        (0, 0) => own(0),
                        (i, 0) if i == m => own(1),
                        (0, j) if j == m => own(2),
                        _ => on.weights(p),
                    };
                    verts.push((p.to_array(), uv, w));
                }
            }
            let (mut pos, mut uvs, mut lists) = (Vec::new(), Vec::new(), Vec::new());
            let mut corner = |i: usize, j: usize| {
                let (p, uv, w) = &verts[index(i, j)];
                pos.push(*p);
                uvs.extend(*uv);
                lists.push(w.clone());
            };
            for i in 0..m {
                for j in 0..m - i {
                    corner(i, j);
                    corner(i + 1, j);
                    corner(i, j + 1);
                    if i + j + 1 < m {
                        corner(i + 1, j);
                        corner(i + 1, j + 1);
                        corner(i, j + 1);
                    }
                }
            }
            (pos, uvs, lists)
        })
        .collect();
    let mut out = Scene {
        objects: scene.objects.clone(),
        materials: scene.materials.clone(),
        lights: scene.lights.clone(),
        textures: scene.textures.clone(),
        ..Default::default()
    };
    let mut all_lists = Vec::new();
    for (t, (pos, uvs, lists)) in parts.into_iter().enumerate() {
        out.uvs.extend(uvs);
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
