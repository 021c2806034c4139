//! Choosing the voxel size for `TargetPatches(n)`.
//!
//! A patch is a cluster of mutually visible pieces of one (voxel, axis) group
//! ([`crate::radiosity::patches::voxelize`]), so the patch count is the group count times a scene-dependent split
//! factor: about 1 on architecture, up to 12 on a triangle soup, where pieces in one voxel rarely
//! see each other. Counting groups alone (clipping only) missed a 10,000-triangle soup's target of
//! 1,000 by 12x. The search therefore runs in two steps:
//!
//! 1. Bisect (log space) on the cheap group count for a first size.
//! 2. Refine on the true patch count (clip, build the visibility BVH, cluster): regula falsi in
//!    log(size)–log(count) between the finest size known to give too many patches and the
//!    coarsest known to give too few, stopping within [`CLOSE_ENOUGH`] of the target or after
//!    [`MAX_EVALUATIONS`] counts (each costs about one voxelisation).
//!
//! The count is not always reachable: the coarsest grid (one voxel across the scene) can still
//! split a scene into more than `n` clusters, and the count can jump between two sizes closer
//! than the search resolves. [`SizeChoice::note`] then says which, for the stage to report.

use crate::radiosity::geometry::{self, Frame, Polygon};
use crate::radiosity::patches::clip::{clip_pieces, clusters, for_each_piece, grid_dims};
use crate::radiosity::patches::overlap::Face;
use crate::raytrace::visibility::Visibility;
use crate::scene::Scene;
use glam::DVec3;

/// Relative miss at which the refinement stops.
pub const CLOSE_ENOUGH: f64 = 0.05;
/// Most true patch counts the refinement computes.
pub const MAX_EVALUATIONS: usize = 12;

/// The inputs of the search: the scene's live triangles and their visible polygons (world
/// coordinates relative to `origin`).
pub(super) struct SizeSearch<'a> {
    pub scene: &'a Scene,
    pub live: &'a [u32],
    pub faces: &'a [Face],
    pub polys: &'a [Vec<Polygon>],
    pub origin: DVec3,
    pub extent: DVec3,
}

/// A voxel size tried and the patch count it gave.
type Tried = (f64, u64);

/// The voxel size chosen, the patch count it gives, and why the count is not closer to the
/// target when it is off by more than 20 %.
#[derive(Clone, Debug)]
pub struct SizeChoice {
    pub size: f64,
    pub patches: u64,
    pub note: Option<String>,
}

impl SizeSearch<'_> {
    /// (voxel, axis) groups of a grid of voxel `size` (`u64::MAX` when the grid is too large).
    fn groups_at(&self, size: f64) -> u64 {
        let Some(dims) = grid_dims(self.extent, size) else {
            return u64::MAX;
        };
        let mut keys = Vec::new();
        for_each_piece(
            self.live,
            self.faces,
            self.polys,
            size,
            dims,
            |key, _, _, _| keys.push(key),
        );
        keys.sort_unstable();
        keys.dedup();
        keys.len() as u64
    }

    /// Patches `voxelize` makes with voxel `size` (`u64::MAX` when the grid is too large). The
    /// clustering asks only occlusion queries, whose answers do not depend on the tree, so each
    /// size tried gets obvhs's medium build rather than the slowest: on the furnished room the
    /// stage went from 2.9 to 2.5 s with `patches.bin` byte-identical.
    fn patches_at(&self, size: f64) -> u64 {
        let Some(dims) = grid_dims(self.extent, size) else {
            return u64::MAX;
        };
        let pieces = clip_pieces(self.live, self.faces, self.polys, size, dims);
        let frame = Frame {
            origin: self.origin,
            scale: size,
        };
        let extent_grid = dims.iter().copied().max().unwrap_or(1) as f64;
        let vis = Visibility::with_build(
            self.scene,
            self.live,
            &frame,
            extent_grid,
            obvhs::BvhBuildParams::medium_build(),
        );
        clusters(&pieces, &vis).len() as u64
    }

    /// Bisect on the group count.
    fn by_groups(&self, target: f64) -> f64 {
        let total: f64 = self.polys.iter().flatten().map(|p| geometry::area(p)).sum();
        let guess = (total / target)
            .sqrt()
            .max(self.extent.max_element() * 1e-6);
        let (mut small, mut large) = (guess / 4.0, guess * 4.0);
        while self.groups_at(small) < target as u64 && small > guess * 1e-6 {
            small /= 4.0;
        }
        while self.groups_at(large) > target as u64 && large < guess * 1e6 {
            large *= 4.0;
        }
        let mut best = (f64::INFINITY, guess);
        for _ in 0..30 {
            let mid = (small * large).sqrt();
            let c = self.groups_at(mid);
            let miss = (c as f64 - target).abs();
            if miss < best.0 {
                best = (miss, mid);
            }
            if c as f64 > target {
                small = mid;
            } else {
                large = mid;
            }
            if large / small < 1.0 + 1e-6 {
                break;
            }
        }
        best.1
    }

    /// The voxel size whose patch count is closest to `target` among those tried.
    pub fn for_target(&self, target: u32) -> SizeChoice {
        let n = target.max(1) as f64;
        // One voxel across the scene's largest side: no grid is coarser.
        let coarsest = self.extent.max_element();
        let mut size = self.by_groups(n).min(coarsest);
        let mut best: Option<(f64, f64, u64)> = None;
        // Finest size known to give too many patches, coarsest known to give too few.
        let (mut fine, mut coarse): (Option<Tried>, Option<Tried>) = (None, None);
        for _ in 0..MAX_EVALUATIONS {
            let c = self.patches_at(size);
            let miss = (c as f64 - n).abs() / n;
            if best.is_none_or(|b| miss < b.0) {
                best = Some((miss, size, c));
            }
            if miss <= CLOSE_ENOUGH {
                break;
            }
            if c as f64 > n {
                fine = Some((size, c));
            } else {
                coarse = Some((size, c));
            }
            size = match (fine, coarse) {
                (Some(a), Some(b)) => {
                    if b.0 / a.0 < 1.0 + 1e-6 {
                        break;
                    }
                    let (la, lb) = ((a.1 as f64).ln(), (b.1.max(1) as f64).ln());
                    let t = if la > lb {
                        ((la - n.ln()) / (la - lb)).clamp(0.15, 0.85)
                    } else {
                        0.5
                    };
                    (a.0.ln() + t * (b.0.ln() - a.0.ln())).exp()
                }
                // Patches scale about as 1 / size² on surfaces.
                (Some(a), None) => {
                    if a.0 >= coarsest {
                        break;
                    }
                    (a.0 * (a.1 as f64 / n).sqrt().min(16.0)).min(coarsest)
                }
                (None, Some(b)) => b.0 * (b.1.max(1) as f64 / n).sqrt().max(1.0 / 16.0),
                (None, None) => unreachable!("every count is too many or too few"),
            };
        }
        let (miss, size, patches) = best.expect("at least one count");
        let note = (miss > 0.2).then(|| match (fine, coarse) {
            (Some((s, c)), None) if s >= coarsest => format!(
                "even one voxel across the scene gives {c} patches: pieces that cannot see each other are never merged into one patch"
            ),
            (Some((a, ca)), Some((b, cb))) => format!(
                "the patch count jumps from {ca} (voxel size {a:.4e}) to {cb} (voxel size {b:.4e}) and no size between gives a count closer to {target}"
            ),
            _ => format!(
                "{MAX_EVALUATIONS} voxel sizes tried, the closest gave {patches} patches"
            ),
        });
        SizeChoice {
            size,
            patches,
            note,
        }
    }
}
