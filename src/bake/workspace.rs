//! The artifacts of a bake in memory, shared by the stages of one run, one typed slot per file
//! kind. Artifacts produced earlier in the same run are reused; artifacts of an existing bake
//! (when one stage runs alone on a baked directory) are read from disk on first use, through
//! the `crate::baked` module of their file.

use crate::baked::{self, form_factors::FormFactorMatrix, Manifest};
use crate::compress::EncodedTransport;
use crate::error::{Error, Result};
use crate::heightmap::HeightMap;
use crate::radiosity::{PatchSet, TransportMatrix};
use crate::scene::Scene;
use crate::terrain::MinMaxMipmap;
use std::path::{Path, PathBuf};

/// In-memory artifacts of a bake.
#[derive(Default)]
pub struct Workspace {
    source: Option<(PathBuf, Manifest)>,
    memory_budget: Option<u64>,
    scene: Option<Scene>,
    heightmap: Option<HeightMap>,
    patches: Option<PatchSet>,
    form_factors: Option<FormFactorMatrix>,
    transport: Option<TransportMatrix>,
    permutation: Option<Vec<u32>>,
    encoded: Option<EncodedTransport>,
    mipmap: Option<MinMaxMipmap>,
}

/// One typed slot: `get` reads it from the source bake on first use, `set` stores what a stage
/// made.
macro_rules! slot {
    ($get:ident, $set:ident, $field:ident, $ty:ty, $file:expr, $read:expr) => {
        #[doc = concat!("The `", stringify!($field), "` artifact (read from the source bake on first use).")]
        pub fn $get(&mut self) -> Result<&$ty> {
            if self.$field.is_none() {
                let dir = self.require_source($file)?;
                self.$field = Some($read(&dir, &self.source.as_ref().unwrap().1)?);
            }
            Ok(self.$field.as_ref().unwrap())
        }

        #[doc = concat!("Store the `", stringify!($field), "` artifact for later stages.")]
        pub fn $set(&mut self, value: $ty) {
            self.$field = Some(value);
        }
    };
}

impl Workspace {
    /// A workspace over a freshly loaded input.
    pub fn new() -> Self {
        Self::default()
    }

    /// A workspace that reads missing artifacts from an existing bake.
    pub fn over_bake(dir: &Path, manifest: Manifest) -> Self {
        Workspace {
            source: Some((dir.to_path_buf(), manifest)),
            ..Default::default()
        }
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

    slot!(
        scene,
        set_scene,
        scene,
        Scene,
        baked::scene::FILE,
        |d: &Path, _: &Manifest| baked::scene::read(d)
    );
    slot!(
        heightmap,
        set_heightmap,
        heightmap,
        HeightMap,
        baked::heightmap::FILE,
        baked::heightmap::read
    );
    slot!(
        patches,
        set_patches,
        patches,
        PatchSet,
        baked::patches::FILE,
        |d: &Path, _: &Manifest| baked::patches::read(d)
    );
    slot!(
        form_factors,
        set_form_factors,
        form_factors,
        FormFactorMatrix,
        baked::form_factors::FILE,
        |d: &Path, _: &Manifest| baked::form_factors::read(d)
    );
    slot!(
        transport,
        set_transport,
        transport,
        TransportMatrix,
        baked::transport::FILE,
        |d: &Path, _: &Manifest| baked::transport::read(d)
    );
    slot!(
        permutation,
        set_permutation,
        permutation,
        Vec<u32>,
        baked::permutation::FILE,
        |d: &Path, _: &Manifest| baked::permutation::read(d)
    );
    slot!(
        encoded,
        set_encoded,
        encoded,
        EncodedTransport,
        baked::encoded::TRANSFER_FILE,
        |d: &Path, _: &Manifest| baked::encoded::read(d)
    );
    slot!(
        mipmap,
        set_mipmap,
        mipmap,
        MinMaxMipmap,
        baked::mipmap::FILE,
        |d: &Path, _: &Manifest| baked::mipmap::read(d)
    );

    /// Is there a permutation, made earlier in this run or in the source bake?
    pub fn has_permutation(&self) -> bool {
        self.permutation.is_some() || self.source_has(baked::permutation::FILE)
    }

    fn source_has(&self, file: &str) -> bool {
        self.source
            .as_ref()
            .is_some_and(|(_, m)| m.file(file).is_some())
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
