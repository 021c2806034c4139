//! `voxelize`: simplify a scene into radiosity patches (docs/algorithms.md §3, after Shcherbakov & Frolov
//! 2016, reference [1] of the radiosity thesis).
//!
//! 1. Skip degenerate (zero-area) triangles and count them.
//! 2. Resolve coplanar overlapping faces ([`crate::radiosity::patches::overlap`]): each region counts once, with the
//!    face on top (emitters cover what they lie on).
//! 3. Clip the visible part of every triangle into a grid of cubic voxels.
//! 4. Group the pieces by (voxel, dominant axis direction ±x ±y ±z of their triangle), then split
//!    each group into clusters of pieces that see each other (the segment between their centroids,
//!    lifted off the surface, is unoccluded). Each cluster is one patch: area = summed area,
//!    centroid = area-weighted centroid, normal = normalised area-weighted normal, albedo and
//!    emitted radiance = area-weighted means. Textured pieces bring the mean of factor × texture
//!    over themselves, and alpha-masked ones only their opaque area
//!    ([`crate::radiosity::patches::albedo`]); a patch whose pieces are all cut out is dropped. The visibility split keeps the two floors on either
//!    side of a wall thinner than a voxel apart, so light does not leak through the wall.
//! 5. Draw `samples_per_patch` points on each patch's pieces for the runtime's direct light, and
//!    compute the per-triangle-corner transfer ([`crate::radiosity::transfer`]).
//!
//! The voxel size is a knob, or it is chosen by bisection so that the number of (voxel, axis)
//! groups is closest to a target patch count.

use crate::error::{Error, Result};
use crate::progress::Silent;
use crate::radiosity::formfactor::{form_factors, Estimator, FormFactorParams};
use crate::radiosity::geometry::{self, axis_vector, split_key, Frame};
use crate::radiosity::patches::adaptive::{self, AdaptiveParams, Cell};
use crate::radiosity::patches::albedo;
use crate::radiosity::patches::clip::{clip_pieces, clusters, grid_dims, SNAP};
use crate::radiosity::patches::overlap::{self, Face};
use crate::radiosity::patches::voxel_size::SizeSearch;
use crate::radiosity::{Patch, PatchLists, PatchSet, Piece, SurfacePoint, VoxelizeStats};
use crate::raytrace::alpha::{AlphaMasks, Cutout, MaskedTriangle};
use crate::raytrace::visibility::Visibility;
use crate::scene::Scene;
use glam::DVec3;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// How fine the voxel grid is.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum Resolution {
    /// Edge length of a voxel in scene units (after the input's `scale`).
    VoxelSize(f64),
    /// Choose the voxel size so that about this many patches result.
    TargetPatches(u32),
    /// About `target` patches, refined where materials, geometry or light vary
    /// ([`crate::radiosity::patches::adaptive`]).
    Adaptive(AdaptiveParams),
}

/// Knobs of [`voxelize`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VoxelizeParams {
    pub resolution: Resolution,
    /// Points per patch stored for the runtime's direct light.
    pub samples_per_patch: u32,
}

/// Seed of the per-patch sample points.
const SAMPLE_SEED: u64 = 0x5a3b_1e5e;

/// Draws of a direct-light sample point before one on a cut-out texel is kept anyway.
const MASK_TRIES: usize = 64;

/// True when grid point `p` on scene triangle `t` is not cut away by its material's mask.
fn opaque_at(scene: &Scene, frame: &Frame, masks: &AlphaMasks, t: usize, p: DVec3) -> bool {
    match masks.cutout(scene, t) {
        Cutout::Nowhere => true,
        Cutout::Everywhere => false,
        Cutout::Masked(image) => {
            let v = scene.triangles[t]
                .map(|i| frame.to_grid(scene.positions[i as usize]).as_vec3().into());
            let uv = masks.corner_uvs(scene, t);
            MaskedTriangle { image, uv }.opaque_at(masks, &v, p.as_vec3().into())
        }
    }
}

