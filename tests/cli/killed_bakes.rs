//! A bake killed with SIGKILL at any moment leaves the previous bake intact (it verifies with
//! `inspect`), and the next `run` into the same output removes what the killed processes left
//! (temporary directories of dead processes; never a live one's).

use crate::common;

use common::{bake, bake_killed_after, data, expect_code};
use std::path::Path;
use std::process::Command;
use std::time::Instant;

fn leftovers(parent: &Path) -> Vec<String> {
    std::fs::read_dir(parent)
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains(".relume-tmp-") || n.contains(".relume-old-"))
        .collect()
}

/// A Cornell bake of a few seconds: voxelize, form factors, transport, reorder, encode.
fn pipeline(dir: &Path) -> std::path::PathBuf {
    let p = dir.join("box.ron");
    std::fs::write(
        &p,
        format!(
            "Pipeline(input: Scene(path: {:?}, scale: 0.001), stages: [Voxelize(resolution: TargetPatches(1500)), FormFactors(samples: 2048), Transport(), Reorder(), Encode()])",
            data("scenes/cornell-box/cornell_box.obj")
        ),
    )
    .unwrap();
    p
}

#[test]
fn twenty_kills_spread_over_every_stage_leave_the_previous_bake_and_no_leftovers() {
    let tmp = tempfile::tempdir().unwrap();
    let p = pipeline(tmp.path());
    let out = tmp.path().join("out");
    let (ps, os) = (p.to_str().unwrap(), out.to_str().unwrap());
    let t0 = Instant::now();
    expect_code(
        &bake(
            tmp.path(),
            &["-q", "run", ps, "--force", "--no-cache", "--out", os],
        ),
        0,
    );
    let full = t0.elapsed().as_secs_f64();
    let before = std::fs::read(out.join("manifest.ron")).unwrap();
    // Kill moments spread evenly over the whole bake (loading to the last rename), in a fixed
    // order so that a failure repeats.
    let kills = 20;
    let mut left_behind = 0;
    for k in 0..kills {
        let at = full * (k as f64 + 0.5) / kills as f64;
        let args = ["-q", "run", ps, "--force", "--no-cache", "--out", os];
        bake_killed_after(tmp.path(), &args, at);
        left_behind += leftovers(tmp.path()).len().min(1);
        // Whatever was interrupted, the output is a whole bake that verifies.
        expect_code(&bake(tmp.path(), &["inspect", os]), 0);
    }
    assert!(
        left_behind > 0,
        "no kill landed while a bake was being written ({full:.2} s per bake)"
    );
    expect_code(
        &bake(
            tmp.path(),
            &["-q", "run", ps, "--force", "--no-cache", "--out", os],
        ),
        0,
    );
    assert_eq!(leftovers(tmp.path()), Vec::<String>::new());
    expect_code(&bake(tmp.path(), &["inspect", os]), 0);
    // The final bake is the same bake as the first (deterministic), manifest and all.
    assert_eq!(std::fs::read(out.join("manifest.ron")).unwrap(), before);
}

#[test]
fn a_live_process_temporary_directory_is_never_removed() {
    let tmp = tempfile::tempdir().unwrap();
    let p = pipeline(tmp.path());
    let out = tmp.path().join("out");
    // A temporary directory owned by a process that is still running (a sleeping child, its
    // lock file written as relume writes it), and one of a process that has exited.
    let mut live = Command::new("sleep").arg("30").spawn().unwrap();
    let stat = std::fs::read_to_string(format!("/proc/{}/stat", live.id())).unwrap();
    let start = stat[stat.rfind(')').unwrap() + 1..]
        .split_whitespace()
        .nth(19)
        .unwrap()
        .to_string();
    let live_dir = tmp.path().join(format!(".out.relume-tmp-{}", live.id()));
    std::fs::create_dir(&live_dir).unwrap();
    std::fs::write(
        live_dir.join(".relume-lock"),
        format!("{} {start}", live.id()),
    )
    .unwrap();
    let mut gone = Command::new("true").spawn().unwrap();
    gone.wait().unwrap();
    let dead_dir = tmp.path().join(format!(".out.relume-tmp-{}", gone.id()));
    std::fs::create_dir(&dead_dir).unwrap();
    std::fs::write(dead_dir.join("form_factors.npy"), b"partial").unwrap();
    let o = bake(
        tmp.path(),
        &[
            "-q",
            "run",
            p.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ],
    );
    let _ = live.kill();
    let _ = live.wait();
    expect_code(&o, 0);
    assert!(live_dir.exists(), "a live process's directory was removed");
    assert!(!dead_dir.exists(), "a dead process's directory was left");
}
