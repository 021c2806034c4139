//! Writing GeoTIFFs band by band: one multi-band float32 GeoTIFF with a band per plane (horizon
//! angles per azimuth), which GDAL, rasterio and QGIS read as one stack, each band's description
//! naming it (GDAL's `GDAL_METADATA` tag, `role="description"`); and any single-band raster
//! compressed with Zstandard, which the tiff crate's encoder does not write.
//!
//! The tiff crate's image encoder writes fixed colour types (one to four samples) and its own
//! codecs, so the directory is assembled here with its tag writer: planar configuration 2 (band after band),
//! strips of about 256 KiB, `SampleFormat` IEEE float, `ExtraSamples` unspecified for bands past
//! the first (baseline TIFF's rule for grey images with more samples). Strips are compressed in
//! parallel (flate2's zlib stream at the level the single-band writer uses, weezl's LZW with
//! TIFF's early code-size change, or zstd at level 1 under GDAL's code 50000), then written in band order: the bytes are the same for any
//! thread count. Written atomically like every GeoTIFF of relume (temporary file, sync, rename).

use super::georef::GeoReference;
use super::geotiff_common::{geo_tags, write_atomically, TiffCompression};
use crate::error::{Error, Result};
use rayon::prelude::*;
use std::io::{Seek, Write};
use std::path::Path;
use tiff::encoder::{TiffEncoder, TiffKind, TiffKindBig, TiffKindStandard};
use tiff::tags::Tag;
use tiff::TiffResult;

/// Zstandard level: at level −3 Puget Sound 2K's 64-band stack took 6.9–7.0 s and 764 MiB against
/// 7.2–7.3 s and 670 MiB at level 1.
const ZSTD_LEVEL: i32 = 1;

/// Uncompressed bytes per strip aimed at.
const STRIP_BYTES: usize = 256 << 10;

/// A sample type the band writer stores.
pub trait Sample: bytemuck::Pod + Send + Sync {
    const BITS: u16;
    /// TIFF's SampleFormat: 1 unsigned integer, 3 IEEE float.
    const FORMAT: u16;
}

impl Sample for f32 {
    const BITS: u16 = 32;
    const FORMAT: u16 = 3;
}

impl Sample for u8 {
    const BITS: u16 = 8;
    const FORMAT: u16 = 1;
}

/// Write `names.len()` bands of `width`×`height` f32 (row 0 north) as one GeoTIFF at `path`,
/// band `k` described as `names[k]`, with `georef`'s tags and GDAL_NODATA `nodata`.
/// `band(k, texels)` gives band `k`'s values at the row-major texel indices `texels` (one strip);
/// it is called in parallel, once per strip, so no band need be held whole.
#[allow(clippy::too_many_arguments)]
pub fn write_geotiff_stack_f32(
    path: &Path,
    width: usize,
    height: usize,
    names: &[String],
    band: impl Fn(usize, std::ops::Range<usize>) -> Vec<f32> + Sync,
    georef: Option<&GeoReference>,
    nodata: Option<f64>,
    compression: TiffCompression,
) -> Result<()> {
    let bands = (names.len(), Some(names));
    write_bands(
        path,
        [width, height],
        bands,
        band,
        georef,
        nodata,
        compression,
    )
}

/// The general writer: `count` bands of `T`, described by `names` when given.
pub(super) fn write_bands<T: Sample>(
    path: &Path,
    [width, height]: [usize; 2],
    (count, names): (usize, Option<&[String]>),
    band: impl Fn(usize, std::ops::Range<usize>) -> Vec<T> + Sync,
    georef: Option<&GeoReference>,
    nodata: Option<f64>,
    compression: TiffCompression,
) -> Result<()> {
    let shown = path.display();
    if count == 0 || count > u16::MAX as usize || names.is_some_and(|n| n.len() != count) {
        let msg = format!("{shown}: {count} bands (1 to 65535, each named or none)");
        return Err(Error::knob(msg));
    }
    if width == 0 || height == 0 || u32::try_from(width.max(height)).is_err() {
        return Err(Error::knob(format!(
            "{shown}: a {width}x{height} GeoTIFF (sides: 1 to 2^32 - 1)"
        )));
    }
    let row_bytes = width * std::mem::size_of::<T>();
    let rows = (STRIP_BYTES / row_bytes).clamp(1, height);
    let per_band = height.div_ceil(rows);
    let n = width * height;
    let strips: Vec<Vec<u8>> = (0..count * per_band)
        .into_par_iter()
        .map(|i| {
            let (k, s) = (i / per_band, i % per_band);
            let texels = s * rows * width..((s + 1) * rows * width).min(n);
            let len = texels.len();
            let v = band(k, texels);
            assert_eq!(v.len(), len, "a strip of band {k} has the wrong length");
            compress(bytemuck::cast_slice(&v), compression)
        })
        .collect();
    let metadata = names.map(gdal_metadata);
    let nodata = nodata.map(|v| v.to_string());
    let total: usize = strips.iter().map(Vec::len).sum();
    write_atomically(path, |out| {
        let d = Layout {
            size: [width as u32, height as u32],
            bands: count as u16,
            rows: rows as u32,
            compression,
            sample: (T::BITS, T::FORMAT),
        };
        let (g, m, nd) = (georef, metadata.as_deref(), nodata.as_deref());
        if total > (1 << 31) {
            encode::<_, TiffKindBig>(out, &d, &strips, g, m, nd)
        } else {
            encode::<_, TiffKindStandard>(out, &d, &strips, g, m, nd)
        }
    })
}

