//! File readers for height maps: each returns the raw samples (file units) and what the file says
//! about no-data and cell size. Scaling and no-data policy are applied by the caller.

use super::{HeightMapOptions, RawGrid};
use crate::error::{Error, IoContext, Result};
use std::path::Path;

pub(super) fn read(path: &Path, opts: &HeightMapOptions) -> Result<RawGrid> {
    let meta = std::fs::metadata(path).at(path, "cannot read height map")?;
    if meta.is_dir() {
        return Err(Error::input(
            path,
            "is a directory, expected a height map file",
        ));
    }
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("png") | Some("jpg") | Some("jpeg") => read_image(path),
        Some("exr") => read_exr(path),
        Some("tif") | Some("tiff") => read_tiff(path),
        Some("raw") | Some("f32") => read_raw(path, opts.raw_size),
        _ => Err(Error::unsupported(
            path,
            "unknown height-map format (expected .png, .jpg, .exr, .tif/.tiff, or .raw/.f32 with explicit size)",
        )),
    }
}

fn read_image(path: &Path) -> Result<RawGrid> {
    use image::DynamicImage as D;
    // Read once; the format guess, the checks and the decoder all work on these bytes.
    let bytes = std::fs::read(path).at(path, "cannot read height map")?;
    let open = || {
        // As `ImageReader::open` does: the extension first, the signature when it has one.
        let mut r = image::ImageReader::new(std::io::Cursor::new(&bytes[..]));
        if let Ok(f) = image::ImageFormat::from_path(path) {
            r.set_format(f);
        }
        r.with_guessed_format().at(path, "cannot read height map")
    };
    let reader = open()?;
    let format = match reader.format() {
        Some(image::ImageFormat::Png) => "png",
        Some(image::ImageFormat::Jpeg) => "jpeg",
        Some(f) => {
            return Err(Error::unsupported(
                path,
                format!(
                    "{f:?} images are not supported as height maps (use PNG, JPEG, EXR or GeoTIFF)"
                ),
            ))
        }
        None => {
            return Err(Error::input(
                path,
                "not a PNG or JPEG image (unrecognised file signature)",
            ))
        }
    };
    if format == "jpeg" {
        check_jpeg_complete(path, &bytes)?;
    }
    // The header alone, before the decoder allocates (and walks) what it declares.
    if let Ok((w, h)) = open()?.into_dimensions() {
        crate::limits::check_declared_samples(path, w as u64, h as u64, 1)?;
        if format == "jpeg" {
            check_jpeg_size(path, &bytes, w as u64, h as u64)?;
        }
        if format == "jpeg" && w.max(h) > 65528 {
            // zune-jpeg 0.5 computes `(side + 7) / 8` in u16: it wraps and decodes zeros (an
            // overflow panic under the fuzzers' overflow checks).
            return Err(Error::unsupported(
                path,
                format!(
                    "a {w}x{h} JPEG: sides over 65528 texels are mis-decoded by the JPEG decoder"
                ),
            ));
        }
    }
    // zune-jpeg 0.5 multiplies a DC prediction by its quantiser unchecked: a malformed scan
    // overflows (a panic where overflow checks are on; found by AFL), so the decoder runs
    // contained and any panic becomes an input error.
    let img = crate::error::contain_panic(path, "image decoder", || reader.decode())?.map_err(
        |e| match e {
            image::ImageError::IoError(io) => Error::io(path, "cannot read height map", io),
            other => Error::input(path, format!("cannot decode {format}: {other}")),
        },
    )?;
    let (w, h) = (img.width() as usize, img.height() as usize);
    let (values, sample): (Vec<f64>, &'static str) = match &img {
        D::ImageLuma8(b) => (b.as_raw().iter().map(|&v| v as f64).collect(), "u8"),
        D::ImageLuma16(b) => (b.as_raw().iter().map(|&v| v as f64).collect(), "u16"),
        D::ImageRgb8(b) => (equal_channels(path, b.as_raw(), 3, w)?, "u8"),
        D::ImageRgb16(b) => (equal_channels(path, b.as_raw(), 3, w)?, "u16"),
        D::ImageLumaA8(_) | D::ImageLumaA16(_) | D::ImageRgba8(_) | D::ImageRgba16(_) => {
            return Err(Error::unsupported(
                path,
                "images with an alpha channel are not height maps; flatten to grayscale",
            ))
        }
        other => {
            return Err(Error::unsupported(
                path,
                format!("unsupported pixel type {:?}", other.color()),
            ))
        }
    };
    Ok(RawGrid {
        width: w,
        height: h,
        values,
        format,
        sample,
        nodata: None,
        georef: None,
        cell_size: None,
    })
}

