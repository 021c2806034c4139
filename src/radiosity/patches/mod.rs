//! From a scene to patches (docs/radiosity.md; Dachsbacher et al. 2014 voxel simplification):
//!
//! - [`voxelize`]: the stage — clip every triangle to a voxel grid and cluster the pieces of
//!   each voxel by dominant axis and mutual visibility into patches;
//! - [`overlap`]: coplanar overlapping faces, so that only the visible part of each triangle
//!   counts;
//! - [`clip`]: clipping triangles to voxels and clustering the pieces;
//! - [`voxel_size`]: the voxel size for a target patch count (bisection);
//! - [`adaptive`]: the octree refinement of `Adaptive` (finer where geometry or light varies);
//! - [`albedo`]: albedo and opaque coverage of textured, alpha-masked pieces (exact
//!   texture-space integration);
//! - [`corners`]: which patches each scene triangle corner interpolates (the display side of
//!   a patch set, computed with it).

pub mod adaptive;
pub mod albedo;
pub mod clip;
pub mod corners;
pub mod overlap;
pub mod voxel_size;
pub mod voxelize;
