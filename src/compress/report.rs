//! The compression error report (docs/algorithms.md §3 "Compression" step 5): the radiosity thesis's three numbers
//! — mean, max and summed absolute error of the decoded matrix against the uncompressed S —
//! plus the RMS relative error of the gathered indirect light for a few deterministic light
//! configurations, and the bytes of the dense part and the sidecar.
//!
//! RMS relative error of a gather: `sqrt(Σ_{c,i} (B̃ − B)²) / sqrt(Σ_{c,i} B²)` with
//! `B = S·E` (dense f32 product) and `B̃` the gather from the compressed form.

use super::dense::BlockValues;
use super::{gather, EncodedTransport, TransportMatrix};
use rayon::prelude::*;
use std::collections::BTreeMap;

/// Per-entry errors of the decoded matrix (dense part decoded + sidecar) against S.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct EntryErrors {
    /// Mean absolute error over all `channels·n²` entries.
    pub mean: f64,
    pub max: f64,
    pub sum: f64,
    /// Root mean square error over all entries (used by the study; not in the manifest).
    pub rms: f64,
}

/// The full report of one encoding.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CompressionReport {
    pub entry: EntryErrors,
    /// (light configuration name, RMS relative error of the gathered light).
    pub gather_rms_rel: Vec<(String, f64)>,
    pub dense_bytes: usize,
    pub sidecar_bytes: usize,
    pub sidecar_entries: usize,
}

impl CompressionReport {
    /// The largest RMS relative gather error over the light configurations.
    pub fn worst_gather(&self) -> f64 {
        self.gather_rms_rel.iter().map(|x| x.1).fold(0.0, f64::max)
    }

    /// Flattened for a manifest's `StageRecord::report`.
    pub fn to_map(&self) -> BTreeMap<String, f64> {
        let mut m = BTreeMap::new();
        m.insert("error_mean_abs".into(), self.entry.mean);
        m.insert("error_max_abs".into(), self.entry.max);
        m.insert("error_sum_abs".into(), self.entry.sum);
        for (name, v) in &self.gather_rms_rel {
            m.insert(format!("gather_rms_rel_{name}"), *v);
        }
        m.insert("dense_bytes".into(), self.dense_bytes as f64);
        m.insert("sidecar_bytes".into(), self.sidecar_bytes as f64);
        m.insert("sidecar_entries".into(), self.sidecar_entries as f64);
        m
    }
}

/// Mean, max, summed and RMS absolute error of `enc` decoded (in permuted order) against `s_perm`
/// (= P S Pᵀ). Block by block; never forms the decoded matrix.
pub fn entry_errors(s_perm: &TransportMatrix, enc: &EncodedTransport) -> EntryErrors {
    let tex = &enc.dense;
    let (n, ch, padded) = (s_perm.n, s_perm.channels, tex.padded);
    let bw = padded / 4;
    let dec = tex.decoder();
    let side = &enc.sidecar;
    let per_row: Vec<(f64, f64, f64)> = (0..bw)
        .into_par_iter()
        .map(|by| {
            // The sidecar's share of these four rows.
            let mut extra = vec![0.0f32; ch * 4 * padded];
            for y in 0..4 {
                let i = 4 * by + y;
                if i >= n {
                    break;
                }
                for k in side.row_ptr[i] as usize..side.row_ptr[i + 1] as usize {
                    let j = side.cols[k] as usize;
                    for c in 0..ch {
                        extra[(c * 4 + y) * padded + j] = side.values[k * ch + c];
                    }
                }
            }
            let mut vals: BlockValues = [[0.0; 16]; 3];
            let (mut sum, mut max, mut sq) = (0.0f64, 0.0f64, 0.0f64);
            for bx in 0..bw {
                dec.block(by, bx, &mut vals);
                for c in 0..ch {
                    for t in 0..16 {
                        let (i, j) = (4 * by + t / 4, 4 * bx + t % 4);
                        if i < n && j < n {
                            let d = vals[c][t] + extra[(c * 4 + t / 4) * padded + j];
                            let err = (d as f64 - s_perm.get(c, i, j) as f64).abs();
                            sum += err;
                            sq += err * err;
                            max = max.max(err);
                        }
                    }
                }
            }
            (sum, max, sq)
        })
        .collect();
    // Summed in block-row order: the same bits for any thread count.
    let (sum, max, sq) = per_row.iter().fold((0.0f64, 0.0f64, 0.0f64), |a, b| {
        (a.0 + b.0, a.1.max(b.1), a.2 + b.2)
    });
    let count = (ch * n * n).max(1) as f64;
    EntryErrors {
        mean: sum / count,
        max,
        sum,
        rms: (sq / count).sqrt(),
    }
}

