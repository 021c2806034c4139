//! Transport compression: the seed's §4.2 (seed 003, DESIGN.md §3 "Compression") and what beats it.
//!
//! Data flow (every step a pure function over plain data):
//!
//! ```text
//! TransportMatrix S ─▶ reorder (permutation P, S' = P S Pᵀ)   [reorder.rs]
//!   ─▶ split: top p % entries → Sidecar (CSR, f32)            [split.rs]
//!   ─▶ dense rest: log map → 8-bit codes                       [logmap.rs]
//!   ─▶ block texture (BC1 / BC4 / BC6H / F16 / F32)            [bc1.rs, blocks.rs, dense.rs]
//!   ─▶ DDS / KTX2 files (tiled when wider than the max size)   [containers.rs]
//! gather: B_ind = S · E straight from the compressed form      [gather.rs]
//! report: the seed's three errors, RMS relative error of B_ind [report.rs]
//! ```
//!
//! Index convention: `perm[k]` is the original patch index placed at position `k`, so
//! `S'[k][l] = S[perm[k]][perm[l]]`, `E'[k] = E[perm[k]]` and `B[perm[k]] = B'[k]`. Texel
//! (x = column j, y = row i) of the dense texture holds entry (i, j) of S' with its colour
//! channels as R, G, B.

// Block and texel index arithmetic is written as in the format specs (and the WGSL port).
#![allow(clippy::needless_range_loop)]

pub mod bc1;
pub mod blocks;
pub mod containers;
pub mod dense;
pub mod gather;
pub mod logmap;
pub mod reorder;
pub mod report;
pub mod split;
pub mod stages;

use crate::error::{Error, Result};
use std::path::Path;

pub use dense::{DenseEncoding, DenseTexture, EncodeOptions};
pub use gather::gather;
pub use reorder::{reorder, ReorderMetric, ReorderOptions};
pub use split::{split_top, Sidecar};

/// A transport matrix per colour channel: `S[c][i][j]` is the transfer from patch `j`'s emitted
/// exitance to patch `i`'s indirect exitance, so that `B_ind[c] = S[c] · E[c]`.
///
/// `data` is channel-major then row-major (`data[(c * n + i) * n + j]`), exactly the C-order
/// layout of the bake's `transport.npy` of shape `[channels, n, n]`. `channels` is 1 for grey
/// scenes and 3 (R, G, B) otherwise. Light vectors `E` and results `B` are `[channels][n]`,
/// channel-major, in the same order.
#[derive(Clone, Debug, PartialEq)]
pub struct TransportMatrix {
    pub channels: usize,
    pub n: usize,
    pub data: Vec<f32>,
}

impl TransportMatrix {
    /// Wrap `data` (`channels * n * n` values, channel-major, row-major).
    pub fn new(channels: usize, n: usize, data: Vec<f32>) -> Result<Self> {
        if channels != 1 && channels != 3 {
            return Err(Error::Internal(format!(
                "a transport matrix has 1 or 3 channels, not {channels}"
            )));
        }
        if data.len() != channels * n * n {
            return Err(Error::Internal(format!(
                "transport matrix of {channels}x{n}x{n} needs {} values, got {}",
                channels * n * n,
                data.len()
            )));
        }
        Ok(TransportMatrix { channels, n, data })
    }

    /// The all-zero matrix.
    pub fn zeros(channels: usize, n: usize) -> Self {
        TransportMatrix {
            channels,
            n,
            data: vec![0.0; channels * n * n],
        }
    }

    /// Entry (i, j) of channel `c`.
    #[inline]
    pub fn get(&self, c: usize, i: usize, j: usize) -> f32 {
        self.data[(c * self.n + i) * self.n + j]
    }

    /// Row `i` of channel `c`.
    #[inline]
    pub fn row(&self, c: usize, i: usize) -> &[f32] {
        let s = (c * self.n + i) * self.n;
        &self.data[s..s + self.n]
    }

    /// Read a `[channels, n, n]` (or `[n, n]` for one channel) f32 `.npy` file.
    pub fn read_npy(path: &Path) -> Result<Self> {
        let (shape, data) = crate::baked::read_npy_f32(path)?;
        let (channels, n) = match shape.as_slice() {
            [c, a, b] if a == b => (*c as usize, *a as usize),
            [a, b] if a == b => (1, *a as usize),
            _ => {
                return Err(Error::input(
                    path,
                    format!("expected a [channels, n, n] matrix, found shape {shape:?}"),
                ))
            }
        };
        if channels != 1 && channels != 3 {
            return Err(Error::input(
                path,
                format!("expected 1 or 3 channels, found {channels}"),
            ));
        }
        if let Some(bad) = data.iter().position(|v| !v.is_finite()) {
            return Err(Error::input(
                path,
                format!("entry {bad} is not finite ({})", data[bad]),
            ));
        }
        Self::new(channels, n, data)
    }