/// GDAL's band descriptions: `<GDALMetadata><Item name="DESCRIPTION" sample="K"
/// role="description">NAME</Item>…</GDALMetadata>` (ASCII; `&`, `<`, `>` escaped).
fn gdal_metadata(names: &[String]) -> String {
    let escape = |s: &str| {
        s.chars()
            .map(|c| match c {
                '&' => "&amp;".to_string(),
                '<' => "&lt;".to_string(),
                '>' => "&gt;".to_string(),
                c if c.is_ascii() && c != '\0' => c.to_string(),
                _ => "?".to_string(),
            })
            .collect::<String>()
    };
    let items: String = names
        .iter()
        .enumerate()
        .map(|(k, n)| {
            format!(
                "<Item name=\"DESCRIPTION\" sample=\"{k}\" role=\"description\">{}</Item>",
                escape(n)
            )
        })
        .collect();
    format!("<GDALMetadata>{items}</GDALMetadata>")
}

/// One strip's bytes, compressed as TIFF stores them.
fn compress(raw: &[u8], how: TiffCompression) -> Vec<u8> {
    use flate2::write::ZlibEncoder;
    let deflate = |level| {
        let mut z = ZlibEncoder::new(Vec::new(), level);
        z.write_all(raw).expect("writing to memory");
        z.finish().expect("writing to memory")
    };
    match how {
        TiffCompression::None => raw.to_vec(), // the strip's only copy
        TiffCompression::Deflate => deflate(flate2::Compression::fast()),
        TiffCompression::DeflateSmall => deflate(flate2::Compression::default()),
        TiffCompression::Lzw => {
            weezl::encode::Encoder::with_tiff_size_switch(weezl::BitOrder::Msb, 8)
                .encode(raw)
                .expect("LZW of bytes in memory")
        }
        TiffCompression::Zstd => {
            zstd::bulk::compress(raw, ZSTD_LEVEL).expect("zstd of bytes in memory")
        }
    }
}

/// The directory's shape.
struct Layout {
    size: [u32; 2],
    bands: u16,
    rows: u32,
    compression: TiffCompression,
    /// BitsPerSample and SampleFormat.
    sample: (u16, u16),
}

fn encode<W: Write + Seek, K: TiffKind>(
    out: W,
    d: &Layout,
    strips: &[Vec<u8>],
    georef: Option<&GeoReference>,
    metadata: Option<&str>,
    nodata: Option<&str>,
) -> TiffResult<()> {
    let mut enc = TiffEncoder::<W, K>::new_generic(out)?;
    let mut dir = enc.image_directory()?;
    let mut offsets = Vec::with_capacity(strips.len());
    for s in strips {
        offsets.push(K::convert_offset(dir.write_data(&s[..])?)?);
    }
    let counts: Vec<K::OffsetType> = strips
        .iter()
        .map(|s| K::convert_offset(s.len() as u64))
        .collect::<TiffResult<_>>()?;
    let n = d.bands as usize;
    dir.write_tag(Tag::ImageWidth, d.size[0])?;
    dir.write_tag(Tag::ImageLength, d.size[1])?;
    dir.write_tag(Tag::BitsPerSample, &vec![d.sample.0; n][..])?;
    let code: u16 = match d.compression {
        TiffCompression::None => 1,
        TiffCompression::Lzw => 5,
        TiffCompression::Deflate | TiffCompression::DeflateSmall => 8,
        TiffCompression::Zstd => 50000,
    };
    dir.write_tag(Tag::Compression, code)?;
    dir.write_tag(Tag::PhotometricInterpretation, 1u16)?; // BlackIsZero
    dir.write_tag(Tag::StripOffsets, K::convert_slice(&offsets))?;
    dir.write_tag(Tag::SamplesPerPixel, d.bands)?;
    dir.write_tag(Tag::RowsPerStrip, d.rows)?;
    dir.write_tag(Tag::StripByteCounts, K::convert_slice(&counts))?;
    dir.write_tag(Tag::PlanarConfiguration, 2u16)?;
    if n > 1 {
        dir.write_tag(Tag::ExtraSamples, &vec![0u16; n - 1][..])?;
    }
    dir.write_tag(Tag::SampleFormat, &vec![d.sample.1; n][..])?;
    geo_tags(&mut dir, georef)?;
    if let Some(m) = metadata {
        dir.write_tag(Tag::Unknown(42112), m)?; // GDAL_METADATA
    }
    if let Some(text) = nodata {
        dir.write_tag(Tag::GdalNodata, text)?;
    }
    dir.finish()
}
