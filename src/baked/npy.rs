//! NumPy `.npy` files (little-endian, C order) of f32 (the matrices of a bake), u16 (horizon
//! maps) and i32 (their directions): readable by numpy.

use crate::error::{Error, IoContext, Result};
use std::path::Path;

/// An element type relume writes to and reads from `.npy`.
pub trait NpyElement: Copy + npyz::Serialize + npyz::AutoSerialize {
    /// numpy's `descr` of the little-endian type, quoted as in the header.
    const DESCR: &'static str;
    /// Bytes per element.
    const SIZE: usize;
    /// The Rust name, for messages.
    const NAME: &'static str;
    /// The element from its little-endian bytes (`SIZE` of them).
    fn from_le(bytes: &[u8]) -> Self;
}

macro_rules! npy_element {
    ($t:ty, $descr:literal, $name:literal) => {
        impl NpyElement for $t {
            const DESCR: &'static str = $descr;
            const SIZE: usize = std::mem::size_of::<$t>();
            const NAME: &'static str = $name;
            fn from_le(b: &[u8]) -> Self {
                <$t>::from_le_bytes(b.try_into().unwrap())
            }
        }
    };
}

npy_element!(f32, "'<f4'", "f32");
npy_element!(u16, "'<u2'", "u16");
npy_element!(i32, "'<i4'", "i32");

/// Write an f32 array as `.npy` with the given shape (C order).
pub fn write_npy_f32(path: &Path, shape: &[u64], data: &[f32]) -> Result<()> {
    write_npy(path, shape, data)
}

/// Write an array as `.npy` with the given shape (C order).
pub fn write_npy<T: NpyElement>(path: &Path, shape: &[u64], data: &[T]) -> Result<()> {
    let expected: u64 = shape.iter().product();
    if expected != data.len() as u64 {
        return Err(Error::Internal(format!(
            "npy shape {shape:?} does not hold {} values",
            data.len()
        )));
    }
    write_npy_iter(path, shape, data.iter().copied())
}

/// Write the values of `data` (exactly the shape's product of them, streamed) as `.npy`.
pub fn write_npy_iter<T: NpyElement>(
    path: &Path,
    shape: &[u64],
    data: impl Iterator<Item = T>,
) -> Result<()> {
    use npyz::WriterBuilder;
    let file = std::fs::File::create(path).at(path, "cannot write")?;
    let mut w = npyz::WriteOptions::new()
        .default_dtype()
        .shape(shape)
        .writer(std::io::BufWriter::new(file))
        .begin_nd()
        .at(path, "cannot write")?;
    w.extend(data).at(path, "cannot write")?;
    w.finish().at(path, "cannot write")
}

/// Read an f32 `.npy` file: (shape, values).
///
/// Hand-written rather than `npyz`'s reader: `npyz` parses the header with a general Python
/// literal grammar (`py_literal`, a backtracking PEG) that takes over 30 s on some 130-byte
/// damaged headers (found by fuzzing; `fuzz/regressions/baked/npy-*`). relume reads only what it
/// writes, `{'descr': '<f4', 'fortran_order': False, 'shape': (...), }` (format versions 1-3), so
/// this parser accepts exactly that, in time linear in the header. `npyz` still writes the files,
/// and numpy reads them in the tests: the two sides stay independent.
pub fn read_npy_f32(path: &Path) -> Result<(Vec<u64>, Vec<f32>)> {
    read_npy(path)
}

/// Read a `.npy` file of `T` (see [`read_npy_f32`]): (shape, values).
pub fn read_npy<T: NpyElement>(path: &Path) -> Result<(Vec<u64>, Vec<T>)> {
    let bytes = std::fs::read(path).at(path, "cannot read")?;
    let (shape, data) = parse_npy(&bytes).map_err(|m| Error::input(path, m))?;
    Ok((shape, data))
}

