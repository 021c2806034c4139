//! The split (the radiosity thesis §4.2; docs/algorithms.md §3 "Compression" step 2): the largest p % of the entries
//! go to a sparse sidecar at full precision and are zeroed in the dense part.
//!
//! An entry is a texel (i, j) with all its channels; its magnitude is the largest absolute value
//! over the channels. `k = round(p/100 · n²)` entries move; ties are broken by the lower linear
//! index `i·n + j`, so the selection is deterministic. The sidecar is CSR over rows of the
//! (permuted) matrix; its binary layout is in docs/baked-format.md (`sidecar.bin`).

use crate::error::{Error, Result};
use crate::radiosity::TransportMatrix;
use rayon::prelude::*;
use std::path::Path;

/// Magic bytes of `sidecar.bin`.
pub const SIDECAR_MAGIC: &[u8; 4] = b"RLSC";
/// Layout version of `sidecar.bin`.
pub const SIDECAR_VERSION: u32 = 1;

/// The largest entries, at full precision, as CSR over rows.
#[derive(Clone, Debug, PartialEq)]
pub struct Sidecar {
    pub n: usize,
    pub channels: usize,
    /// `row_ptr[i]..row_ptr[i+1]` are row `i`'s entries (length n + 1).
    pub row_ptr: Vec<u32>,
    /// Column of each entry, increasing within a row.
    pub cols: Vec<u32>,
    /// `channels` values per entry, entry-major.
    pub values: Vec<f32>,
}

impl Sidecar {
    /// The columns of row `i`'s entries, ascending.
    pub fn row_cols(&self, i: usize) -> &[u32] {
        &self.cols[self.row_ptr[i] as usize..self.row_ptr[i + 1] as usize]
    }

    /// An empty sidecar.
    pub fn empty(channels: usize, n: usize) -> Self {
        Sidecar {
            n,
            channels,
            row_ptr: vec![0; n + 1],
            cols: Vec::new(),
            values: Vec::new(),
        }
    }

    /// Number of entries.
    pub fn nnz(&self) -> usize {
        self.cols.len()
    }

    /// Bytes of [`Sidecar::to_bytes`].
    pub fn byte_len(&self) -> usize {
        HEADER + 4 * (self.n + 1) + 4 * self.nnz() + 4 * self.values.len()
    }

    /// Add `S_side · e` into `b` (both `[channels][n]`).
    pub fn gather_into(&self, e: &[f32], b: &mut [f32]) {
        let (n, ch) = (self.n, self.channels);
        for i in 0..n {
            for k in self.row_ptr[i] as usize..self.row_ptr[i + 1] as usize {
                let j = self.cols[k] as usize;
                for c in 0..ch {
                    b[c * n + i] += self.values[k * ch + c] * e[c * n + j];
                }
            }
        }
    }

