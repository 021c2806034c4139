//! Writing GeoTIFFs: single-band f32 and u8 rasters with a [`GeoReference`]'s tags and GDAL's
//! no-data tag, atomically (temporary file, sync, rename), compressed as the caller chooses.

use super::georef::GeoReference;
use crate::error::{Error, Result};
use std::io::{Seek, Write};
use std::path::Path;
use tiff::encoder::{colortype, Compression, DeflateLevel, Predictor};
use tiff::encoder::{
    DirectoryEncoder, TiffEncoder, TiffKind, TiffKindBig, TiffKindStandard, TiffValue,
};
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
    fn method(self) -> Option<Compression> {
        match self {
            TiffCompression::None => Some(Compression::Uncompressed),
            TiffCompression::Lzw => Some(Compression::Lzw),
            TiffCompression::Deflate => Some(Compression::Deflate(DeflateLevel::Fast)),
            TiffCompression::DeflateSmall => Some(Compression::Deflate(DeflateLevel::Balanced)),
            TiffCompression::Zstd => None,
        }
    }
}

/// Writes a single-band float32 GeoTIFF atomically: to a temporary file beside `path`
/// (`.NAME.relume-tmp-PID`), then rename, removing the temporary on any error. Carries `georef`'s
/// tags unchanged (GeoAsciiParams characters TIFF ASCII cannot hold become `?`), and GDAL_NODATA
/// (tag 42113, ASCII) when `nodata` is given. Compressed by [`TiffCompression::default`]
/// ([`write_geotiff_f32_with`] chooses). Row 0 = north, as read.
pub fn write_geotiff_f32(
    path: &Path,
    width: usize,
    height: usize,
    values: &[f32],
    georef: Option<&GeoReference>,
    nodata: Option<f64>,
) -> Result<()> {
    let c = TiffCompression::default();
    write_geotiff_f32_with(path, width, height, values, georef, nodata, c)
}

/// [`write_geotiff_f32`] with the compression `compression`.
pub fn write_geotiff_f32_with(
    path: &Path,
    width: usize,
    height: usize,
    values: &[f32],
    georef: Option<&GeoReference>,
    nodata: Option<f64>,
    compression: TiffCompression,
) -> Result<()> {
    let Some(method) = compression.method() else {
        return write_one_band(path, [width, height], values, georef, nodata, compression);
    };
    // The shortest decimal that reads back the same ("-9999", "NaN", "inf"; never an exponent).
    let nodata = nodata.map(|v| v.to_string());
    let p = Predictor::None; // tiff 0.10 cannot write the floating-point predictor
    let settings = (p, method);
    write::<colortype::Gray32Float>(path, [width, height], values, georef, nodata, settings)
}

/// The same for u8 (masks: 0 shadow, 255 lit, and a nodata value such as 1 or 128 chosen by the
/// caller).
pub fn write_geotiff_u8(
    path: &Path,
    width: usize,
    height: usize,
    values: &[u8],
    georef: Option<&GeoReference>,
    nodata: Option<u8>,
) -> Result<()> {
    let c = TiffCompression::default();
    write_geotiff_u8_with(path, width, height, values, georef, nodata, c)
}

/// [`write_geotiff_u8`] with the compression `compression`.
pub fn write_geotiff_u8_with(
    path: &Path,
    width: usize,
    height: usize,
    values: &[u8],
    georef: Option<&GeoReference>,
    nodata: Option<u8>,
    compression: TiffCompression,
) -> Result<()> {
    let Some(method) = compression.method() else {
        let nodata = nodata.map(f64::from);
        return write_one_band(path, [width, height], values, georef, nodata, compression);
    };
    let p = match compression {
        TiffCompression::None => Predictor::None,
        _ => Predictor::Horizontal,
    };
    let (nodata, settings) = (nodata.map(|v| v.to_string()), (p, method));
    write::<colortype::Gray8>(path, [width, height], values, georef, nodata, settings)
}

/// A single-band raster through the band writer (`geotiff_stack`), for the codecs the tiff
/// crate lacks.
fn write_one_band<T: super::geotiff_stack::Sample>(
    path: &Path,
    [w, h]: [usize; 2],
    values: &[T],
    georef: Option<&GeoReference>,
    nodata: Option<f64>,
    compression: TiffCompression,
) -> Result<()> {
    let (n, shown) = (values.len(), path.display());
    if w.checked_mul(h) != Some(n) {
        let msg = format!("{shown}: {n} values for a {w}x{h} GeoTIFF (sides: 1 to 2^32 - 1)");
        return Err(Error::knob(msg));
    }
    let band = |_: usize, texels: std::ops::Range<usize>| values[texels].to_vec();
    super::geotiff_stack::write_bands(path, [w, h], (1, None), band, georef, nodata, compression)
}

/// Checks the sizes and writes the GeoTIFF atomically ([`write_atomically`]).
fn write<C: colortype::ColorType>(
    path: &Path,
    size: [usize; 2],
    values: &[C::Inner],
    georef: Option<&GeoReference>,
    nodata: Option<String>,
    p: (Predictor, Compression),
) -> Result<()>
where
    [C::Inner]: TiffValue,
{
    let ([w, h], n, shown) = (size, values.len(), path.display());
    if w == 0 || h == 0 || u32::try_from(w.max(h)).is_err() || w.checked_mul(h) != Some(n) {
        let msg = format!("{shown}: {n} values for a {w}x{h} GeoTIFF (sides: 1 to 2^32 - 1)");
        return Err(Error::knob(msg));
    }
    write_atomically(path, |out| {
        let nodata = nodata.as_deref();
        match std::mem::size_of_val(values) > 1 << 31 {
            // BigTIFF when the offsets may pass 4 GiB
            true => encode::<_, TiffKindBig, C>(out, size, values, georef, nodata, p),
            false => encode::<_, TiffKindStandard, C>(out, size, values, georef, nodata, p),
        }
    })
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

fn encode<W: Write + Seek, K: TiffKind, C: colortype::ColorType>(
    out: W,
    [w, h]: [usize; 2],
    values: &[C::Inner],
    georef: Option<&GeoReference>,
    nodata: Option<&str>,
    (p, compression): (Predictor, Compression),
) -> TiffResult<()>
where
    [C::Inner]: TiffValue,
{
    let mut enc = TiffEncoder::<W, K>::new_generic(out)?.with_predictor(p);
    enc = enc.with_compression(compression);
    let mut image = enc.new_image::<C>(w as u32, h as u32)?;
    let dir = image.encoder(); // tags written here join the image's directory
    geo_tags(dir, georef)?;
    if let Some(text) = nodata {
        dir.write_tag(Tag::GdalNodata, text)?;
    }
    image.write_data(values)
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