/// Simplify `scene` into patches. Preconditions: the scene passed [`Scene::validate`].
pub fn voxelize(scene: &Scene, params: &VoxelizeParams) -> Result<PatchSet> {
    voxelize_noting(scene, params).map(|(set, _)| set)
}

/// [`voxelize`], with why `TargetPatches(n)` could not come within 20 % of `n` when it could not
/// ([`crate::radiosity::patches::voxel_size`]).
pub fn voxelize_noting(
    scene: &Scene,
    params: &VoxelizeParams,
) -> Result<(PatchSet, Option<String>)> {
    let live = scene.live_triangles();
    let degenerate = scene.triangles.len() - live.len();
    if live.is_empty() {
        return Err(Error::input(
            "scene",
            "the scene has no triangle with positive area: nothing to voxelize",
        ));
    }
    let world = |v: u32| glam::Vec3::from(scene.positions[v as usize]).as_dvec3();
    let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
    for &t in &live {
        for v in scene.triangles[t as usize] {
            lo = lo.min(world(v));
            hi = hi.max(world(v));
        }
    }
    let extent = hi - lo;
    let magnitude = lo.abs().max(hi.abs()).max_element();
    // Coplanarity tolerance: relative to the scene, never below the f32 grain of its coordinates.
    let tolerance = (1e-6 * extent.length()).max(8.0 * f32::EPSILON as f64 * magnitude);
    let faces: Vec<Face> = live
        .iter()
        .map(|&t| {
            let corners = scene.triangles[t as usize].map(|v| world(v) - lo);
            let normal = (corners[1] - corners[0])
                .cross(corners[2] - corners[0])
                .normalize();
            let m = &scene.materials[scene.triangle_material[t as usize] as usize];
            Face {
                corners,
                normal,
                emissive: m.is_emissive(),
            }
        })
        .collect();
    let visible = overlap::visible_parts(&faces, tolerance);

    let search = SizeSearch {
        scene,
        live: &live,
        faces: &faces,
        polys: &visible.polygons,
        origin: lo,
        extent,
    };
    let grid = |size: f64| {
        let Some(dims) = grid_dims(extent, size) else {
            let dims_f = (extent / size - DVec3::splat(SNAP)).ceil().max(DVec3::ONE);
            return Err(Error::knob(format!(
                "voxel size {size} gives a grid of {:.0} x {:.0} x {:.0} voxels for a scene of extent {:?}; use a larger voxel size or a smaller target patch count",
                dims_f.x, dims_f.y, dims_f.z, extent.to_array()
            )));
        };
        let frame = Frame {
            origin: lo,
            scale: size,
        };
        let pieces = clip_pieces(&live, &faces, &visible.polygons, size, dims);
        let extent_grid = dims.iter().copied().max().unwrap_or(1) as f64;
        let vis = Visibility::new(scene, &live, &frame, extent_grid);
        Ok((dims, frame, pieces, vis))
    };

    let mut note = None;
    let (dims, frame, pieces, vis, groups) = match params.resolution {
        Resolution::VoxelSize(size) => {
            let (dims, frame, pieces, vis) = grid(size)?;
            let groups = clusters(&pieces, &vis);
            (dims, frame, pieces, vis, groups)
        }
        Resolution::TargetPatches(n) => {
            let choice = search.for_target(n);
            note = choice.note;
            let (dims, frame, pieces, vis) = grid(choice.size)?;
            let groups = clusters(&pieces, &vis);
            (dims, frame, pieces, vis, groups)
        }
        Resolution::Adaptive(a) => {
            let ((dims, frame, mut pieces, vis), cells) = adaptive_base(&search, &grid, scene, &a)?;
            let materials = cells.len();
            let (cells, report) =
                adaptive::refine(&mut pieces, cells, dims, &vis, &a, |cells, pieces| {
                    coarse_light(scene, &frame, dims, cells, pieces)
                });
            note = adaptive_note(&a, cells.len(), materials, &report);
            let groups = cells.into_iter().map(|c| (c.key, c.members)).collect();
            (dims, frame, pieces, vis, groups)
        }
    };
    let size = frame.scale;

    // One patch per cluster of mutually visible pieces of a (voxel, axis) group.
    let mut set = PatchSet {
        voxel_size: size,
        origin: lo.to_array(),
        dims,
        ..Default::default()
    };
    let surfaces = albedo::piece_surfaces(scene, &frame, &pieces);
    for (key, members) in groups {
        let cut = Cut::Textured(&surfaces);
        if let Some(patch) = build_patch(scene, &frame, key, dims, &members, &pieces, cut, &mut set)
        {
            set.patches.push(patch);
        }
    }
    drop(pieces);

    // Direct-light sample points and the triangle → patch map.
    // On alpha-masked pieces a point on a cut-out texel is drawn again (up to MASK_TRIES times).
    set.samples_per_patch = params.samples_per_patch;
    let masks = AlphaMasks::new(scene);
    for (i, patch) in set.patches.iter().enumerate() {
        let sampler = set.piece_sampler(patch);
        let triangles: Vec<u32> = set.patch_pieces(patch).iter().map(|p| p.triangle).collect();
        let mut rng = geometry::item_rng(SAMPLE_SEED, i as u64, 0);
        let k = params.samples_per_patch as usize;
        for (u, v) in rng.jittered(k) {
            let (mut u, mut v) = (u, v);
            let mut tries = 0;
            while tries < MASK_TRIES && !masks.is_empty() {
                let t = triangles[sampler.source(u)] as usize;
                let (p, _) = sampler.sample_square(u, v);
                if opaque_at(scene, &frame, &masks, t, p) {
                    break;
                }
                (u, v, tries) = (rng.f64(), rng.f64(), tries + 1);
            }
            let (p, n) = sampler.sample_square(u, v);
            set.samples.push(SurfacePoint {
                position: frame.to_world(p).as_vec3().to_array(),
                normal: n.as_vec3().to_array(),
            });
        }
    }
    set.triangle_patches = triangle_map(scene, &set, size);

    set.corners = crate::radiosity::patches::corners::corner_patches(scene, &set, &vis);
    set.objects = scene.objects.clone();
    set.stats = VoxelizeStats {
        degenerate_triangles: degenerate as u32,
        covered_faces: visible.covered_faces as u32,
        covered_area: visible.covered_area,
        corners_without_patch: live
            .iter()
            .flat_map(|&t| (0..3).map(move |c| 3 * t as usize + c))
            .filter(|&c| set.corners.list(c).0.is_empty())
            .count() as u32,
    };
    Ok((set, note))
}

