//! The `reorder` and `encode` pipeline stages: thin glue between the workspace / baked
//! directory and the pure functions of this module (docs/baked-format.md lists their files).

use super::containers::{self, Tile};
use super::dense::{DenseEncoding, DenseTexture, EncodeOptions};
use super::logmap::LogMap;
use super::reorder::{reorder, ReorderMetric, ReorderOptions};
use super::report::{report, standard_lights};
use super::{compress, EncodedTransport, Sidecar, TransportMatrix};
use crate::baked::{BakeTransaction, StageRecord};
use crate::error::{Error, IoContext, Result};
use crate::pipeline::{PlanState, PlannedStage, StageRun};
use crate::progress::Progress;
use crate::workspace::Workspace;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The transport matrix written by the `transport` stage.
pub const TRANSPORT_FILE: &str = "transport.npy";
/// The permutation written by `reorder`.
pub const PERMUTATION_FILE: &str = "permutation.bin";
/// The sidecar written by `encode`.
pub const SIDECAR_FILE: &str = "sidecar.bin";
/// How to read the encoded transport (postcard [`TransferInfo`]).
pub const TRANSFER_FILE: &str = "transfer.bin";
/// File stem of the dense texture (tiles add `_rR_cC`).
pub const TEXTURE_STEM: &str = "transfer";

/// Knobs of the `reorder` stage.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReorderKnobs {
    /// Greedy passes: 0 (identity), 1 (rows), 2 (rows then columns, the seed's).
    #[serde(
        default = "default_passes",
        deserialize_with = "crate::pipeline::parse::zero_to_two"
    )]
    pub passes: u8,
    /// `Linear` (the seed's: raw values, default) or `Log` (the 8-bit log codes the encoder
    /// sees; measured no better, see docs/compression.md).
    #[serde(default = "default_metric")]
    pub metric: ReorderMetric,
}

fn default_passes() -> u8 {
    2
}
fn default_metric() -> ReorderMetric {
    ReorderMetric::Linear
}

impl Default for ReorderKnobs {
    fn default() -> Self {
        ReorderKnobs {
            passes: default_passes(),
            metric: default_metric(),
        }
    }
}

/// A texture container to write.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Container {
    Dds,
    Ktx2,
}

impl Container {
    pub fn extension(self) -> &'static str {
        match self {
            Container::Dds => "dds",
            Container::Ktx2 => "ktx2",
        }
    }
}

/// Knobs of the `encode` stage.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EncodeKnobs {
    /// Dense-part encoding: `Bc6h` (default), `Bc1Log` (the seed's), `Bc4Log`, `F16`, `F32`.
    #[serde(default = "default_encoding")]
    pub encoding: DenseEncoding,
    /// Percentage of the entries (largest first) kept exactly in the sidecar.
    #[serde(
        default = "default_split",
        deserialize_with = "crate::pipeline::parse::percent"
    )]
    pub split_percent: f64,
    /// Natural-log range of the log mapping (the seed's 25).
    #[serde(
        default = "default_log_range",
        deserialize_with = "crate::pipeline::parse::positive_f32"
    )]
    pub log_range: f32,
    /// Carry each row's running error into the next block (keeps row sums).
    #[serde(default = "default_feedback")]
    pub feedback: bool,
    /// Fill the sidecar's holes in the dense part instead of zeroing them (sidecar holds the
    /// residual).
    #[serde(default = "default_fill_holes")]
    pub fill_holes: bool,
    /// Largest texture side; bigger matrices are split into tiles.
    #[serde(
        default = "default_max_texture_size",
        deserialize_with = "crate::pipeline::parse::texture_size"
    )]
    pub max_texture_size: u32,
    /// Containers to write (at least one).
    #[serde(default = "default_containers")]
    pub containers: Vec<Container>,
}

/// The default encoding: BC6H with filled holes and a 1 % sidecar reached the goal
/// (≤ 2 % RMS relative gather error at ≤ 1.5x the seed's bytes) by a wide margin; see
/// docs/compression.md for the measurements.
fn default_encoding() -> DenseEncoding {
    DenseEncoding::Bc6h
}
fn default_split() -> f64 {
    1.0
}
fn default_log_range() -> f32 {
    super::logmap::SEED_RANGE
}
fn default_feedback() -> bool {
    false
}
fn default_fill_holes() -> bool {
    true
}
fn default_max_texture_size() -> u32 {
    8192
}
fn default_containers() -> Vec<Container> {
    vec![Container::Dds, Container::Ktx2]
}

