//! Radiosity bake, first half (docs/algorithms.md §3; the radiosity thesis §3.5, §4.1): the scene is simplified
//! into patches ([`voxelize::voxelize`]), form factors between patches are estimated with BVH
//! visibility ([`formfactor`]), and the k-bounce or infinite-bounce transport matrix
//! `S = Σ_{h=1..k} (diag(ρ) F)^h` is precomputed ([`transport`]) so that the runtime gets the
//! indirect light of any direct lighting `E` as one product `S · E` per colour channel.
//!
//! Conventions (docs/algorithms.md §9): patch emission is radiance L as in the scene; the exitance of an
//! emitting patch is π·L; B, E and S·E are exitances; `F_ij` is the fraction of the energy leaving
//! patch i that arrives at patch j, so the gathered irradiance is `H_i = Σ_j F_ij B_j` and
//! `B = E + diag(ρ) F B`.
//!
//! This module computes on plain data and writes no file: `crate::baked::{patches, form_factors,
//! transport}` store its results, `crate::bake::stages::radiosity` runs it as pipeline stages.
//! docs/baked-format.md describes
//! them byte by byte.

pub mod formfactor;
pub mod geometry;
pub mod mesh;
pub mod patches;
pub mod transport;

use serde::{Deserialize, Serialize};
pub use transport::matrix::TransportMatrix;

/// Everything `voxelize` produces: the patches, the pieces of triangles they are made of, points
/// for the runtime's direct light, and the maps from the full mesh to the patches.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct PatchSet {
    /// Edge length of a voxel, in scene units.
    pub voxel_size: f64,
    /// World position of the grid's corner (grid coordinates are `(world − origin) / voxel_size`).
    pub origin: [f64; 3],
    /// Voxels along x, y, z.
    pub dims: [u32; 3],
    /// The patches, sorted by (voxel, axis); index = patch id = row/column of the matrices.
    pub patches: Vec<Patch>,
    /// Pieces of triangles (clipped to voxels), grouped by patch (`Patch::first_piece`).
    pub pieces: Vec<Piece>,
    /// Sample points per patch for direct light.
    pub samples_per_patch: u32,
    /// `samples_per_patch` points of patch i at `[i * samples_per_patch ..]`, world coordinates.
    pub samples: Vec<SurfacePoint>,
    /// For every scene triangle: the patches its visible area went into, with that area (scene
    /// units²). Degenerate triangles have an empty list.
    pub triangle_patches: PatchLists,
    /// For every scene triangle corner (`3 * triangle + corner`): the patches whose radiosity
    /// interpolates to it, with weights summing to 1 (empty only if no patch could be found).
    pub corners: PatchLists,
    /// Names of the scene's source objects (`Patch::objects` indexes them).
    pub objects: Vec<String>,
    pub stats: VoxelizeStats,
}

/// One patch: a cluster of mutually visible triangle pieces inside one voxel that face the same
/// dominant axis direction.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Patch {
    /// The voxel (x, y, z).
    pub voxel: [u32; 3],
    /// Dominant axis direction: 0 +x, 1 −x, 2 +y, 3 −y, 4 +z, 5 −z.
    pub axis: u8,
    /// Area in scene units².
    pub area: f32,
    /// Area-weighted centroid, world coordinates.
    pub centroid: [f32; 3],
    /// Normalised area-weighted normal of the pieces.
    pub normal: [f32; 3],
    /// Area-weighted albedo ρ (linear RGB).
    pub albedo: [f32; 3],
    /// Area-weighted emitted radiance L (linear RGB); the exitance is π·L.
    pub emission: [f32; 3],
    /// The patch's pieces are `pieces[first_piece .. first_piece + piece_count]`.
    pub first_piece: u32,
    pub piece_count: u32,
    /// Source objects (indices into `PatchSet::objects`), sorted.
    pub objects: Vec<u32>,
}

/// The visible part of one triangle inside one voxel (a convex polygon).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Piece {
    /// Scene triangle index.
    pub triangle: u32,
    /// Unit normal of the triangle.
    pub normal: [f64; 3],
    /// Vertices in grid coordinates, counter-clockwise about the normal.
    pub vertices: Vec<[f64; 3]>,
    /// Area in grid units² (voxel faces).
    pub area: f64,
}

