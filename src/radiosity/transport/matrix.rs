//! The one transport-matrix type: `S[c]` per colour channel, its product with a light vector,
//! and the permutations the compressor applies to it. Every consumer (the transport stage, the
//! compressor, the study, the player's dense gather and the CPU twins) uses this type and this
//! light-vector layout: `[channels][n]`, channel-major.

// Index arithmetic is written as in the layout description.
#![allow(clippy::needless_range_loop)]

use crate::error::{Error, Result};

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

    /// `(S · e)_i` for channel `c` with f64 accumulation (a grey matrix serves every channel):
    /// the reference the tests compare fast paths against.
    pub fn apply(&self, c: usize, e: &[f64]) -> Vec<f64> {
        let c = c.min(self.channels - 1);
        (0..self.n)
            .map(|i| {
                self.row(c, i)
                    .iter()
                    .zip(e)
                    .map(|(&s, &x)| s as f64 * x)
                    .sum()
            })
            .collect()
    }

    /// The dense product `B = S · E` per channel (f32 row dot products in index order,
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

/// Σ term(a_i, b_i) with eight independent f32 accumulators (vectorises; a fixed order, so the
/// result does not depend on threads). The one summation kernel of [`dot`] and
/// `compress::distance::l1`.
#[inline(always)]
pub fn sum_pairs8(a: &[f32], b: &[f32], term: impl Fn(f32, f32) -> f32) -> f32 {
    let mut acc = [0.0f32; 8];
    let ca = a.chunks_exact(8);
    let cb = b.chunks_exact(8);
    let (ra, rb) = (ca.remainder(), cb.remainder());
    for (x, y) in ca.zip(cb) {
        for l in 0..8 {
            acc[l] += term(x[l], y[l]);
        }
    }
    let mut s = 0.0f32;
    for (x, y) in ra.iter().zip(rb) {
        s += term(*x, *y);
    }
    ((acc[0] + acc[4]) + (acc[1] + acc[5])) + ((acc[2] + acc[6]) + (acc[3] + acc[7])) + s
}

/// Dot product (see [`sum_pairs8`]).
#[inline]
pub fn dot(a: &[f32], b: &[f32]) -> f32 {
    sum_pairs8(a, b, |x, y| x * y)
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
