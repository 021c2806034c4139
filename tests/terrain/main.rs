//! Integration tests: terrain: hard and soft shadows, horizon maps, sunlight, real DEMs, the
//! terrain commands.
//!
//! One test binary per concept (each links the whole library once); one module per file.

#[path = "../common/mod.rs"]
mod common;
#[path = "../terrain_common/mod.rs"]
mod terrain_common;

mod cli;
mod exactness;
mod f32;
mod first_view;
mod geo;
mod horizon;
mod horizon_bake;
mod real_dems;
mod shapes;
mod soft;
mod sunlight;
mod sweep_near;