/// Area-weighted sums of some pieces, in the order given: (area, Σ area·centroid,
/// Σ area·normal) in grid units. A patch's centroid is the second over the first, its normal the
/// third normalised (`voxelize`, and the adaptive refinement's cells).
pub fn piece_moments<'a>(
    pieces: impl IntoIterator<Item = &'a Piece>,
) -> (f64, glam::DVec3, glam::DVec3) {
    use glam::DVec3;
    let (mut area, mut centroid, mut normal) = (0.0, DVec3::ZERO, DVec3::ZERO);
    for p in pieces {
        let poly: Vec<DVec3> = p.vertices.iter().map(|&v| DVec3::from(v)).collect();
        area += p.area;
        centroid += p.area * geometry::centroid(&poly);
        normal += p.area * DVec3::from(p.normal);
    }
    (area, centroid, normal)
}

/// A point on a surface with its unit normal.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct SurfacePoint {
    pub position: [f32; 3],
    pub normal: [f32; 3],
}

/// Lists of (patch, value) in compressed-row form: list `k` is
/// `patches[offsets[k]..offsets[k+1]]` with `values[...]` alongside.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct PatchLists {
    pub offsets: Vec<u32>,
    pub patches: Vec<u32>,
    pub values: Vec<f32>,
}

impl PatchLists {
    pub fn from_lists(lists: Vec<Vec<(u32, f32)>>) -> Self {
        let mut out = PatchLists {
            offsets: vec![0],
            ..Default::default()
        };
        for list in lists {
            for (p, v) in list {
                out.patches.push(p);
                out.values.push(v);
            }
            out.offsets.push(out.patches.len() as u32);
        }
        out
    }

    /// Number of lists.
    pub fn len(&self) -> usize {
        self.offsets.len().saturating_sub(1)
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// List `k`: (patches, values).
    pub fn list(&self, k: usize) -> (&[u32], &[f32]) {
        let r = self.offsets[k] as usize..self.offsets[k + 1] as usize;
        (&self.patches[r.clone()], &self.values[r])
    }
}

/// What `voxelize` noticed.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct VoxelizeStats {
    /// Degenerate (zero-area) triangles skipped.
    pub degenerate_triangles: u32,
    /// Triangles that lost area to a coplanar face on top of them.
    pub covered_faces: u32,
    /// Area removed from covered faces (scene units², before voxelisation).
    pub covered_area: f64,
    /// Triangle corners for which no patch could be found (they get no indirect light).
    pub corners_without_patch: u32,
}

impl PatchSet {
    /// Number of patches.
    pub fn len(&self) -> usize {
        self.patches.len()
    }

    pub fn is_empty(&self) -> bool {
        self.patches.is_empty()
    }

    /// The pieces of `patch`.
    pub fn patch_pieces(&self, patch: &Patch) -> &[Piece] {
        &self.pieces[patch.first_piece as usize..(patch.first_piece + patch.piece_count) as usize]
    }

    /// An area sampler over a patch's pieces (grid coordinates).
    pub fn piece_sampler(&self, patch: &Patch) -> geometry::AreaSampler {
        let polys: Vec<(Vec<glam::DVec3>, glam::DVec3)> = self
            .patch_pieces(patch)
            .iter()
            .map(|p| {
                (
                    p.vertices.iter().map(|&v| glam::DVec3::from(v)).collect(),
                    glam::DVec3::from(p.normal),
                )
            })
            .collect();
        geometry::AreaSampler::new(polys.iter().map(|(p, n)| (p.as_slice(), *n)))
    }

    /// The ray tracer over the live triangles of `scene` in this voxelization's grid frame.
    pub fn visibility(
        &self,
        scene: &crate::scene::Scene,
    ) -> crate::raytrace::visibility::Visibility {
        let extent = self.dims.iter().copied().max().unwrap_or(1) as f64;
        crate::raytrace::visibility::Visibility::new(
            scene,
            &scene.live_triangles(),
            &self.frame(),
            extent,
        )
    }

    /// The grid frame of this patch set.
    pub fn frame(&self) -> geometry::Frame {
        geometry::Frame {
            origin: glam::DVec3::from(self.origin),
            scale: self.voxel_size,
        }
    }

    /// True when every patch's albedo has R = G = B (one transport channel suffices).
    pub fn is_grey(&self) -> bool {
        self.patches
            .iter()
            .all(|p| p.albedo[0] == p.albedo[1] && p.albedo[1] == p.albedo[2])
    }
}
