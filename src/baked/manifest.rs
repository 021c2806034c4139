//! `manifest.ron`: the self-description of a baked directory (docs/baked-format.md).

use crate::error::{Error, IoContext, Result};
use crate::pipeline::Pipeline;
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use std::collections::BTreeMap;
use std::io::Read;
use std::path::Path;

/// Version of the baked-directory format. Readers refuse other versions.
pub const FORMAT_VERSION: u32 = 2;

/// The manifest's file name inside a baked directory.
pub const MANIFEST: &str = "manifest.ron";

/// Everything a reader needs to trust and interpret a baked directory.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Manifest {
    /// [`FORMAT_VERSION`] of the writer.
    pub format_version: u32,
    /// Version of the relume that wrote the bake.
    pub relume_version: String,
    /// The resolved pipeline that made this bake (input path resolved, all knobs explicit).
    pub pipeline: Pipeline,
    /// The input file's name, size and content hash.
    pub input: FileRecord,
    /// What each stage wrote and measured, in order (the first is always `load`).
    pub stages: Vec<StageRecord>,
    /// Every file of the bake except the manifest itself.
    pub files: Vec<FileRecord>,
}

/// A file with its size and SHA-256.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FileRecord {
    /// Name relative to the baked directory (or the input's file name).
    pub name: String,
    pub bytes: u64,
    /// Lower-case hex SHA-256 of the content.
    pub sha256: String,
}

/// What one stage wrote and the numbers it measured.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StageRecord {
    /// Stage name (`load`, `voxelize`, ...).
    pub stage: String,
    /// Files this stage wrote.
    pub outputs: Vec<String>,
    /// Named measurements (counts, errors, bytes). Deterministic: never times.
    #[serde(default)]
    pub report: BTreeMap<String, f64>,
    /// Named text facts (formats, units, conventions).
    #[serde(default)]
    pub facts: BTreeMap<String, String>,
}

impl Manifest {
    /// Serialise as pretty RON.
    pub fn to_ron(&self) -> String {
        let cfg = ron::ser::PrettyConfig::new()
            .depth_limit(6)
            .struct_names(true)
            .extensions(
                ron::extensions::Extensions::UNWRAP_VARIANT_NEWTYPES
                    | ron::extensions::Extensions::IMPLICIT_SOME,
            );
        ron::ser::to_string_pretty(self, cfg).expect("manifest serialises")
    }

    /// Parse a manifest; `path` names the file in errors.
    pub fn from_ron(path: &Path, text: &str) -> Result<Self> {
        let options = ron::Options::default().with_default_extension(
            ron::extensions::Extensions::IMPLICIT_SOME
                | ron::extensions::Extensions::UNWRAP_VARIANT_NEWTYPES,
        );
        let m: Manifest = options.from_str(text).map_err(|e| Error::Located {
            path: path.to_path_buf(),
            line: e.span.start.line,
            col: e.span.start.col,
            message: format!("invalid manifest: {}", e.code),
            unsupported: false,
        })?;
        if m.format_version != FORMAT_VERSION {
            return Err(Error::unsupported(
                path,
                format!("baked format version {} (this relume reads version {FORMAT_VERSION}); re-bake with this version", m.format_version),
            ));
        }
        Ok(m)
    }

    /// Read `DIR/manifest.ron`.
    pub fn read(dir: &Path) -> Result<Self> {
        let path = dir.join(MANIFEST);
        if !dir.is_dir() {
            return Err(Error::input(
                dir,
                "not a directory; expected a baked directory",
            ));
        }
        let text = std::fs::read_to_string(&path)
            .at(&path, "cannot read manifest (is this a baked directory?)")?;
        Self::from_ron(&path, &text)
    }

    /// The record of a file by name.
    pub fn file(&self, name: &str) -> Option<&FileRecord> {
        self.files.iter().find(|f| f.name == name)
    }

    /// The record of a stage by name.
    pub fn stage(&self, name: &str) -> Option<&StageRecord> {
        self.stages.iter().find(|s| s.stage == name)
    }
}

/// SHA-256 of a byte slice, as lower-case hex.
pub fn sha256_hex(bytes: &[u8]) -> String {
    hex(&Sha256::digest(bytes))
}

