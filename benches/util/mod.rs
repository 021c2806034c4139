//! Shared helpers of the benchmarks: CPU time and the bundled DEMs.
#![allow(dead_code)]

use relume::heightmap::HeightMap;

/// CPU seconds (user + system) of this process so far, from /proc/self/stat (Linux; 0
/// elsewhere). On a shared machine CPU time is a steadier measure than wall time.
pub fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let after = stat.rsplit_once(')').map(|(_, a)| a).unwrap_or("");
    let f: Vec<f64> = after
        .split_whitespace()
        .filter_map(|x| x.parse().ok())
        .collect();
    // After the command name the fields start at field 3 (state, a letter, is dropped by the
    // parse): utime and stime are fields 14 and 15, in clock ticks of 1/100 s.
    if f.len() > 12 {
        (f[10] + f[11]) / 100.0
    } else {
        0.0
    }
}

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
