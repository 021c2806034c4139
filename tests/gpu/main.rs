//! Integration tests: GPU kernels against their CPU twins (Mesa lavapipe in CI), uniform layouts,
//! headless player frames.
//!
//! One test binary per concept (each links the whole library once); one module per file.

#[path = "../common/mod.rs"]
mod common;
#[path = "../support/fixtures.rs"]
mod fixtures;
#[path = "../support/gltf_cameras.rs"]
mod gltf_cameras;
#[path = "../support/gpu_twins.rs"]
mod twins;

mod atmosphere;
mod exposure;
mod freeform_gpu_shade;
mod freeform_gpu_texture;
mod freeform_twin;
mod gather;
mod kernels;
mod layout;
mod player;
mod player_ui;
mod terrain;
mod terrain_air;
mod textures;
mod themes;
mod twins_direct;
mod twins_lighting;
mod twins_raster;
