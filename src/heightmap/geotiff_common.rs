//! What the two GeoTIFF writers share: the compression choice, the atomic write (temporary
//! file, sync, rename) and the GeoTIFF tags of a georeference. `geotiff_write` writes single
//! rasters with the tiff crate's image encoder, `geotiff_stack` band by band with its tag writer.

use super::georef::GeoReference;
use crate::error::{Error, Result};
use std::io::{Seek, Write};
use std::path::Path;
use tiff::encoder::{Compression, DeflateLevel, DirectoryEncoder, TiffKind};
use tiff::tags::Tag;
use tiff::TiffResult;

/// How a GeoTIFF's pixels are compressed; GDAL, rasterio and QGIS read all of them. Measured on
/// the 64 horizon planes of Puget Sound 512² (f32; `relume-bake horizon
/// pipelines/puget-sound-512.ron --directions 64 --out DIR --compress HOW`, 2 cores, three runs;
/// the same command writing only a sky-view EXR takes 0.59–0.62 s):
///
/// | HOW | wall | bytes |
/// |---|---|---|
/// | `none` | 0.57–0.59 s | 64.3 MiB |
/// | `lzw` | 1.17–1.25 s | 62.3 MiB |
/// | `deflate` (default) | 0.79–0.81 s | 41.1 MiB |
/// | `deflate-small` | 1.62–1.71 s | 33.9 MiB |
///
/// `zstd` (written by `geotiff_stack`): 0.77 s and 52 MiB in a later pair of runs where `none`
/// took 0.68 s and `deflate` 0.90 s (docs/terrain.md has those and the 2K numbers).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum TiffCompression {
    /// Raw pixels: the fastest to write and to read, the largest.
    None,
    /// LZW (TIFF's classic; horizontal differencing for 8-bit masks).
    Lzw,
    /// Deflate at zlib's fast level (horizontal differencing for 8-bit masks).
    #[default]
    Deflate,
    /// Deflate at zlib's balanced level: a fifth smaller than `deflate`, twice the time.
    DeflateSmall,
    /// Zstandard at level 1 (GDAL's compression 50000; GDAL, rasterio and QGIS read it).
    Zstd,
}

impl TiffCompression {
    /// The tiff crate's codec, None for those written by `geotiff_stack` (zstd).
    pub(super) fn method(self) -> Option<Compression> {
        match self {
            TiffCompression::None => Some(Compression::Uncompressed),
            TiffCompression::Lzw => Some(Compression::Lzw),
            TiffCompression::Deflate => Some(Compression::Deflate(DeflateLevel::Fast)),
            TiffCompression::DeflateSmall => Some(Compression::Deflate(DeflateLevel::Balanced)),
            TiffCompression::Zstd => None,
        }
    }
}

/// Run `encode` into a temporary file beside `path` (`.NAME.relume-tmp-PID`), sync it and rename
/// it onto `path`; the temporary is removed on any error.
pub(super) fn write_atomically(
    path: &Path,
    encode: impl FnOnce(&mut std::io::BufWriter<std::fs::File>) -> TiffResult<()>,
) -> Result<()> {
    let shown = path.display();
    let Some(name) = path.file_name() else {
        return Err(Error::knob(format!("{shown}: not a file path")));
    };
    let pid = std::process::id();
    let tmp = path.with_file_name(format!(".{}.relume-tmp-{pid}", name.to_string_lossy()));
    let io = |e| Error::io(path, "cannot write GeoTIFF", e);
    let result = (|| {
        let file = std::fs::File::create(&tmp).map_err(io)?;
        let mut out = std::io::BufWriter::new(file);
        encode(&mut out).map_err(|e| match e {
            tiff::TiffError::IoError(e) => io(e),
            other => Error::unsupported(path, format!("cannot encode GeoTIFF: {other}")),
        })?;
        let file = out.into_inner().map_err(|e| io(e.into_error()))?;
        file.sync_all().map_err(io)?;
        std::fs::rename(&tmp, path).map_err(io)
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// Write `georef`'s GeoTIFF tags (those it has) into the directory `dir`.
pub(super) fn geo_tags<W: Write + Seek, K: TiffKind>(
    dir: &mut DirectoryEncoder<'_, W, K>,
    georef: Option<&GeoReference>,
) -> TiffResult<()> {
    let Some(g) = georef else {
        return Ok(());
    };
    for (tag, v) in [
        (Tag::ModelPixelScaleTag, &g.pixel_scale),
        (Tag::ModelTiepointTag, &g.tiepoints),
        (Tag::ModelTransformationTag, &g.transformation),
        (Tag::GeoDoubleParamsTag, &g.geo_doubles),
    ] {
        if !v.is_empty() {
            dir.write_tag(tag, &v[..])?; // [f64] is written as DOUBLE
        }
    }
    if !g.geo_keys.is_empty() {
        dir.write_tag(Tag::GeoKeyDirectoryTag, &g.geo_keys[..])?; // [u16]: SHORT
    }
    if !g.geo_ascii.is_empty() {
        let ascii = |c: char| if c.is_ascii() && c != '\0' { c } else { '?' };
        let text: String = g.geo_ascii.chars().map(ascii).collect();
        dir.write_tag(Tag::GeoAsciiParamsTag, text.as_str())?; // str: ASCII + NUL
    }
    Ok(())
}
