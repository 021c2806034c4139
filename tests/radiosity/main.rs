//! Integration tests: the radiosity bake: patches, form factors, visibility (against Embree),
//! transport, export.
//!
//! One test binary per concept (each links the whole library once); one module per file.

#[path = "../common/mod.rs"]
mod common;
#[path = "../support/fixtures.rs"]
mod fixtures;
#[path = "../support/room_light.rs"]
mod room_light;

mod adaptive;
mod alpha;
mod alpha_embree;
mod export_gltf;
mod formfactors;
mod locate;
mod objects;
mod rooms;
mod transport;
mod visibility;
mod visibility_embree;
mod voxelize;
