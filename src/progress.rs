//! Progress reporting without I/O in the library: stages call a [`Progress`] sink; the binaries
//! implement it with indicatif bars (or plain lines, or nothing with `--quiet`).

use std::sync::atomic::{AtomicU64, Ordering};

/// Receives progress from long-running work. Implementations must be cheap and thread-safe:
/// `advance` is called from rayon workers.
pub trait Progress: Sync {
    /// A new phase begins with `total` units of work (0 = unknown).
    fn begin(&self, phase: &str, total: u64);
    /// `n` more units are done.
    fn advance(&self, n: u64);
    /// The current phase is finished.
    fn finish(&self);
    /// A warning worth showing to the user (not an error).
    fn warn(&self, message: &str);
}

/// Discards everything (tests, `--quiet` without warnings).
pub struct Silent;

impl Progress for Silent {
    fn begin(&self, _: &str, _: u64) {}
    fn advance(&self, _: u64) {}
    fn finish(&self) {}
    fn warn(&self, _: &str) {}
}

/// Counts units and collects warnings; useful in tests.
#[derive(Default)]
pub struct Counting {
    pub units: AtomicU64,
    pub warnings: std::sync::Mutex<Vec<String>>,
}

impl Progress for Counting {
    fn begin(&self, _: &str, _: u64) {}
    fn advance(&self, n: u64) {
        self.units.fetch_add(n, Ordering::Relaxed);
    }
    fn finish(&self) {}
    fn warn(&self, message: &str) {
        self.warnings.lock().unwrap().push(message.to_string());
    }
}
