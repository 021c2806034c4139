//! The encoded transport of a scene bake, written by `encode`: the dense part as texture tiles
//! (`transfer[_rR_cC].dds` / `.ktx2`), the exact top entries in `sidecar.bin`, and what a reader
//! needs to put them together in `transfer.bin` (postcard [`TransferInfo`]). "Transfer" in a
//! bake's file names always means this encoded transport.

use super::{read_postcard, to_postcard, BakeTransaction};
use crate::compress::containers::{self, Container, Tile};
use crate::compress::dense::{DenseEncoding, DenseTexture};
use crate::compress::logmap::LogMap;
use crate::compress::{EncodedTransport, Sidecar};
use crate::error::{Error, IoContext, Result};
use crate::radiosity::transport::matrix::is_permutation;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The sidecar written by `encode`.
pub const SIDECAR_FILE: &str = "sidecar.bin";
/// How to read the encoded transport (postcard [`TransferInfo`]).
pub const TRANSFER_FILE: &str = "transfer.bin";
/// The file whose presence marks a bake as encoded.
pub const FILE: &str = TRANSFER_FILE;
/// File stem of the dense texture (tiles add `_rR_cC`).
pub const TEXTURE_STEM: &str = "transfer";

/// What a reader needs besides the texture files: `transfer.bin` (postcard, field order).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TransferInfo {
    pub encoding: DenseEncoding,
    pub n: u32,
    pub channels: u32,
    /// Texture side: n rounded up to a multiple of 4.
    pub padded: u32,
    /// Per channel: log map (log encodings) or the value stored as 1.0 (BC6H, F16).
    pub maps: Vec<LogMap>,
    /// `perm[k]` = original patch index at position k (identity without `reorder`).
    pub perm: Vec<u32>,
    pub tiles: Vec<Tile>,
    pub containers: Vec<Container>,
}

/// Write the encoded transport into a bake: every tile in every container, the sidecar and
/// `transfer.bin`. Returns the files written and the tiles.
pub fn write(
    txn: &mut BakeTransaction,
    enc: &EncodedTransport,
    max_texture_size: usize,
    containers_to_write: &[Container],
) -> Result<(Vec<String>, Vec<Tile>)> {
    let tiles = containers::plan_tiles(enc.dense.padded, max_texture_size, TEXTURE_STEM)?;
    let mut outputs = Vec::new();
    for tile in &tiles {
        let layers = containers::tile_layers(&enc.dense, tile);
        for c in containers_to_write {
            let name = format!("{}.{}", tile.stem, c.extension());
            let bytes = match c {
                Container::Dds => {
                    containers::dds_bytes(enc.dense.encoding, tile.cols, tile.rows, &layers)?
                }
                Container::Ktx2 => {
                    containers::ktx2_bytes(enc.dense.encoding, tile.cols, tile.rows, &layers)
                }
            };
            txn.write(&name, &bytes)?;
            outputs.push(name);
        }
    }
    txn.write(SIDECAR_FILE, &enc.sidecar.to_bytes())?;
    outputs.push(SIDECAR_FILE.into());
    let info = TransferInfo {
        encoding: enc.dense.encoding,
        n: enc.dense.n as u32,
        channels: enc.dense.channels as u32,
        padded: enc.dense.padded as u32,
        maps: enc.dense.maps.clone(),
        perm: enc.perm.clone(),
        tiles: tiles.clone(),
        containers: containers_to_write.to_vec(),
    };
    txn.write(TRANSFER_FILE, &to_postcard(&info)?)?;
    outputs.push(TRANSFER_FILE.into());
    Ok((outputs, tiles))
}

/// Read a `sidecar.bin`.
pub fn read_sidecar(path: &Path) -> Result<Sidecar> {
    let bytes = std::fs::read(path).at(path, "cannot read")?;
    Sidecar::from_bytes(path, &bytes)
}

