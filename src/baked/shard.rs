//! Shard files: one process's part of an expensive stage (`relume-bake run --shard I/N`), merged
//! by `relume-bake merge` (docs/scale-out.md).
//!
//! A shard file `STAGE.I-of-N.shard` is
//!
//! ```text
//! "RELUME-SHARD-01\n"          16 bytes
//! header length                 u64 little-endian
//! header                        JSON (ShardHeader)
//! payload                       the sections, each little-endian, back to back
//! SHA-256                       32 bytes: of everything before it
//! ```
//!
//! The header names the bake (`bake`: the hash of the pipeline and the input file), the stage,
//! the shard's index and count, the stage's cache key (relume's version and source, the baked
//! format, the stage's knobs and the hashes of every file the stage reads: see `bake::cache`),
//! and the payload's sections and size; the file ends with the SHA-256 of all that comes before,
//! so a changed header is caught as surely as a changed payload. It is written to `.NAME.tmp-PID` in the same
//! directory and renamed into place, so a killed shard leaves either nothing or a whole file;
//! the next shard written into that directory on the same host removes temporaries of processes
//! that no longer run.

use super::transaction::left_by_dead_process;
use crate::error::{Error, IoContext, Result};
use crate::pipeline::Pipeline;
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use std::collections::BTreeMap;
use std::io::{Read, Write};
use std::path::{Path, PathBuf};

/// The first 16 bytes of every shard file.
pub const MAGIC: &[u8; 16] = b"RELUME-SHARD-01\n";

/// One array of the payload.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Section {
    pub name: String,
    /// `f32`, `f64`, `u32` or `u64`.
    pub dtype: String,
    /// Elements.
    pub len: u64,
}

/// What a shard file says about itself.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ShardHeader {
    /// SHA-256 of the pipeline (JSON) and the input file's hash: which bake this is part of.
    pub bake: String,
    /// The stage this is part of (`form_factors`, `transport`).
    pub stage: String,
    pub index: u32,
    pub count: u32,
    /// The stage's cache key: equal keys mean equal inputs, knobs and relume.
    pub key: String,
    pub relume_version: String,
    /// The pipeline, so that `merge` can finish the bake.
    pub pipeline: Pipeline,
    /// What part of the stage this is, for people (`rows 0..150 of 600`).
    pub part: String,
    /// Filled in by [`write`].
    pub sections: Vec<Section>,
    /// Filled in by [`write`].
    pub payload_bytes: u64,
}

impl ShardHeader {
    /// The header of part `index` of `count` of `stage` of bake `bake` (sections and size are
    /// filled in by [`write`]).
    pub fn new(
        bake: String,
        stage: String,
        (index, count): (usize, usize),
        key: &str,
        pipeline: &Pipeline,
        part: String,
    ) -> Self {
        ShardHeader {
            bake,
            stage,
            index: index as u32,
            count: count as u32,
            key: key.into(),
            relume_version: env!("CARGO_PKG_VERSION").into(),
            pipeline: pipeline.clone(),
            part,
            sections: Vec::new(),
            payload_bytes: 0,
        }
    }
}

/// Writes a section's little-endian bytes, piece by piece, into a sink.
type Emit<'a> = Box<dyn Fn(&mut dyn FnMut(&[u8])) + 'a>;

/// The arrays of a shard, by section name.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Payload {
    pub f32s: BTreeMap<String, Vec<f32>>,
    pub f64s: BTreeMap<String, Vec<f64>>,
    pub u32s: BTreeMap<String, Vec<u32>>,
    pub u64s: BTreeMap<String, Vec<u64>>,
}

impl Payload {
    fn take<T>(map: &mut BTreeMap<String, Vec<T>>, name: &str, path: &Path) -> Result<Vec<T>> {
        map.remove(name)
            .ok_or_else(|| Error::verify(path, format!("the shard has no section `{name}`")))
    }
    pub fn f32s(&mut self, name: &str, path: &Path) -> Result<Vec<f32>> {
        Self::take(&mut self.f32s, name, path)
    }
    pub fn f64s(&mut self, name: &str, path: &Path) -> Result<Vec<f64>> {
        Self::take(&mut self.f64s, name, path)
    }
    pub fn u32s(&mut self, name: &str, path: &Path) -> Result<Vec<u32>> {
        Self::take(&mut self.u32s, name, path)
    }
    pub fn u64s(&mut self, name: &str, path: &Path) -> Result<Vec<u64>> {
        Self::take(&mut self.u64s, name, path)
    }

