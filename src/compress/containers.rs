//! Standard texture containers for the dense part: DDS (via `ddsfile`) and KTX2 (written here).
//!
//! Formats: `Bc1Log` → DDS with the legacy `DXT1` FourCC (the most widely read form; Pillow,
//! GPUs, DirectXTex) and KTX2 `VK_FORMAT_BC1_RGB_UNORM_BLOCK`; `Bc4Log` → `BC4_UNORM`;
//! `Bc6h` → `BC6H_UF16` / `VK_FORMAT_BC6H_UFLOAT_BLOCK`; `F16` → `R16_FLOAT`; `F32` →
//! `R32_FLOAT`. Per-channel encodings store one array layer per channel. One mip level.
//!
//! KTX2 is written by hand (about 100 lines; the `ktx2` crate is a reader only, and is used by
//! the tests as an independent check): the 80-byte header, one level index entry, a Basic Data
//! Format Descriptor with one sample (Khronos Data Format 1.3), a `KTXwriter` key/value entry,
//! and the level's data (layers in order), aligned to 16 bytes. No supercompression.
//!
//! Textures wider than the maximum dimension are split into tiles of at most `max_size` texels
//! (a multiple of 4) per side: tile (r, c) holds rows `r·max_size..` and columns `c·max_size..`
//! of the padded matrix.

use super::dense::{DenseEncoding, DenseTexture};
use crate::error::{Error, Result};
use ddsfile::{AlphaMode, D3D10ResourceDimension, D3DFormat, Dds, DxgiFormat};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// A texture container the `encode` stage writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum Container {
    Dds,
    Ktx2,
}

impl Container {
    /// The file extension.
    pub fn extension(self) -> &'static str {
        match self {
            Container::Dds => "dds",
            Container::Ktx2 => "ktx2",
        }
    }
}

/// A rectangle of the padded texture stored in one file.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Tile {
    /// First row and column (texels) of the tile in the padded matrix.
    pub row0: u32,
    pub col0: u32,
    /// Size in texels (multiples of 4).
    pub rows: u32,
    pub cols: u32,
    /// File name stem; the files are `STEM.dds` and/or `STEM.ktx2`.
    pub stem: String,
}

/// Cut a `padded`-wide texture into tiles of at most `max_size` per side.
pub fn plan_tiles(padded: usize, max_size: usize, stem: &str) -> Result<Vec<Tile>> {
    if max_size < 4 || !max_size.is_multiple_of(4) {
        return Err(Error::knob(format!(
            "max_texture_size {max_size} must be a positive multiple of 4"
        )));
    }
    let count = padded.div_ceil(max_size).max(1);
    let mut tiles = Vec::new();
    for r in 0..count {
        for c in 0..count {
            let (row0, col0) = (r * max_size, c * max_size);
            tiles.push(Tile {
                row0: row0 as u32,
                col0: col0 as u32,
                rows: (padded - row0).min(max_size) as u32,
                cols: (padded - col0).min(max_size) as u32,
                stem: if count == 1 {
                    stem.to_string()
                } else {
                    format!("{stem}_r{r}_c{c}")
                },
            });
        }
    }
    Ok(tiles)
}

/// The bytes of each layer inside `tile`, in the file's order.
pub fn tile_layers(tex: &DenseTexture, tile: &Tile) -> Vec<Vec<u8>> {
    let enc = tex.encoding;
    let (unit, row_units, unit_rows, r0, c0, rows, cols) = if enc.is_block_compressed() {
        (
            enc.block_bytes(),
            tex.padded / 4,
            4,
            tile.row0 as usize / 4,
            tile.col0 as usize / 4,
            tile.rows as usize / 4,
            tile.cols as usize / 4,
        )
    } else {
        (
            enc.block_bytes() / 16,
            tex.padded,
            1,
            tile.row0 as usize,
            tile.col0 as usize,
            tile.rows as usize,
            tile.cols as usize,
        )
    };
    let _ = unit_rows;
    tex.layers
        .iter()
        .map(|layer| {
            let mut out = Vec::with_capacity(rows * cols * unit);
            for r in r0..r0 + rows {
                let s = (r * row_units + c0) * unit;
                out.extend_from_slice(&layer[s..s + cols * unit]);
            }
            out
        })
        .collect()
}