impl Default for EncodeKnobs {
    fn default() -> Self {
        EncodeKnobs {
            encoding: default_encoding(),
            split_percent: default_split(),
            log_range: default_log_range(),
            feedback: default_feedback(),
            fill_holes: default_fill_holes(),
            max_texture_size: default_max_texture_size(),
            containers: default_containers(),
        }
    }
}

impl EncodeKnobs {
    /// The dense-encoding options of these knobs.
    pub fn options(&self) -> EncodeOptions {
        EncodeOptions {
            encoding: self.encoding,
            log_range: self.log_range,
            feedback: self.feedback,
            fill_holes: self.fill_holes,
        }
    }
}

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

/// Read the transport matrix of a bake.
fn read_transport(path: &Path) -> Result<TransportMatrix> {
    TransportMatrix::read_npy(path)
}

/// `permutation.bin`: magic `RLPM`, u32 version 1, u32 n, then n u32 (little-endian).
pub fn permutation_bytes(perm: &[u32]) -> Vec<u8> {
    let mut out = Vec::with_capacity(12 + 4 * perm.len());
    out.extend_from_slice(b"RLPM");
    out.extend_from_slice(&1u32.to_le_bytes());
    out.extend_from_slice(&(perm.len() as u32).to_le_bytes());
    for p in perm {
        out.extend_from_slice(&p.to_le_bytes());
    }
    out
}

/// Read `permutation.bin`, checking that it is a permutation.
pub fn read_permutation(path: &Path) -> Result<Vec<u32>> {
    let b = std::fs::read(path).at(path, "cannot read")?;
    if b.len() < 12 || &b[..4] != b"RLPM" || b[4..8] != 1u32.to_le_bytes() {
        return Err(Error::input(path, "not a relume permutation (RLPM v1)"));
    }
    let n = u32::from_le_bytes(b[8..12].try_into().unwrap()) as usize;
    if b.len() != 12 + 4 * n {
        return Err(Error::input(path, "truncated permutation"));
    }
    let perm: Vec<u32> = b[12..]
        .chunks_exact(4)
        .map(|c| u32::from_le_bytes(c.try_into().unwrap()))
        .collect();
    if !super::is_permutation(&perm) {
        return Err(Error::input(path, "not a permutation of 0..n"));
    }
    Ok(perm)
}

impl StageRun for ReorderKnobs {
    fn run(
        &self,
        ws: &mut Workspace,
        txn: &mut BakeTransaction,
        progress: &dyn Progress,
    ) -> Result<StageRecord> {
        let s = ws.get::<TransportMatrix>(TRANSPORT_FILE, read_transport)?;
        progress.begin("reorder", 0);
        let perm = reorder(
            s,
            ReorderOptions {
                passes: self.passes,
                metric: self.metric,
            },
        );
        progress.finish();
        let moved = perm
            .iter()
            .enumerate()
            .filter(|(k, &p)| *k != p as usize)
            .count();
        txn.write(PERMUTATION_FILE, &permutation_bytes(&perm))?;
        let mut rec = StageRecord {
            stage: "reorder".into(),
            outputs: vec![PERMUTATION_FILE.into()],
            ..Default::default()
        };
        rec.report.insert("patches".into(), perm.len() as f64);
        rec.report.insert("moved".into(), moved as f64);
        rec.facts
            .insert("metric".into(), format!("{:?}", self.metric));
        ws.put(PERMUTATION_FILE, perm);
        Ok(rec)
    }

    fn estimate(&self, state: &mut PlanState) -> PlannedStage {
        let n = state.patches;
        let ch = state.channels.max(1);
        PlannedStage {
            stage: "reorder".into(),
            // Feature vectors + distance matrix + one permuted copy.
            peak_bytes: 4 * n * n * (2 * ch + 1),
            output_bytes: 12 + 4 * n,
            notes: format!("{} greedy pass(es) over {n} patches", self.passes),
        }
    }
}

