//! The stage cache: what each finished stage of a bake wrote, kept so that a killed or changed bake
//! redoes only the stages whose inputs changed.
//!
//! A stage's **key** is the SHA-256 of relume's version and source fingerprint (`build.rs`: a
//! different build never reuses another's stages), the baked format version, the stage's
//! knobs (its RON) and the names and content hashes of every file the bake held before the stage
//! ran. Stages read nothing but those files (the workspace's artifacts are their decoded
//! contents) and are deterministic, so equal keys mean byte-identical outputs. The key of the
//! first stage covers the load's canonical output (`scene.bin`, `heightmap.exr`), so a changed
//! `.mtl`, texture or `.bin` buffer of a scene changes every key even when the scene file itself
//! did not change.
//!
//! An **entry** is a directory `SCOPE/KEY/` holding the files the stage wrote (hard links to the
//! bake's own files where the file system allows, so a cache beside its bake costs almost no
//! space) and `entry.ron` with the stage's record and the files' sizes and hashes. Entries are
//! written into `SCOPE/.tmp-PID-KEY/` and renamed into place, so a killed process leaves no entry
//! half written; a hit is verified (sizes and hashes) before it is used. The **scope** is one
//! output directory (`NAME-HASH` of its absolute path): after each commit the scope keeps only the
//! entries of the bake just made, so the cache never grows past one bake per output.

use crate::baked::manifest::{hash_file, sha256_hex};
use crate::baked::{self, BakeTransaction, FileRecord, StageRecord};
use crate::error::{Error, IoContext, Result};
use crate::heightmap::georef::GeoReference;
use crate::pipeline::Stage;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The cache of one output directory.
pub struct StageCache {
    scope: PathBuf,
}

/// What an entry stores besides its files.
#[derive(Debug, Serialize, Deserialize)]
struct Entry {
    stage: String,
    record: StageRecord,
    files: Vec<FileRecord>,
    removed: Vec<String>,
}

/// A verified entry, ready to be linked into a bake.
pub struct Hit {
    dir: PathBuf,
    entry: Entry,
}

const ENTRY: &str = "entry.ron";

impl StageCache {
    /// The cache under `root` for bakes into `output` (created on first store).
    pub fn open(root: &Path, output: &Path) -> Self {
        let abs = std::path::absolute(output).unwrap_or_else(|_| output.to_path_buf());
        let name = output
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_else(|| "bake".into());
        let tag = &sha256_hex(abs.to_string_lossy().as_bytes())[..12];
        StageCache {
            scope: root.join(format!("{name}-{tag}")),
        }
    }

    /// The directory of this output's entries.
    pub fn scope(&self) -> &Path {
        &self.scope
    }

    /// The key of `stage` run on a bake holding `files`, over an input with georeference
    /// `georef` (which places a `Themes` stage's georeferenced polygons).
    pub fn key(stage: &Stage, files: &[FileRecord], georef: Option<&GeoReference>) -> String {
        let mut text = format!(
            "relume {} source {} format {}\n{}\n",
            env!("CARGO_PKG_VERSION"),
            env!("RELUME_SOURCE_HASH"),
            baked::FORMAT_VERSION,
            ron::to_string(stage).expect("stage knobs serialise")
        );
        // A stage that reads files of its own keys on their contents too.
        if let Stage::Themes(k) = stage {
            for f in crate::load::themes::theme_files(&k.file) {
                let digest =
                    hash_file(&f).map_or_else(|_| "unreadable".into(), |(n, h)| format!("{n} {h}"));
                text += &format!("reads {} {digest}\n", f.display());
            }
            if let Some(g) = georef {
                text += &format!("georeference {}\n", ron::to_string(g).expect("serialises"));
            }
        }
        let mut sorted: Vec<&FileRecord> = files.iter().collect();
        sorted.sort_by(|a, b| a.name.cmp(&b.name));
        for f in sorted {
            text += &format!("{} {} {}\n", f.name, f.bytes, f.sha256);
        }
        sha256_hex(text.as_bytes())
    }

    /// The entry for `key`, if there is one whose files still match their hashes (a damaged entry
    /// is removed and counts as a miss).
    pub fn lookup(&self, key: &str) -> Option<Hit> {
        let dir = self.scope.join(key);
        let text = std::fs::read_to_string(dir.join(ENTRY)).ok()?;
        let intact = ron::from_str::<Entry>(&text).ok().filter(|e| {
            e.files.iter().all(|f| {
                hash_file(&dir.join(&f.name))
                    .is_ok_and(|(bytes, sha)| bytes == f.bytes && sha == f.sha256)
            })
        });
        match intact {
            Some(entry) => Some(Hit { dir, entry }),
            None => {
                let _ = std::fs::remove_dir_all(&dir);
                None
            }
        }
    }