/// RMS relative error of `approx` against `exact` (see the module doc); 0 when both are zero.
pub fn rms_relative(approx: &[f32], exact: &[f32]) -> f64 {
    let num: f64 = approx
        .iter()
        .zip(exact)
        .map(|(a, b)| (*a as f64 - *b as f64).powi(2))
        .sum();
    let den: f64 = exact.iter().map(|b| (*b as f64).powi(2)).sum();
    if den == 0.0 {
        if num == 0.0 {
            0.0
        } else {
            f64::INFINITY
        }
    } else {
        (num / den).sqrt()
    }
}

/// Deterministic light configurations over patch indices (original order), `[channels][n]`:
/// - `uniform`: every patch emits 1;
/// - `random`: a hash of the patch index, uniform in [0, 1) (incoherent light);
/// - `half`: the first half of the patches emit 1 (a large, localised light);
/// - `one`: a single patch, the middle one, emits 1 (one column of S).
pub fn standard_lights(channels: usize, n: usize) -> Vec<(String, Vec<f32>)> {
    let hash = |j: usize| {
        let mut z = (j as u64).wrapping_add(0x9E37_79B9_7F4A_7C15);
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 40) as f32 / (1u64 << 24) as f32
    };
    let make = |f: &dyn Fn(usize) -> f32| -> Vec<f32> {
        (0..channels * n).map(|k| f(k % n.max(1))).collect()
    };
    vec![
        ("uniform".to_string(), make(&|_| 1.0)),
        ("random".to_string(), make(&hash)),
        (
            "half".to_string(),
            make(&|j| if j < n.div_ceil(2) { 1.0 } else { 0.0 }),
        ),
        (
            "one".to_string(),
            make(&|j| if j == n / 2 { 1.0 } else { 0.0 }),
        ),
    ]
}

/// The full report of `enc` against the original (unpermuted) `s` and its permuted `s_perm`,
/// with the gather error for each of `lights`.
pub fn report(
    s: &TransportMatrix,
    s_perm: &TransportMatrix,
    enc: &EncodedTransport,
    lights: &[(String, Vec<f32>)],
) -> CompressionReport {
    let exact: Vec<Vec<f32>> = lights.iter().map(|(_, e)| s.mat_vec(e)).collect();
    report_from(&exact, s_perm, enc, lights)
}

/// [`report`] given the exact gathers `exact[k] = S · lights[k]` (computed before S was
/// permuted in place, as the encode stage does).
pub fn report_from(
    exact: &[Vec<f32>],
    s_perm: &TransportMatrix,
    enc: &EncodedTransport,
    lights: &[(String, Vec<f32>)],
) -> CompressionReport {
    let gather_rms_rel = lights
        .iter()
        .zip(exact)
        .map(|((name, e), exact)| (name.clone(), rms_relative(&gather(enc, e), exact)))
        .collect();
    CompressionReport {
        entry: entry_errors(s_perm, enc),
        gather_rms_rel,
        dense_bytes: enc.dense.bytes(),
        sidecar_bytes: enc.sidecar.byte_len(),
        sidecar_entries: enc.sidecar.nnz(),
    }
}
