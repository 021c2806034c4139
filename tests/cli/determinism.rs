//! Every output kind is byte-identical for 1, 2 and 8 worker threads: a whole scene bake (every
//! file of `pipelines/cornell.ron`, manifest included), a height-map bake, hard and soft shadow
//! images (PNG and EXR), and headless player frames (the player has no `-j`: its CPU work runs
//! on rayon's global pool, sized by `RAYON_NUM_THREADS`). The study's reports are checked in
//! `tests/cli/study_cli.rs`.

use crate::common;

use common::{bake, contents, data, expect_code, gpu};
use std::path::Path;
use std::process::Command;

const THREADS: [&str; 3] = ["1", "2", "8"];

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn assert_same(dirs: &[std::path::PathBuf], what: &str) {
    let first = contents(&dirs[0]);
    assert!(!first.is_empty(), "{what}: nothing written");
    for (d, t) in dirs.iter().zip(THREADS).skip(1) {
        let other = contents(d);
        assert_eq!(
            first.iter().map(|f| &f.0).collect::<Vec<_>>(),
            other.iter().map(|f| &f.0).collect::<Vec<_>>(),
            "{what}: files differ with -j {t}"
        );
        for (a, b) in first.iter().zip(&other) {
            assert!(
                a.1 == b.1,
                "{what}: {} differs between -j 1 and -j {t}",
                a.0
            );
        }
    }
}

#[test]
fn bakes_and_shadow_images_are_identical_for_any_thread_count() {
    let tmp = tempfile::tempdir().unwrap();
    let mut scene_dirs = Vec::new();
    let mut map_dirs = Vec::new();
    let mut image_dirs = Vec::new();
    for t in THREADS {
        let scene = tmp.path().join(format!("cornell-{t}"));
        let o = bake(
            tmp.path(),
            &[
                "-q",
                "-j",
                t,
                "run",
                s(&data("pipelines/cornell.ron")),
                "--out",
                s(&scene),
            ],
        );
        expect_code(&o, 0);
        scene_dirs.push(scene);
        let map = tmp.path().join(format!("puget-{t}"));
        let o = bake(
            tmp.path(),
            &[
                "-q",
                "-j",
                t,
                "run",
                s(&data("pipelines/puget-sound-512.ron")),
                "--out",
                s(&map),
            ],
        );
        expect_code(&o, 0);
        map_dirs.push(map);
        let images = tmp.path().join(format!("images-{t}"));
        std::fs::create_dir(&images).unwrap();
        let p512 = data("pipelines/puget-sound-512.ron");
        for args in [
            vec![
                "shadow",
                s(&p512),
                "--sun-azimuth",
                "300",
                "--sun-elevation",
                "5",
            ],
            vec![
                "softshadow",
                s(&p512),
                "--sun-azimuth",
                "300",
                "--sun-elevation",
                "3",
            ],
        ] {
            for ext in ["png", "exr"] {
                if args[0] == "shadow" && ext == "exr" {
                    continue; // the hard mask is PNG only
                }
                let out = images.join(format!("{}.{ext}", args[0]));
                let mut a = vec!["-q", "-j", t];
                a.extend(&args);
                a.extend(["--out", s(&out)]);
                let shaded = images.join(format!("{}-shaded.png", args[0]));
                if ext == "png" {
                    a.extend(["--shaded", s(&shaded)]);
                }
                expect_code(&bake(tmp.path(), &a), 0);
            }
        }
        image_dirs.push(images);
    }
    assert_same(&scene_dirs, "scene bake");
    assert_same(&map_dirs, "height-map bake");
    assert_same(&image_dirs, "shadow images");
}

#[test]
fn headless_player_frames_are_identical_for_any_thread_count() {
    if gpu().is_none() {
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    let baked = tmp.path().join("cornell");
    expect_code(
        &bake(
            tmp.path(),
            &[
                "-q",
                "run",
                s(&data("pipelines/cornell.ron")),
                "--out",
                s(&baked),
            ],
        ),
        0,
    );
    let mut frames = Vec::new();
    for t in THREADS {
        let out = tmp.path().join(format!("frames-{t}"));
        let o = Command::new(env!("CARGO_BIN_EXE_relume-player"))
            .args([
                s(&baked),
                "--headless",
                "-q",
                "--size",
                "160x120",
                "--sun",
                "20,30",
            ])
            .args(["--frames", "2", "--out", s(&out)])
            .env("RAYON_NUM_THREADS", t)
            .output()
            .unwrap();
        expect_code(&o, 0);
        // frames.json holds measured times; the frames themselves must match.
        std::fs::remove_file(out.join("frames.json")).unwrap();
        frames.push(out);
    }
    assert_same(&frames, "player frames");
}
