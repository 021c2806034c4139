//! The rasters the terrain commands write over a height map's grid (`relume-bake shadow`,
//! `softshadow`, `horizon`, `sunlight`): shadow masks, lit fractions, float rasters, one
//! horizon-angle plane per azimuth and the shaded relief. A `.tif` is a GeoTIFF with the input's
//! georeference, the input's no-data texels written as the raster's no-data value; the other
//! formats go through `baked::images` (atomic).

use crate::baked::images::{self, is_exr, is_tiff};
use crate::error::{Error, Result};
use crate::heightmap::georef::{write_geotiff_f32_with, write_geotiff_u8_with, TiffCompression};
use crate::heightmap::{HeightMap, HeightMapInfo};
use crate::render::tonemap::linear_to_srgb8;
use crate::terrain::hard::relief;
use crate::terrain::horizon::map::{decode, HorizonMap};
use crate::terrain::Sun;
use std::path::Path;

/// The no-data value of float GeoTIFF rasters (horizon angles, sky view, sun hours).
pub const NODATA: f64 = -9999.0;

/// Whether texel `i` of the loaded map is no-data (false where the map has no mask).
pub fn is_nodata(info: &HeightMapInfo, i: usize) -> bool {
    info.nodata_mask.get(i).copied().unwrap_or(false)
}

/// Write a hard-shadow mask (`true` = in shadow, one per texel of `map`): a GeoTIFF u8 (255 lit,
/// 0 shadow, 128 no-data; compressed by `compress`) or a PNG (255 lit, 0 shadow).
pub fn write_shadow_mask(
    path: &Path,
    map: &HeightMap,
    info: &HeightMapInfo,
    mask: &[bool],
    compress: TiffCompression,
) -> Result<()> {
    if is_tiff(path) {
        let px = masked(info, mask.len(), 128u8, |i| if mask[i] { 0 } else { 255 });
        let georef = info.georef.as_ref();
        write_geotiff_u8_with(
            path,
            map.width,
            map.height,
            &px,
            georef,
            Some(128),
            compress,
        )
    } else {
        let pixels: Vec<u8> = mask.iter().map(|&s| if s { 0 } else { 255 }).collect();
        images::write_png_gray8(path, map.width, map.height, pixels)
    }
}

/// Write a lit fraction in [0, 1] per texel of `map`: a GeoTIFF f32 (no-data −1; compressed by
/// `compress`), an EXR (f32) or a 16-bit PNG (65535 = fully lit).
pub fn write_lit_fraction(
    path: &Path,
    map: &HeightMap,
    info: &HeightMapInfo,
    lit: &[f32],
    compress: TiffCompression,
) -> Result<()> {
    if is_tiff(path) {
        write_tiff_f32(path, map, info, lit, -1.0, compress)
    } else if is_exr(path) {
        images::write_exr_gray(path, map.width, map.height, lit)
    } else {
        let px = lit
            .iter()
            .map(|&l| (l.clamp(0.0, 1.0) * 65535.0).round() as u16)
            .collect();
        images::write_png_gray16(path, map.width, map.height, px)
    }
}

/// Write a float raster over `map` (one value per texel): an EXR as is, else a GeoTIFF f32 with
/// the input's georeference and no-data texels as [`NODATA`], compressed by `compress`.
pub fn write_float_raster(
    path: &Path,
    map: &HeightMap,
    info: &HeightMapInfo,
    v: &[f32],
    compress: TiffCompression,
) -> Result<()> {
    if is_exr(path) {
        return images::write_exr_gray(path, map.width, map.height, v);
    }
    write_tiff_f32(path, map, info, v, NODATA as f32, compress)
}

/// `value(i)` for each of the `n` texels, `nodata` where the input had no data.
fn masked<T: Copy>(
    info: &HeightMapInfo,
    n: usize,
    nodata: T,
    value: impl Fn(usize) -> T,
) -> Vec<T> {
    (0..n)
        .map(|i| if is_nodata(info, i) { nodata } else { value(i) })
        .collect()
}

/// A GeoTIFF f32 over `map` with the input's georeference, `nodata` where the input had none.
fn write_tiff_f32(
    path: &Path,
    map: &HeightMap,
    info: &HeightMapInfo,
    v: &[f32],
    nodata: f32,
    compress: TiffCompression,
) -> Result<()> {
    let v = masked(info, v.len(), nodata, |i| v[i]);
    let (georef, nodata) = (info.georef.as_ref(), Some(nodata as f64));
    write_geotiff_f32_with(path, map.width, map.height, &v, georef, nodata, compress)
}

/// Write one horizon-angle GeoTIFF per azimuth of `hm` (degrees, f32) into `dir` (created if
/// missing), named `horizon_AAA.AAA.tif` by the direction's exact azimuth, compressed by
/// `compress`; the files are encoded in parallel on rayon's pool (`-j`), each byte-identical to a
/// sequential write.
pub fn write_horizon_planes(
    dir: &Path,
    map: &HeightMap,
    info: &HeightMapInfo,
    hm: &HorizonMap,
    compress: TiffCompression,
) -> Result<()> {
    use rayon::prelude::*;
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, "cannot create directory", e))?;
    // One file per direction, encoded in parallel (deflate is most of the time); each file is
    // written atomically, and the first error in azimuth order is the one reported.
    let results: Vec<Result<()>> = hm
        .directions
        .par_iter()
        .zip(&hm.angles)
        .map(|(d, plane)| {
            let v: Vec<f32> = plane.iter().map(|&q| decode(q) as f32).collect();
            let p = dir.join(format!("horizon_{:07.3}.tif", d.azimuth_deg));
            write_float_raster(&p, map, info, &v, compress)
        })
        .collect();
    results.into_iter().collect()
}

/// Write the horizon angles of every azimuth of `hm` (degrees, f32) as one GeoTIFF at `path`, a
/// band per azimuth described as `azimuth AAA.AAA deg` by its exact azimuth, with the input's
/// georeference and no-data texels, compressed by `compress`.
pub fn write_horizon_stack(
    path: &Path,
    map: &HeightMap,
    info: &HeightMapInfo,
    hm: &HorizonMap,
    compress: TiffCompression,
) -> Result<()> {
    let band = |k: usize, texels: std::ops::Range<usize>| {
        let plane = &hm.angles[k];
        let nodata = NODATA as f32;
        texels
            .map(|i| {
                if is_nodata(info, i) {
                    nodata
                } else {
                    decode(plane[i]) as f32
                }
            })
            .collect()
    };
    let names: Vec<String> = hm
        .directions
        .iter()
        .map(|d| format!("azimuth {:.3} deg", d.azimuth_deg))
        .collect();
    let georef = info.georef.as_ref();
    crate::heightmap::georef::write_geotiff_stack_f32(
        path,
        map.width,
        map.height,
        &names,
        band,
        georef,
        Some(NODATA),
        compress,
    )
}

/// Write the shaded relief of `map` (8-bit sRGB PNG): Lambert × (k_shadow + (1 − k_shadow)·lit),
/// `shadow` the shadowed fraction per texel (`terrain::hard::relief::shaded_relief`; the k's
/// checked by `relief::check_k`).
pub fn write_shaded_relief(
    path: &Path,
    map: &HeightMap,
    sun: &Sun,
    shadow: &[f32],
    k_dark: f64,
    k_bright: f64,
) -> Result<()> {
    let relief = relief::shaded_relief(map, sun, shadow, k_dark, k_bright);
    let px = relief.into_iter().map(linear_to_srgb8).collect();
    images::write_png_gray8(path, map.width, map.height, px)
}