    /// Write as a `[channels, n, n]` f32 `.npy` file.
    pub fn write_npy(&self, path: &Path) -> Result<()> {
        crate::baked::write_npy_f32(
            path,
            &[self.channels as u64, self.n as u64, self.n as u64],
            &self.data,
        )
    }

    /// The reference dense product `B = S · E` per channel (f32 row dot products in index order,
    /// parallel over rows). `e` is `[channels][n]`.
    pub fn mat_vec(&self, e: &[f32]) -> Vec<f32> {
        use rayon::prelude::*;
        let n = self.n;
        assert_eq!(e.len(), self.channels * n, "light vector length");
        let mut out = vec![0.0f32; self.channels * n];
        out.par_chunks_mut(n.max(1))
            .enumerate()
            .for_each(|(c, oc)| {
                let ec = &e[c * n..(c + 1) * n];
                oc.par_iter_mut().enumerate().for_each(|(i, o)| {
                    *o = dot(self.row(c, i), ec);
                });
            });
        out
    }

    /// `P S Pᵀ`: entry (k, l) of the result is entry (perm[k], perm[l]) of `self`.
    pub fn permuted(&self, perm: &[u32]) -> Self {
        use rayon::prelude::*;
        let n = self.n;
        assert_eq!(perm.len(), n, "permutation length");
        let mut data = vec![0.0f32; self.data.len()];
        data.par_chunks_mut(n.max(1))
            .enumerate()
            .for_each(|(ck, row)| {
                let (c, k) = (ck / n, ck % n);
                let src = self.row(c, perm[k] as usize);
                for (l, v) in row.iter_mut().enumerate() {
                    *v = src[perm[l] as usize];
                }
            });
        TransportMatrix {
            channels: self.channels,
            n,
            data,
        }
    }
}

/// Dot product with eight independent f32 accumulators (vectorises; fixed order, so the
/// result does not depend on threads).
#[inline]
pub fn dot(a: &[f32], b: &[f32]) -> f32 {
    let mut acc = [0.0f32; 8];
    let ca = a.chunks_exact(8);
    let cb = b.chunks_exact(8);
    let (ra, rb) = (ca.remainder(), cb.remainder());
    for (x, y) in ca.zip(cb) {
        for l in 0..8 {
            acc[l] += x[l] * y[l];
        }
    }
    let mut s = 0.0f32;
    for (x, y) in ra.iter().zip(rb) {
        s += x * y;
    }
    ((acc[0] + acc[4]) + (acc[1] + acc[5])) + ((acc[2] + acc[6]) + (acc[3] + acc[7])) + s
}

/// Apply a permutation to a light vector: `E'[c][k] = E[c][perm[k]]`.
pub fn permute_vector(e: &[f32], perm: &[u32]) -> Vec<f32> {
    let n = perm.len();
    let mut out = vec![0.0f32; e.len()];
    for (oc, ec) in out.chunks_mut(n.max(1)).zip(e.chunks(n.max(1))) {
        for (k, o) in oc.iter_mut().enumerate() {
            *o = ec[perm[k] as usize];
        }
    }
    out
}

/// Undo [`permute_vector`]: `B[c][perm[k]] = B'[c][k]`.
pub fn unpermute_vector(b: &[f32], perm: &[u32]) -> Vec<f32> {
    let n = perm.len();
    let mut out = vec![0.0f32; b.len()];
    for (oc, bc) in out.chunks_mut(n.max(1)).zip(b.chunks(n.max(1))) {
        for (k, v) in bc.iter().enumerate() {
            oc[perm[k] as usize] = *v;
        }
    }
    out
}

/// Is `perm` a permutation of `0..perm.len()`?
pub fn is_permutation(perm: &[u32]) -> bool {
    let mut seen = vec![false; perm.len()];
    for &p in perm {
        match seen.get_mut(p as usize) {
            Some(s) if !*s => *s = true,
            _ => return false,
        }
    }
    true
}

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
    let (dense_part, mut sidecar) = split_top(s_perm, split_percent)?;
    if !opts.fill_holes {
        let dense = dense::encode_dense(&dense_part, opts, None)?;
        return Ok(EncodedTransport {
            perm,
            dense,
            sidecar,
        });
    }
    let dense = dense::encode_dense(&dense_part, opts, Some(&sidecar))?;
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
