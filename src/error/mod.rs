//! One error type for the whole library, sorted by who is at fault (as the `image` crate does):
//! the input (a malformed file, a NaN height, an impossible knob), the file system (a file that
//! cannot be read or written), a resource limit (a bake larger than the memory budget), a feature
//! this version does not support, or relume itself (a bug). Every variant names the offending
//! path when there is one; binaries print the whole cause chain and exit with [`Error::exit_code`].

pub mod ron_located;

use std::fmt;
use std::path::{Path, PathBuf};

/// The result type of every fallible library function.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Exit codes of the binaries, one per cause. Listed in `--help` and the README.
pub mod exit {
    /// Success.
    pub const OK: i32 = 0;
    /// relume itself failed (a bug: please report it).
    pub const INTERNAL: i32 = 1;
    /// The command line is wrong (clap's own code for usage errors).
    pub const USAGE: i32 = 2;
    /// An input file or knob is invalid: malformed file, NaN height, out-of-range knob.
    pub const INPUT: i32 = 3;
    /// A file could not be read or written (missing, permissions, disk full, path is a directory).
    pub const IO: i32 = 4;
    /// The work would exceed a resource limit, e.g. `--max-memory`.
    pub const LIMIT: i32 = 5;
    /// The input asks for something this version does not support.
    pub const UNSUPPORTED: i32 = 6;
    /// A baked directory failed verification (`inspect`: a missing, truncated or altered file).
    pub const VERIFY: i32 = 7;

    /// The table every binary prints in its help (`after_help`).
    pub const HELP: &str = "\
Exit codes:
  0  success
  1  internal error (a bug in relume: please report it)
  2  usage error (bad command line)
  3  invalid input (malformed file, NaN height, out-of-range knob)
  4  I/O error (cannot read or write a file)
  5  over a resource limit (e.g. --max-memory)
  6  unsupported (valid input that this version cannot handle; relume-player: no GPU adapter,
     install mesa-vulkan-drivers)
  7  verification failed (a missing, truncated or altered file of a bake)";
}

/// Everything that can go wrong, sorted by who is at fault.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The input is wrong: the user (or the tool that made the file) must fix it.
    #[error("{}: {message}", path.display())]
    Input { path: PathBuf, message: String },

    /// A problem at a line and column of a text file (pipelines, manifests).
    #[error("{}:{line}:{col}: {message}", path.display())]
    Located {
        path: PathBuf,
        line: usize,
        col: usize,
        message: String,
        unsupported: bool,
    },

    /// A knob or argument value is out of its valid range (not tied to one file).
    #[error("{message}")]
    Knob { message: String },

    /// The file system refused: missing file, permissions, disk full.
    #[error("{}: {action}", path.display())]
    Io {
        path: PathBuf,
        action: &'static str,
        #[source]
        source: std::io::Error,
    },

    /// The work would exceed a limit the user set (or the machine has).
    #[error("{message}")]
    Limit { message: String },

    /// Valid input that this version of relume does not handle.
    #[error("{}: {message}", path.display())]
    Unsupported { path: PathBuf, message: String },

    /// A baked directory does not match its manifest.
    #[error("{}: {message}", path.display())]
    Verify { path: PathBuf, message: String },

    /// No usable GPU (adapter or device), with the fix to try.
    #[error("{0}")]
    Gpu(String),

    /// A bug in relume.
    #[error("internal error: {0}")]
    Internal(String),
}

impl Error {
    /// An input error naming `path`.
    pub fn input(path: impl AsRef<Path>, message: impl fmt::Display) -> Self {
        Error::Input {
            path: path.as_ref().to_path_buf(),
            message: message.to_string(),
        }
    }

    /// A knob error (out-of-range or contradictory settings).
    pub fn knob(message: impl fmt::Display) -> Self {
        Error::Knob {
            message: message.to_string(),
        }
    }