pub use crate::radiosity::patches::clip::clip_to_voxels;

/// A grid: its dimensions and frame, the pieces clipped into it, the visibility BVH over it.
type Grid = ([u32; 3], Frame, Vec<(u64, Piece)>, Visibility);

/// The base grid of `Adaptive`, split by material: sized for `base_share · target` patches,
/// and made coarser (up to twice more) while the material split alone exceeds the target.
fn adaptive_base(
    search: &SizeSearch,
    grid: &dyn Fn(f64) -> Result<Grid>,
    scene: &Scene,
    a: &AdaptiveParams,
) -> Result<(Grid, Vec<Cell>)> {
    let mut base = (a.target as f64 * a.base_share).max(1.0);
    for attempt in 1.. {
        let choice = search.for_target(base.round().max(1.0) as u32);
        let (dims, frame, pieces, vis) = grid(choice.size)?;
        let groups = clusters(&pieces, &vis);
        let (cells, _) = adaptive::by_material(scene, groups, &pieces, dims, a.albedo_tolerance);
        if cells.len() <= a.target as usize || attempt == 3 {
            return Ok(((dims, frame, pieces, vis), cells));
        }
        base *= 0.8 * a.target as f64 / cells.len() as f64;
    }
    unreachable!()
}

/// Why `Adaptive` missed its target by more than 20 %, if it did.
fn adaptive_note(
    a: &AdaptiveParams,
    patches: usize,
    materials: usize,
    report: &adaptive::Refinement,
) -> Option<String> {
    let n = a.target as f64;
    if (patches as f64 - n).abs() <= 0.2 * n {
        return None;
    }
    Some(if materials as f64 > 1.2 * n {
        format!(
            "separating materials (albedo_tolerance {}) alone makes {materials} patches on the coarsest base grid tried; raise the target or the tolerance",
            a.albedo_tolerance
        )
    } else {
        format!(
            "every cell that could be split was split {} time(s) (max_level) after {} geometry and {} light splits; raise max_level or base_share",
            a.max_level, report.geometry_splits, report.light_splits
        )
    })
}