/// Read the encoded transport of a bake (`transfer.bin`, the texture tiles — DDS when written,
/// else KTX2 — and `sidecar.bin`).
pub fn read(dir: &Path) -> Result<EncodedTransport> {
    let info: TransferInfo = read_postcard(&dir.join(TRANSFER_FILE))?;
    let (n, ch, padded) = (
        info.n as usize,
        info.channels as usize,
        info.padded as usize,
    );
    let info_path = dir.join(TRANSFER_FILE);
    // Sizes come from the file: check them before allocating the texture. `perm` has n entries,
    // which bounds n by the file's length; the texture by the tiles' lengths below.
    if !(1..=4).contains(&ch)
        || info.maps.len() != ch
        || info.perm.len() != n
        || padded != 4 * n.div_ceil(4)
    {
        return Err(Error::input(
            &info_path,
            format!(
                "inconsistent sizes: n {n}, padded {padded}, {ch} channel(s) with {} map(s), \
                 a permutation of {}",
                info.maps.len(),
                info.perm.len()
            ),
        ));
    }
    let nl = DenseTexture::layer_count(info.encoding, ch);
    let enc = info.encoding;
    let layer_len = (padded / 4) * (padded / 4) * enc.block_bytes();
    let container = *info
        .containers
        .first()
        .ok_or_else(|| Error::input(&info_path, "lists no container"))?;
    let tile_path = |stem: &str| dir.join(format!("{stem}.{}", container.extension()));
    // Every tile file must hold the blocks transfer.bin says it has, and the tiles must cover
    // the texture: so what is allocated below is bounded by the bytes on disk.
    let mut covered = 0u64;
    for t in &info.tiles {
        let path = tile_path(&t.stem);
        let need = (t.cols.div_ceil(4) as u64)
            * (t.rows.div_ceil(4) as u64)
            * (enc.block_bytes() * nl) as u64;
        let have = std::fs::metadata(&path).at(&path, "cannot read")?.len();
        if have < need {
            return Err(Error::input(
                &path,
                format!(
                    "{have} bytes: too short for the {}x{} {} tile transfer.bin describes \
                     (truncated, or from another bake)",
                    t.cols,
                    t.rows,
                    enc.name()
                ),
            ));
        }
        covered += t.cols as u64 * t.rows as u64;
    }
    if covered != (padded as u64) * (padded as u64) {
        return Err(Error::input(
            &info_path,
            format!("its tiles cover {covered} texels of a {padded}x{padded} texture"),
        ));
    }
    let mut tex = DenseTexture {
        encoding: enc,
        n,
        channels: ch,
        padded,
        maps: info.maps.clone(),
        layers: vec![vec![0u8; layer_len]; nl],
    };
    for tile in &info.tiles {
        let path = tile_path(&tile.stem);
        let (w, h, layers) = match container {
            Container::Dds => {
                containers::parse_dds(&path, &std::fs::read(&path).at(&path, "cannot read")?, enc)?
            }
            Container::Ktx2 => containers::parse_ktx2(
                &path,
                &std::fs::read(&path).at(&path, "cannot read")?,
                enc,
                nl,
            )?,
        };
        if (w, h) != (tile.cols, tile.rows) {
            return Err(Error::input(
                &path,
                format!(
                    "{w}x{h} texels, transfer.bin says {}x{}",
                    tile.cols, tile.rows
                ),
            ));
        }
        containers::untile(&mut tex, tile, &layers)
            .map_err(|_| Error::input(&path, "texture data has the wrong size"))?;
    }
    tex.validate()?;
    let sidecar = read_sidecar(&dir.join(SIDECAR_FILE))?;
    if sidecar.n != n || sidecar.channels != ch || !is_permutation(&info.perm) {
        return Err(Error::input(
            dir.join(SIDECAR_FILE),
            "sidecar or permutation does not match transfer.bin",
        ));
    }
    Ok(EncodedTransport {
        perm: info.perm,
        dense: tex,
        sidecar,
    })
}