/// Put tiles' layers back into full layers (inverse of [`tile_layers`]).
pub fn untile(tex: &mut DenseTexture, tile: &Tile, layers: &[Vec<u8>]) -> Result<()> {
    let enc = tex.encoding;
    let (unit, row_units, r0, c0, rows, cols) = if enc.is_block_compressed() {
        (
            enc.block_bytes(),
            tex.padded / 4,
            tile.row0 as usize / 4,
            tile.col0 as usize / 4,
            tile.rows as usize / 4,
            tile.cols as usize / 4,
        )
    } else {
        (
            enc.block_bytes() / 16,
            tex.padded,
            tile.row0 as usize,
            tile.col0 as usize,
            tile.rows as usize,
            tile.cols as usize,
        )
    };
    if layers.len() != tex.layers.len() || layers.iter().any(|l| l.len() != rows * cols * unit) {
        return Err(Error::Internal(format!(
            "tile {} has the wrong size",
            tile.stem
        )));
    }
    for (dst, src) in tex.layers.iter_mut().zip(layers) {
        for (k, r) in (r0..r0 + rows).enumerate() {
            let d = (r * row_units + c0) * unit;
            dst[d..d + cols * unit].copy_from_slice(&src[k * cols * unit..(k + 1) * cols * unit]);
        }
    }
    Ok(())
}

fn dxgi_format(enc: DenseEncoding) -> DxgiFormat {
    match enc {
        DenseEncoding::Bc1Log => DxgiFormat::BC1_UNorm,
        DenseEncoding::Bc4Log => DxgiFormat::BC4_UNorm,
        DenseEncoding::Bc6h => DxgiFormat::BC6H_UF16,
        DenseEncoding::F16 => DxgiFormat::R16_Float,
        DenseEncoding::F32 => DxgiFormat::R32_Float,
    }
}

/// DDS bytes of one tile.
pub fn dds_bytes(
    enc: DenseEncoding,
    width: u32,
    height: u32,
    layers: &[Vec<u8>],
) -> Result<Vec<u8>> {
    let fail = |e: ddsfile::Error| Error::Internal(format!("DDS header: {e}"));
    let mut dds = if enc == DenseEncoding::Bc1Log && layers.len() == 1 {
        Dds::new_d3d(ddsfile::NewD3dParams {
            height,
            width,
            depth: None,
            format: D3DFormat::DXT1,
            mipmap_levels: None,
            caps2: None,
        })
        .map_err(fail)?
    } else {
        Dds::new_dxgi(ddsfile::NewDxgiParams {
            height,
            width,
            depth: None,
            format: dxgi_format(enc),
            mipmap_levels: None,
            array_layers: if layers.len() > 1 {
                Some(layers.len() as u32)
            } else {
                None
            },
            caps2: None,
            is_cubemap: false,
            resource_dimension: D3D10ResourceDimension::Texture2D,
            alpha_mode: AlphaMode::Unknown,
        })
        .map_err(fail)?
    };
    dds.data = layers.concat();
    let mut out = Vec::new();
    dds.write(&mut out).map_err(fail)?;
    Ok(out)
}

/// The largest DDS side relume reads: twice the largest tile it writes (`max_texture_size`).
const MAX_DDS_SIDE: u32 = 16384;