/// The JPEG decoder fills a truncated scan with made-up samples instead of failing (found by the
/// bad-input corpus: a cut file read as a "colour image"), so a JPEG must have its end-of-image
/// marker after its last start-of-scan. Markers cannot occur inside entropy-coded data (a 0xFF
/// there is stuffed as FF 00), so the search is exact.
fn check_jpeg_complete(path: &Path, bytes: &[u8]) -> Result<()> {
    let last_scan = bytes.windows(2).rposition(|w| w == [0xFF, 0xDA]);
    let complete = last_scan.is_some_and(|s| bytes[s..].windows(2).any(|w| w == [0xFF, 0xD9]));
    if complete {
        Ok(())
    } else {
        Err(Error::input(
            path,
            format!(
                "truncated JPEG: no end-of-image marker after the last scan ({} bytes)",
                bytes.len()
            ),
        ))
    }
}

/// A JPEG whose declared size its file cannot hold (a decompression bomb: the fuzzer's 343-byte
/// files declaring 100–390 M texels took the decoder 2–14 s and gigabytes, filling the missing
/// scan data with zeros). In a Huffman-coded JPEG (baseline, extended, progressive or lossless:
/// SOF0–3, 5–7) every 8×8 block of every component has its DC coefficient coded, at least one
/// bit (a Huffman code is 1–16 bits long), so the file holds at least one bit per block of the
/// component with the fewest blocks. Where no frame header is found (the decoder found one:
/// it gave the size), the bound assumes the deepest subsampling a frame can declare (4:1 each
/// way). Arithmetic-coded files are left to the decoder, which refuses them.
fn check_jpeg_size(path: &Path, bytes: &[u8], w: u64, h: u64) -> Result<()> {
    let frame = match jpeg_frame_header(bytes) {
        Frame::Huffman(frame) => frame,
        Frame::Arithmetic => return Ok(()),
        Frame::NotFound => &[],
    };
    let mut factors: Vec<(u64, u64)> = frame
        .get(8..)
        .unwrap_or(&[])
        .chunks_exact(3)
        .take(frame.get(7).copied().unwrap_or(0) as usize)
        .map(|c| ((c[1] >> 4) as u64, (c[1] & 15) as u64))
        .filter(|&(hf, vf)| hf > 0 && vf > 0)
        .collect();
    if factors.is_empty() {
        factors = vec![(1, 1), (4, 4)];
    }
    let hmax = factors.iter().map(|f| f.0).max().unwrap_or(1);
    let vmax = factors.iter().map(|f| f.1).max().unwrap_or(1);
    let blocks = factors
        .iter()
        .map(|&(hf, vf)| (w * hf).div_ceil(hmax).div_ceil(8) * (h * vf).div_ceil(vmax).div_ceil(8))
        .min()
        .unwrap_or(0);
    let need = blocks.div_ceil(8);
    if (bytes.len() as u64) < need {
        return Err(Error::input(
            path,
            format!(
                "a {w}x{h} JPEG cannot be coded in {} bytes: its {blocks} blocks of 8x8 texels need at least {need} (one bit each); the file is damaged or a decompression bomb",
                bytes.len()
            ),
        ));
    }
    Ok(())
}

/// What [`jpeg_frame_header`] found.
enum Frame<'a> {
    /// The segment of a Huffman-coded frame header (SOF0–3, 5–7) after its marker: length (2
    /// bytes), precision (1), height (2), width (2), component count (1), then (id, sampling
    /// factors, table) per component from byte 8.
    Huffman(&'a [u8]),
    /// An arithmetic-coded frame header (SOF9–11, 13–15).
    Arithmetic,
    /// No frame header before the first scan, or a segment running past the end.
    NotFound,
}

