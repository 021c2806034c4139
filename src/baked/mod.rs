//! The baked directory: the contract between `relume-bake` and `relume-player`
//! (docs/baked-format.md). A manifest lists every file with its size and SHA-256; files are
//! written through a [`BakeTransaction`] so that a bake appears whole or not at all.
//!
//! One module per file kind (`scene`, `heightmap`, `patches`, `form_factors`, `transport`,
//! `permutation`, `encoded`, `mipmap`, `horizon`): its file name, reader and writer; nothing else reads or
//! writes that file. File kinds: `scene.bin` and other structured records are postcard-encoded (a stable,
//! documented serde wire format); matrices are NumPy `.npy` (little-endian f32, C order) so anyone
//! can check them with numpy; images and height fields are OpenEXR.

pub mod encoded;
pub mod export;
pub mod exr_io;
pub mod form_factors;
pub mod gltf;
pub mod gltf_materials;
pub mod heightmap;
pub mod horizon;
pub mod images;
pub mod manifest;
pub mod mipmap;
pub mod npy;
pub mod patches;
pub mod permutation;
pub mod rasters;
pub mod scene;
pub mod shard;
pub mod themes;
pub(crate) mod transaction;
pub mod transport;

pub use manifest::{
    verify, FileRecord, Manifest, StageRecord, VerifyProblem, FORMAT_VERSION, MANIFEST,
};
pub use transaction::BakeTransaction;

use crate::error::{Error, IoContext, Result};
use serde::{de::DeserializeOwned, Serialize};
use std::path::Path;

/// Encode a record with postcard.
pub fn to_postcard<T: Serialize>(value: &T) -> Result<Vec<u8>> {
    postcard::to_stdvec(value).map_err(|e| Error::Internal(format!("cannot encode record: {e}")))
}

/// Read and decode a postcard record; `path` names the file in errors.
pub fn read_postcard<T: DeserializeOwned>(path: &Path) -> Result<T> {
    let bytes = std::fs::read(path).at(path, "cannot read")?;
    postcard::from_bytes(&bytes).map_err(|e| Error::input(path, format!("corrupt record: {e}")))
}
