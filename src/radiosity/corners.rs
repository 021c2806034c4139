//! The transfer from patches back to the full mesh: for every triangle corner, a short list of
//! (patch, weight) whose weighted radiosity is the corner's smooth indirect light.
//!
//! For a corner at grid position `p` of a triangle with normal `n` and dominant axis `a`:
//!
//! 1. Trilinear weights over the 8 voxels whose centres surround `p` (centres at half-integers).
//! 2. In each of those voxels take the patch with the same axis `a` nearest to `p` (compatible
//!    orientation), and keep it only when
//!    * its nearest point `q` lies within half a voxel of the triangle's plane (`|n·(q − p)| ≤ ½`):
//!      a shelf above a floor does not light the floor, and
//!    * the segment from `p` to `q`, both lifted off their surfaces, is unoccluded: a wall between
//!      them — however thin — blocks the pair. This is what stops leaks through walls thinner than
//!      a voxel (the voxelisation already keeps the two sides of such a wall in separate patches).
//! 3. Normalise the kept weights to sum 1. If none is kept, fall back to the patch the corner's
//!    own triangle piece belongs to.
//!
//! The weights vary continuously with `p` along a surface, so the interpolated light is smooth.

use super::geometry::dominant_axis;
use super::locate::{voxel_of, PatchLocator};
use super::visibility::Visibility;
use super::{PatchLists, PatchSet};
use crate::scene::Scene;
use glam::DVec3;
use rayon::prelude::*;

/// Largest distance of a kept patch from the corner's plane, in voxels.
const PLANE_DISTANCE: f64 = 0.5;

/// Per-corner transfer lists (`3 * triangle + corner`) for every scene triangle; degenerate
/// triangles get empty lists. `vis` must be built over the same grid frame as `set`.
pub fn corner_patches(scene: &Scene, set: &PatchSet, vis: &Visibility) -> PatchLists {
    let transfer = PointTransfer::new(scene, set, vis);
    let lists: Vec<[Vec<(u32, f32)>; 3]> = (0..scene.triangles.len())
        .into_par_iter()
        .map(|t| {
            if scene.is_degenerate(t) {
                return Default::default();
            }
            let on = transfer.on_triangle(scene, t);
            scene.triangles[t].map(|v| on.weights(glam::Vec3::from(scene.positions[v as usize])))
        })
        .collect();
    PatchLists::from_lists(lists.into_iter().flatten().collect())
}

/// The transfer weights of any point on a scene triangle, by the rule of the corners: what the
/// display mesh (`radiosity::display`) and the glTF export use at the vertices of a split
/// triangle, where blending the triangle's three corners would spread one corner's light over
/// a whole wall. `vis` is the BVH of the voxelization ([`Visibility::for_patches`]).
pub struct PointTransfer<'a> {
    locator: PatchLocator,
    vis: &'a Visibility,
    frame: super::geometry::Frame,
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
        PointTransfer {
            locator: PatchLocator::new(set, scene),
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
        let t = self.transfer;
        corner_weights(
            t.frame.to_grid(p.to_array()),
            self.normal,
            self.centre,
            &t.locator,
            t.vis,
            t.dims,
            t.lift,
        )
    }
}

fn corner_weights(
    p: DVec3,
    n: DVec3,
    centre: DVec3,
    locator: &PatchLocator,
    vis: &Visibility,
    dims: [u32; 3],
    lift: f64,
) -> Vec<(u32, f32)> {
    let axis = dominant_axis(n);
    // The corner lifted off its surface and nudged into its triangle, so the leak test starts
    // in the open and not on an adjoining wall's plane.
    let inward = (centre - p).try_normalize().unwrap_or(DVec3::ZERO);
    let from = p + n * lift + inward * lift;
    let g = p - DVec3::splat(0.5);
    let base = g.floor();
    let f = g - base;
    let mut out: Vec<(u32, f64)> = Vec::with_capacity(8);
    for corner in 0..8 {
        let d = [corner & 1, (corner >> 1) & 1, (corner >> 2) & 1];
        let w: f64 = (0..3)
            .map(|a| if d[a] == 1 { f[a] } else { 1.0 - f[a] })
            .product();
        if w <= 0.0 {
            continue;
        }
        let voxel = std::array::from_fn(|a| base[a] as i64 + d[a] as i64);
        let Some((j, _, q)) = locator.nearest_in_voxel(p, voxel, axis) else {
            continue;
        };
        if n.dot(q - p).abs() > PLANE_DISTANCE {
            continue;
        }
        let qn = locator.piece_normal_near(j as usize, q);
        let to = q + qn * lift + (p - q).try_normalize().unwrap_or(DVec3::ZERO) * lift;
        if vis.occluded(from, to) {
            continue;
        }
        match out.iter_mut().find(|e| e.0 == j) {
            Some(e) => e.1 += w,
            None => out.push((j, w)),
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

/// Interpolate per-patch values (e.g. radiosity of one channel) to every triangle corner.
pub fn interpolate(lists: &PatchLists, values: &[f32]) -> Vec<f32> {
    (0..lists.len())
        .map(|k| {
            let (p, w) = lists.list(k);
            p.iter().zip(w).map(|(&j, &w)| w * values[j as usize]).sum()
        })
        .collect()
}
