//! CPU reference renderer and the pieces shared with the GPU player (camera, tone mapping).

pub mod camera;
pub mod direct;
pub mod exposure;
pub mod first_view;
pub mod freeform_image;
pub mod freeform_shade;
pub mod lights;
pub mod material_maps;
pub mod mesh_reference;
pub mod raycast;
pub mod terrain_shading;
pub mod terrain_view;
pub mod tonemap;
