//! All-or-nothing writing of a baked directory: every file goes into a temporary sibling
//! directory; only when the manifest is written does the temporary directory replace the target
//! (rename, with the previous bake kept until the swap succeeded). A failed or interrupted bake
//! leaves the previous bake untouched and no partial output.

use super::manifest::{hash_file, FileRecord, Manifest, MANIFEST};
use crate::error::{Error, IoContext, Result};
use std::path::{Path, PathBuf};

/// A baked directory being written.
pub struct BakeTransaction {
    target: PathBuf,
    tmp: PathBuf,
    files: Vec<FileRecord>,
    committed: bool,
}

impl BakeTransaction {
    /// Start writing a bake that will replace `target` when committed.
    ///
    /// Refuses a `target` that is a file, or a non-empty directory that is not a baked directory
    /// (relume never deletes what it did not write).
    pub fn begin(target: &Path) -> Result<Self> {
        check_target(target)?;
        let parent = match target.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        std::fs::create_dir_all(&parent).at(&parent, "cannot create output directory")?;
        let name = target
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_else(|| "bake".into());
        let tmp = parent.join(format!(".{name}.relume-tmp-{}", std::process::id()));
        if tmp.exists() {
            std::fs::remove_dir_all(&tmp).at(&tmp, "cannot remove stale temporary directory")?;
        }
        std::fs::create_dir(&tmp).at(&tmp, "cannot create temporary directory")?;
        Ok(BakeTransaction {
            target: target.to_path_buf(),
            tmp,
            files: Vec::new(),
            committed: false,
        })
    }

    /// The directory files are written into before the commit.
    pub fn staging_dir(&self) -> &Path {
        &self.tmp
    }

    /// Write a whole file from bytes.
    pub fn write(&mut self, name: &str, bytes: &[u8]) -> Result<()> {
        let path = self.tmp.join(name);
        std::fs::write(&path, bytes).at(&path, "cannot write")?;
        self.record(name)
    }

    /// Let `f` write the file at the given staging path (for writers that take a path), then
    /// record its size and hash.
    pub fn write_with(&mut self, name: &str, f: impl FnOnce(&Path) -> Result<()>) -> Result<()> {
        let path = self.tmp.join(name);
        f(&path)?;
        self.record(name)
    }

    /// Take a file unchanged from an existing bake (hard link when possible, else copy).
    pub fn carry(&mut self, from_dir: &Path, rec: &FileRecord) -> Result<()> {
        let src = from_dir.join(&rec.name);
        let dst = self.tmp.join(&rec.name);
        if std::fs::hard_link(&src, &dst).is_err() {
            std::fs::copy(&src, &dst).at(&src, "cannot copy")?;
        }
        self.files.push(rec.clone());
        Ok(())
    }

    /// Forget a file written earlier in this transaction (a later stage replaced it).
    pub fn remove(&mut self, name: &str) -> Result<()> {
        if let Some(i) = self.files.iter().position(|f| f.name == name) {
            self.files.remove(i);
            let p = self.tmp.join(name);
            std::fs::remove_file(&p).at(&p, "cannot remove")?;
        }
        Ok(())
    }

    fn record(&mut self, name: &str) -> Result<()> {
        let (bytes, sha256) = hash_file(&self.tmp.join(name))?;
        self.files.retain(|f| f.name != name);
        self.files.push(FileRecord {
            name: name.to_string(),
            bytes,
            sha256,
        });
        Ok(())
    }

    /// Records of the files written so far, sorted by name.
    pub fn files(&self) -> Vec<FileRecord> {
        let mut f = self.files.clone();
        f.sort_by(|a, b| a.name.cmp(&b.name));
        f
    }

    /// Write the manifest (its `files` replaced by what was written) and atomically replace the
    /// target directory.
    pub fn commit(mut self, mut manifest: Manifest) -> Result<()> {
        manifest.files = self.files();
        let mpath = self.tmp.join(MANIFEST);
        std::fs::write(&mpath, manifest.to_ron()).at(&mpath, "cannot write")?;
        check_target(&self.target)?;
        if self.target.exists() {
            let old = self.tmp.with_file_name(
                self.tmp
                    .file_name()
                    .unwrap()
                    .to_string_lossy()
                    .replace("relume-tmp", "relume-old"),
            );
            std::fs::rename(&self.target, &old)
                .at(&self.target, "cannot move the previous bake aside")?;
            if let Err(e) = std::fs::rename(&self.tmp, &self.target) {
                let _ = std::fs::rename(&old, &self.target);
                return Err(Error::io(
                    &self.target,
                    "cannot move the new bake into place",
                    e,
                ));
            }
            let _ = std::fs::remove_dir_all(&old);
        } else {
            std::fs::rename(&self.tmp, &self.target)
                .at(&self.target, "cannot move the new bake into place")?;
        }
        self.committed = true;
        Ok(())
    }
}

impl Drop for BakeTransaction {
    fn drop(&mut self) {
        if !self.committed {
            let _ = std::fs::remove_dir_all(&self.tmp);
        }
    }
}

/// The output may be absent, an empty directory, or a previous bake; anything else is refused.
fn check_target(target: &Path) -> Result<()> {
    match std::fs::symlink_metadata(target) {
        Err(_) => Ok(()),
        Ok(m) if m.is_dir() => {
            let empty = std::fs::read_dir(target)
                .at(target, "cannot list")?
                .next()
                .is_none();
            if empty || target.join(MANIFEST).is_file() {
                Ok(())
            } else {
                Err(Error::io(
                    target,
                    "refusing to replace a directory that is not a relume bake (no manifest.ron)",
                    std::io::Error::new(std::io::ErrorKind::AlreadyExists, "choose another --out"),
                ))
            }
        }
        Ok(_) => Err(Error::io(
            target,
            "cannot write the bake here",
            std::io::Error::new(
                std::io::ErrorKind::AlreadyExists,
                "the output path exists and is a file, not a directory",
            ),
        )),
    }
}
