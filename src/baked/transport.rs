//! `transport.npy`: the `[channels, n, n]` f32 transport matrix S (channels = 1 for grey
//! scenes, else 3), written by `transport`. An `[n, n]` file reads as one channel.

use super::{npy, BakeTransaction};
use crate::error::{Error, Result};
use crate::radiosity::TransportMatrix;
use std::path::Path;

/// File name of the transport matrix.
pub const FILE: &str = "transport.npy";

/// Read the transport of the bake in `dir`.
pub fn read(dir: &Path) -> Result<TransportMatrix> {
    read_file(&dir.join(FILE))
}

/// Write the transport into a bake.
pub fn write(txn: &mut BakeTransaction, m: &TransportMatrix) -> Result<()> {
    txn.write_with(FILE, |p| write_file(p, m))
}

/// Read a `[channels, n, n]` (or `[n, n]` for one channel) f32 `.npy` file.
pub fn read_file(path: &Path) -> Result<TransportMatrix> {
    let (shape, data) = npy::read_npy_f32(path)?;
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
    TransportMatrix::new(channels, n, data)
}

/// Write a `[channels, n, n]` f32 `.npy` file.
pub fn write_file(path: &Path, m: &TransportMatrix) -> Result<()> {
    npy::write_npy_f32(path, &[m.channels as u64, m.n as u64, m.n as u64], &m.data)
}
