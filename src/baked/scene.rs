//! `scene.bin`: the loaded scene of a scene bake (postcard [`Scene`]).

use super::{read_postcard, to_postcard, BakeTransaction};
use crate::error::Result;
use crate::scene::{Scene, Viewpoint};
use std::path::Path;

/// File name of the scene record in a scene bake.
pub const FILE: &str = "scene.bin";

/// Read the scene of a scene bake.
pub fn read(dir: &Path) -> Result<Scene> {
    read_postcard(&dir.join(FILE))
}

/// File name of the source file's cameras, written only when it has any.
pub const VIEWS_FILE: &str = "views.json";

/// Write the scene into a bake (and its cameras, when it has any, into `views.json`).
pub fn write(txn: &mut BakeTransaction, scene: &Scene) -> Result<()> {
    txn.write(FILE, &to_postcard(scene)?)?;
    if !scene.viewpoints.is_empty() {
        let json = serde_json::to_vec_pretty(&scene.viewpoints)
            .map_err(|e| crate::error::Error::Internal(format!("views serialise: {e}")))?;
        txn.write(VIEWS_FILE, &json)?;
    }
    Ok(())
}

/// The source file's cameras of a scene bake (none when it has no `views.json`).
pub fn read_views(dir: &Path) -> Result<Vec<Viewpoint>> {
    let path = dir.join(VIEWS_FILE);
    if !path.is_file() {
        return Ok(Vec::new());
    }
    let bytes =
        std::fs::read(&path).map_err(|e| crate::error::Error::io(&path, "cannot read", e))?;
    serde_json::from_slice(&bytes)
        .map_err(|e| crate::error::Error::input(&path, format!("malformed camera list: {e}")))
}
