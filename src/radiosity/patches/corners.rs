//! The transfer from patches back to the full mesh: for every triangle corner, a short list of
//! (patch, weight) whose weighted radiosity is the corner's smooth indirect light.
//!
//! Every patch has a *cell*: its voxel, or — where its (voxel, axis) group holds several patches
//! (adaptive refinement, [`crate::radiosity::patches::adaptive`], or clusters split by a thin wall) — the smallest
//! dyadic sub-cube of the voxel (edge 2^−l, l ≤ [`MAX_CELL_LEVEL`]) holding its pieces. For a
//! corner at grid position `p` of a triangle with normal `n` and dominant axis `a`:
//!
//! 1. Each patch with axis `a` in the 27 voxels around `p` gets the tent weight of its cell,
//!    `Π_k max(0, 1 − |p_k − c_k| / s)` (centre c, edge s). On a grid of whole voxels these are
//!    the trilinear weights over the 8 voxels whose centres surround `p`; where cells of
//!    different sizes meet, each tent still falls to 0 continuously, so the blend has no seam.
//! 2. A patch is kept only when
//!    * its nearest point `q` lies within half a voxel of the triangle's plane (`|n·(q − p)| ≤ ½`):
//!      a shelf above a floor does not light the floor, and
//!    * the segment from `p` to `q`, both lifted off their surfaces, is unoccluded: a wall between
//!      them — however thin — blocks the pair. This is what stops leaks through walls thinner than
//!      a voxel (the voxelisation already keeps the two sides of such a wall in separate patches).
//! 3. Normalise the kept weights to sum 1. If none is kept, fall back to the patch the corner's
//!    own triangle piece belongs to.
//!
//! The weights vary continuously with `p` along a surface, so the interpolated light is smooth.

use crate::radiosity::formfactor::locate::{voxel_of, PatchLocator};
use crate::radiosity::geometry::dominant_axis;
use crate::radiosity::patches::clip::SNAP;
use crate::radiosity::{PatchLists, PatchSet};
use crate::raytrace::visibility::Visibility;
use crate::scene::Scene;
use glam::DVec3;
use rayon::prelude::*;

/// Largest distance of a kept patch from the corner's plane, in voxels.
const PLANE_DISTANCE: f64 = 0.5;
/// Height (grid units) of the second leak test between patches that share a voxel.
const RAISE: f64 = 0.05;
/// Deepest sub-cube level of a patch's cell (the adaptive refinement's `max_level` limit).
pub const MAX_CELL_LEVEL: u32 = 6;

/// The cell (lowest corner, edge; grid units) of every patch of `set`.
pub fn patch_cells(set: &PatchSet) -> Vec<(DVec3, f64)> {
    let mut out = Vec::with_capacity(set.patches.len());
    let mut start = 0;
    while start < set.patches.len() {
        let first = &set.patches[start];
        let same = |p: &crate::radiosity::Patch| p.voxel == first.voxel && p.axis == first.axis;
        let end = start + set.patches[start..].iter().take_while(|p| same(p)).count();
        let voxel = DVec3::from(first.voxel.map(|v| v as f64));
        for patch in &set.patches[start..end] {
            if end - start == 1 {
                out.push((voxel, 1.0));
                continue;
            }
            let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
            for piece in set.patch_pieces(patch) {
                for &v in &piece.vertices {
                    lo = lo.min(DVec3::from(v) - voxel);
                    hi = hi.max(DVec3::from(v) - voxel);
                }
            }
            let (lo, hi) = (lo + DVec3::splat(SNAP), hi - DVec3::splat(SNAP));
            let mut cell = (voxel, 1.0);
            for level in 1..=MAX_CELL_LEVEL {
                let s = 0.5f64.powi(level as i32);
                let a = (lo / s).floor().max(DVec3::ZERO);
                if a != (hi / s).floor().max(a) {
                    break;
                }
                cell = (voxel + a * s, s);
            }
            out.push(cell);
        }
        start = end;
    }
    out
}

