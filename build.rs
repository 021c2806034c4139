//! Two build facts:
//! - intel_tex_2 ships prebuilt ISPC kernels compiled as C++; with Rust's default linker they need
//!   libstdc++ linked explicitly (see docs/dependencies.md).
//! - `RELUME_SOURCE_HASH`: a fingerprint of the sources this build was made from (`src/`,
//!   `shaders/`, `Cargo.toml`, `Cargo.lock`). The stage cache keys on it, so that a bake cached by
//!   one build is never reused by a different build with the same version number.

use std::hash::{Hash, Hasher};
use std::path::Path;

fn main() {
    let target = std::env::var("TARGET").unwrap_or_default();
    if target.contains("linux") {
        println!("cargo:rustc-link-lib=dylib=stdc++");
    }
    println!("cargo:rerun-if-changed=build.rs");
    let mut h = std::collections::hash_map::DefaultHasher::new();
    for root in ["src", "shaders", "Cargo.toml", "Cargo.lock"] {
        println!("cargo:rerun-if-changed={root}");
        hash_tree(Path::new(root), &mut h);
    }
    println!("cargo:rustc-env=RELUME_SOURCE_HASH={:016x}", h.finish());
}

/// Hash the names and contents of every file under `path`, in sorted order.
fn hash_tree(path: &Path, h: &mut impl Hasher) {
    if path.is_dir() {
        let mut entries: Vec<_> = std::fs::read_dir(path)
            .map(|rd| rd.flatten().map(|e| e.path()).collect())
            .unwrap_or_default();
        entries.sort();
        for e in entries {
            hash_tree(&e, h);
        }
    } else if let Ok(bytes) = std::fs::read(path) {
        path.to_string_lossy().hash(h);
        bytes.hash(h);
    }
}
