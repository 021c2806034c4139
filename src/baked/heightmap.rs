//! `heightmap.exr`: the height field of a height-map bake (one f32 channel `Y`, metres); its
//! cell size and height scale are in the manifest's `load` record.

use super::{exr_io, BakeTransaction, Manifest};
use crate::error::{Error, Result};
use crate::heightmap::HeightMap;
use std::path::Path;

/// File name of the height field in a height-map bake.
pub const FILE: &str = "heightmap.exr";

/// The `load` record's fact that keeps the input's georeference (a GeoTIFF's tags for the
/// loaded grid, as RON), when it has one.
pub const GEOREFERENCE_FACT: &str = "georeference";

/// Write the height field into a bake.
pub fn write(txn: &mut BakeTransaction, map: &HeightMap) -> Result<()> {
    txn.write_with(FILE, |p| write_file(p, map))
}

/// Write a height field as a one-channel (`Y`) f32 EXR.
pub fn write_file(path: &Path, map: &HeightMap) -> Result<()> {
    exr_io::write_f32_channels(path, map.width, map.height, &[("Y", &map.heights)])
}

/// Read the height field of a height-map bake; cell size and height scale come from the
/// manifest's `load` record.
pub fn read(dir: &Path, manifest: &Manifest) -> Result<HeightMap> {
    let path = dir.join(FILE);
    let (w, h, mut channels) = exr_io::read_f32_channels(&path)?;
    let load = manifest
        .stage("load")
        .ok_or_else(|| Error::input(dir.join(super::MANIFEST), "no `load` stage record"))?;
    let get = |k: &str| {
        load.report.get(k).copied().ok_or_else(|| {
            Error::input(
                dir.join(super::MANIFEST),
                format!("`load` record lacks `{k}`"),
            )
        })
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