/// Per-corner transfer lists (`3 * triangle + corner`) for every scene triangle; degenerate
/// triangles get empty lists. `vis` must be built over the same grid frame as `set`.
///
/// Corners are weighted by position: a vertex is the corner of about six triangles, and the
/// nearest-piece searches of a position (most of the work) are the same for all of them, so
/// each is done once per position ([`Nearest`]). The lists are those of weighting every corner
/// on its own, bit for bit.
pub fn corner_patches(scene: &Scene, set: &PatchSet, vis: &Visibility) -> PatchLists {
    let transfer = PointTransfer::new(scene, set, vis);
    let position = |c: usize| scene.positions[scene.triangles[c / 3][c % 3] as usize];
    let mut corners: Vec<([u32; 3], u32)> = (0..3 * scene.triangles.len())
        .filter(|&c| !scene.is_degenerate(c / 3))
        .map(|c| (position(c).map(f32::to_bits), c as u32))
        .collect();
    corners.par_sort_unstable();
    let groups: Vec<&[([u32; 3], u32)]> = corners.chunk_by(|a, b| a.0 == b.0).collect();
    let weighted: Vec<(u32, Vec<(u32, f32)>)> = groups
        .par_iter()
        .flat_map_iter(|group| {
            let (transfer, position) = (&transfer, &position);
            let mut memo = Nearest::default();
            group.iter().map(move |&(_, c)| {
                let on = transfer.on_triangle(scene, c as usize / 3);
                let p = glam::Vec3::from(position(c as usize));
                (c, on.weights_with(p, &mut memo))
            })
        })
        .collect();
    let mut lists = vec![Vec::new(); 3 * scene.triangles.len()];
    for (c, list) in weighted {
        lists[c as usize] = list;
    }
    PatchLists::from_lists(lists)
}

/// The nearest-piece answers at one position, kept while the corners there are weighted:
/// [`PatchLocator::nearest`] by patch and [`PatchLocator::nearest_in_voxel`] by (voxel, axis)
/// depend on the position alone. A few dozen entries at most (27 voxels' patches): searched
/// in order.
#[derive(Default)]
struct Nearest {
    patches: Vec<(usize, DVec3, DVec3)>,
    voxels: Vec<([i64; 3], u8, Option<u32>)>,
}

impl Nearest {
    fn patch(&mut self, locator: &PatchLocator, p: DVec3, j: usize) -> (DVec3, DVec3) {
        if let Some(&(_, q, qn)) = self.patches.iter().find(|e| e.0 == j) {
            return (q, qn);
        }
        let (_, q, qn) = locator.nearest(p, j);
        self.patches.push((j, q, qn));
        (q, qn)
    }

    fn in_voxel(&mut self, locator: &PatchLocator, p: DVec3, v: [i64; 3], axis: u8) -> Option<u32> {
        if let Some(&(_, _, c)) = self.voxels.iter().find(|e| e.0 == v && e.1 == axis) {
            return c;
        }
        let c = locator.nearest_in_voxel(p, v, axis).map(|c| c.0);
        self.voxels.push((v, axis, c));
        c
    }
}

/// The transfer weights of any point on a scene triangle, by the rule of the corners: what the
/// display mesh (`radiosity::mesh::display`) and the glTF export use at the vertices of a split
/// triangle, where blending the triangle's three corners would spread one corner's light over
/// a whole wall. `vis` is the BVH of the voxelization ([`PatchSet::visibility`](crate::radiosity::PatchSet::visibility)).
pub struct PointTransfer<'a> {
    locator: PatchLocator,
    cells: Vec<(DVec3, f64)>,
    albedo: Vec<[f32; 3]>,
    vis: &'a Visibility,
    frame: crate::radiosity::geometry::Frame,
    dims: [u32; 3],
    lift: f64,
}

/// A scene triangle's plane in grid coordinates, for [`PointTransfer`] queries on it.
pub struct OnTriangle<'t, 'a> {
    transfer: &'t PointTransfer<'a>,
    normal: DVec3,
    centre: DVec3,
}

impl<'a> PointTransfer<'a> {
    pub fn new(scene: &Scene, set: &PatchSet, vis: &'a Visibility) -> Self {
        Self::with_cells(scene, set, vis, patch_cells(set))
    }

    /// [`PointTransfer::new`] with the [`patch_cells`] of `set` already computed.
    pub fn with_cells(
        scene: &Scene,
        set: &PatchSet,
        vis: &'a Visibility,
        cells: Vec<(DVec3, f64)>,
    ) -> Self {
        PointTransfer {
            locator: PatchLocator::new(set, scene),
            cells,
            albedo: set.patches.iter().map(|p| p.albedo).collect(),
            vis,
            frame: set.frame(),
            dims: set.dims,
            lift: 4.0 * vis.epsilon as f64,
        }
    }

    /// Queries on scene triangle `t` (its normal and centre computed once).
    pub fn on_triangle(&self, scene: &Scene, t: usize) -> OnTriangle<'_, 'a> {
        let c = scene.triangles[t].map(|v| self.frame.to_grid(scene.positions[v as usize]));
        OnTriangle {
            transfer: self,
            normal: (c[1] - c[0]).cross(c[2] - c[0]).normalize(),
            centre: (c[0] + c[1] + c[2]) / 3.0,
        }
    }
}

impl OnTriangle<'_, '_> {
    /// Weights (patch, weight summing to 1) of the point `p` (world) on the triangle.
    pub fn weights(&self, p: glam::Vec3) -> Vec<(u32, f32)> {
        self.weights_with(p, &mut Nearest::default())
    }

