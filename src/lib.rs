//! relume: bake light offline and play it back in real time.
//!
//! The library does the work; the binaries (`relume-bake`, `relume-player`) parse arguments,
//! show progress and print errors. Each pipeline stage is a module with one entry function over
//! plain data. Start at [`pipeline`] (what a bake is), [`bake`] (how it runs) and [`baked`] (what
//! it writes).

pub mod atmosphere;
pub mod bake;
pub mod baked;
pub mod compress;
pub mod cpu;
pub mod error;
pub mod freeform;
#[cfg(feature = "player")]
pub mod gpu;
pub mod heightmap;
pub mod limits;
pub mod load;
pub mod pipeline;
#[cfg(feature = "player")]
pub mod player;
pub mod progress;
pub mod radiosity;
pub mod raytrace;
pub mod render;
pub mod scene;
pub mod study;
pub mod terrain;
pub mod theme;

pub use error::{Error, Result};