    /// An I/O error naming `path` and what was being done (`"cannot read"`, ...). A file that
    /// ends too soon or is not the text it should be is the input's fault, not the file
    /// system's: those become [`Error::Input`] ("truncated" / "malformed").
    pub fn io(path: impl AsRef<Path>, action: &'static str, source: std::io::Error) -> Self {
        use std::io::ErrorKind;
        let fault = match source.kind() {
            ErrorKind::UnexpectedEof => Some("truncated: the file ends early"),
            ErrorKind::InvalidData => Some("malformed"),
            _ => None,
        };
        if let Some(fault) = fault {
            return Error::input(path, format!("{action}: {fault} ({source})"));
        }
        Error::Io {
            path: path.as_ref().to_path_buf(),
            action,
            source,
        }
    }

    /// A resource-limit error.
    pub fn limit(message: impl fmt::Display) -> Self {
        Error::Limit {
            message: message.to_string(),
        }
    }

    /// An unsupported-feature error naming `path`.
    pub fn unsupported(path: impl AsRef<Path>, message: impl fmt::Display) -> Self {
        Error::Unsupported {
            path: path.as_ref().to_path_buf(),
            message: message.to_string(),
        }
    }

    /// A verification failure naming `path`.
    pub fn verify(path: impl AsRef<Path>, message: impl fmt::Display) -> Self {
        Error::Verify {
            path: path.as_ref().to_path_buf(),
            message: message.to_string(),
        }
    }

    /// The process exit code for this error's cause (see [`exit`]).
    pub fn exit_code(&self) -> i32 {
        match self {
            Error::Located {
                unsupported: true, ..
            } => exit::UNSUPPORTED,
            Error::Input { .. } | Error::Knob { .. } | Error::Located { .. } => exit::INPUT,
            Error::Io { .. } => exit::IO,
            Error::Limit { .. } => exit::LIMIT,
            Error::Unsupported { .. } | Error::Gpu(_) => exit::UNSUPPORTED,
            Error::Verify { .. } => exit::VERIFY,
            Error::Internal(_) => exit::INTERNAL,
        }
    }

    /// Short name of the cause class, for `--json` reports.
    pub fn class(&self) -> &'static str {
        match self {
            Error::Located {
                unsupported: true, ..
            } => "unsupported",
            Error::Input { .. } | Error::Knob { .. } | Error::Located { .. } => "input",
            Error::Io { .. } => "io",
            Error::Limit { .. } => "limit",
            Error::Unsupported { .. } => "unsupported",
            Error::Gpu(_) => "gpu",
            Error::Verify { .. } => "verify",
            Error::Internal(_) => "internal",
        }
    }
}

/// Attach a path and an action to `std::io::Result`s.
pub trait IoContext<T> {
    /// Map an I/O error to [`Error::Io`] naming `path`.
    fn at(self, path: &Path, action: &'static str) -> Result<T>;
}

impl<T> IoContext<T> for std::io::Result<T> {
    fn at(self, path: &Path, action: &'static str) -> Result<T> {
        self.map_err(|e| Error::io(path, action, e))
    }
}

/// Run a third-party decoder that may panic on malformed input (a bug of that crate), turning a
/// panic into [`Error::Input`] naming `path`. The panic message is kept out of stderr: a user
/// sees one clear error, not a backtrace. Other threads' panics still reach the previous hook.
pub fn contain_panic<T>(path: &Path, decoder: &str, f: impl FnOnce() -> T) -> Result<T> {
    use std::cell::Cell;
    use std::panic::{catch_unwind, AssertUnwindSafe};
    thread_local!(static CONTAINED: Cell<bool> = const { Cell::new(false) });
    static HOOK: std::sync::Once = std::sync::Once::new();
    HOOK.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if !CONTAINED.with(Cell::get) {
                previous(info)
            }
        }));
    });
    CONTAINED.with(|c| c.set(true));
    let r = catch_unwind(AssertUnwindSafe(f));
    CONTAINED.with(|c| c.set(false));
    r.map_err(|payload| {
        let what = payload
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| payload.downcast_ref::<String>().cloned())
            .unwrap_or_default();
        Error::input(
            path,
            format!("malformed file: the {decoder} failed ({what})"),
        )
    })
}
