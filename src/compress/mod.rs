//! Transport compression: the radiosity thesis's §4.2 (docs/algorithms.md §3 "Compression") and what beats it.
//!
//! Data flow (every step a pure function over plain data):
//!
//! ```text
//! TransportMatrix S ─▶ reorder (permutation P, S' = P S Pᵀ)   [reorder.rs]
//!   ─▶ split: top p % entries → Sidecar (CSR, f32)            [split.rs]
//!   ─▶ dense rest: log map → 8-bit codes                       [logmap.rs]
//!   ─▶ block texture (BC1 / BC4 / BC6H / F16 / F32)            [bc1.rs, bc4.rs, bc6h.rs, encode.rs]
//!   ─▶ DDS / KTX2 files (tiled when wider than the max size)   [containers.rs]
//! gather: B_ind = S · E straight from the compressed form      [gather.rs]
//! report: the thesis's three errors, RMS relative error of B_ind [report.rs]
//! ```
//!
//! Index convention: `perm[k]` is the original patch index placed at position `k`, so
//! `S'[k][l] = S[perm[k]][perm[l]]`, `E'[k] = E[perm[k]]` and `B[perm[k]] = B'[k]`. Texel
//! (x = column j, y = row i) of the dense texture holds entry (i, j) of S' with its colour
//! channels as R, G, B.

// Block and texel index arithmetic is written as in the format specs (and the WGSL port).
#![allow(clippy::needless_range_loop)]

pub mod bc1;
pub mod bc4;
pub mod bc6h;
pub mod containers;
pub mod decode;
pub mod dense;
pub mod distance;
pub mod encode;
pub mod gather;
pub mod logmap;
pub mod reorder;
pub mod reorder_bounded;
pub mod report;
pub mod split;

use crate::error::Result;
use crate::radiosity::TransportMatrix;

pub use dense::{DenseEncoding, DenseTexture, EncodeOptions};
pub use gather::gather;
pub use reorder::{reorder, ReorderMethod, ReorderMetric, ReorderOptions};
pub use split::{split_top, Sidecar};

/// A compressed transport: permutation, dense texture and sidecar (all in permuted order).
#[derive(Clone, Debug, PartialEq)]
pub struct EncodedTransport {
    /// `perm[k]` = original patch index at position `k`.
    pub perm: Vec<u32>,
    pub dense: DenseTexture,
    pub sidecar: Sidecar,
}

impl EncodedTransport {
    /// Payload bytes: dense texture + sidecar file.
    pub fn bytes(&self) -> usize {
        self.dense.bytes() + self.sidecar.byte_len()
    }
}

/// Split and encode an already permuted matrix `s_perm` (`perm` records the order).
pub fn compress(
    s_perm: &TransportMatrix,
    perm: Vec<u32>,
    split_percent: f64,
    opts: &EncodeOptions,
) -> Result<EncodedTransport> {
    if !opts.fill_holes {
        let (dense_part, sidecar) = split_top(s_perm, split_percent)?;
        let dense = encode::encode_dense(&dense_part, opts, None)?;
        return Ok(EncodedTransport {
            perm,
            dense,
            sidecar,
        });
    }
    // With hole filling the dense part is `s_perm` itself, its sidecar entries counting as zero.
    let mut sidecar = split::top_entries(s_perm, split_percent)?;
    let dense = encode::encode_dense(s_perm, opts, Some(&sidecar))?;
    // The sidecar holds what the dense texel at each hole lacks: S − decoded.
    let dec = dense.decoder();
    let mut vals = [[0.0f32; 16]; 3];
    let ch = s_perm.channels;
    for i in 0..s_perm.n {
        for k in sidecar.row_ptr[i] as usize..sidecar.row_ptr[i + 1] as usize {
            let j = sidecar.cols[k] as usize;
            dec.block(i / 4, j / 4, &mut vals);
            for c in 0..ch {
                let t = 4 * (i % 4) + j % 4;
                sidecar.values[k * ch + c] = s_perm.get(c, i, j) - vals[c][t];
            }
        }
    }
    Ok(EncodedTransport {
        perm,
        dense,
        sidecar,
    })
}