    /// The sections in file order, each with a writer of its little-endian bytes (in pieces,
    /// so that no copy of a large array is made).
    fn sections(&self) -> Vec<(Section, Emit<'_>)> {
        fn put<'a, T: Copy, const W: usize>(
            out: &mut Vec<(Section, Emit<'a>)>,
            map: &'a BTreeMap<String, Vec<T>>,
            dtype: &str,
            le: fn(T) -> [u8; W],
        ) {
            for (k, v) in map {
                let section = Section {
                    name: k.clone(),
                    dtype: dtype.into(),
                    len: v.len() as u64,
                };
                let emit = move |sink: &mut dyn FnMut(&[u8])| {
                    let mut buf = Vec::with_capacity(1 << 16);
                    for chunk in v.chunks(1 << 14) {
                        buf.clear();
                        for &x in chunk {
                            buf.extend_from_slice(&le(x));
                        }
                        sink(&buf);
                    }
                };
                out.push((section, Box::new(emit)));
            }
        }
        let mut out = Vec::new();
        put(&mut out, &self.f32s, "f32", f32::to_le_bytes);
        put(&mut out, &self.f64s, "f64", f64::to_le_bytes);
        put(&mut out, &self.u32s, "u32", u32::to_le_bytes);
        put(&mut out, &self.u64s, "u64", u64::to_le_bytes);
        out
    }
}

/// The file name of shard `index` of `count` of `stage`.
pub fn file_name(stage: &str, index: u32, count: u32) -> String {
    format!("{stage}.{index}-of-{count}.shard")
}

/// Write a shard into `dir` atomically; returns its path. `header`'s sections, size and hash are
/// filled in here.
pub fn write(dir: &Path, mut header: ShardHeader, payload: &Payload) -> Result<PathBuf> {
    std::fs::create_dir_all(dir).at(dir, "cannot create the shard directory")?;
    clean_stale(dir);
    let sections = payload.sections();
    header.sections = sections.iter().map(|(s, _)| s.clone()).collect();
    header.payload_bytes = header
        .sections
        .iter()
        .map(|s| {
            s.len
                * if s.dtype == "f64" || s.dtype == "u64" {
                    8
                } else {
                    4
                }
        })
        .sum();
    let json = serde_json::to_vec(&header).map_err(|e| Error::Internal(e.to_string()))?;
    let name = file_name(&header.stage, header.index, header.count);
    let path = dir.join(&name);
    let tmp = dir.join(format!(".{name}.tmp-{}-{}", host(), std::process::id()));
    let result = (|| -> std::io::Result<()> {
        let mut f = std::io::BufWriter::new(std::fs::File::create(&tmp)?);
        let mut hasher = Sha256::new();
        let mut put = |f: &mut std::io::BufWriter<std::fs::File>, b: &[u8]| {
            hasher.update(b);
            f.write_all(b)
        };
        put(&mut f, MAGIC)?;
        put(&mut f, &(json.len() as u64).to_le_bytes())?;
        put(&mut f, &json)?;
        let mut failed = None;
        for (_, emit) in &sections {
            emit(&mut |b: &[u8]| {
                if failed.is_none() {
                    if let Err(e) = put(&mut f, b) {
                        failed = Some(e);
                    }
                }
            });
        }
        if let Some(e) = failed {
            return Err(e);
        }
        f.write_all(&hasher.finalize())?;
        f.into_inner().map_err(|e| e.into_error())?.sync_all()
    })();
    if let Err(e) = result {
        let _ = std::fs::remove_file(&tmp);
        return Err(Error::io(&tmp, "cannot write the shard", e));
    }
    std::fs::rename(&tmp, &path).at(&path, "cannot move the shard into place")?;
    Ok(path)
}