/// `ddsfile` computes sizes from the header with unchecked arithmetic (overflows found by
/// fuzzing), so the header's sizes are checked here first: one 2-D level, sides in
/// 1..=[`MAX_DDS_SIDE`], at most 64 array layers. relume writes exactly such files.
fn check_dds_header(path: &Path, bytes: &[u8]) -> Result<()> {
    let bad = |m: String| Error::input(path, format!("not a DDS file relume writes: {m}"));
    if bytes.len() < 128 || &bytes[..4] != b"DDS " {
        return Err(bad("missing `DDS ` header".into()));
    }
    let u32_at = |o: usize| u32::from_le_bytes(bytes[o..o + 4].try_into().unwrap());
    let (height, width, depth, mips) = (u32_at(12), u32_at(16), u32_at(24), u32_at(28));
    if !(1..=MAX_DDS_SIDE).contains(&width) || !(1..=MAX_DDS_SIDE).contains(&height) {
        return Err(bad(format!(
            "{width}x{height} texels (sides must be 1..={MAX_DDS_SIDE})"
        )));
    }
    if depth > 1 || mips > 1 {
        return Err(bad(format!(
            "depth {depth}, {mips} mip levels (expected 1 and 1)"
        )));
    }
    let dx10 = &bytes[84..88] == b"DX10";
    if dx10 && bytes.len() >= 148 && u32_at(140) > 64 {
        return Err(bad(format!("{} array layers (at most 64)", u32_at(140))));
    }
    Ok(())
}

/// Parse a DDS tile: (width, height, layers). `path` names the file in errors.
pub fn parse_dds(
    path: &Path,
    bytes: &[u8],
    enc: DenseEncoding,
) -> Result<(u32, u32, Vec<Vec<u8>>)> {
    check_dds_header(path, bytes)?;
    let dds = Dds::read(bytes).map_err(|e| Error::input(path, format!("not a DDS file: {e}")))?;
    let ok = match enc {
        DenseEncoding::Bc1Log => {
            dds.get_d3d_format() == Some(D3DFormat::DXT1)
                || dds.get_dxgi_format() == Some(DxgiFormat::BC1_UNorm)
        }
        e => dds.get_dxgi_format() == Some(dxgi_format(e)),
    };
    if !ok {
        return Err(Error::input(
            path,
            format!("DDS format is not the manifest's {}", enc.name()),
        ));
    }
    let layers = (0..dds.get_num_array_layers())
        .map(|l| {
            dds.get_data(l)
                .map(<[u8]>::to_vec)
                .map_err(|e| Error::input(path, format!("truncated DDS: {e}")))
        })
        .collect::<Result<Vec<_>>>()?;
    Ok((dds.get_width(), dds.get_height(), layers))
}

/// Vulkan format, bytes per texel block, DFD colour model, channel type and bit length.
fn ktx2_format(enc: DenseEncoding) -> (u32, u32, u8, u8, u8, [u32; 2]) {
    // (vkFormat, bytesPlane0, colorModel, channelType, bitLength-1, [lower, upper])
    match enc {
        DenseEncoding::Bc1Log => (131, 8, 128, 0, 63, [0, u32::MAX]),
        DenseEncoding::Bc4Log => (139, 8, 131, 0, 63, [0, u32::MAX]),
        DenseEncoding::Bc6h => (143, 16, 133, 0x80, 127, [0xBF80_0000, 0x3F80_0000]),
        DenseEncoding::F16 => (76, 2, 1, 0xC0, 15, [0xBF80_0000, 0x3F80_0000]),
        DenseEncoding::F32 => (100, 4, 1, 0xC0, 31, [0xBF80_0000, 0x3F80_0000]),
    }
}

/// KTX2 identifier.
pub const KTX2_MAGIC: [u8; 12] = [
    0xAB, 0x4B, 0x54, 0x58, 0x20, 0x32, 0x30, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A,
];

