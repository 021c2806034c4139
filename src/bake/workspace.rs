//! The artifacts of a bake in memory, shared by the stages of one run, one typed slot per file
//! kind. Artifacts produced earlier in the same run are reused; artifacts of an existing bake
//! (when one stage runs alone on a baked directory) are read from disk on first use, through
//! the `crate::baked` module of their file.

use crate::baked::form_factors::MappedFormFactors;
use crate::baked::{self, form_factors::FormFactorMatrix, Manifest};
use crate::compress::EncodedTransport;
use crate::error::{Error, Result};
use crate::heightmap::georef::GeoReference;
use crate::heightmap::HeightMap;
use crate::radiosity::{PatchSet, TransportMatrix};
use crate::scene::Scene;
use crate::terrain::MinMaxMipmap;
use std::path::{Path, PathBuf};

/// The form factors, in memory or mapped from a file.
pub enum FormFactorView<'a> {
    Owned(&'a FormFactorMatrix),
    Mapped(MappedFormFactors),
}

impl FormFactorView<'_> {
    pub fn n(&self) -> usize {
        match self {
            FormFactorView::Owned(f) => f.n,
            FormFactorView::Mapped(m) => m.n,
        }
    }

    /// `[n, n]` row-major F.
    pub fn values(&self) -> &[f32] {
        match self {
            FormFactorView::Owned(f) => &f.values,
            FormFactorView::Mapped(m) => m.values(),
        }
    }
}

/// In-memory artifacts of a bake.
#[derive(Default)]
pub struct Workspace {
    /// Where artifacts not made in this run are read from: a baked directory with its manifest,
    /// or a bake's staging directory (stages linked from the stage cache) without one.
    source: Option<(PathBuf, Option<Manifest>)>,
    memory_budget: Option<u64>,
    scene: Option<Scene>,
    heightmap: Option<HeightMap>,
    /// The input height map's georeference: Some(None) when it has none, None when not known yet.
    georef: Option<Option<GeoReference>>,
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
    ($get:ident, $set:ident, $ty:ty) => {
        #[doc = concat!("The `", stringify!($get), "` artifact (`crate::baked::", stringify!($get), "`, read from the source bake on first use).")]
        pub fn $get(&mut self) -> Result<&$ty> {
            if self.$get.is_none() {
                let dir = self.require_source(baked::$get::FILE)?;
                self.$get = Some(baked::$get::read(&dir)?);
            }
            Ok(self.$get.as_ref().unwrap())
        }

        #[doc = concat!("Store the `", stringify!($get), "` artifact for later stages.")]
        pub fn $set(&mut self, value: $ty) {
            self.$get = Some(value);
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
            source: Some((dir.to_path_buf(), Some(manifest))),
            ..Default::default()
        }
    }

    /// Read artifacts this run has not made from the files in `dir` (a bake being written, into
    /// which cached stages were linked).
    pub fn read_missing_from(&mut self, dir: &Path) {
        self.source = Some((dir.to_path_buf(), None));
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

    slot!(scene, set_scene, Scene);
    slot!(patches, set_patches, PatchSet);
    slot!(form_factors, set_form_factors, FormFactorMatrix);
    slot!(transport, set_transport, TransportMatrix);
    slot!(permutation, set_permutation, Vec<u32>);
    slot!(encoded, set_encoded, EncodedTransport);
    slot!(mipmap, set_mipmap, MinMaxMipmap);

    /// The height map (read from the source bake on first use; its cell size and height scale
    /// come from the source's manifest).
    pub fn heightmap(&mut self) -> Result<&HeightMap> {
        if self.heightmap.is_none() {
            let dir = self.require_source(baked::heightmap::FILE)?;
            let Some(manifest) = &self.source.as_ref().unwrap().1 else {
                return Err(Error::Internal(
                    "height map requested before the load".into(),
                ));
            };
            self.heightmap = Some(baked::heightmap::read(&dir, manifest)?);
        }
        Ok(self.heightmap.as_ref().unwrap())
    }

    /// The form factors without copying them: borrowed when this run made or read them, else
    /// memory-mapped from the source bake's file (a transport shard reads F once to factor it).
    pub fn form_factors_mapped(&mut self) -> Result<FormFactorView<'_>> {
        if let Some(f) = &self.form_factors {
            return Ok(FormFactorView::Owned(f));
        }
        let dir = self.require_source(baked::form_factors::FILE)?;
        Ok(FormFactorView::Mapped(MappedFormFactors::open(
            &dir.join(baked::form_factors::FILE),
        )?))
    }

    /// The transport, to be changed in place and restored (the bounded reorder transposes it).
    pub fn transport_mut(&mut self) -> Result<&mut TransportMatrix> {
        self.transport()?;
        Ok(self.transport.as_mut().unwrap())
    }

    /// Store the height map for later stages.
    pub fn set_heightmap(&mut self, value: HeightMap) {
        self.heightmap = Some(value);
    }

    /// The input height map's georeference (None when it has none): as loaded in this run, else
    /// the source bake's `load` record (fact `georeference`, RON).
    pub fn georef(&mut self) -> Result<Option<&GeoReference>> {
        if self.georef.is_none() {
            let load = match &self.source {
                Some((_, Some(manifest))) => manifest.stage("load"),
                _ => None,
            };
            let fact = load.and_then(|r| r.facts.get(baked::heightmap::GEOREFERENCE_FACT));
            let georef = match fact {
                Some(text) => Some(ron::from_str(text).map_err(|e| {
                    let (dir, _) = self.source.as_ref().unwrap();
                    let why = format!("the `load` record's georeference does not parse: {e}");
                    Error::input(dir.join(baked::MANIFEST), why)
                })?),
                None => None,
            };
            self.georef = Some(georef);
        }
        Ok(self.georef.as_ref().unwrap().as_ref())
    }

    /// Store the input height map's georeference for later stages.
    pub fn set_georef(&mut self, value: Option<GeoReference>) {
        self.georef = Some(value);
    }

    /// The scene and its patches together (each read on first use), for stages that need both.
    pub fn scene_and_patches(&mut self) -> Result<(&Scene, &PatchSet)> {
        self.scene()?;
        self.patches()?;
        Ok((self.scene.as_ref().unwrap(), self.patches.as_ref().unwrap()))
    }

    /// Is there a permutation, made earlier in this run or in the source bake?
    pub fn has_permutation(&self) -> bool {
        self.permutation.is_some() || self.source_has(baked::permutation::FILE)
    }

    fn source_has(&self, file: &str) -> bool {
        self.source.as_ref().is_some_and(|(dir, m)| match m {
            Some(m) => m.file(file).is_some(),
            None => dir.join(file).is_file(),
        })
    }

    fn require_source(&self, file: &str) -> Result<PathBuf> {
        match &self.source {
            Some((dir, _)) if self.source_has(file) => Ok(dir.clone()),
            Some((dir, _)) => Err(Error::input(
                dir,
                format!("this bake has no `{file}`; run the stage that writes it first (see `relume-bake inspect`)"),
            )),
            None => Err(Error::Internal(format!("artifact {file} requested before any stage produced it"))),
        }
    }
}