    /// [`OnTriangle::weights`], with the nearest-piece answers at `p` kept in `memo` (which
    /// must hold answers at `p` only).
    fn weights_with(&self, p: glam::Vec3, memo: &mut Nearest) -> Vec<(u32, f32)> {
        let t = self.transfer;
        corner_weights(
            t.frame.to_grid(p.to_array()),
            self.normal,
            self.centre,
            t,
            memo,
        )
    }
}

fn corner_weights(
    p: DVec3,
    n: DVec3,
    centre: DVec3,
    t: &PointTransfer,
    memo: &mut Nearest,
) -> Vec<(u32, f32)> {
    let (locator, cells, vis, dims, lift) = (&t.locator, &t.cells, t.vis, t.dims, t.lift);
    let axis = dominant_axis(n);
    // The corner lifted off its surface and nudged into its triangle, so the leak test starts
    // in the open and not on an adjoining wall's plane.
    let inward = (centre - p).try_normalize().unwrap_or(DVec3::ZERO);
    let from = p + n * lift + inward * lift;
    let home = p.floor();
    let mut out: Vec<(u32, f64)> = Vec::with_capacity(8);
    for k in 0..27i64 {
        let voxel: [i64; 3] =
            std::array::from_fn(|a| home[a] as i64 + (k / 3i64.pow(a as u32)) % 3 - 1);
        let group = locator.candidates(voxel, axis);
        let shared = group.len() > 1;
        // Where a voxel holds several patches of this orientation, its nearest one is blended
        // with those of the same material in cells apart from its own (the octants of an
        // adaptive split); a patch of another material, or a cluster sharing its cell, is not
        // (a threshold under a closed door does not light the floor beside it).
        // The nearest patch is found when a patch of the group first has a weight at p: most of
        // the 27 voxels' cells do not reach it.
        let mut own: Option<Option<usize>> = None;
        for j in group {
            let (lo, size) = cells[j];
            let centre = lo + DVec3::splat(0.5 * size);
            let w: f64 = (0..3)
                .map(|a| (1.0 - (p[a] - centre[a]).abs() / size).max(0.0))
                .product();
            if w <= 0.0 {
                continue;
            }
            if shared {
                let own = *own.get_or_insert_with(|| {
                    memo.in_voxel(locator, p, voxel, axis).map(|c| c as usize)
                });
                if let Some(k) = own {
                    if j != k && !(same_material(&t.albedo, j, k) && apart(cells[j], cells[k])) {
                        continue;
                    }
                }
            }
            let (q, qn) = memo.patch(locator, p, j);
            if n.dot(q - p).abs() > PLANE_DISTANCE {
                continue;
            }
            let to = q + qn * lift + (p - q).try_normalize().unwrap_or(DVec3::ZERO) * lift;
            if vis.occluded(from, to) {
                continue;
            }
            // Patches sharing a voxel are blended (not just the nearest taken), so a pair that
            // meets under a wall's edge is tested again higher up, where the wall is.
            if shared && vis.occluded(from + n * RAISE, to + qn * RAISE) {
                continue;
            }
            out.push((j as u32, w));
        }
    }
    let total: f64 = out.iter().map(|e| e.1).sum();
    if total > 0.0 {
        out.sort_by_key(|e| e.0);
        return out
            .into_iter()
            .map(|(j, w)| (j, (w / total) as f32))
            .collect();
    }
    let inside = p + inward * (4.0 * lift);
    locator
        .locate(inside, axis)
        .or_else(|| {
            let v = voxel_of(inside, dims);
            locator.nearest_in_voxel(inside, v, axis).map(|c| c.0)
        })
        .map(|j| vec![(j, 1.0)])
        .unwrap_or_default()
}

/// Albedos of patches `a` and `b` within the adaptive refinement's default tolerance.
fn same_material(albedo: &[[f32; 3]], a: usize, b: usize) -> bool {
    (0..3).all(|c| {
        (albedo[a][c] - albedo[b][c]).abs() as f64
            <= crate::radiosity::patches::adaptive::ALBEDO_TOLERANCE
    })
}

/// Whether two cells (lowest corner, edge) have no interior in common.
fn apart(a: (DVec3, f64), b: (DVec3, f64)) -> bool {
    (0..3).any(|k| a.0[k] + a.1 <= b.0[k] + SNAP || b.0[k] + b.1 <= a.0[k] + SNAP)
}

/// Interpolate per-patch values (e.g. radiosity of one channel) to every triangle corner.
pub fn interpolate(lists: &PatchLists, values: &[f32]) -> Vec<f32> {
    (0..lists.len())
        .map(|k| {
            let (p, w) = lists.list(k);
            p.iter().zip(w).map(|(&j, &w)| w * values[j as usize]).sum()
        })
        .collect()
}
