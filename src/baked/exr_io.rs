//! Small EXR helpers over the `exr` crate: f32 channels of one layer, written deterministically
//! (single-threaded chunk order, lossless ZIP compression) so that bakes are byte-identical.

use crate::error::{Error, Result};
use std::path::Path;

/// Named f32 channels of one layer.
pub type Channels = Vec<(String, Vec<f32>)>;

/// Write one layer of f32 channels, each `width * height` values, row-major, row 0 at the top.
pub fn write_f32_channels(
    path: &Path,
    width: usize,
    height: usize,
    channels: &[(&str, &[f32])],
) -> Result<()> {
    use exr::prelude::{
        AnyChannel, AnyChannels, Blocks, Compression, Encoding, FlatSamples, Image, Layer,
        LayerAttributes, LineOrder, SmallVec, WritableImage,
    };
    for (name, data) in channels {
        if data.len() != width * height {
            return Err(Error::Internal(format!(
                "EXR channel {name}: {} values for {width}x{height}",
                data.len()
            )));
        }
    }
    let list: SmallVec<[AnyChannel<FlatSamples>; 4]> = channels
        .iter()
        .map(|(name, data)| AnyChannel::new(*name, FlatSamples::F32(data.to_vec())))
        .collect();
    let encoding = Encoding {
        compression: Compression::ZIP16,
        blocks: Blocks::ScanLines,
        line_order: LineOrder::Increasing,
    };
    let layer = Layer::new(
        (width, height),
        LayerAttributes::default(),
        encoding,
        AnyChannels::sort(list),
    );
    Image::from_layer(layer)
        .write()
        .non_parallel()
        .to_file(path)
        .map_err(|e| exr_error(path, "cannot write EXR", e))
}

/// Read the first layer's channels as f32: (width, height, [(name, values)]), channels sorted by name.
pub fn read_f32_channels(path: &Path) -> Result<(usize, usize, Channels)> {
    use exr::prelude::FlatSamples;
    let parts = crate::limits::check_exr_header(path)?;
    if parts > 1 {
        return Err(Error::input(
            path,
            format!("a multi-part EXR ({parts} parts) where relume writes a single part"),
        ));
    }
    let image =
        crate::heightmap::decode_exr(path)?.map_err(|e| exr_error(path, "cannot read EXR", e))?;
    let layer = image.layer_data;
    let channels = layer
        .channel_data
        .list
        .into_iter()
        .map(|c| {
            let v: Vec<f32> = match c.sample_data {
                FlatSamples::F16(v) => v.into_iter().map(|x| x.to_f32()).collect(),
                FlatSamples::F32(v) => v,
                FlatSamples::U32(v) => v.into_iter().map(|x| x as f32).collect(),
            };
            (c.name.to_string(), v)
        })
        .collect();
    Ok((layer.size.width(), layer.size.height(), channels))
}

/// Map an `exr` error to ours: I/O stays I/O, the rest is a malformed file.
pub fn exr_error(path: &Path, action: &'static str, e: exr::error::Error) -> Error {
    match e {
        exr::error::Error::Io(io) => Error::io(path, action, io),
        other => Error::input(path, format!("{action}: {other}")),
    }
}
