//! Helpers shared by the integration tests: run the real binaries, find bundled data.
#![allow(dead_code)]

pub mod freeform;
pub mod study;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The repository root.
pub fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A path inside the repository.
pub fn data(rel: &str) -> PathBuf {
    repo().join(rel)
}

/// Start `relume-bake` with arguments in `cwd` and SIGKILL it after `seconds`.
pub fn bake_killed_after(cwd: &Path, args: &[&str], seconds: f64) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_relume-bake"))
        .args(args)
        .current_dir(cwd)
        .spawn()
        .expect("relume-bake starts");
    std::thread::sleep(std::time::Duration::from_secs_f64(seconds));
    let _ = child.kill();
    let _ = child.wait();
}

/// Run `relume-bake` with arguments in `cwd`.
pub fn bake(cwd: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_relume-bake"))
        .args(args)
        .current_dir(cwd)
        .output()
        .expect("relume-bake runs")
}

/// Stdout and stderr of a run, for assertion messages.
pub fn text(o: &Output) -> String {
    format!(
        "status {:?}\n--- stdout\n{}\n--- stderr\n{}",
        o.status.code(),
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

/// Assert a run exited with `code`, and return its stderr.
pub fn expect_code(o: &Output, code: i32) -> String {
    assert_eq!(o.status.code(), Some(code), "{}", text(o));
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Is a Python interpreter with these modules available (for cross-checks)?
pub fn python_with(modules: &[&str]) -> bool {
    let code = modules
        .iter()
        .map(|m| format!("import {m}"))
        .collect::<Vec<_>>()
        .join("; ");
    Command::new("python3")
        .args(["-c", &code])
        .output()
        .map(|o| o.status.success())
        .unwrap_or(false)
}

/// Run a Python snippet; panic with its output if it fails. Returns stdout.
pub fn python(code: &str, args: &[&str]) -> String {
    let o = Command::new("python3")
        .arg("-c")
        .arg(code)
        .args(args)
        .output()
        .expect("python3 runs");
    assert!(
        o.status.success(),
        "python cross-check failed:\n{}",
        text(&o)
    );
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// Every file under `dir` (sorted relative names) with its bytes: two bakes are byte-identical
/// when these are equal.
pub fn contents(dir: &Path) -> Vec<(String, Vec<u8>)> {
    list_files(dir)
        .into_iter()
        .map(|f| {
            let bytes = std::fs::read(dir.join(&f)).unwrap();
            (f, bytes)
        })
        .collect()
}

/// All files (recursively) under `dir`, relative names, sorted.
pub fn list_files(dir: &Path) -> Vec<String> {
    let mut out = Vec::new();
    fn walk(base: &Path, d: &Path, out: &mut Vec<String>) {
        if let Ok(rd) = std::fs::read_dir(d) {
            for e in rd.flatten() {
                let p = e.path();
                if p.is_dir() {
                    walk(base, &p, out);
                } else {
                    out.push(p.strip_prefix(base).unwrap().display().to_string());
                }
            }
        }
    }
    walk(dir, dir, &mut out);
    out.sort();
    out
}

/// The GPU: a Vulkan adapter (Mesa's lavapipe here and in CI, where the GPU tests' tolerances
/// against their CPU twins were measured) unless `WGPU_BACKEND` names others; None with a
/// visible SKIP message when there is none. (Left to choose on a machine without Vulkan, wgpu
/// took GL: Debian's Mesa 22.3.6-1+deb12u1 llvmpipe, older than the one `make deps` installs,
/// put the freeform planet's normals over their bound, p99 0.056 against 0.023 on lavapipe.)
pub fn gpu() -> Option<relume::gpu::Gpu> {
    let backend = std::env::var_os("WGPU_BACKEND")
        .is_none()
        .then_some(relume::gpu::BackendChoice::Vulkan);
    match relume::gpu::Gpu::new(backend) {
        Ok(g) => Some(g),
        Err(e) => {
            missing(&format!("a GPU adapter ({e})"));
            None
        }
    }
}

/// Must every test run? True under CI (`CI=true`, set by the CI runner) or with
/// `RELUME_REQUIRE_ALL=1`: then a missing tool or device fails the test that needs it.
pub fn require_all() -> bool {
    let on = |k: &str| {
        std::env::var(k)
            .map(|v| !v.is_empty() && v != "0" && !v.eq_ignore_ascii_case("false"))
            .unwrap_or(false)
    };
    on("CI") || on("RELUME_REQUIRE_ALL")
}

/// Something a test needs is missing (`what` says what and how to install it): fail under
/// [`require_all`], else print a visible SKIP line and let the caller return.
pub fn missing(what: &str) {
    if require_all() {
        panic!("missing {what}; CI=true (or RELUME_REQUIRE_ALL=1) requires it: `make deps` installs it");
    }
    eprintln!("SKIP: missing {what} (`make deps` installs it; CI fails instead of skipping)");
}

/// Python 3 with these modules for a cross-check; [`missing`] when it is not there.
pub fn require_python(modules: &[&str]) -> bool {
    if python_with(modules) {
        return true;
    }
    missing(&format!(
        "python3 with {} (make deps-py)",
        modules.join(", ")
    ));
    false
}

/// Run `relume-player` in a window under a virtual X server (`xvfb-run -a`; `make test` installs
/// xvfb) for `frames` frames and check that it showed them. `None` (after reporting it through
/// [`missing`]) when there is no xvfb-run.
pub fn player_in_window(args: &[&std::ffi::OsStr], frames: u32) -> Option<()> {
    if Command::new("xvfb-run").arg("--help").output().is_err() {
        missing("xvfb-run for the window test (apt-get install xvfb xauth)");
        return None;
    }
    let o = Command::new("xvfb-run")
        .args(["-a", env!("CARGO_BIN_EXE_relume-player")])
        .args(args)
        .args(["--exit-after", &frames.to_string()])
        .output()
        .unwrap();
    assert!(o.status.success(), "window: {}", text(&o));
    assert!(
        String::from_utf8_lossy(&o.stderr)
            .contains(&format!("showed {frames} frame(s) in a window")),
        "{}",
        text(&o)
    );
    Some(())
}

/// The Khronos glTF-Validator's wrapper script (`tools/npm/validate-gltf.js`, run with node),
/// when `make deps-npm` installed it; reports it missing otherwise (fails under CI).
pub fn validator() -> Option<PathBuf> {
    let script = repo().join("tools/npm/validate-gltf.js");
    let installed = repo()
        .join("tools/npm/node_modules/gltf-validator")
        .is_dir();
    let node = Command::new("node").arg("--version").output().is_ok();
    if installed && node {
        Some(script)
    } else {
        missing("the Khronos glTF-Validator (node and tools/npm/node_modules: make deps-npm)");
        None
    }
}
