//! The artifacts of a bake in memory, shared by the stages of one run. Artifacts produced earlier
//! in the same run are reused; artifacts of an existing bake (when one stage runs alone on a baked
//! directory) are read from disk on first use.

use crate::error::{Error, Result};
use crate::heightmap::HeightMap;
use crate::scene::Scene;
use std::any::Any;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// In-memory artifacts keyed by the name of the file that stores them.
#[derive(Default)]
pub struct Workspace {
    source: Option<(PathBuf, crate::baked::Manifest)>,
    scene: Option<Scene>,
    heightmap: Option<HeightMap>,
    artifacts: HashMap<String, Box<dyn Any + Send + Sync>>,
    memory_budget: Option<u64>,
}

impl Workspace {
    /// A workspace over a freshly loaded input.
    pub fn new() -> Self {
        Self::default()
    }

    /// A workspace that reads missing artifacts from an existing bake.
    pub fn over_bake(dir: &Path, manifest: crate::baked::Manifest) -> Self {
        Workspace {
            source: Some((dir.to_path_buf(), manifest)),
            ..Default::default()
        }
    }

    /// The existing bake this workspace reads from, if any.
    pub fn source_dir(&self) -> Option<&Path> {
        self.source.as_ref().map(|(d, _)| d.as_path())
    }

    /// Set the memory budget stages check their allocations against (`--max-memory`).
    pub fn set_memory_budget(&mut self, bytes: u64) {
        self.memory_budget = Some(bytes);
    }

    /// The memory budget in bytes (default: 75 % of physical memory).
    pub fn memory_budget(&self) -> u64 {
        self.memory_budget
            .unwrap_or_else(crate::limits::default_max_memory)
    }

    pub fn set_scene(&mut self, scene: Scene) {
        self.scene = Some(scene);
    }

    pub fn set_heightmap(&mut self, map: HeightMap) {
        self.heightmap = Some(map);
    }

    /// The scene (loaded from `scene.bin` of the source bake on first use).
    pub fn scene(&mut self) -> Result<&Scene> {
        if self.scene.is_none() {
            let dir = self.require_source(crate::baked::SCENE_FILE)?;
            self.scene = Some(crate::baked::read_scene(&dir)?);
        }
        Ok(self.scene.as_ref().unwrap())
    }

    /// The height map (loaded from `heightmap.exr` of the source bake on first use).
    pub fn heightmap(&mut self) -> Result<&HeightMap> {
        if self.heightmap.is_none() {
            let dir = self.require_source(crate::baked::HEIGHTMAP_FILE)?;
            let manifest = &self.source.as_ref().unwrap().1;
            self.heightmap = Some(crate::baked::read_heightmap(&dir, manifest)?);
        }
        Ok(self.heightmap.as_ref().unwrap())
    }

    /// Is there an artifact under `file`, made earlier in this run or in the source bake?
    pub fn has(&self, file: &str) -> bool {
        self.artifacts.contains_key(file)
            || self
                .source
                .as_ref()
                .is_some_and(|(_, m)| m.file(file).is_some())
    }

    /// Store an artifact under the file name it is written to.
    pub fn put<T: Any + Send + Sync>(&mut self, file: &str, value: T) {
        self.artifacts.insert(file.to_string(), Box::new(value));
    }

    /// The artifact stored under `file`, or read it from the source bake with `read` (which gets
    /// the file's path) on first use.
    pub fn get<T: Any + Send + Sync>(
        &mut self,
        file: &str,
        read: impl FnOnce(&Path) -> Result<T>,
    ) -> Result<&T> {
        if !self.artifacts.contains_key(file) {
            let dir = self.require_source(file)?;
            let value = read(&dir.join(file))?;
            self.artifacts.insert(file.to_string(), Box::new(value));
        }
        self.artifacts[file]
            .downcast_ref::<T>()
            .ok_or_else(|| Error::Internal(format!("artifact {file} has an unexpected type")))
    }

    fn require_source(&self, file: &str) -> Result<PathBuf> {
        match &self.source {
            Some((dir, manifest)) if manifest.file(file).is_some() => Ok(dir.clone()),
            Some((dir, _)) => Err(Error::input(
                dir,
                format!("this bake has no `{file}`; run the stage that writes it first (see `relume-bake inspect`)"),
            )),
            None => Err(Error::Internal(format!("artifact {file} requested before any stage produced it"))),
        }
    }
}