/// This machine's host name (temporaries of other hosts sharing the directory are left alone:
/// whether their process runs cannot be told from here).
fn host() -> String {
    std::fs::read_to_string("/proc/sys/kernel/hostname")
        .map(|h| h.trim().replace(['/', '-'], "_"))
        .unwrap_or_else(|_| "host".into())
}

/// Remove `.NAME.shard.tmp-HOST-PID` files of this host's processes that no longer run.
fn clean_stale(dir: &Path) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    let mine = format!(".shard.tmp-{}-", host());
    for e in entries.flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        let Some((_, pid)) = name.rsplit_once(&mine) else {
            continue;
        };
        if let Ok(pid) = pid.parse::<u32>() {
            if name.starts_with('.') && left_by_dead_process(&e.path(), pid) {
                let _ = std::fs::remove_file(e.path());
            }
        }
    }
}

/// Read a shard's header, checking the magic and that the file is as long as it says.
pub fn read_header(path: &Path) -> Result<ShardHeader> {
    let mut f = std::fs::File::open(path).at(path, "cannot read the shard")?;
    let mut magic = [0u8; 16];
    let mut len = [0u8; 8];
    f.read_exact(&mut magic)
        .and_then(|_| f.read_exact(&mut len))
        .map_err(|_| Error::verify(path, "not a relume shard (too short)"))?;
    if &magic != MAGIC {
        return Err(Error::verify(path, "not a relume shard (bad magic)"));
    }
    let len = u64::from_le_bytes(len);
    let size = f.metadata().at(path, "cannot read the shard")?.len();
    if len > size {
        return Err(Error::verify(
            path,
            "truncated: the header ends past the file",
        ));
    }
    let mut json = vec![0u8; len as usize];
    f.read_exact(&mut json)
        .map_err(|_| Error::verify(path, "truncated: the header ends past the file"))?;
    let header: ShardHeader = serde_json::from_slice(&json)
        .map_err(|e| Error::verify(path, format!("the shard's header is malformed: {e}")))?;
    let want = (24 + len + TRAILER).checked_add(header.payload_bytes);
    if want != Some(size) {
        let want = want.map_or("more than 2^64".into(), |w| w.to_string());
        return Err(Error::verify(
            path,
            format!(
                "truncated or padded: {size} bytes, the header says {want} (was the shard still being copied?)"
            ),
        ));
    }
    Ok(header)
}

/// Read a shard whole: header and payload, the file's SHA-256 checked.
pub fn read(path: &Path) -> Result<(ShardHeader, Payload)> {
    let header = read_header(path)?;
    let bytes = std::fs::read(path).at(path, "cannot read the shard")?;
    let body = checked_body(&bytes, path)?;
    let data = &body[body.len() - header.payload_bytes as usize..];
    let mut payload = Payload::default();
    let mut at = 0usize;
    for s in &header.sections {
        let width = match s.dtype.as_str() {
            "f32" | "u32" => 4,
            "f64" | "u64" => 8,
            other => {
                return Err(Error::verify(
                    path,
                    format!("unknown section type `{other}`"),
                ))
            }
        };
        let end = section_end(at, s.len, width, data.len())
            .ok_or_else(|| Error::verify(path, "the sections run past the payload"))?;
        let raw = &data[at..end];
        let name = s.name.clone();
        match s.dtype.as_str() {
            "f32" => {
                let v = raw
                    .chunks_exact(4)
                    .map(|c| f32::from_le_bytes(c.try_into().unwrap()));
                payload.f32s.insert(name, v.collect());
            }
            "u32" => {
                let v = raw
                    .chunks_exact(4)
                    .map(|c| u32::from_le_bytes(c.try_into().unwrap()));
                payload.u32s.insert(name, v.collect());
            }
            "f64" => {
                let v = raw
                    .chunks_exact(8)
                    .map(|c| f64::from_le_bytes(c.try_into().unwrap()));
                payload.f64s.insert(name, v.collect());
            }
            _ => {
                let v = raw
                    .chunks_exact(8)
                    .map(|c| u64::from_le_bytes(c.try_into().unwrap()));
                payload.u64s.insert(name, v.collect());
            }
        }
        at = end;
    }
    if at != data.len() {
        return Err(Error::verify(
            path,
            "the payload is longer than its sections",
        ));
    }
    Ok((header, payload))
}

