//! Function-based geometry (Vyatkin et al. 2018, first half): freeform surfaces — a base quadric
//! plus perturbation functions `gᵢ·max(Qᵢ, 0)³`, combined by min/max — ray cast without ever being
//! tessellated.
//!
//! - [`field`]: the compiled field (world quadrics, perturbations, the CSG program);
//! - [`poly`]: certified real roots of polynomials of degree ≤ 6;
//! - [`reference`]: the exact per-ray cast every other method is tested against;
//! - [`bounds`]: interval and affine bounds of the field over a view-pyramid cell;
//! - [`texture`]: shape textures (a height grid displacing a plane or sphere), their bounds
//!   from the min/max mipmap and their certified cast;
//! - [`twin`], [`twin_cast`], [`twin_texture`]: the f32 twin of the GPU kernel;
//! - [`view`]: the f64 camera and its cells; [`rmlrc`]: the multilevel caster;
//! - [`shade`]: normals, sun lighting and shadows, frames.
//!
//! Plain data in, plain data out: the scene description comes from
//! [`crate::scene::freeform`], images are written by the callers.

pub mod bounds;
pub mod field;
pub mod mesh;
pub mod mesh_error;
pub mod mesh_texture;
pub mod poly;
pub mod reference;
pub mod rmlrc;
pub mod shade;
pub mod texture;
pub mod texture_bounds;
pub mod texture_cast;
pub mod twin;
pub mod twin_cast;
pub mod twin_texture;
pub mod view;

pub use bounds::Bound;
pub use field::Field;
pub use rmlrc::RmlrcParams;
pub use shade::{render, Frame, Lighting, Method};
pub use view::View;
