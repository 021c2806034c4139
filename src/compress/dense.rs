//! The dense part as a texture: the encodings of the `encode` stage's `encoding` knob, their
//! per-strip encoders and their per-block decoders (docs/algorithms.md §3 "Compression" steps 3–4).
//!
//! Layout: the matrix is padded with zeros to `padded = 4·⌈n/4⌉`. Block encodings store blocks
//! in row-major block order (block (by, bx) covers rows 4by..4by+4, columns 4bx..4bx+4);
//! F16/F32 store texels row-major. RGB encodings (BC1, BC6H) have one layer whose R, G, B are
//! the channels (a grey matrix repeats its one channel); per-channel encodings (BC4, F16, F32)
//! have one layer per channel.
//!
//! Error feedback (`feedback: true`, beyond the radiosity thesis): blocks of a block row are encoded left
//! to right, and each row carries the running linear error `Σ (S − decoded)` of the blocks before
//! it into the next block's target (spread over the block's entries in proportion to their
//! values, at most doubling or halving any entry). Row sums — and so the gathered light for any
//! light that varies slowly along the reordered columns — stay close to exact, while each entry
//! keeps the encoding's own per-entry error.

use super::logmap::LogMap;
use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};

/// How the dense part is stored.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum DenseEncoding {
    /// The radiosity thesis's: 8-bit log codes of the three channels as one BC1 texel (0.5 byte/entry).
    Bc1Log,
    /// 8-bit log codes, one BC4 texture layer per channel (0.5 byte/entry/channel).
    Bc4Log,
    /// BC6H unsigned half float, RGB, values divided by the channel maximum (1 byte/entry).
    Bc6h,
    /// Half floats divided by the channel maximum, one layer per channel (2 bytes/entry/channel).
    F16,
    /// f32, one layer per channel (uncompressed reference, 4 bytes/entry/channel).
    F32,
}

impl DenseEncoding {
    /// All encodings, for sweeps.
    pub const ALL: [DenseEncoding; 5] = [
        DenseEncoding::Bc1Log,
        DenseEncoding::Bc4Log,
        DenseEncoding::Bc6h,
        DenseEncoding::F16,
        DenseEncoding::F32,
    ];

    /// Does this encoding use the log mapping?
    pub fn is_log(self) -> bool {
        matches!(self, DenseEncoding::Bc1Log | DenseEncoding::Bc4Log)
    }

    /// One layer holding all channels (RGB texels)?
    pub fn is_rgb(self) -> bool {
        matches!(self, DenseEncoding::Bc1Log | DenseEncoding::Bc6h)
    }

    /// Bytes of one layer's 4x4 block (or 16 texels).
    pub fn block_bytes(self) -> usize {
        match self {
            DenseEncoding::Bc1Log | DenseEncoding::Bc4Log => 8,
            DenseEncoding::Bc6h => 16,
            DenseEncoding::F16 => 32,
            DenseEncoding::F32 => 64,
        }
    }

    /// Is the layer stored as 4x4 blocks (else row-major texels)?
    pub fn is_block_compressed(self) -> bool {
        !matches!(self, DenseEncoding::F16 | DenseEncoding::F32)
    }

    /// Name used in files and reports.
    pub fn name(self) -> &'static str {
        match self {
            DenseEncoding::Bc1Log => "bc1_log",
            DenseEncoding::Bc4Log => "bc4_log",
            DenseEncoding::Bc6h => "bc6h",
            DenseEncoding::F16 => "f16",
            DenseEncoding::F32 => "f32",
        }
    }
}

/// Knobs of the dense encoding.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EncodeOptions {
    pub encoding: DenseEncoding,
    /// Natural-log range of the log mapping (the radiosity thesis's 25).
    pub log_range: f32,
    /// Carry each row's running error into the next block (see the module doc).
    pub feedback: bool,
    /// Instead of zeroing the sidecar's entries in the dense part (the radiosity thesis), fill them like
    /// padding and store `S − decoded` in the sidecar (exact sum, tighter blocks).
    pub fill_holes: bool,
}

/// The radiosity thesis's scheme (Bc1Log, range 25, no feedback, zeroed holes). The `encode` stage's
/// defaults differ (see `stages::EncodeKnobs`).
impl Default for EncodeOptions {
    fn default() -> Self {
        EncodeOptions {
            encoding: DenseEncoding::Bc1Log,
            log_range: super::logmap::SEED_RANGE,
            feedback: false,
            fill_holes: false,
        }
    }
}

/// The encoded dense part.
#[derive(Clone, Debug, PartialEq)]
pub struct DenseTexture {
    pub encoding: DenseEncoding,
    pub n: usize,
    pub channels: usize,
    /// `n` rounded up to a multiple of 4: the texture's width and height.
    pub padded: usize,
    /// Per channel: the log mapping (log encodings), or `scale` = the value stored as 1.0
    /// (BC6H, F16; 1.0 for F32).
    pub maps: Vec<LogMap>,
    /// One layer (RGB encodings) or one per channel.
    pub layers: Vec<Vec<u8>>,
}

/// Linear values of one 4x4 block: `[channel][4·y + x]`.
pub type BlockValues = [[f32; 16]; 3];

impl DenseTexture {
    /// Bytes of the texture payload (all layers).
    pub fn bytes(&self) -> usize {
        self.layers.iter().map(Vec::len).sum()
    }

    /// Number of layers the encoding uses for `channels`.
    pub fn layer_count(encoding: DenseEncoding, channels: usize) -> usize {
        if encoding.is_rgb() {
            1
        } else {
            channels
        }
    }

    /// Check sizes against the header fields (for textures read from files).
    pub fn validate(&self) -> Result<()> {
        let blocks = (self.padded / 4) * (self.padded / 4);
        let want = blocks * self.encoding.block_bytes();
        if self.padded != 4 * self.n.div_ceil(4)
            || self.maps.len() != self.channels
            || self.layers.len() != Self::layer_count(self.encoding, self.channels)
            || self.layers.iter().any(|l| l.len() != want)
        {
            return Err(Error::Internal(format!(
                "dense texture sizes do not match a {}x{} {} matrix",
                self.n,
                self.n,
                self.encoding.name()
            )));
        }
        Ok(())
    }
}