/// KTX2 bytes of one tile.
pub fn ktx2_bytes(enc: DenseEncoding, width: u32, height: u32, layers: &[Vec<u8>]) -> Vec<u8> {
    let (vk, bytes_plane, model, channel_type, bit_len, [lower, upper]) = ktx2_format(enc);
    let block = enc.is_block_compressed();
    // Data format descriptor: total size, then one basic block with one sample.
    let mut dfd = Vec::new();
    let block_size: u32 = 24 + 16;
    dfd.extend_from_slice(&(4 + block_size).to_le_bytes());
    dfd.extend_from_slice(&0u32.to_le_bytes()); // vendor 0 (Khronos), descriptor type 0 (basic)
    dfd.extend_from_slice(&(2u32 | (block_size << 16)).to_le_bytes()); // version 2, size
                                                                       // colour model, primaries BT.709, transfer linear, flags: straight alpha.
    dfd.extend_from_slice(&[model, 1, 1, 0]);
    let dim = if block { 3 } else { 0 };
    dfd.extend_from_slice(&[dim, dim, 0, 0]);
    let mut planes = [0u8; 8];
    planes[0] = bytes_plane as u8;
    dfd.extend_from_slice(&planes);
    // The sample: bit offset 0, length, channel type; position 0; lower/upper.
    dfd.extend_from_slice(&0u16.to_le_bytes());
    dfd.extend_from_slice(&[bit_len, channel_type]);
    dfd.extend_from_slice(&[0, 0, 0, 0]);
    dfd.extend_from_slice(&lower.to_le_bytes());
    dfd.extend_from_slice(&upper.to_le_bytes());

    let mut kvd = Vec::new();
    let entry = format!("KTXwriter\0relume {}\0", env!("CARGO_PKG_VERSION"));
    kvd.extend_from_slice(&(entry.len() as u32).to_le_bytes());
    kvd.extend_from_slice(entry.as_bytes());
    while kvd.len() % 4 != 0 {
        kvd.push(0);
    }

    let dfd_offset = 80 + 24;
    let kvd_offset = dfd_offset + dfd.len();
    let data_offset = (kvd_offset + kvd.len()).div_ceil(16) * 16;
    let data_len: usize = layers.iter().map(Vec::len).sum();
    let mut out = Vec::with_capacity(data_offset + data_len);
    out.extend_from_slice(&KTX2_MAGIC);
    let type_size = if block { 1 } else { bytes_plane };
    let layer_count = if layers.len() > 1 {
        layers.len() as u32
    } else {
        0
    };
    for v in [vk, type_size, width, height, 0, layer_count, 1, 1, 0] {
        out.extend_from_slice(&v.to_le_bytes());
    }
    for v in [
        dfd_offset as u32,
        dfd.len() as u32,
        kvd_offset as u32,
        kvd.len() as u32,
    ] {
        out.extend_from_slice(&v.to_le_bytes());
    }
    out.extend_from_slice(&0u64.to_le_bytes()); // sgd offset
    out.extend_from_slice(&0u64.to_le_bytes()); // sgd length
    for v in [data_offset as u64, data_len as u64, data_len as u64] {
        out.extend_from_slice(&v.to_le_bytes());
    }
    out.extend_from_slice(&dfd);
    out.extend_from_slice(&kvd);
    out.resize(data_offset, 0);
    for l in layers {
        out.extend_from_slice(l);
    }
    out
}

/// Parse a KTX2 tile written by [`ktx2_bytes`]: (width, height, layers). `path` names the
/// file in errors.
pub fn parse_ktx2(
    path: &Path,
    bytes: &[u8],
    enc: DenseEncoding,
    layer_count: usize,
) -> Result<(u32, u32, Vec<Vec<u8>>)> {
    let bad = |m: String| Error::input(path, format!("not a relume KTX2 texture: {m}"));
    if bytes.len() < 104 || bytes[..12] != KTX2_MAGIC {
        return Err(bad("missing KTX2 identifier".into()));
    }
    let u32_at = |o: usize| u32::from_le_bytes(bytes[o..o + 4].try_into().unwrap());
    let u64_at = |o: usize| u64::from_le_bytes(bytes[o..o + 8].try_into().unwrap());
    let (vk, ..) = ktx2_format(enc);
    if u32_at(12) != vk {
        return Err(bad(format!(
            "vkFormat {} is not the manifest's {}",
            u32_at(12),
            enc.name()
        )));
    }
    if u32_at(44) != 0 || u32_at(40) != 1 {
        return Err(bad("supercompressed or mipmapped".into()));
    }
    let (w, h) = (u32_at(20), u32_at(24));
    let (off, len) = (u64_at(80) as usize, u64_at(88) as usize);
    if off.checked_add(len).is_none_or(|e| e > bytes.len()) || len % layer_count.max(1) != 0 {
        return Err(bad("level data out of bounds".into()));
    }
    let data = &bytes[off..off + len];
    let per = len / layer_count.max(1);
    Ok((w, h, data.chunks(per.max(1)).map(<[u8]>::to_vec).collect()))
}
