//! `permutation.bin`: the reorder stage's permutation (`perm[k]` = original patch index placed at
//! position k).

use super::BakeTransaction;
use crate::error::{Error, IoContext, Result};
use crate::radiosity::transport::matrix::is_permutation;
use std::path::Path;

/// File name of the permutation.
pub const FILE: &str = "permutation.bin";

/// Read the permutation of the bake in `dir`.
pub fn read(dir: &Path) -> Result<Vec<u32>> {
    read_file(&dir.join(FILE))
}

/// Write the permutation into a bake.
pub fn write(txn: &mut BakeTransaction, perm: &[u32]) -> Result<()> {
    txn.write(FILE, &to_bytes(perm))
}

/// `permutation.bin`: magic `RLPM`, u32 version 1, u32 n, then n u32 (little-endian).
pub fn to_bytes(perm: &[u32]) -> Vec<u8> {
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
pub fn read_file(path: &Path) -> Result<Vec<u32>> {
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
    if !is_permutation(&perm) {
        return Err(Error::input(path, "not a permutation of 0..n"));
    }
    Ok(perm)
}
