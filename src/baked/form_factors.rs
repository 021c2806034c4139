//! `form_factors.npy`: the `[n, n]` f32 form-factor matrix (row i = F_ij, the fraction of the
//! energy leaving patch i that arrives at patch j), written by `form_factors`.

use super::{npy, BakeTransaction};
use crate::error::{Error, IoContext, Result};
use std::path::Path;

/// File name of the form factors.
pub const FILE: &str = "form_factors.npy";

/// A form-factor matrix: `values[i * n + j] = F_ij`.
#[derive(Clone, Debug, PartialEq)]
pub struct FormFactorMatrix {
    pub n: usize,
    pub values: Vec<f32>,
}

/// Read `form_factors.npy` at `path`, checking that it is square.
pub fn read_file(path: &Path) -> Result<FormFactorMatrix> {
    let (shape, values) = npy::read_npy_f32(path)?;
    match shape.as_slice() {
        [a, b] if a == b => Ok(FormFactorMatrix {
            n: *a as usize,
            values,
        }),
        _ => Err(Error::input(
            path,
            format!("expected an [n, n] matrix, found shape {shape:?}"),
        )),
    }
}

/// Read the form factors of the bake in `dir`.
pub fn read(dir: &Path) -> Result<FormFactorMatrix> {
    read_file(&dir.join(FILE))
}

/// Write the form factors into a bake.
pub fn write(txn: &mut BakeTransaction, f: &FormFactorMatrix) -> Result<()> {
    txn.write_with(FILE, |p| {
        npy::write_npy_f32(p, &[f.n as u64, f.n as u64], &f.values)
    })
}

/// F memory-mapped from a bake's file: pages are read on demand and nothing is copied (a
/// transport shard reads F once to factor it, then only the rows of its own columns).
pub struct MappedFormFactors {
    map: memmap2::Mmap,
    offset: usize,
    pub n: usize,
}

impl MappedFormFactors {
    /// Map `form_factors.npy` at `path`, checking its header and that it is square.
    pub fn open(path: &Path) -> Result<Self> {
        let file = std::fs::File::open(path).at(path, "cannot read")?;
        // SAFETY: bake files are written once and renamed into place, never changed in place;
        // a file replaced meanwhile keeps the mapped inode alive.
        let map = unsafe { memmap2::Mmap::map(&file) }.at(path, "cannot map")?;
        let (shape, offset) =
            npy::parse_npy_header::<f32>(&map).map_err(|m| Error::input(path, m))?;
        let n = match shape.as_slice() {
            [a, b] if a == b => *a as usize,
            _ => {
                return Err(Error::input(
                    path,
                    format!("expected an [n, n] matrix, found shape {shape:?}"),
                ))
            }
        };
        if offset % 4 != 0 || cfg!(target_endian = "big") {
            return Err(Error::Unsupported {
                path: path.into(),
                message: "the matrix cannot be mapped as f32 here (misaligned or big-endian)"
                    .into(),
            });
        }
        Ok(MappedFormFactors { map, offset, n })
    }

    /// The `[n, n]` row-major values.
    pub fn values(&self) -> &[f32] {
        bytemuck::cast_slice(&self.map[self.offset..])
    }
}
