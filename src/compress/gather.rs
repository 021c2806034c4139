//! The CPU gather `B_ind = S · E` straight from the compressed form (docs/algorithms.md §2 "player":
//! decode BC1 + add the sidecar), the reference the GPU player's gather is tested against.
//!
//! Steps: permute the light (`E'[k] = E[perm[k]]`); for each block row (4 output rows, in
//! parallel) decode its blocks one at a time ([`super::dense::decode_block_at`]) and accumulate
//! `Σ_j S'_ij E'_j` in f32 in column order; add the sidecar rows; un-permute
//! (`B[perm[k]] = B'[k]`). No dense f32 matrix is ever formed: memory is the compressed form plus
//! two vectors. The summation order is fixed, so the result does not depend on the thread count.

use super::dense::BlockValues;
use super::EncodedTransport;
use crate::radiosity::transport::matrix::{permute_vector, unpermute_vector};
use rayon::prelude::*;

/// `B = S · E` per channel from `enc`; `e` and the result are `[channels][n]` in original
/// patch order.
pub fn gather(enc: &EncodedTransport, e: &[f32]) -> Vec<f32> {
    let tex = &enc.dense;
    let (n, ch, padded) = (tex.n, tex.channels, tex.padded);
    assert_eq!(e.len(), ch * n, "light vector length");
    let ep = permute_vector(e, &enc.perm);
    // Zero-padded copy per channel so padded columns contribute nothing.
    let mut epad = vec![0.0f32; ch * padded];
    for c in 0..ch {
        epad[c * padded..c * padded + n].copy_from_slice(&ep[c * n..(c + 1) * n]);
    }
    let dec = tex.decoder();
    let bw = padded / 4;
    let rows: Vec<[[f32; 4]; 3]> = (0..bw)
        .into_par_iter()
        .map(|by| {
            let mut acc = [[0.0f32; 4]; 3];
            let mut vals: BlockValues = [[0.0; 16]; 3];
            for bx in 0..bw {
                dec.block(by, bx, &mut vals);
                for c in 0..ch {
                    let ec = &epad[c * padded + 4 * bx..c * padded + 4 * bx + 4];
                    let v = &vals[c];
                    for y in 0..4 {
                        acc[c][y] += v[4 * y] * ec[0]
                            + v[4 * y + 1] * ec[1]
                            + v[4 * y + 2] * ec[2]
                            + v[4 * y + 3] * ec[3];
                    }
                }
            }
            let side = &enc.sidecar;
            for y in 0..4 {
                let i = 4 * by + y;
                if i >= n {
                    break;
                }
                for k in side.row_ptr[i] as usize..side.row_ptr[i + 1] as usize {
                    let j = side.cols[k] as usize;
                    for c in 0..ch {
                        acc[c][y] += side.values[k * ch + c] * ep[c * n + j];
                    }
                }
            }
            acc
        })
        .collect();
    let mut bp = vec![0.0f32; ch * n];
    for (by, acc) in rows.iter().enumerate() {
        for y in 0..4 {
            let i = 4 * by + y;
            if i < n {
                for c in 0..ch {
                    bp[c * n + i] = acc[c][y];
                }
            }
        }
    }
    unpermute_vector(&bp, &enc.perm)
}