    /// The binary layout of `sidecar.bin` (little-endian; docs/baked-format.md).
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut out = Vec::with_capacity(self.byte_len());
        out.extend_from_slice(SIDECAR_MAGIC);
        out.extend_from_slice(&SIDECAR_VERSION.to_le_bytes());
        out.extend_from_slice(&(self.n as u32).to_le_bytes());
        out.extend_from_slice(&(self.channels as u32).to_le_bytes());
        out.extend_from_slice(&(self.nnz() as u64).to_le_bytes());
        for v in &self.row_ptr {
            out.extend_from_slice(&v.to_le_bytes());
        }
        for v in &self.cols {
            out.extend_from_slice(&v.to_le_bytes());
        }
        for v in &self.values {
            out.extend_from_slice(&v.to_le_bytes());
        }
        out
    }

    /// Parse [`Sidecar::to_bytes`]; `path` names the file in errors.
    pub fn from_bytes(path: &Path, bytes: &[u8]) -> Result<Self> {
        let bad = |m: &str| Error::input(path, format!("corrupt sidecar: {m}"));
        if bytes.len() < HEADER || &bytes[0..4] != SIDECAR_MAGIC {
            return Err(bad("missing RLSC header"));
        }
        let u32_at = |o: usize| u32::from_le_bytes(bytes[o..o + 4].try_into().unwrap());
        if u32_at(4) != SIDECAR_VERSION {
            return Err(Error::unsupported(
                path,
                format!("sidecar layout version {}", u32_at(4)),
            ));
        }
        let n = u32_at(8) as usize;
        let channels = u32_at(12) as usize;
        let nnz = u64::from_le_bytes(bytes[16..24].try_into().unwrap()) as usize;
        // Checked: the counts come from the file, and a wrapped sum could match its length.
        let expect = (n as u64 + 1)
            .checked_add(nnz as u64)
            .and_then(|w| w.checked_add((nnz as u64).checked_mul(channels as u64)?))
            .and_then(|w| w.checked_mul(4)?.checked_add(HEADER as u64));
        if expect != Some(bytes.len() as u64) {
            let implied = expect.map_or("more than 2^64".into(), |e| e.to_string());
            return Err(bad(&format!(
                "{} bytes, header implies {implied}",
                bytes.len()
            )));
        }
        let words = |o: usize, count: usize| -> Vec<u32> {
            bytes[o..o + 4 * count]
                .chunks_exact(4)
                .map(|c| u32::from_le_bytes(c.try_into().unwrap()))
                .collect()
        };
        let row_ptr = words(HEADER, n + 1);
        let cols = words(HEADER + 4 * (n + 1), nnz);
        let values: Vec<f32> = words(HEADER + 4 * (n + 1) + 4 * nnz, nnz * channels)
            .into_iter()
            .map(f32::from_bits)
            .collect();
        if row_ptr[0] != 0
            || row_ptr.windows(2).any(|w| w[0] > w[1])
            || row_ptr[n] as usize != nnz
            || cols.iter().any(|&c| c as usize >= n)
        {
            return Err(bad("inconsistent row pointers or columns"));
        }
        Ok(Sidecar {
            n,
            channels,
            row_ptr,
            cols,
            values,
        })
    }
}

const HEADER: usize = 24;

/// Number of entries that `percent` % of an n×n matrix is.
pub fn split_count(n: usize, percent: f64) -> usize {
    let total = (n * n) as f64;
    ((percent / 100.0 * total).round() as usize).min(n * n)
}

/// Move the largest `percent` % of the entries of `m` into a sidecar; return the dense rest
/// (those entries zeroed) and the sidecar. Preconditions: `0 ≤ percent ≤ 100`; `n² < 2³²`.
pub fn split_top(m: &TransportMatrix, percent: f64) -> Result<(TransportMatrix, Sidecar)> {
    let sidecar = top_entries(m, percent)?;
    let mut dense = m.clone();
    let (n, ch) = (m.n, m.channels);
    for i in 0..n {
        for &j in sidecar.row_cols(i) {
            for c in 0..ch {
                dense.data[(c * n + i) * n + j as usize] = 0.0;
            }
        }
    }
    Ok((dense, sidecar))
}

/// The sidecar of [`split_top`] alone: the largest `percent` % of the entries of `m` (by
/// largest magnitude over the channels, ties to the lower index), without the dense copy
/// (encoding with hole filling reads `m` itself and treats the sidecar's entries as zero).
pub fn top_entries(m: &TransportMatrix, percent: f64) -> Result<Sidecar> {
    let (n, ch) = (m.n, m.channels);
    if !(0.0..=100.0).contains(&percent) {
        return Err(Error::knob(format!(
            "split percentage {percent} is outside [0, 100]"
        )));
    }
    if (n as u64) * (n as u64) >= u32::MAX as u64 {
        return Err(Error::limit(format!(
            "{n} patches is too many for the sidecar's 32-bit indices"
        )));
    }
    let k = split_count(n, percent);
    if k == 0 {
        return Ok(Sidecar::empty(ch, n));
    }
    // Magnitude per entry; the key orders by magnitude descending, then index ascending.
    let nn = n * n;
    let key = |ij: usize| {
        let mag = (0..ch).fold(0.0f32, |a, c| a.max(m.data[c * nn + ij].abs()));
        // Non-negative finite floats order like their bit patterns.
        let mag = if mag.is_finite() { mag } else { f32::MAX };
        !mag.to_bits()
    };
    let chosen = smallest(nn, k, key);
    let mut row_ptr = vec![0u32; n + 1];
    let mut cols = Vec::with_capacity(chosen.len());
    let mut values = Vec::with_capacity(chosen.len() * ch);
    for &ij in &chosen {
        let (i, j) = (ij as usize / n, ij as usize % n);
        row_ptr[i + 1] += 1;
        cols.push(j as u32);
        for c in 0..ch {
            let idx = c * n * n + ij as usize;
            values.push(m.data[idx]);
        }
    }
    for i in 0..n {
        row_ptr[i + 1] += row_ptr[i];
    }
    Ok(Sidecar {
        n,
        channels: ch,
        row_ptr,
        cols,
        values,
    })
}

