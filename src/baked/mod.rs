//! The baked directory: the contract between `relume-bake` and `relume-player`
//! (docs/baked-format.md). A manifest lists every file with its size and SHA-256; files are
//! written through a [`BakeTransaction`] so that a bake appears whole or not at all.
//!
//! File kinds: `scene.bin` and other structured records are postcard-encoded (a stable,
//! documented serde wire format); matrices are NumPy `.npy` (little-endian f32, C order) so anyone
//! can check them with numpy; images and height fields are OpenEXR.

pub mod exr_io;
pub mod manifest;
mod transaction;

pub use manifest::{
    verify, FileRecord, Manifest, StageRecord, VerifyProblem, FORMAT_VERSION, MANIFEST,
};
pub use transaction::BakeTransaction;

use crate::error::{Error, IoContext, Result};
use crate::heightmap::HeightMap;
use crate::scene::Scene;
use serde::{de::DeserializeOwned, Serialize};
use std::path::Path;

/// File name of the scene record in a scene bake.
pub const SCENE_FILE: &str = "scene.bin";
/// File name of the height field in a height-map bake.
pub const HEIGHTMAP_FILE: &str = "heightmap.exr";

/// Encode a record with postcard.
pub fn to_postcard<T: Serialize>(value: &T) -> Result<Vec<u8>> {
    postcard::to_stdvec(value).map_err(|e| Error::Internal(format!("cannot encode record: {e}")))
}

/// Read and decode a postcard record; `path` names the file in errors.
pub fn read_postcard<T: DeserializeOwned>(path: &Path) -> Result<T> {
    let bytes = std::fs::read(path).at(path, "cannot read")?;
    postcard::from_bytes(&bytes).map_err(|e| Error::input(path, format!("corrupt record: {e}")))
}

/// Read the scene of a scene bake.
pub fn read_scene(dir: &Path) -> Result<Scene> {
    read_postcard(&dir.join(SCENE_FILE))
}

/// Write a height field as a one-channel (`Y`) f32 EXR.
pub fn write_heightmap(path: &Path, map: &HeightMap) -> Result<()> {
    exr_io::write_f32_channels(path, map.width, map.height, &[("Y", &map.heights)])
}

/// Read the height field of a height-map bake; cell size and height scale come from the
/// manifest's `load` record.
pub fn read_heightmap(dir: &Path, manifest: &Manifest) -> Result<HeightMap> {
    let path = dir.join(HEIGHTMAP_FILE);
    let (w, h, mut channels) = exr_io::read_f32_channels(&path)?;
    let load = manifest
        .stage("load")
        .ok_or_else(|| Error::input(dir.join(MANIFEST), "no `load` stage record"))?;
    let get = |k: &str| {
        load.report
            .get(k)
            .copied()
            .ok_or_else(|| Error::input(dir.join(MANIFEST), format!("`load` record lacks `{k}`")))
    };
    let cell_size = [get("cell_size_x")?, get("cell_size_y")?];
    let height_scale = get("height_scale")?;
    if channels.len() != 1 {
        return Err(Error::input(
            &path,
            format!("expected one channel, found {}", channels.len()),
        ));
    }
    let heights = channels.pop().unwrap().1;
    Ok(HeightMap {
        width: w,
        height: h,
        heights,
        cell_size,
        height_scale,
    })
}

/// Write an f32 array as `.npy` with the given shape (C order).
pub fn write_npy_f32(path: &Path, shape: &[u64], data: &[f32]) -> Result<()> {
    use npyz::WriterBuilder;
    let expected: u64 = shape.iter().product();
    if expected != data.len() as u64 {
        return Err(Error::Internal(format!(
            "npy shape {shape:?} does not hold {} values",
            data.len()
        )));
    }
    let file = std::fs::File::create(path).at(path, "cannot write")?;
    let mut w = npyz::WriteOptions::new()
        .default_dtype()
        .shape(shape)
        .writer(std::io::BufWriter::new(file))
        .begin_nd()
        .at(path, "cannot write")?;
    w.extend(data.iter().copied()).at(path, "cannot write")?;
    w.finish().at(path, "cannot write")
}

/// Read an f32 `.npy` file: (shape, values).
pub fn read_npy_f32(path: &Path) -> Result<(Vec<u64>, Vec<f32>)> {
    let bytes = std::fs::read(path).at(path, "cannot read")?;
    let npy = npyz::NpyFile::new(&bytes[..])
        .map_err(|e| Error::input(path, format!("not a .npy file: {e}")))?;
    let shape = npy.shape().to_vec();
    let data = npy
        .into_vec::<f32>()
        .map_err(|e| Error::input(path, format!("not an f32 .npy file: {e}")))?;
    Ok((shape, data))
}
