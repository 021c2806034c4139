//! All-or-nothing writing of a baked directory: every file goes into a temporary sibling
//! directory; only when the manifest is written does the temporary directory replace the target
//! (one atomic exchange of the two directories on Linux, else two renames with the previous bake
//! kept until the swap succeeded). A failed or killed bake leaves the previous bake untouched;
//! the next bake into the same output removes what a killed one left (`clean_stale`).

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
        clean_stale(&parent, &name, target)?;
        let tmp = parent.join(format!(".{name}.relume-tmp-{}", std::process::id()));
        if tmp.exists() {
            std::fs::remove_dir_all(&tmp).at(&tmp, "cannot remove stale temporary directory")?;
        }
        std::fs::create_dir(&tmp).at(&tmp, "cannot create temporary directory")?;
        let lock = tmp.join(LOCK);
        std::fs::write(&lock, owner_tag(std::process::id())).at(&lock, "cannot write")?;
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
        let path = self.fresh_path(name)?;
        std::fs::write(&path, bytes).at(&path, "cannot write")?;
        self.record(name)
    }

    /// Let `f` write the file at the given staging path (for writers that take a path), then
    /// record its size and hash.
    pub fn write_with(&mut self, name: &str, f: impl FnOnce(&Path) -> Result<()>) -> Result<()> {
        let path = self.fresh_path(name)?;
        f(&path)?;
        self.record(name)
    }

    /// Take a file unchanged from an existing bake (hard link when possible, else copy).
    pub fn carry(&mut self, from_dir: &Path, rec: &FileRecord) -> Result<()> {
        let src = from_dir.join(&rec.name);
        let dst = self.fresh_path(&rec.name)?;
        if std::fs::hard_link(&src, &dst).is_err() {
            std::fs::copy(&src, &dst).at(&src, "cannot copy")?;
        }
        self.files.retain(|f| f.name != rec.name);
        self.files.push(rec.clone());
        Ok(())
    }

    /// The staging path of `name`, with any file already there unlinked first: a carried file is
    /// a hard link shared with a previous bake or the stage cache, and writing through it would
    /// change those too.
    fn fresh_path(&self, name: &str) -> Result<PathBuf> {
        let path = self.tmp.join(name);
        match std::fs::remove_file(&path) {
            Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
                Err(Error::io(&path, "cannot replace", e))
            }
            _ => Ok(path),
        }
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
        let lock = self.tmp.join(LOCK);
        std::fs::remove_file(&lock).at(&lock, "cannot remove")?;
        check_target(&self.target)?;
        if self.target.exists() {
            let old = self.tmp.with_file_name(
                self.tmp
                    .file_name()
                    .unwrap()
                    .to_string_lossy()
                    .replace("relume-tmp", "relume-old"),
            );
            if exchange(&self.tmp, &self.target) {
                // One atomic step: the target is the new bake, `tmp` holds the previous one.
                std::fs::rename(&self.tmp, &old)
                    .at(&self.tmp, "cannot move the previous bake aside")?;
            } else {
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

/// The lock file in a temporary bake directory: `PID START` of the process writing it (START:
/// the process's start time in clock ticks since boot, from `/proc/PID/stat`, so that a reused
/// PID is not taken for the writer).
pub const LOCK: &str = ".relume-lock";

/// `PID START` of a process (START empty where `/proc` is not there).
pub(crate) fn owner_tag(pid: u32) -> String {
    format!("{pid} {}", start_time(pid).unwrap_or_default())
}

/// Field 22 of `/proc/PID/stat` (after the parenthesised command name).
fn start_time(pid: u32) -> Option<String> {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).ok()?;
    let after = &stat[stat.rfind(')')? + 1..];
    after.split_whitespace().nth(19).map(str::to_string)
}

/// Is the process that wrote `tag` (`PID START`) still running?
fn owner_alive(tag: &str) -> bool {
    let mut w = tag.split_whitespace();
    let Some(pid) = w.next().and_then(|p| p.parse::<u32>().ok()) else {
        return false;
    };
    match (start_time(pid), w.next()) {
        (Some(now), Some(then)) => now == then,
        (Some(_), None) => true,
        // No /proc entry: the process is gone (or this is not Linux: ask the kernel).
        (None, _) if Path::new("/proc/self").exists() => false,
        // SAFETY: signal 0 only checks that the process exists.
        (None, _) => (unsafe { libc::kill(pid as libc::pid_t, 0) }) == 0,
    }
}

/// Was the temporary directory `dir`, named after process `pid`, left by a process that no longer
/// runs? Its `.relume-lock` names the writer (`PID START`); without one, the PID in the name does.
/// Never true for this process.
pub(crate) fn left_by_dead_process(dir: &Path, pid: u32) -> bool {
    // A lock still being written reads empty: then the name's PID answers (concurrent shard
    // processes beside one output start at the same moment; an empty tag once counted as dead
    // and a live process's directory was removed under it).
    let tag = std::fs::read_to_string(dir.join(LOCK))
        .ok()
        .filter(|t| !t.trim().is_empty())
        .unwrap_or_else(|| format!("{pid}"));
    pid != std::process::id() && !owner_alive(&tag)
}

/// Remove what killed bakes of `target` left beside it: `.NAME.relume-tmp-PID` directories of
/// processes that no longer run (never a live one's), and `.NAME.relume-old-PID` ones, which hold
/// the previous bake if a process died between the two renames of a commit: moved back when the
/// target is missing, else removed.
fn clean_stale(parent: &Path, name: &str, target: &Path) -> Result<()> {
    let Ok(entries) = std::fs::read_dir(parent) else {
        return Ok(());
    };
    let (tmp_prefix, old_prefix) = (
        format!(".{name}.relume-tmp-"),
        format!(".{name}.relume-old-"),
    );
    for e in entries.flatten() {
        let file = e.file_name().to_string_lossy().into_owned();
        let (is_old, pid) = if let Some(p) = file.strip_prefix(&tmp_prefix) {
            (false, p)
        } else if let Some(p) = file.strip_prefix(&old_prefix) {
            (true, p)
        } else {
            continue;
        };
        let Ok(pid) = pid.parse::<u32>() else {
            continue;
        };
        let path = e.path();
        if !left_by_dead_process(&path, pid) {
            continue;
        }
        if is_old && !target.exists() {
            std::fs::rename(&path, target).at(target, "cannot restore the previous bake")?;
        } else {
            std::fs::remove_dir_all(&path).at(&path, "cannot remove a killed bake's leftovers")?;
        }
    }
    Ok(())
}

/// Swap two directories atomically (Linux `renameat2(RENAME_EXCHANGE)`); false where the system
/// or the file system cannot, and the caller falls back to two renames.
fn exchange(a: &Path, b: &Path) -> bool {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    {
        use std::os::unix::ffi::OsStrExt;
        let (Ok(ca), Ok(cb)) = (
            std::ffi::CString::new(a.as_os_str().as_bytes()),
            std::ffi::CString::new(b.as_os_str().as_bytes()),
        ) else {
            return false;
        };
        // SAFETY: two valid NUL-terminated paths relative to the working directory.
        unsafe {
            libc::renameat2(
                libc::AT_FDCWD,
                ca.as_ptr(),
                libc::AT_FDCWD,
                cb.as_ptr(),
                libc::RENAME_EXCHANGE,
            ) == 0
        }
    }
    #[cfg(not(all(target_os = "linux", target_env = "gnu")))]
    {
        let _ = (a, b);
        false
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