    /// Keep what `stage` wrote into `txn` (the files that differ from `before`) under `key`. A
    /// cache that cannot be written costs only the reuse: the error is returned for a warning,
    /// never fails the bake.
    pub fn store(
        &self,
        key: &str,
        stage: &Stage,
        record: &StageRecord,
        before: &[FileRecord],
        txn: &BakeTransaction,
    ) -> Result<()> {
        let after = txn.files();
        let files: Vec<FileRecord> = after
            .iter()
            .filter(|f| !before.contains(f))
            .cloned()
            .collect();
        let removed = before
            .iter()
            .filter(|b| !after.iter().any(|a| a.name == b.name))
            .map(|b| b.name.clone())
            .collect();
        let entry = Entry {
            stage: stage.kind().name().to_string(),
            record: record.clone(),
            files,
            removed,
        };
        std::fs::create_dir_all(&self.scope).at(&self.scope, "cannot create the stage cache")?;
        clean_dead_temporaries(&self.scope);
        let tmp = self
            .scope
            .join(format!(".tmp-{}-{key}", std::process::id()));
        let _ = std::fs::remove_dir_all(&tmp);
        std::fs::create_dir(&tmp).at(&tmp, "cannot create")?;
        let lock = tmp.join(baked::transaction::LOCK);
        std::fs::write(&lock, baked::transaction::owner_tag(std::process::id()))
            .at(&lock, "cannot write")?;
        let result = (|| {
            for f in &entry.files {
                link_or_copy(&txn.staging_dir().join(&f.name), &tmp.join(&f.name))?;
            }
            let path = tmp.join(ENTRY);
            let text = ron::ser::to_string_pretty(&entry, Default::default())
                .map_err(|e| Error::Internal(format!("cache entry: {e}")))?;
            std::fs::write(&path, text).at(&path, "cannot write")?;
            std::fs::remove_file(&lock).at(&lock, "cannot remove")?;
            let dst = self.scope.join(key);
            if std::fs::rename(&tmp, &dst).is_err() && !dst.join(ENTRY).is_file() {
                return Err(Error::Internal(format!(
                    "cannot move the cache entry into {}",
                    dst.display()
                )));
            }
            Ok(())
        })();
        let _ = std::fs::remove_dir_all(&tmp);
        result
    }

    /// Remove every entry of this output whose key is not in `keep` (after a commit: the cache
    /// then holds exactly the stages of the bake just made).
    pub fn retain(&self, keep: &[String]) {
        let Ok(entries) = std::fs::read_dir(&self.scope) else {
            return;
        };
        for e in entries.flatten() {
            let name = e.file_name().to_string_lossy().into_owned();
            if !name.starts_with('.') && !keep.contains(&name) {
                let _ = std::fs::remove_dir_all(e.path());
            }
        }
        clean_dead_temporaries(&self.scope);
    }
}

impl Hit {
    /// Link the entry's files into `txn` (and drop what the stage removed); the stage's record.
    pub fn apply(&self, txn: &mut BakeTransaction) -> Result<StageRecord> {
        for name in &self.entry.removed {
            txn.remove(name)?;
        }
        for f in &self.entry.files {
            txn.carry(&self.dir, f)?;
        }
        Ok(self.entry.record.clone())
    }
}

/// Hard link `src` to `dst`, or copy where the two are on different file systems.
fn link_or_copy(src: &Path, dst: &Path) -> Result<()> {
    if std::fs::hard_link(src, dst).is_err() {
        std::fs::copy(src, dst).at(src, "cannot copy into the stage cache")?;
    }
    Ok(())
}

/// Remove `.tmp-PID-KEY` directories of processes that no longer run.
fn clean_dead_temporaries(scope: &Path) {
    let Ok(entries) = std::fs::read_dir(scope) else {
        return;
    };
    for e in entries.flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        let Some(rest) = name.strip_prefix(".tmp-") else {
            continue;
        };
        let Some(pid) = rest.split('-').next().and_then(|p| p.parse::<u32>().ok()) else {
            continue;
        };
        if baked::transaction::left_by_dead_process(&e.path(), pid) {
            let _ = std::fs::remove_dir_all(e.path());
        }
    }
}
