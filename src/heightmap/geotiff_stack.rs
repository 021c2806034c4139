//! Writing one multi-band float32 GeoTIFF: a band per plane (horizon angles per azimuth), which
//! GDAL, rasterio and QGIS read as one stack, each band's description naming it (GDAL's
//! `GDAL_METADATA` tag, `role="description"`).
//!
//! The tiff crate's image encoder writes fixed colour types (one to four samples), so the
//! directory is assembled here with its tag writer: planar configuration 2 (band after band),
//! strips of about 256 KiB, `SampleFormat` IEEE float, `ExtraSamples` unspecified for bands past
//! the first (baseline TIFF's rule for grey images with more samples). Strips are compressed in
//! parallel (flate2's zlib stream at the level the single-band writer uses, or weezl's LZW with
//! TIFF's early code-size change), then written in band order: the bytes are the same for any
//! thread count. Written atomically like every GeoTIFF of relume (temporary file, sync, rename).

use super::georef::GeoReference;
use super::geotiff_write::{geo_tags, TiffCompression};
use crate::error::{Error, Result};
use rayon::prelude::*;
use std::io::{Seek, Write};
use std::path::Path;
use tiff::encoder::{TiffEncoder, TiffKind, TiffKindBig, TiffKindStandard};
use tiff::tags::Tag;
use tiff::TiffResult;

/// Uncompressed bytes per strip aimed at.
const STRIP_BYTES: usize = 256 << 10;

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
    let shown = path.display();
    if names.is_empty() || names.len() > u16::MAX as usize {
        let msg = format!("{shown}: {} bands (1 to 65535)", names.len());
        return Err(Error::knob(msg));
    }
    if width == 0 || height == 0 || u32::try_from(width.max(height)).is_err() {
        return Err(Error::knob(format!(
            "{shown}: a {width}x{height} GeoTIFF (sides: 1 to 2^32 - 1)"
        )));
    }
    let rows = (STRIP_BYTES / (4 * width)).clamp(1, height);
    let per_band = height.div_ceil(rows);
    let n = width * height;
    let strips: Vec<Vec<u8>> = (0..names.len() * per_band)
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
    let metadata = gdal_metadata(names);
    let nodata = nodata.map(|v| v.to_string());
    let total: usize = strips.iter().map(Vec::len).sum();
    super::geotiff_write::write_atomically(path, |out| {
        let d = Layout {
            size: [width as u32, height as u32],
            bands: names.len() as u16,
            rows: rows as u32,
            compression,
        };
        let (g, m, nd) = (georef, metadata.as_str(), nodata.as_deref());
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
    }
}

/// The directory's shape.
struct Layout {
    size: [u32; 2],
    bands: u16,
    rows: u32,
    compression: TiffCompression,
}

fn encode<W: Write + Seek, K: TiffKind>(
    out: W,
    d: &Layout,
    strips: &[Vec<u8>],
    georef: Option<&GeoReference>,
    metadata: &str,
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
    dir.write_tag(Tag::BitsPerSample, &vec![32u16; n][..])?;
    let code: u16 = match d.compression {
        TiffCompression::None => 1,
        TiffCompression::Lzw => 5,
        TiffCompression::Deflate | TiffCompression::DeflateSmall => 8,
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
    dir.write_tag(Tag::SampleFormat, &vec![3u16; n][..])?; // IEEE float
    geo_tags(&mut dir, georef)?;
    dir.write_tag(Tag::Unknown(42112), metadata)?; // GDAL_METADATA
    if let Some(text) = nodata {
        dir.write_tag(Tag::GdalNodata, text)?;
    }
    dir.finish()
}
