//! Ray tracing against a scene's triangles, for the radiosity bake, the reference renderer and
//! the glTF export:
//!
//! - [`visibility`]: the queries — closest hit and occlusion of a segment — in grid coordinates
//!   ([`Frame`]);
//! - [`wide_collapse`]: obvhs's binary tree collapsed to eight children and leaves of up to four
//!   triangles;
//! - [`wide_bvh`]: the 8-wide BVH built from it and its traversal;
//! - [`wide_node`]: one node (Embree's BVH8 layout) and its slab test of all eight children;
//! - [`alpha`]: alpha-masked triangles (a ray passes through cut-out texels);
//! - [`watertight`]: watertight ray/triangle tests (Woop, Benthin and Wald 2013), one at a time
//!   or four in SSE lanes with the same operations.

use glam::{DVec3, Vec3};

pub mod alpha;
pub mod visibility;
pub mod watertight;
pub mod wide_bvh;
pub mod wide_collapse;
pub mod wide_node;

/// A uniform grid frame: grid coordinates are `(world − origin) / scale`. The radiosity bake
/// traces in the grid of its voxels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    /// World position of the grid's corner (the scene's bounds minimum).
    pub origin: DVec3,
    /// World units per grid unit (the voxel size).
    pub scale: f64,
}

impl Frame {
    pub fn to_grid(&self, world: [f32; 3]) -> DVec3 {
        (Vec3::from(world).as_dvec3() - self.origin) / self.scale
    }

    pub fn to_world(&self, grid: DVec3) -> DVec3 {
        self.origin + grid * self.scale
    }
}