/// Rays per patch of the coarse bake that guides light refinement.
pub const COARSE_RAYS: u32 = 1024;

/// The coarse bake of `Adaptive`: each cell's gathered light H_i = Σ_j F_ij B_j (mean over the
/// colour channels) from the scene's emitters, by reciprocal hemisphere form factors
/// ([`COARSE_RAYS`] rays per cell) and Gauss–Seidel; `None` when the scene has no emitter.
fn coarse_light(
    scene: &Scene,
    frame: &Frame,
    dims: [u32; 3],
    cells: &[Cell],
    pieces: &[(u64, Piece)],
) -> Option<Vec<f64>> {
    if !scene.materials.iter().any(|m| m.is_emissive()) {
        return None;
    }
    let mut set = PatchSet {
        voxel_size: frame.scale,
        origin: frame.origin.to_array(),
        dims,
        ..Default::default()
    };
    let means = scene.mean_albedos();
    for c in cells {
        let cut = Cut::MaterialMeans(&means);
        if let Some(patch) =
            build_patch(scene, frame, c.key, dims, &c.members, pieces, cut, &mut set)
        {
            set.patches.push(patch);
        }
    }
    let params = FormFactorParams {
        estimator: Estimator::HemisphereReciprocal,
        samples: COARSE_RAYS,
        seed: 0,
    };
    let f = form_factors(scene, &set, &params, &Silent).ok()?;
    let n = f.n;
    let mut h = vec![0.0; n];
    for c in 0..3 {
        let rho: Vec<f64> = set.patches.iter().map(|p| p.albedo[c] as f64).collect();
        let e: Vec<f64> = set
            .patches
            .iter()
            .map(|p| std::f64::consts::PI * p.emission[c] as f64)
            .collect();
        let b =
            crate::radiosity::transport::reference::gauss_seidel(&f.values, &rho, &e, 1e-4, 1000)
                .ok()?
                .b;
        let gathered: Vec<f64> = f
            .values
            .par_chunks(n)
            .map(|row| row.iter().zip(&b).map(|(&fij, bj)| fij as f64 * bj).sum())
            .collect();
        for (h, g) in h.iter_mut().zip(gathered) {
            *h += g / 3.0;
        }
    }
    Some(h)
}

