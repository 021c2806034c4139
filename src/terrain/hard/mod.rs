//! Hard shadows of the sun on a height map (docs/algorithms.md §4; Timonen and Westerholm 2010):
//!
//! - [`exact_traversal`]: visit every texel on the sun's track (algorithm A1, the reference);
//! - [`accelerated_traversal`]: the same walk over the min/max mipmap, skipping blocks that
//!   cannot shadow (algorithm A2), equal to A1;
//! - [`sweep`]: the certified sweep, the default method (bounds along bands of lines,
//!   witnesses, the exact walk for the rest), equal to A1;
//! - [`hard_f32`]: f32 twins of A1 and A2, line for line as the GPU evaluates them;
//! - [`relief`]: whole-image shadow masks and shaded relief.

pub mod accelerated_traversal;
pub mod exact_traversal;
pub mod hard_f32;
pub mod relief;
pub mod sweep;
