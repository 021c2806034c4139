//! `minmax_mipmap.exr`: the min/max mipmap of a height-map bake, written by `minmax_mipmap`.

use super::{exr_io, BakeTransaction};
use crate::error::Result;
use crate::terrain::minmax_mipmap::{level_sizes, top_max_min, MinMaxMipmap, MipLevel};
use std::path::Path;

/// File name of the mipmap.
pub const FILE: &str = "minmax_mipmap.exr";

/// Read the mipmap of the bake in `dir`.
pub fn read(dir: &Path) -> Result<MinMaxMipmap> {
    read_file(&dir.join(FILE))
}

/// Write the mipmap into a bake.
pub fn write(txn: &mut BakeTransaction, mip: &MinMaxMipmap) -> Result<()> {
    txn.write_with(FILE, |p| write_file(p, mip))
}

/// Write as a multi-part OpenEXR file (docs/baked-format.md): one part per level named
/// `level0`, `level1`, ..., each with f32 channels `max` and `min`, ZIP compression, and the
/// height map's size in the custom attribute `relumeMapSize` (v2i) of every part.
/// Deterministic.
pub fn write_file(path: &Path, mip: &MinMaxMipmap) -> Result<()> {
    use exr::meta::attribute::AttributeValue;
    use exr::prelude::*;
    let encoding = Encoding {
        compression: Compression::ZIP16,
        blocks: Blocks::ScanLines,
        line_order: LineOrder::Increasing,
    };
    let mut layers: SmallVec<[Layer<AnyChannels<FlatSamples>>; 2]> = SmallVec::new();
    for (i, l) in mip.levels.iter().enumerate() {
        let n = l.width * l.height;
        let pairs = &mip.data[2 * l.offset..2 * (l.offset + n)];
        let max: Vec<f32> = pairs.iter().step_by(2).copied().collect();
        let min: Vec<f32> = pairs.iter().skip(1).step_by(2).copied().collect();
        let channels = AnyChannels::sort(SmallVec::from_vec(vec![
            AnyChannel::new("max", FlatSamples::F32(max)),
            AnyChannel::new("min", FlatSamples::F32(min)),
        ]));
        let mut attributes = LayerAttributes::named(format!("level{i}").as_str());
        attributes.other.insert(
            Text::from("relumeMapSize"),
            AttributeValue::IntVec2(Vec2(mip.map_width as i32, mip.map_height as i32)),
        );
        layers.push(Layer::new(
            (l.width, l.height),
            attributes,
            encoding,
            channels,
        ));
    }
    let attributes = ImageAttributes::new(IntegerBounds::from_dimensions((
        mip.levels[0].width,
        mip.levels[0].height,
    )));
    Image::from_layers(attributes, layers)
        .write()
        .non_parallel()
        .to_file(path)
        .map_err(|e| exr_io::exr_error(path, "cannot write EXR", e))
}

/// Read a file written by [`write_file`], checking its structure.
pub fn read_file(path: &Path) -> Result<MinMaxMipmap> {
    use exr::meta::attribute::AttributeValue;
    use exr::prelude::*;
    crate::limits::check_exr_header(path)?;
    let reader = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .all_layers()
        .all_attributes();
    // Debug builds decode on this thread, contained (exr_io::read_f32_channels).
    #[cfg(debug_assertions)]
    let reader = reader.non_parallel();
    let image = crate::error::contain_panic(path, "EXR decoder", || reader.from_file(path))?
        .map_err(|e| exr_io::exr_error(path, "cannot read EXR", e))?;
    let bad = |m: String| crate::error::Error::input(path, m);
    let first = image.layer_data.first().map(|l| &l.attributes.other);
    let (mw, mh) = match first.and_then(|o| o.get(&Text::from("relumeMapSize"))) {
        Some(AttributeValue::IntVec2(Vec2(w, h))) if *w > 0 && *h > 0 => (*w as usize, *h as usize),
        _ => {
            return Err(bad(
                "not a relume min/max mipmap: no `relumeMapSize` attribute".into(),
            ))
        }
    };
    let sizes = level_sizes(mw, mh);
    if image.layer_data.len() != sizes.len() {
        return Err(bad(format!(
            "a {mw}x{mh} map has {} mipmap levels, the file has {} parts",
            sizes.len(),
            image.layer_data.len()
        )));
    }
    let mut levels = Vec::new();
    let mut data = Vec::new();
    for (i, (layer, &(w, h))) in image.layer_data.iter().zip(&sizes).enumerate() {
        let name = layer.attributes.layer_name.as_ref().map(|t| t.to_string());
        if name.as_deref() != Some(format!("level{i}").as_str())
            || layer.size.width() != w
            || layer.size.height() != h
        {
            return Err(bad(format!(
                "part {i} should be `level{i}` of {w}x{h}, found {:?} of {}x{}",
                name,
                layer.size.width(),
                layer.size.height()
            )));
        }
        let channel = |n: &str| -> crate::error::Result<Vec<f32>> {
            let c = layer
                .channel_data
                .list
                .iter()
                .find(|c| c.name.to_string() == n)
                .ok_or_else(|| bad(format!("part level{i} has no `{n}` channel")))?;
            match &c.sample_data {
                FlatSamples::F32(v) => Ok(v.clone()),
                _ => Err(bad(format!("channel {n} of level{i} is not f32"))),
            }
        };
        let (max, min) = (channel("max")?, channel("min")?);
        levels.push(MipLevel {
            width: w,
            height: h,
            offset: data.len() / 2,
        });
        for (a, b) in max.into_iter().zip(min) {
            data.push(a);
            data.push(b);
        }
    }
    let (max_height, min_height) = top_max_min(&levels, &data);
    Ok(MinMaxMipmap {
        map_width: mw,
        map_height: mh,
        levels,
        data,
        max_height,
        min_height,
    })
}