/// The frame header of a JPEG, walking its segments as decoders do: bytes between segments,
/// fill bytes (FF FF), `FF 00` and the markers that carry no length (TEM, RST0–7, SOI) are
/// skipped (AFL: a stray `FF 00` read as a segment with a length hid the frame of a 541-byte
/// file declaring 184 M texels, which the decoder found and filled for 23 s).
fn jpeg_frame_header(bytes: &[u8]) -> Frame<'_> {
    let mut i = 2; // after SOI
    while i + 4 <= bytes.len() {
        if bytes[i] != 0xFF {
            i += 1; // junk between segments: decoders skip to the next marker, so do we
            continue;
        }
        let marker = bytes[i + 1];
        match marker {
            0xFF => {
                i += 1; // fill byte
                continue;
            }
            0x00 | 0x01 | 0xD0..=0xD8 => {
                i += 2; // not a segment: no length follows
                continue;
            }
            _ => {}
        }
        let len = u16::from_be_bytes([bytes[i + 2], bytes[i + 3]]) as usize;
        let Some(body) = bytes.get(i + 2..i + 2 + len) else {
            return Frame::NotFound;
        };
        match marker {
            0xC0..=0xC3 | 0xC5..=0xC7 => return Frame::Huffman(body),
            0xC9..=0xCB | 0xCD..=0xCF => return Frame::Arithmetic,
            0xDA | 0xD9 => return Frame::NotFound,
            _ => i += 2 + len,
        }
    }
    Frame::NotFound
}

/// Take one channel of an RGB image whose channels are all equal; refuse real colour images.
fn equal_channels<T: Copy + PartialEq + Into<f64>>(
    path: &Path,
    data: &[T],
    n: usize,
    width: usize,
) -> Result<Vec<f64>> {
    let mut out = Vec::with_capacity(data.len() / n);
    for (i, px) in data.chunks_exact(n).enumerate() {
        if px.iter().any(|c| *c != px[0]) {
            let rgb: Vec<f64> = px.iter().map(|&c| c.into()).collect();
            return Err(Error::input(
                path,
                format!(
                    "colour image: channels differ at column {}, row {} ({rgb:?}); a height map must be grayscale or have equal R, G, B",
                    i % width.max(1),
                    i / width.max(1)
                ),
            ));
        }
        out.push(px[0].into());
    }
    Ok(out)
}

/// An EXR's first valid layer at its largest resolution, every channel as flat samples: the
/// one decode of relume's EXR readers (height maps here, the bake's own files in
/// `crate::baked::exr_io`). The caller checks the part count first
/// (`crate::limits::check_exr_header`) and maps the decoder's errors its own way.
///
/// exr 1.74's B44 decoder relies on wrapping u32 arithmetic (as OpenEXR's C code does with
/// unsigned ints): release builds wrap and decode in parallel; with overflow checks (debug
/// builds, and the fuzzers' builds) it panics — in a worker thread, where the panic aborts the
/// process (found by AFL). So debug builds decode on this thread, and the decode is contained
/// either way: a panic is an input error naming the file.
pub fn decode_exr(path: &Path) -> Result<std::result::Result<ExrImage, exr::error::Error>> {
    use exr::prelude::{read, ReadChannels, ReadLayers};
    let reader = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes();
    #[cfg(debug_assertions)]
    let reader = reader.non_parallel();
    crate::error::contain_panic(path, "EXR decoder", || reader.from_file(path))
}

/// What [`decode_exr`] returns: one layer, any channels, flat samples.
pub type ExrImage =
    exr::image::Image<exr::image::Layer<exr::image::AnyChannels<exr::image::FlatSamples>>>;

fn read_exr(path: &Path) -> Result<RawGrid> {
    use exr::prelude::FlatSamples;
    let parts = crate::limits::check_exr_header(path)?;
    if parts > 1 {
        // A multi-part file (e.g. a bake's minmax_mipmap.exr) is not one height field; reading
        // its first part also trips an internal assertion of exr 1.74 (found by fuzzing).
        return Err(Error::unsupported(
            path,
            format!("a multi-part EXR ({parts} parts): a height map is a single-part file"),
        ));
    }
    let image = decode_exr(path)?.map_err(|e| match e {
        exr::error::Error::Io(io) => Error::io(path, "cannot read height map", io),
        other => Error::input(path, format!("cannot decode EXR: {other}")),
    })?;
    let layer = &image.layer_data;
    let channels = &layer.channel_data.list;
    let pick = if channels.len() == 1 {
        0
    } else if let Some(i) = channels
        .iter()
        .position(|c| matches!(c.name.to_string().as_str(), "Y" | "Z" | "H" | "height"))
    {
        i
    } else {
        let names: Vec<String> = channels.iter().map(|c| c.name.to_string()).collect();
        return Err(Error::unsupported(
            path,
            format!("EXR has channels {names:?}; a height map needs a single channel (or one named Y, Z, H or height)"),
        ));
    };
    let ch = &channels[pick];
    let (sample, values): (&'static str, Vec<f64>) = match &ch.sample_data {
        FlatSamples::F16(v) => ("f16", v.iter().map(|x| x.to_f64()).collect()),
        FlatSamples::F32(v) => ("f32", v.iter().map(|&x| x as f64).collect()),
        FlatSamples::U32(v) => ("u32", v.iter().map(|&x| x as f64).collect()),
    };
    let size = layer.size;
    Ok(RawGrid {
        width: size.width(),
        height: size.height(),
        values,
        format: "exr",
        sample,
        nodata: None,
        georef: None,
        cell_size: None,
    })
}