/// A shard file memory-mapped, its payload verified: sections are copied out one at a time, so
/// that a reader of large arrays (the transport's LU factors) holds one of them at once.
pub struct Mapped {
    map: memmap2::Mmap,
    start: usize,
    pub header: ShardHeader,
    path: PathBuf,
}

impl Mapped {
    /// Map `path`, check its header and its payload's SHA-256.
    pub fn open(path: &Path) -> Result<Self> {
        let header = read_header(path)?;
        let file = std::fs::File::open(path).at(path, "cannot read the shard")?;
        // SAFETY: shard files are written once and renamed into place, never changed in place.
        let map = unsafe { memmap2::Mmap::map(&file) }.at(path, "cannot map the shard")?;
        let body_len = checked_body(&map, path)?.len();
        let start = body_len - header.payload_bytes as usize;
        Ok(Mapped {
            map,
            start,
            header,
            path: path.to_path_buf(),
        })
    }

    fn section(&self, name: &str, dtype: &str) -> Result<&[u8]> {
        let mut at = self.start;
        for s in &self.header.sections {
            let width = if s.dtype == "f64" || s.dtype == "u64" {
                8
            } else {
                4
            };
            let end = section_end(at, s.len, width, self.map.len() - TRAILER as usize)
                .ok_or_else(|| Error::verify(&self.path, "the sections run past the payload"))?;
            if s.name == name {
                if s.dtype != dtype {
                    return Err(Error::verify(
                        &self.path,
                        format!("section `{name}` is {}, not {dtype}", s.dtype),
                    ));
                }
                return Ok(&self.map[at..end]);
            }
            at = end;
        }
        Err(Error::verify(
            &self.path,
            format!("the shard has no section `{name}`"),
        ))
    }

    /// Does the shard have a section `name` of type `dtype`?
    pub fn has(&self, name: &str, dtype: &str) -> bool {
        self.header
            .sections
            .iter()
            .any(|s| s.name == name && s.dtype == dtype)
    }

    pub fn f32s(&self, name: &str) -> Result<Vec<f32>> {
        let b = self.section(name, "f32")?;
        Ok(b.chunks_exact(4)
            .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
            .collect())
    }
    pub fn f64s(&self, name: &str) -> Result<Vec<f64>> {
        let b = self.section(name, "f64")?;
        Ok(b.chunks_exact(8)
            .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
            .collect())
    }
    pub fn u32s(&self, name: &str) -> Result<Vec<u32>> {
        let b = self.section(name, "u32")?;
        Ok(b.chunks_exact(4)
            .map(|c| u32::from_le_bytes(c.try_into().unwrap()))
            .collect())
    }
    pub fn u64s(&self, name: &str) -> Result<Vec<u64>> {
        let b = self.section(name, "u64")?;
        Ok(b.chunks_exact(8)
            .map(|c| u64::from_le_bytes(c.try_into().unwrap()))
            .collect())
    }
    pub fn path(&self) -> &Path {
        &self.path
    }
}

/// Where a section of `len` elements of `width` bytes starting at `at` ends, if within `limit`
/// (a header may claim any length: no overflow, no slice past the end).
fn section_end(at: usize, len: u64, width: usize, limit: usize) -> Option<usize> {
    usize::try_from(len)
        .ok()
        .and_then(|l| l.checked_mul(width))
        .and_then(|b| b.checked_add(at))
        .filter(|&e| e <= limit)
}

/// Bytes of the SHA-256 that ends every shard file (of everything before it: magic, header,
/// payload).
const TRAILER: u64 = 32;

/// The file without its trailer, once the trailer is the SHA-256 of the rest (every header field
/// and every payload byte is covered).
fn checked_body<'a>(bytes: &'a [u8], path: &Path) -> Result<&'a [u8]> {
    let cut = bytes
        .len()
        .checked_sub(TRAILER as usize)
        .ok_or_else(|| Error::verify(path, "truncated: shorter than its checksum"))?;
    let (body, sum) = bytes.split_at(cut);
    if Sha256::digest(body).as_slice() != sum {
        return Err(Error::verify(
            path,
            "damaged: the file does not match its SHA-256",
        ));
    }
    Ok(body)
}
