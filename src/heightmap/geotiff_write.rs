//! Writing GeoTIFFs: single-band f32 and u8 rasters with a [`GeoReference`]'s tags and GDAL's
//! no-data tag, atomically (temporary file, sync, rename), compressed as the caller chooses.

use super::georef::GeoReference;
use super::geotiff_common::{geo_tags, write_atomically, TiffCompression};
use crate::error::{Error, Result};
use std::io::{Seek, Write};
use std::path::Path;
use tiff::encoder::{colortype, Compression, Predictor};
use tiff::encoder::{TiffEncoder, TiffKind, TiffKindBig, TiffKindStandard, TiffValue};
use tiff::tags::Tag;
use tiff::TiffResult;

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
