//! `form_factors.npy`: the `[n, n]` f32 form-factor matrix (row i = F_ij, the fraction of the
//! energy leaving patch i that arrives at patch j), written by `form_factors`.

use super::{npy, BakeTransaction};
use crate::error::{Error, Result};
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