fn read_tiff(path: &Path) -> Result<RawGrid> {
    use tiff::decoder::{Decoder, DecodingResult};
    use tiff::tags::Tag;
    use tiff::ColorType;
    let file = std::fs::File::open(path).at(path, "cannot read height map")?;
    let tiff_err = |e: tiff::TiffError| match e {
        tiff::TiffError::IoError(io) => Error::io(path, "cannot read height map", io),
        tiff::TiffError::UnsupportedError(u) => {
            Error::unsupported(path, format!("unsupported TIFF: {u}"))
        }
        other => Error::input(path, format!("cannot decode TIFF: {other}")),
    };
    // tiff 0.10 panics on some malformed tags (an empty SampleFormat, found by fuzzing).
    let mut dec = crate::error::contain_panic(path, "TIFF decoder", || {
        let mut limits = tiff::decoder::Limits::default();
        limits.decoding_buffer_size = (crate::limits::MAX_IMAGE_SAMPLES * 8) as usize;
        Decoder::new(std::io::BufReader::new(file)).map(|d| d.with_limits(limits))
    })?
    .map_err(tiff_err)?;
    let (w, h) = dec.dimensions().map_err(tiff_err)?;
    crate::limits::check_declared_samples(path, w as u64, h as u64, 1)?;
    match dec.colortype().map_err(tiff_err)? {
        ColorType::Gray(_) => {}
        other => {
            return Err(Error::unsupported(
                path,
                format!("TIFF pixel type {other:?}: a height map must have one sample per pixel"),
            ))
        }
    }
    let nodata = match dec.find_tag(Tag::GdalNodata) {
        Ok(Some(v)) => v
            .into_string()
            .ok()
            .and_then(|s| s.trim().trim_end_matches('\0').parse::<f64>().ok()),
        _ => None,
    };
    let pixel_scale = match dec.find_tag(Tag::ModelPixelScaleTag) {
        Ok(Some(v)) => v
            .into_f64_vec()
            .ok()
            .filter(|s| s.len() >= 2 && s[0] > 0.0 && s[1] > 0.0)
            .map(|s| [s[0], s[1]]),
        _ => None,
    };
    let georef = super::georef::GeoReference::read(&mut dec);
    let data = dec.read_image().map_err(tiff_err)?;
    let (sample, values): (&'static str, Vec<f64>) = match data {
        DecodingResult::U8(v) => ("u8", v.into_iter().map(f64::from).collect()),
        DecodingResult::U16(v) => ("u16", v.into_iter().map(f64::from).collect()),
        DecodingResult::I16(v) => ("i16", v.into_iter().map(f64::from).collect()),
        DecodingResult::F32(v) => ("f32", v.into_iter().map(f64::from).collect()),
        other => {
            let kind = match other {
                DecodingResult::U32(_) => "uint32",
                DecodingResult::U64(_) => "uint64",
                DecodingResult::I8(_) => "int8",
                DecodingResult::I32(_) => "int32",
                DecodingResult::I64(_) => "int64",
                DecodingResult::F16(_) => "float16",
                DecodingResult::F64(_) => "float64",
                _ => "this",
            };
            return Err(Error::unsupported(
                path,
                format!("TIFF sample format {kind} is not supported (use int16, uint16, float32 or uint8)"),
            ));
        }
    };
    let cell_size = match read_world_file(path)? {
        Some(c) => Some((c, "world-file")),
        None => pixel_scale.map(|c| (c, "geotiff-tag")),
    };
    Ok(RawGrid {
        width: w as usize,
        height: h as usize,
        values,
        format: "geotiff",
        sample,
        nodata,
        cell_size,
        georef,
    })
}

