//! From patches back to the scene's mesh, for what a viewer or a tool reads:
//!
//! - [`display`]: the mesh the player draws (long triangles split into grids) with the corner
//!   weights of every vertex;
//! - [`objects`]: mean irradiance per scene object, from the display mesh and from the patches.

pub mod display;
pub mod objects;
