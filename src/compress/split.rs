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
    let mut dense = m.clone();
    if k == 0 {
        return Ok((dense, Sidecar::empty(ch, n)));
    }
    // Magnitude per entry; the key orders by magnitude descending, then index ascending.
    let mut keys: Vec<(u32, u32)> = (0..n * n)
        .into_par_iter()
        .map(|ij| {
            let mag = (0..ch).fold(0.0f32, |a, c| a.max(m.data[c * n * n + ij].abs()));
            // Non-negative finite floats order like their bit patterns.
            let mag = if mag.is_finite() { mag } else { f32::MAX };
            (!mag.to_bits(), ij as u32)
        })
        .collect();
    if k < keys.len() {
        keys.select_nth_unstable(k - 1);
        keys.truncate(k);
    }
    let mut chosen: Vec<u32> = keys.into_iter().map(|(_, ij)| ij).collect();
    chosen.sort_unstable();
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
            dense.data[idx] = 0.0;
        }
    }
    for i in 0..n {
        row_ptr[i + 1] += row_ptr[i];
    }
    Ok((
        dense,
        Sidecar {
            n,
            channels: ch,
            row_ptr,
            cols,
            values,
        },
    ))
}
