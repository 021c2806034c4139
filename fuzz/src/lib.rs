//! The fuzz targets' harnesses (see `targets.rs`), shared by the AFL binaries in `src/bin/`.
pub mod targets;
