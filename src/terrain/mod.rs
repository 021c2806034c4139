//! Terrain: relief shadows on height maps (docs/algorithms.md §4, §5).
//!
//! - [`sun`]: the sun direction and its track in texel space (the constants every kernel uses);
//! - [`exact_traversal`]: hard shadows by visiting every texel on the track (algorithm A1, the reference);
//! - [`minmax_mipmap`]: the min/max mipmap (in `heightmap`, the data layer, so that freeform
//!   shape textures share it; stored by `crate::baked::mipmap`);
//! - [`accelerated_traversal`]: hard shadows over the mipmap (algorithm A2), equal to the exact answer;
//! - [`sweep`]: hard shadows by a certified sweep (bounds along bands, witnesses, exact
//!   traversal for the rest), equal to the exact answer; [`sweep_bound`] its bound,
//!   [`sweep_near`] the exact test of each track's first lines as a per-row stencil,
//!   [`sweep_exact`] its scalar walk and witnesses;
//! - [`horizon`]: horizon angles for N azimuths by a line sweep with convex hulls;
//! - [`horizon_map`]: the quantised horizon map: sky-view factor, O(1) shadows for any sun;
//! - [`hard_f32`]: f32 twins of the hard-shadow kernels (what a GPU port evaluates);
//! - [`relief`]: whole-image shadow masks and shaded relief;
//! - [`soft`]: soft shadows of the sun's disc on flat or curved terrain (four methods);
//! - [`solar`]: the sun's position from date, time and place (NREL SPA);
//! - [`sunlight`]: hours of direct sun (and clear-sky insolation) over a day from horizon maps;
//! - [`generate`]: synthetic height maps (stress maps and analytic shapes);
//!
//! Per-pixel kernels are plain loops over flat arrays (no recursion, no allocation) so that
//! the GPU player can port them line by line to WGSL.

pub mod generate;
pub mod hard;
pub mod horizon;
pub use crate::heightmap::minmax_mipmap;
pub mod soft;
pub mod sun;
pub mod transpose;

pub use minmax_mipmap::MinMaxMipmap;
pub use sun::{Sun, Track, TrackKind};
