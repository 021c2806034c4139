//! NumPy `.npy` files of f32 (little-endian, C order): the matrices of a bake, readable by numpy.

use crate::error::{Error, IoContext, Result};
use std::path::Path;

/// Write an f32 array as `.npy` with the given shape (C order).
pub fn write_npy_f32(path: &Path, shape: &[u64], data: &[f32]) -> Result<()> {
    use npyz::WriterBuilder;
    let expected: u64 = shape.iter().product();
    if expected != data.len() as u64 {
        return Err(Error::Internal(format!(
            "npy shape {shape:?} does not hold {} values",
            data.len()
        )));
    }
    let file = std::fs::File::create(path).at(path, "cannot write")?;
    let mut w = npyz::WriteOptions::new()
        .default_dtype()
        .shape(shape)
        .writer(std::io::BufWriter::new(file))
        .begin_nd()
        .at(path, "cannot write")?;
    w.extend(data.iter().copied()).at(path, "cannot write")?;
    w.finish().at(path, "cannot write")
}

/// Read an f32 `.npy` file: (shape, values).
pub fn read_npy_f32(path: &Path) -> Result<(Vec<u64>, Vec<f32>)> {
    let bytes = std::fs::read(path).at(path, "cannot read")?;
    let npy = npyz::NpyFile::new(&bytes[..])
        .map_err(|e| Error::input(path, format!("not a .npy file: {e}")))?;
    let shape = npy.shape().to_vec();
    let data = npy
        .into_vec::<f32>()
        .map_err(|e| Error::input(path, format!("not an f32 .npy file: {e}")))?;
    Ok((shape, data))
}
