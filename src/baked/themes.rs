//! `themes.bin`: the theme set of a height-map bake, written by the `themes` stage
//! (docs/baked-format.md, docs/themes.md).
//!
//! Layout: the 8 bytes `RLTHEME1`, a u32 (little-endian) header length, the JSON header
//! (themes, classes, index size and counts, texture size and levels, noise size, drift), then
//! little-endian sections: the level-0 index map Colour Cell Compressed (u32 words, lossless
//! with its exception blocks of 16 bytes), the theme texels (RGBA8, every theme's mip chain),
//! the turbulence map (f32 pairs). Coarser index levels are rebuilt on reading (they follow from
//! level 0 by the mip rule).

use super::BakeTransaction;
use crate::error::{Error, IoContext, Result};
use crate::theme::ccc::Ccc;
use crate::theme::mip::IndexMips;
use crate::theme::noise::TurbulenceMap;
use crate::theme::textures::ThemeTextures;
use crate::theme::{Class, ThemeSet};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// File name.
pub const FILE: &str = "themes.bin";
/// The stage that writes it.
pub const STAGE: &str = "themes";
const MAGIC: &[u8; 8] = b"RLTHEME1";

#[derive(Serialize, Deserialize)]
struct Header {
    themes: Vec<String>,
    classes: Vec<Class>,
    index: [usize; 2],
    words: usize,
    exceptions: usize,
    texture_size: usize,
    texture_levels: usize,
    noise_size: usize,
    drift: [f32; 2],
}

/// The file's bytes.
pub fn encode(set: &ThemeSet) -> Vec<u8> {
    let base = &set.index.levels[0];
    let ccc = Ccc::encode(base, true);
    let header = Header {
        themes: set.themes.clone(),
        classes: set.classes.clone(),
        index: [base.width, base.height],
        words: ccc.words.len(),
        exceptions: ccc.exceptions.len(),
        texture_size: set.textures.size,
        texture_levels: set.textures.levels,
        noise_size: set.noise.size,
        drift: set.drift,
    };
    let json = serde_json::to_vec(&header).expect("theme header serialises");
    let mut out = Vec::new();
    out.extend(MAGIC);
    out.extend((json.len() as u32).to_le_bytes());
    out.extend(json);
    out.extend(ccc.words.iter().flat_map(|w| w.to_le_bytes()));
    out.extend(ccc.exceptions.iter().flatten());
    out.extend(set.textures.texels.iter().flatten());
    out.extend(
        set.noise
            .values
            .iter()
            .flatten()
            .flat_map(|v| v.to_le_bytes()),
    );
    out
}

/// Write the theme set into a bake.
pub fn write(txn: &mut BakeTransaction, set: &ThemeSet) -> Result<()> {
    let bytes = encode(set);
    txn.write_with(FILE, |p| {
        std::fs::write(p, &bytes).map_err(|e| Error::io(p, "cannot write", e))
    })
}

/// Read `themes.bin` from the bake in `dir`.
pub fn read(dir: &Path) -> Result<ThemeSet> {
    let path = dir.join(FILE);
    let bytes = std::fs::read(&path).at(&path, "cannot read")?;
    decode(&bytes).map_err(|m| Error::verify(&path, m))
}

/// Parse the file's bytes; the message says what is wrong.
pub fn decode(bytes: &[u8]) -> std::result::Result<ThemeSet, String> {
    if bytes.len() < 12 || &bytes[..8] != MAGIC {
        return Err("not a relume theme file (no RLTHEME1 magic)".into());
    }
    let n = u32::from_le_bytes(bytes[8..12].try_into().unwrap()) as usize;
    let json = bytes
        .get(12..12 + n)
        .ok_or("the header runs past the end of the file")?;
    let h: Header = serde_json::from_slice(json).map_err(|e| format!("bad header: {e}"))?;
    let [w, hgt] = h.index;
    let ok_size = (1..=65536).contains(&w) && (1..=65536).contains(&hgt);
    let ts = h.texture_size;
    let sizes_agree = ok_size
        && h.words == w.div_ceil(4) * hgt.div_ceil(4)
        && ts.is_power_of_two()
        && ts <= 1024
        && h.texture_levels == ts.trailing_zeros() as usize + 1
        && (1..=4096).contains(&h.noise_size)
        && h.drift.iter().all(|d| d.is_finite());
    let classes_valid = !h.themes.is_empty()
        && !h.classes.is_empty()
        && h.classes.len() <= crate::theme::MAX_CLASSES
        && h.classes.iter().all(|c| {
            (c.theme as usize) < h.themes.len()
                && c.border.check().is_ok()
                && c.tiling.check().is_ok()
        });
    if !(sizes_agree && classes_valid) {
        return Err("the header's sizes or classes are inconsistent".into());
    }
    let per_theme: usize = (0..h.texture_levels).map(|l| (ts >> l).pow(2)).sum();
    let texels = per_theme * h.themes.len();
    let want = h.words * 4 + h.exceptions * 16 + texels * 4 + h.noise_size.pow(2) * 8;
    let body = &bytes[12 + n..];
    if body.len() != want {
        return Err(format!(
            "the sections hold {} bytes, the header says {want} (truncated or padded)",
            body.len()
        ));
    }
    let (words, rest) = body.split_at(h.words * 4);
    let (exc, rest) = rest.split_at(h.exceptions * 16);
    let (tex, noise) = rest.split_at(texels * 4);
    let ccc = Ccc {
        width: w,
        height: hgt,
        words: words
            .chunks(4)
            .map(|c| u32::from_le_bytes(c.try_into().unwrap()))
            .collect(),
        exceptions: exc.chunks(16).map(|c| c.try_into().unwrap()).collect(),
        lossy_texels: 0,
    };
    let classes = h.classes.len();
    for &word in &ccc.words {
        let (a, b) = ((word & 0xff) as usize, ((word >> 8) & 0xff) as usize);
        let bad = if a == 255 {
            (word >> 8) as usize >= ccc.exceptions.len()
        } else {
            a >= classes || b >= classes
        };
        if bad {
            return Err(
                "an index word names a class or exception block that does not exist".into(),
            );
        }
    }
    if ccc
        .exceptions
        .iter()
        .flatten()
        .any(|&c| c as usize >= classes)
    {
        return Err("an exception block names a class that does not exist".into());
    }
    let values: Vec<[f32; 2]> = noise
        .chunks(8)
        .map(|c| {
            [
                f32::from_le_bytes(c[..4].try_into().unwrap()),
                f32::from_le_bytes(c[4..].try_into().unwrap()),
            ]
        })
        .collect();
    if values.iter().flatten().any(|v| !v.is_finite()) {
        return Err("the turbulence map holds a non-finite value".into());
    }
    Ok(ThemeSet {
        themes: h.themes,
        classes: h.classes,
        index: IndexMips::build(ccc.decode()),
        textures: ThemeTextures {
            size: ts,
            levels: h.texture_levels,
            texels: tex.chunks(4).map(|c| c.try_into().unwrap()).collect(),
        },
        noise: TurbulenceMap {
            size: h.noise_size,
            values,
        },
        drift: h.drift,
    })
}
