//! Integration tests: the real binaries as a user runs them: bakes, bad inputs, kills and resumes,
//! shards, determinism.
//!
//! One test binary per concept (each links the whole library once); one module per file.

#[path = "../common/mod.rs"]
mod common;
#[path = "../support/fixtures.rs"]
mod fixtures;

mod bad_inputs;
mod cli_foundation;
mod cli_radiosity;
mod compress_cli;
mod crytek_sponza;
mod determinism;
mod docs_images;
mod fuzz_corpus;
mod k8s;
mod killed_bakes;
mod memory_plan;
mod resume;
mod shard;
mod sponza;
mod study_cli;
mod study_objects_cli;
mod themes_cli;
mod themes_geo_cli;