/// Size and SHA-256 of a file, streamed.
pub fn hash_file(path: &Path) -> Result<(u64, String)> {
    let mut f = std::fs::File::open(path).at(path, "cannot read")?;
    let mut h = Sha256::new();
    let mut buf = vec![0u8; 1 << 20];
    let mut total = 0u64;
    loop {
        let n = f.read(&mut buf).at(path, "cannot read")?;
        if n == 0 {
            break;
        }
        total += n as u64;
        h.update(&buf[..n]);
    }
    Ok((total, hex(&h.finalize())))
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

/// One problem found by [`verify`].
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct VerifyProblem {
    pub file: String,
    pub problem: String,
}

/// Check every file the manifest lists: present, the recorded size, the recorded hash.
/// Returns the list of problems (empty when the bake is intact).
pub fn verify(dir: &Path, manifest: &Manifest) -> Vec<VerifyProblem> {
    verify_files(dir, &manifest.files)
}

/// [`verify`] for some of a manifest's files.
pub fn verify_files<'a>(
    dir: &Path,
    files: impl IntoIterator<Item = &'a FileRecord>,
) -> Vec<VerifyProblem> {
    let mut problems = Vec::new();
    for rec in files {
        let path = dir.join(&rec.name);
        let problem = match std::fs::metadata(&path) {
            Err(_) => Some("missing".to_string()),
            Ok(m) if m.len() != rec.bytes => Some(format!(
                "size {} bytes, manifest says {} (truncated or replaced)",
                m.len(),
                rec.bytes
            )),
            Ok(_) => match hash_file(&path) {
                Err(e) => Some(e.to_string()),
                Ok((_, h)) if h != rec.sha256 => {
                    Some("content hash differs from the manifest (altered)".to_string())
                }
                Ok(_) => None,
            },
        };
        if let Some(problem) = problem {
            problems.push(VerifyProblem {
                file: rec.name.clone(),
                problem,
            });
        }
    }
    problems
}

/// A baked directory read and verified (`relume-bake inspect`).
#[derive(Clone, Debug, Serialize)]
pub struct Inspection {
    pub dir: String,
    pub ok: bool,
    pub manifest: Manifest,
    pub problems: Vec<VerifyProblem>,
}

impl Inspection {
    /// Read the manifest of `dir` and verify every file it lists.
    pub fn of(dir: &Path) -> Result<Inspection> {
        let manifest = Manifest::read(dir)?;
        let problems = verify(dir, &manifest);
        Ok(Inspection {
            dir: dir.display().to_string(),
            ok: problems.is_empty(),
            manifest,
            problems,
        })
    }

    /// The first problem as an error (exit code 7), or `Ok` when the bake is intact.
    pub fn result(&self) -> Result<()> {
        match self.problems.first() {
            None => Ok(()),
            Some(first) => Err(crate::error::Error::verify(
                Path::new(&self.dir).join(&first.file),
                format!(
                    "{} ({} problem(s) in this bake)",
                    first.problem,
                    self.problems.len()
                ),
            )),
        }
    }

    /// The manifest and the state of every file, for people.
    pub fn to_text(&self) -> String {
        let m = &self.manifest;
        let mut t = format!(
            "baked dir  {}\nformat     v{} (relume {})\ninput      {} ({} bytes, sha256 {})\n",
            self.dir,
            m.format_version,
            m.relume_version,
            m.input.name,
            m.input.bytes,
            &m.input.sha256[..16.min(m.input.sha256.len())]
        );
        for s in &m.stages {
            t += &format!("stage      {}  → {}\n", s.stage, s.outputs.join(", "));
            for (k, v) in &s.report {
                t += &format!("  {k:<28} {v}\n");
            }
            for (k, v) in &s.facts {
                t += &format!("  {k:<28} {v}\n");
            }
        }
        for f in &m.files {
            let status = self
                .problems
                .iter()
                .find(|p| p.file == f.name)
                .map(|p| p.problem.as_str())
                .unwrap_or("ok");
            t += &format!(
                "file       {:<28} {:>12} bytes  {}\n",
                f.name, f.bytes, status
            );
        }
        t
    }
}
