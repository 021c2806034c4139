//! `patches.bin`: the patches of a scene bake (postcard [`PatchSet`]), written by `voxelize`.

use super::{read_postcard, to_postcard, BakeTransaction};
use crate::error::Result;
use crate::radiosity::PatchSet;
use std::path::Path;

/// File name of the patches.
pub const FILE: &str = "patches.bin";

/// Read `patches.bin` at `path`.
pub fn read_file(path: &Path) -> Result<PatchSet> {
    read_postcard(path)
}

/// Read the patches of the bake in `dir`.
pub fn read(dir: &Path) -> Result<PatchSet> {
    read_file(&dir.join(FILE))
}

/// Write the patches into a bake.
pub fn write(txn: &mut BakeTransaction, set: &PatchSet) -> Result<()> {
    txn.write(FILE, &to_postcard(set)?)
}
