//! `scene.bin`: the loaded scene of a scene bake (postcard [`Scene`]).

use super::{read_postcard, to_postcard, BakeTransaction};
use crate::error::Result;
use crate::scene::Scene;
use std::path::Path;

/// File name of the scene record in a scene bake.
pub const FILE: &str = "scene.bin";

/// Read the scene of a scene bake.
pub fn read(dir: &Path) -> Result<Scene> {
    read_postcard(&dir.join(FILE))
}

/// Write the scene into a bake.
pub fn write(txn: &mut BakeTransaction, scene: &Scene) -> Result<()> {
    txn.write(FILE, &to_postcard(scene)?)
}