/// What a textured piece reflects and keeps.
#[derive(Clone, Copy)]
enum Cut<'a> {
    /// Per piece, from its textures ([`albedo::piece_surfaces`], indexed like the pieces).
    Textured(&'a [Option<albedo::Surface>]),
    /// Each material's mean albedo ([`Scene::mean_albedos`]), opaque everywhere: the coarse
    /// bake that guides adaptive refinement, before the pieces are final.
    MaterialMeans(&'a [[f32; 3]]),
}

/// The patch made of `members` (indices into `pieces`), its pieces appended to `set.pieces`;
/// None when alpha masks cut all of them away.
#[allow(clippy::too_many_arguments)]
fn build_patch(
    scene: &Scene,
    frame: &Frame,
    key: u64,
    dims: [u32; 3],
    members: &[usize],
    pieces: &[(u64, Piece)],
    cut: Cut,
    set: &mut PatchSet,
) -> Option<Patch> {
    let (voxel, axis) = split_key(key, dims);
    let first_piece = set.pieces.len() as u32;
    // Each kept piece with its albedo; a piece's area counts only its opaque part.
    let mut kept: Vec<(Piece, DVec3)> = Vec::with_capacity(members.len());
    for &i in members {
        let p = &pieces[i].1;
        let material = scene.triangle_material[p.triangle as usize] as usize;
        let (surface, plain) = match cut {
            Cut::Textured(s) => (s[i], scene.materials[material].albedo),
            Cut::MaterialMeans(means) => (None, means[material]),
        };
        match surface {
            Some(s) if s.coverage <= 0.0 => {}
            Some(s) => {
                let mut p = p.clone();
                p.area *= s.coverage;
                kept.push((p, s.albedo));
            }
            None => kept.push((p.clone(), glam::Vec3::from(plain).as_dvec3())),
        }
    }
    if kept.is_empty() {
        return None;
    }
    let (area, centroid, normal) = crate::radiosity::piece_moments(kept.iter().map(|(p, _)| p));
    let (mut albedo, mut emission) = (DVec3::ZERO, DVec3::ZERO);
    let mut objects = Vec::new();
    let piece_count = kept.len() as u32;
    for (p, rho) in kept {
        let t = p.triangle as usize;
        let m = &scene.materials[scene.triangle_material[t] as usize];
        albedo += p.area * rho;
        emission += p.area * glam::Vec3::from(m.emission).as_dvec3();
        objects.push(scene.triangle_object[t]);
        set.pieces.push(p);
    }
    objects.sort_unstable();
    objects.dedup();
    let normal = normal.try_normalize().unwrap_or_else(|| axis_vector(axis));
    Some(Patch {
        voxel,
        axis,
        area: (area * frame.scale * frame.scale) as f32,
        centroid: frame.to_world(centroid / area).as_vec3().to_array(),
        normal: normal.as_vec3().to_array(),
        albedo: (albedo / area).as_vec3().to_array(),
        emission: (emission / area).as_vec3().to_array(),
        first_piece,
        piece_count,
        objects,
    })
}

/// For every scene triangle, the patches its visible pieces feed and the area (world units) each.
fn triangle_map(scene: &Scene, set: &PatchSet, size: f64) -> PatchLists {
    let mut per: Vec<Vec<(u32, f32)>> = vec![Vec::new(); scene.triangles.len()];
    for (i, patch) in set.patches.iter().enumerate() {
        for p in set.patch_pieces(patch) {
            let list = &mut per[p.triangle as usize];
            let a = (p.area * size * size) as f32;
            match list.iter_mut().find(|e| e.0 == i as u32) {
                Some(e) => e.1 += a,
                None => list.push((i as u32, a)),
            }
        }
    }
    PatchLists::from_lists(per)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::radiosity::geometry::group_key;

    #[test]
    fn clipping_covers_the_polygon_exactly() {
        let tri = vec![
            DVec3::new(0.2, 0.1, 0.5),
            DVec3::new(3.7, 0.4, 0.5),
            DVec3::new(1.1, 2.9, 0.5),
        ];
        let pieces = clip_to_voxels(&tri, [4, 3, 1]);
        let sum: f64 = pieces.iter().map(|(_, p)| geometry::area(p)).sum();
        assert!((sum - geometry::area(&tri)).abs() < 1e-12);
        for (v, p) in &pieces {
            for q in p {
                for a in 0..3 {
                    assert!(q[a] >= v[a] as f64 - 1e-12 && q[a] <= v[a] as f64 + 1.0 + 1e-12);
                }
            }
        }
    }

    #[test]
    fn keys_round_trip() {
        let dims = [5, 7, 3];
        let k = group_key([4, 6, 2], 5, dims);
        assert_eq!(split_key(k, dims), ([4, 6, 2], 5));
    }
}