/// The indices of the `k` smallest (key(i), i) over `0..len`, ascending (1 ≤ k ≤ len), without
/// storing a key per index: a histogram of the keys' high 16 bits finds the bucket of the k-th,
/// one of its low 16 bits the k-th key K itself; then every index with a key below K is taken,
/// and the lowest ones with key K up to k. Three passes over the keys, in parallel over chunks,
/// and memory for the answer only (the split of a 4,000-patch bake kept 126 MB of keys).
fn smallest(len: usize, k: usize, key: impl Fn(usize) -> u32 + Sync) -> Vec<u32> {
    const CHUNK: usize = 1 << 18;
    let chunks = len.div_ceil(CHUNK);
    let range = |c: usize| c * CHUNK..((c + 1) * CHUNK).min(len);
    // Counts of the keys that `bucket` maps to Some(b) (b < 2¹⁶).
    let histogram = |bucket: &(dyn Fn(u32) -> Option<usize> + Sync)| {
        (0..chunks)
            .into_par_iter()
            .map(|c| {
                let mut h = vec![0usize; 1 << 16];
                for i in range(c) {
                    if let Some(b) = bucket(key(i)) {
                        h[b] += 1;
                    }
                }
                h
            })
            .reduce(
                || vec![0usize; 1 << 16],
                |mut a, b| {
                    a.iter_mut().zip(b).for_each(|(x, y)| *x += y);
                    a
                },
            )
    };
    // The bucket holding the `rank`-th smallest (0-based) and how many come before it.
    let locate = |h: &[usize], rank: usize| {
        let mut before = 0;
        for (b, &count) in h.iter().enumerate() {
            if before + count > rank {
                return (b, before);
            }
            before += count;
        }
        unreachable!("rank {rank} beyond the {before} keys counted")
    };
    let (high, below_high) = locate(&histogram(&|x| Some((x >> 16) as usize)), k - 1);
    let low_hist = histogram(&|x| ((x >> 16) as usize == high).then_some((x & 0xffff) as usize));
    let (low, below_low) = locate(&low_hist, k - 1 - below_high);
    let threshold = (high as u32) << 16 | low as u32;
    let below = below_high + below_low;
    // Per chunk, in order: the indices under the threshold and those at it.
    let parts: Vec<(Vec<u32>, Vec<u32>)> = (0..chunks)
        .into_par_iter()
        .map(|c| {
            let (mut under, mut at) = (Vec::new(), Vec::new());
            for i in range(c) {
                match key(i).cmp(&threshold) {
                    std::cmp::Ordering::Less => under.push(i as u32),
                    std::cmp::Ordering::Equal => at.push(i as u32),
                    std::cmp::Ordering::Greater => {}
                }
            }
            (under, at)
        })
        .collect();
    let mut ties = k - below;
    let mut chosen = Vec::with_capacity(k);
    for (under, at) in parts {
        chosen.extend(under);
        let take = ties.min(at.len());
        chosen.extend(&at[..take]);
        ties -= take;
    }
    chosen.sort_unstable();
    chosen
}
