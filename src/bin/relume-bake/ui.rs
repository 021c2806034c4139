//! Terminal output: progress bars on a terminal, plain lines otherwise, nothing with `--quiet`;
//! errors with their whole cause chain.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use relume::progress::Progress;
use std::io::IsTerminal;
use std::sync::Mutex;
use std::time::Instant;

/// Progress on stderr: indicatif bars on a terminal, one line per phase when piped.
pub struct Ui {
    quiet: bool,
    fancy: bool,
    state: Mutex<Option<(String, Instant, Option<ProgressBar>)>>,
}

impl Ui {
    pub fn new(quiet: bool) -> Self {
        Ui {
            quiet,
            fancy: std::io::stderr().is_terminal(),
            state: Mutex::new(None),
        }
    }
}

impl Progress for Ui {
    fn begin(&self, phase: &str, total: u64) {
        if self.quiet {
            return;
        }
        let bar = if self.fancy {
            let bar = if total > 0 {
                ProgressBar::new(total)
            } else {
                ProgressBar::new_spinner()
            };
            bar.set_draw_target(ProgressDrawTarget::stderr());
            let template = if total > 0 {
                "{prefix:>14.cyan.bold} [{bar:32}] {pos}/{len} ({eta} left)"
            } else {
                "{prefix:>14.cyan.bold} {spinner} {elapsed}"
            };
            bar.set_style(
                ProgressStyle::with_template(template)
                    .unwrap()
                    .progress_chars("=> "),
            );
            bar.set_prefix(phase.to_string());
            Some(bar)
        } else {
            None
        };
        *self.state.lock().unwrap() = Some((phase.to_string(), Instant::now(), bar));
    }

    fn advance(&self, n: u64) {
        if let Some((_, _, Some(bar))) = &*self.state.lock().unwrap() {
            bar.inc(n);
        }
    }

    fn finish(&self) {
        if let Some((phase, t0, bar)) = self.state.lock().unwrap().take() {
            if let Some(bar) = bar {
                bar.finish_and_clear();
            }
            eprintln!("{phase:>14} done in {:.2} s", t0.elapsed().as_secs_f64());
        }
    }

    fn warn(&self, message: &str) {
        if !self.quiet {
            eprintln!("warning: {message}");
        }
    }
}

impl Ui {
    /// A line for people (not a warning), unless quiet.
    pub fn note(&self, message: &str) {
        if !self.quiet {
            eprintln!("note: {message}");
        }
    }
}

/// Print an error and its cause chain the way people expect from a CLI.
pub fn print_error(e: &relume::Error) {
    eprintln!("error: {e}");
    let mut source = std::error::Error::source(e);
    while let Some(s) = source {
        eprintln!("  caused by: {s}");
        source = s.source();
    }
}
