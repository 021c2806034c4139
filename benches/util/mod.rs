//! Shared helpers of the benchmarks: CPU time and the bundled DEMs.
#![allow(dead_code)]

use relume::heightmap::HeightMap;

#[allow(unused_imports)]
pub use relume::study::timing::cpu_seconds;

/// The height map of a bundled pipeline (with its input knobs).
pub fn load(pipeline: &str) -> HeightMap {
    let root = env!("CARGO_MANIFEST_DIR");
    let p = relume::pipeline::parse_pipeline(std::path::Path::new(&format!(
        "{root}/pipelines/{pipeline}"
    )))
    .unwrap();
    match relume::load::load_input(&p.input).unwrap() {
        relume::load::LoadedInput::HeightMap(m, _) => m,
        _ => unreachable!(),
    }
}

/// An environment variable parsed, or a default.
pub fn env<T: std::str::FromStr>(name: &str, default: T) -> T {
    std::env::var(name)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

/// A comma-separated list from an environment variable, or a default list.
pub fn env_list<T: std::str::FromStr>(name: &str, default: &str) -> Vec<T> {
    env::<String>(name, default.into())
        .split(',')
        .filter_map(|s| s.trim().parse().ok())
        .collect()
}