/// Parse the bytes of an f32 `.npy` file (see [`read_npy_f32`]); the error is a message.
pub fn parse_npy_f32(bytes: &[u8]) -> std::result::Result<(Vec<u64>, Vec<f32>), String> {
    parse_npy(bytes)
}

/// Parse the bytes of a `.npy` file of `T` (see [`read_npy_f32`]); the error is a message.
pub fn parse_npy<T: NpyElement>(bytes: &[u8]) -> std::result::Result<(Vec<u64>, Vec<T>), String> {
    let (shape, offset) = parse_npy_header::<T>(bytes)?;
    let values = bytes[offset..]
        .chunks_exact(T::SIZE)
        .map(T::from_le)
        .collect();
    Ok((shape, values))
}

/// The shape of a `.npy` file of `T` and the offset of its data, checked to fill the rest of
/// `bytes` exactly (see [`read_npy_f32`]).
pub fn parse_npy_header<T: NpyElement>(
    bytes: &[u8],
) -> std::result::Result<(Vec<u64>, usize), String> {
    let bad = |m: &str| format!("not a .npy file: {m}");
    if bytes.len() < 10 || &bytes[..6] != b"\x93NUMPY" {
        return Err(bad("missing the \\x93NUMPY magic"));
    }
    let (len, start) = match bytes[6] {
        1 => (u16::from_le_bytes([bytes[8], bytes[9]]) as usize, 10usize),
        2 | 3 if bytes.len() >= 12 => (
            u32::from_le_bytes(bytes[8..12].try_into().unwrap()) as usize,
            12,
        ),
        v => return Err(bad(&format!("format version {v}"))),
    };
    let header = bytes
        .get(start..start.saturating_add(len))
        .ok_or_else(|| bad("the header runs past the end of the file"))?;
    let header = std::str::from_utf8(header).map_err(|_| bad("the header is not text"))?;
    let compact: String = header.chars().filter(|c| !c.is_whitespace()).collect();
    let body = compact
        .strip_prefix('{')
        .and_then(|b| b.strip_suffix('}'))
        .ok_or_else(|| bad("the header is not a dictionary"))?;
    let (mut descr, mut fortran, mut shape) = (None, None, None);
    let mut rest = body;
    while !rest.is_empty() {
        let (key, after) = rest
            .split_once(':')
            .ok_or_else(|| bad("a header entry without a value"))?;
        let (value, next) = if let Some(tuple) = after.strip_prefix('(') {
            let end = tuple.find(')').ok_or_else(|| bad("an unclosed shape"))?;
            (&after[..end + 2], &tuple[end + 1..])
        } else {
            after.split_at(after.find(',').unwrap_or(after.len()))
        };
        match key {
            "'descr'" => descr = Some(value),
            "'fortran_order'" => fortran = Some(value),
            "'shape'" => shape = Some(value),
            k => return Err(bad(&format!("unexpected header key {k}"))),
        }
        rest = next.strip_prefix(',').unwrap_or(next);
    }
    match descr {
        Some(d) if d == T::DESCR => {}
        Some(d) => return Err(format!("not a .npy file of {}: dtype {d}", T::NAME)),
        None => return Err(bad("no 'descr' in the header")),
    }
    if fortran != Some("False") {
        return Err(bad("Fortran order (relume writes C order)"));
    }
    let dims = shape
        .and_then(|s| s.strip_prefix('('))
        .and_then(|s| s.strip_suffix(')'))
        .ok_or_else(|| bad("no 'shape' tuple in the header"))?;
    let shape: Vec<u64> = dims
        .split(',')
        .filter(|d| !d.is_empty())
        .map(|d| d.parse::<u64>())
        .collect::<std::result::Result<_, _>>()
        .map_err(|_| bad(&format!("shape ({dims}) is not a tuple of sizes")))?;
    let data = &bytes[start + len..];
    let count = shape.iter().try_fold(1u64, |a, &d| a.checked_mul(d));
    let size = T::SIZE as u64;
    if count.and_then(|c| c.checked_mul(size)) != Some(data.len() as u64) {
        return Err(bad(&format!(
            "shape {shape:?} needs {} bytes of data, the file has {}",
            count
                .and_then(|c| c.checked_mul(size))
                .map_or("more than 2^64".into(), |c| c.to_string()),
            data.len()
        )));
    }
    Ok((shape, start + len))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// What numpy 1.x/2.x writes for `np.save(f, np.zeros(shape, "<f4"))` (header padded to 64).
    fn numpy_file(shape: &str, descr: &str, data: &[f32]) -> Vec<u8> {
        let mut h = format!("{{'descr': '{descr}', 'fortran_order': False, 'shape': {shape}, }}");
        while (10 + h.len() + 1) % 64 != 0 {
            h.push(' ');
        }
        h.push('\n');
        let mut out = b"\x93NUMPY\x01\x00".to_vec();
        out.extend_from_slice(&(h.len() as u16).to_le_bytes());
        out.extend_from_slice(h.as_bytes());
        out.extend(data.iter().flat_map(|v| v.to_le_bytes()));
        out
    }

    #[test]
    fn reads_what_numpy_and_npyz_write() {
        let (shape, v) =
            parse_npy_f32(&numpy_file("(2, 3)", "<f4", &[1., 2., 3., 4., 5., 6.])).unwrap();
        assert_eq!((shape, v), (vec![2, 3], vec![1., 2., 3., 4., 5., 6.]));
        let (shape, v) = parse_npy_f32(&numpy_file("(1,)", "<f4", &[7.])).unwrap();
        assert_eq!((shape, v), (vec![1], vec![7.]));
        let (shape, v) = parse_npy_f32(&numpy_file("()", "<f4", &[9.])).unwrap();
        assert_eq!((shape, v), (vec![], vec![9.]));
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("m.npy");
        let data: Vec<f32> = (0..24).map(|i| i as f32 * 0.5).collect();
        write_npy_f32(&p, &[2, 3, 4], &data).unwrap();
        assert_eq!(read_npy_f32(&p).unwrap(), (vec![2, 3, 4], data));
    }

    #[test]
    fn u16_and_i32_round_trip_and_keep_their_types() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("h.npy");
        let v: Vec<u16> = vec![0, 1, 65535, 32768, 7, 9];
        write_npy(&p, &[3, 2], &v).unwrap();
        assert_eq!(read_npy::<u16>(&p).unwrap(), (vec![3, 2], v));
        assert!(read_npy::<f32>(&p).unwrap_err().to_string().contains("<u2"));
        let d: Vec<i32> = vec![-3, 1, 64, -64];
        write_npy(&p, &[2, 2], &d).unwrap();
        assert_eq!(read_npy::<i32>(&p).unwrap(), (vec![2, 2], d));
        assert!(read_npy::<u16>(&p).unwrap_err().to_string().contains("<i4"));
    }

    #[test]
    fn refuses_what_it_does_not_write() {
        let err = |b: &[u8]| parse_npy_f32(b).unwrap_err();
        assert!(
            err(&numpy_file("(2,)", "<f8", &[0., 0., 0., 0.])).contains("not a .npy file of f32")
        );
        let good = numpy_file("(2, 3)", "<f4", &[0.; 6]);
        assert!(err(&good[..good.len() - 4]).contains("needs 24 bytes"));
        assert!(err(&good[..40]).contains("runs past the end"));
        assert!(err(&numpy_file("(99999999999, 99999999999, 99)", "<f4", &[])).contains("needs"));
        assert!(err(b"PK\x03\x04 not numpy").contains("magic"));
        let mut f = good.clone();
        let at = f.windows(5).position(|w| w == b"False").unwrap();
        f[at..at + 5].copy_from_slice(b"True ");
        assert!(err(&f).contains("Fortran"));
    }
}
