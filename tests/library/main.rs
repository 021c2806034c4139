//! Integration tests: the library's algorithms against independent references, and the layout of
//! the source tree.
//!
//! One test binary per concept (each links the whole library once); one module per file.

#[path = "../common/mod.rs"]
mod common;
#[path = "../support/gltf_cameras.rs"]
mod gltf_cameras;
#[path = "../support/transport_box.rs"]
mod transport_box;

mod architecture;
mod atmosphere;
mod atmosphere_orders;
mod compress_lib;
mod first_view;
mod freeform_mesh;
mod freeform_mesh_texture;
mod freeform_quadrics;
mod freeform_rmlrc;
mod freeform_texture;
mod history;
mod independent_decoders;
mod loaders;
mod material_maps;
mod reorder_bounded;
mod textures;
mod themes;
mod themes_geo;