/// Cell size from an ESRI world file beside `path` (`.tfw`, or `.tifw`/`.wld`): six numbers
/// A, D, B, E, C, F; the cell size is (|(A, D)|, |(B, E)|).
fn read_world_file(path: &Path) -> Result<Option<[f64; 2]>> {
    for ext in ["tfw", "tifw", "wld"] {
        let wf = path.with_extension(ext);
        let Ok(text) = std::fs::read_to_string(&wf) else {
            continue;
        };
        let nums: Vec<f64> = text
            .split_whitespace()
            .filter_map(|t| t.parse().ok())
            .collect();
        if nums.len() != 6 {
            return Err(Error::input(
                &wf,
                format!("a world file has six numbers, this one has {}", nums.len()),
            ));
        }
        let cx = nums[0].hypot(nums[1]);
        let cy = nums[2].hypot(nums[3]);
        if !(cx > 0.0 && cy > 0.0 && cx.is_finite() && cy.is_finite()) {
            return Err(Error::input(
                &wf,
                "the world file gives a zero or non-finite cell size",
            ));
        }
        return Ok(Some([cx, cy]));
    }
    Ok(None)
}

fn read_raw(path: &Path, size: Option<[usize; 2]>) -> Result<RawGrid> {
    let Some([w, h]) = size else {
        return Err(Error::knob(format!(
            "{}: a raw f32 height map needs its size: `raw_size: Some((W, H))` in the pipeline or `--raw-size WxH`",
            path.display()
        )));
    };
    let bytes = std::fs::read(path).at(path, "cannot read height map")?;
    let expected = w.checked_mul(h).and_then(|n| n.checked_mul(4));
    if expected != Some(bytes.len()) {
        return Err(Error::input(
            path,
            format!(
                "{w}x{h} f32 needs {} bytes, the file has {}",
                w.saturating_mul(h).saturating_mul(4),
                bytes.len()
            ),
        ));
    }
    let values = bytes
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64)
        .collect();
    Ok(RawGrid {
        width: w,
        height: h,
        values,
        format: "raw-f32",
        sample: "f32",
        nodata: None,
        georef: None,
        cell_size: None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// SOF0 of a `w`x`h` one-component frame (sampling 1x1).
    fn sof0(w: u16, h: u16) -> Vec<u8> {
        let mut s = vec![0xFF, 0xC0, 0, 11, 8];
        s.extend(h.to_be_bytes());
        s.extend(w.to_be_bytes());
        s.extend([1, 1, 0x11, 0]);
        s
    }

    #[test]
    fn the_segment_walk_skips_what_carries_no_length() {
        // SOI, a stray FF 00, TEM, RST3, fill bytes, then the frame.
        let mut bytes = vec![
            0xFF, 0xD8, 0xFF, 0x00, 0x04, 0x05, 0xFF, 0x01, 0xFF, 0xD3, 0xFF,
        ];
        bytes.extend(sof0(640, 480));
        match jpeg_frame_header(&bytes) {
            Frame::Huffman(body) => assert_eq!(&body[3..7], &[1, 224, 2, 128]),
            _ => panic!("frame header not found"),
        }
    }

    #[test]
    fn the_size_bound_holds_without_a_frame_header() {
        let path = Path::new("x.jpg");
        // No frame: 4:1 subsampling assumed, 4096x4096 -> 128x128 blocks -> 2,048 bytes.
        let bytes = vec![0xFF, 0xD8, 0xFF, 0xDA, 0, 2];
        assert!(check_jpeg_size(path, &bytes, 4096, 4096).is_err());
        let mut big = bytes.clone();
        big.resize(2048, 0);
        assert!(check_jpeg_size(path, &big, 4096, 4096).is_ok());
        // With the frame: one bit per 8x8 block of the one component (512x512 blocks).
        let mut framed = vec![0xFF, 0xD8];
        framed.extend(sof0(4096, 4096));
        framed.resize(32767, 0);
        assert!(check_jpeg_size(path, &framed, 4096, 4096).is_err());
        framed.resize(32768, 0);
        assert!(check_jpeg_size(path, &framed, 4096, 4096).is_ok());
    }
}