impl StageRun for EncodeKnobs {
    fn run(
        &self,
        ws: &mut Workspace,
        txn: &mut BakeTransaction,
        progress: &dyn Progress,
    ) -> Result<StageRecord> {
        if self.containers.is_empty() {
            return Err(Error::knob(
                "`containers` must name at least one of Dds, Ktx2",
            ));
        }
        let perm = if ws.has(PERMUTATION_FILE) {
            Some(
                ws.get::<Vec<u32>>(PERMUTATION_FILE, read_permutation)?
                    .clone(),
            )
        } else {
            None
        };
        let s = ws.get::<TransportMatrix>(TRANSPORT_FILE, read_transport)?;
        let perm = match perm {
            Some(p) if p.len() != s.n => {
                return Err(Error::input(
                    PERMUTATION_FILE,
                    format!("has {} entries, the transport has {} patches", p.len(), s.n),
                ))
            }
            Some(p) => p,
            None => (0..s.n as u32).collect(),
        };
        progress.begin("encode", 0);
        let s_perm = s.permuted(&perm);
        let enc = compress(&s_perm, perm, self.split_percent, &self.options())?;
        progress.finish();
        progress.begin("encode report", 0);
        let rep = report(s, &s_perm, &enc, &standard_lights(s.channels, s.n));
        progress.finish();
        let tiles = containers::plan_tiles(
            enc.dense.padded,
            self.max_texture_size as usize,
            TEXTURE_STEM,
        )?;
        let mut outputs = Vec::new();
        for tile in &tiles {
            let layers = containers::tile_layers(&enc.dense, tile);
            for c in &self.containers {
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
            containers: self.containers.clone(),
        };
        txn.write(TRANSFER_FILE, &crate::baked::to_postcard(&info)?)?;
        outputs.push(TRANSFER_FILE.into());

        let mut rec = StageRecord {
            stage: "encode".into(),
            outputs,
            report: rep.to_map(),
            ..Default::default()
        };
        rec.report.insert("tiles".into(), tiles.len() as f64);
        rec.report
            .insert("padded_size".into(), enc.dense.padded as f64);
        rec.facts
            .insert("encoding".into(), enc.dense.encoding.name().into());
        rec.facts.insert(
            "tiles".into(),
            tiles
                .iter()
                .map(|t| {
                    format!(
                        "{} rows {}+{} cols {}+{}",
                        t.stem, t.row0, t.rows, t.col0, t.cols
                    )
                })
                .collect::<Vec<_>>()
                .join("; "),
        );
        rec.facts.insert(
            "gather_error".into(),
            "RMS relative error of S·E for the standard lights (uniform, random, half, one)".into(),
        );
        ws.put(TRANSFER_FILE, enc);
        Ok(rec)
    }

    fn estimate(&self, state: &mut PlanState) -> PlannedStage {
        let n = state.patches;
        let ch = state.channels.max(1);
        let padded = 4 * n.div_ceil(4);
        let per_entry = match self.encoding {
            DenseEncoding::Bc1Log => 0.5,
            DenseEncoding::Bc4Log => 0.5 * ch as f64,
            DenseEncoding::Bc6h => 1.0,
            DenseEncoding::F16 => 2.0 * ch as f64,
            DenseEncoding::F32 => 4.0 * ch as f64,
        };
        let dense = (padded * padded) as f64 * per_entry;
        let side = (n * n) as f64 * self.split_percent / 100.0 * (4.0 + 4.0 * ch as f64);
        let files = (dense * self.containers.len() as f64 + side) as u64;
        PlannedStage {
            stage: "encode".into(),
            // Transport + permuted copy + dense part + sort keys of the split.
            peak_bytes: 4 * n * n * (3 * ch + 2) + files,
            output_bytes: files,
            notes: format!(
                "{} dense part, {} % sidecar",
                self.encoding.name(),
                self.split_percent
            ),
        }
    }
}

/// Read the encoded transport of a bake (`transfer.bin`, the texture tiles — DDS when written,
/// else KTX2 — and `sidecar.bin`).
pub fn read_encoded(dir: &Path) -> Result<EncodedTransport> {
    let info: TransferInfo = crate::baked::read_postcard(&dir.join(TRANSFER_FILE))?;
    let (n, ch, padded) = (
        info.n as usize,
        info.channels as usize,
        info.padded as usize,
    );
    let nl = DenseTexture::layer_count(info.encoding, ch);
    let enc = info.encoding;
    let layer_len = (padded / 4) * (padded / 4) * enc.block_bytes();
    let mut tex = DenseTexture {
        encoding: enc,
        n,
        channels: ch,
        padded,
        maps: info.maps.clone(),
        layers: vec![vec![0u8; layer_len]; nl],
    };
    let container = *info
        .containers
        .first()
        .ok_or_else(|| Error::input(dir.join(TRANSFER_FILE), "lists no container"))?;
    for tile in &info.tiles {
        let path = dir.join(format!("{}.{}", tile.stem, container.extension()));
        let (w, h, layers) = match container {
            Container::Dds => containers::read_dds(&path, enc)?,
            Container::Ktx2 => containers::read_ktx2(&path, enc, nl)?,
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
    let sidecar = Sidecar::read(&dir.join(SIDECAR_FILE))?;
    if sidecar.n != n
        || sidecar.channels != ch
        || !super::is_permutation(&info.perm)
        || info.perm.len() != n
    {
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
