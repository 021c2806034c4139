//! Time measurement for the studies and the benches. On a shared machine times are noisy:
//! compare ratios measured in the same run, and prefer CPU time ([`cpu_seconds`]) for long
//! parallel loops.

use std::time::Instant;

/// Run `f` once; (its result, wall seconds).
pub fn timed<T>(f: impl FnOnce() -> T) -> (T, f64) {
    let t = Instant::now();
    let v = f();
    (v, t.elapsed().as_secs_f64())
}

/// Median wall seconds of `runs` runs of `f` (at least one).
pub fn median_secs(runs: usize, mut f: impl FnMut()) -> f64 {
    let mut t: Vec<f64> = (0..runs.max(1))
        .map(|_| {
            let t0 = Instant::now();
            f();
            t0.elapsed().as_secs_f64()
        })
        .collect();
    t.sort_by(f64::total_cmp);
    t[t.len() / 2]
}

/// CPU seconds (user + system) of this process so far, from /proc/self/stat (Linux; 0
/// elsewhere). On a shared machine CPU time is a steadier measure than wall time.
pub fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let after = stat.rsplit_once(')').map(|(_, a)| a).unwrap_or("");
    let f: Vec<f64> = after
        .split_whitespace()
        .filter_map(|x| x.parse().ok())
        .collect();
    // Fields after the command name start at field 3 (state, a letter, is skipped by the
    // parse): utime and stime are fields 14 and 15, in clock ticks of 1/100 s.
    if f.len() > 12 {
        (f[10] + f[11]) / 100.0
    } else {
        0.0
    }
}

/// Run `f` once; (its result, wall seconds, CPU seconds of the whole process meanwhile).
pub fn timed_cpu<T>(f: impl FnOnce() -> T) -> (T, f64, f64) {
    let c = cpu_seconds();
    let (v, wall) = timed(f);
    (v, wall, cpu_seconds() - c)
}
