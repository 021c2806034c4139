//! Bakes split over processes (docs/scale-out.md): for N = 1..4 shard processes run at once, the
//! merged bake is byte-identical to a single `run` (every file, manifest included) for each
//! form-factor estimator, infinite and finite bounces, grey and coloured scenes; a missing,
//! duplicated, truncated, damaged or foreign shard is refused with its name (exit 7); a shard
//! killed with SIGKILL and run again writes the same file; the scheduler's environment selects
//! the shard. The library's row blocks and transport parts assemble exactly for any split.

use crate::common;

use common::{bake, bake_killed_after, contents, data, expect_code};
use relume::progress::Silent;
use relume::radiosity::formfactor::{
    assemble, form_factor_rows, form_factors, shard_rows, Estimator, FormFactorParams,
};
use relume::radiosity::patches::voxelize::{voxelize, Resolution, VoxelizeParams};
use relume::radiosity::transport::shard::{assemble_infinite, factor_channels, solve_part};
use relume::radiosity::transport::{transport, Bounces, Power, TransportParams};
use std::path::{Path, PathBuf};
use std::process::{Child, Command};

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// A pipeline over the Cornell box (coloured: three channels) in `dir`.
fn pipeline(
    dir: &Path,
    name: &str,
    patches: u32,
    estimator: &str,
    samples: u32,
    bounces: &str,
) -> PathBuf {
    let p = dir.join(format!("{name}.ron"));
    std::fs::write(
        &p,
        format!(
            "Pipeline(input: Scene(path: {:?}, scale: 0.001), stages: [Voxelize(resolution: TargetPatches({patches})), FormFactors(estimator: {estimator}, samples: {samples}), Transport(bounces: {bounces}), Reorder(), Encode()])",
            data("scenes/cornell-box/cornell_box.obj")
        ),
    )
    .unwrap();
    p
}

fn spawn(cwd: &Path, args: &[&str]) -> Child {
    Command::new(env!("CARGO_BIN_EXE_relume-bake"))
        .args(args)
        .current_dir(cwd)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap()
}

/// Run every round of `count` shard processes at once, merging after each, until the merge
/// writes the bake. Returns the number of rounds.
fn sharded_bake(cwd: &Path, p: &Path, out: &Path, count: usize) -> usize {
    let shards = out.with_extension("shards");
    for round in 1..=3 {
        let children: Vec<Child> = (0..count)
            .map(|i| {
                let shard = format!("{i}/{count}");
                spawn(
                    cwd,
                    &[
                        "-q",
                        "-j",
                        "1",
                        "run",
                        s(p),
                        "--out",
                        s(out),
                        "--shard",
                        &shard,
                        "--shard-dir",
                        s(&shards),
                    ],
                )
            })
            .collect();
        for c in children {
            let o = c.wait_with_output().unwrap();
            assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        }
        let o = bake(cwd, &["--json", "merge", s(out), s(&shards)]);
        expect_code(&o, 0);
        let report: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        if report["needs_shards"].is_null() {
            return round;
        }
    }
    panic!("the merge never finished");
}

#[test]
fn merged_bakes_are_byte_identical_to_a_single_run_for_1_to_4_shards() {
    let tmp = tempfile::tempdir().unwrap();
    // (name, patches, estimator, samples, bounces, rounds)
    let cases = [
        ("hemisphere-inf", 300, "Hemisphere", 512, "Infinite", 2),
        (
            "reciprocal-inf",
            250,
            "HemisphereReciprocal",
            512,
            "Infinite",
            2,
        ),
        ("pairwise-finite", 120, "Pairwise", 4, "Finite(3)", 1),
    ];
    for (name, patches, est, samples, bounces, rounds) in cases {
        let p = pipeline(tmp.path(), name, patches, est, samples, bounces);
        let whole = tmp.path().join(format!("{name}-whole"));
        expect_code(
            &bake(
                tmp.path(),
                &["-q", "run", s(&p), "--out", s(&whole), "--no-cache"],
            ),
            0,
        );
        let want = contents(&whole);
        for count in 1..=4 {
            let out = tmp.path().join(format!("{name}-{count}"));
            assert_eq!(sharded_bake(tmp.path(), &p, &out, count), rounds, "{name}");
            let got = contents(&out);
            assert_eq!(
                want.iter().map(|f| &f.0).collect::<Vec<_>>(),
                got.iter().map(|f| &f.0).collect::<Vec<_>>(),
                "{name}, {count} shards: files"
            );
            for (a, b) in want.iter().zip(&got) {
                assert!(a.1 == b.1, "{name}, {count} shards: {} differs", a.0);
            }
        }
    }
}

/// Shards of the first round of `p` in `dir` (count `n`).
fn first_round(cwd: &Path, p: &Path, out: &Path, dir: &Path, n: usize) {
    for i in 0..n {
        let shard = format!("{i}/{n}");
        expect_code(
            &bake(
                cwd,
                &[
                    "-q",
                    "run",
                    s(p),
                    "--out",
                    s(out),
                    "--shard",
                    &shard,
                    "--shard-dir",
                    s(dir),
                ],
            ),
            0,
        );
    }
}

fn refused(cwd: &Path, out: &Path, dir: &Path, names: &[&str]) -> String {
    let o = bake(cwd, &["merge", s(out), s(dir)]);
    let err = expect_code(&o, 7);
    for n in names {
        assert!(err.contains(n), "the error names {n}: {err}");
    }
    assert!(!out.exists(), "nothing written on a refused merge");
    err
}

#[test]
fn missing_duplicated_truncated_damaged_and_foreign_shards_are_refused_by_name() {
    let tmp = tempfile::tempdir().unwrap();
    let t = tmp.path();
    let p = pipeline(t, "box", 200, "Hemisphere", 256, "Infinite");
    let other = pipeline(t, "other", 150, "Hemisphere", 256, "Infinite");
    let out = t.join("out");
    let good = t.join("good");
    first_round(t, &p, &out, &good, 3);
    let shard = |i: usize| good.join(format!("form_factors.{i}-of-3.shard"));
    let case = |name: &str| {
        let d = t.join(name);
        std::fs::create_dir(&d).unwrap();
        for i in 0..3 {
            std::fs::copy(shard(i), d.join(format!("form_factors.{i}-of-3.shard"))).unwrap();
        }
        d
    };
    // Missing.
    let d = case("missing");
    std::fs::remove_file(d.join("form_factors.1-of-3.shard")).unwrap();
    refused(t, &out, &d, &["form_factors.1-of-3.shard", "missing"]);
    // Duplicated (a copy under another name).
    let d = case("duplicated");
    std::fs::copy(shard(2), d.join("copy.shard")).unwrap();
    refused(
        t,
        &out,
        &d,
        &["copy.shard", "form_factors.2-of-3.shard", "duplicates"],
    );
    // Truncated.
    let d = case("truncated");
    let f = d.join("form_factors.0-of-3.shard");
    let bytes = std::fs::read(&f).unwrap();
    std::fs::write(&f, &bytes[..bytes.len() - 100]).unwrap();
    refused(t, &out, &d, &["form_factors.0-of-3.shard", "truncated"]);
    // Damaged (one payload byte flipped).
    let d = case("damaged");
    let f = d.join("form_factors.2-of-3.shard");
    let mut bytes = std::fs::read(&f).unwrap();
    let last = bytes.len() - 1;
    bytes[last] ^= 0x40;
    std::fs::write(&f, &bytes).unwrap();
    refused(t, &out, &d, &["form_factors.2-of-3.shard", "SHA-256"]);
    // Foreign: another pipeline's shard among them.
    let d = case("foreign");
    let elsewhere = t.join("elsewhere");
    first_round(t, &other, &t.join("other-out"), &elsewhere, 2);
    std::fs::copy(
        elsewhere.join("form_factors.1-of-2.shard"),
        d.join("other.shard"),
    )
    .unwrap();
    refused(t, &out, &d, &["other.shard", "different bakes"]);
    // Not a shard at all, and an empty directory.
    let d = case("garbage");
    std::fs::write(d.join("junk.shard"), b"hello").unwrap();
    refused(t, &out, &d, &["junk.shard", "not a relume shard"]);
    let d = t.join("empty");
    std::fs::create_dir(&d).unwrap();
    refused(t, &out, &d, &["no shard files"]);
    // The good set merges; that merge prepares the transport's factors for round 2.
    expect_code(&bake(t, &["-q", "merge", s(&out), s(&good)]), 0);
    let prepared = good.join("transport-prepared.0-of-1.shard");
    assert!(prepared.is_file());
    let round2 = [
        "-q",
        "run",
        s(&p),
        "--out",
        s(&out),
        "--shard",
        "0/3",
        "--shard-dir",
        s(&good),
    ];
    // Damaged factors, then none at all: refused by name.
    let bytes = std::fs::read(&prepared).unwrap();
    let mut bad = bytes.clone();
    let last = bad.len() - 1;
    bad[last] ^= 1;
    std::fs::write(&prepared, &bad).unwrap();
    let err = expect_code(&bake(t, &round2), 7);
    assert!(
        err.contains("transport-prepared.0-of-1.shard") && err.contains("SHA-256"),
        "{err}"
    );
    std::fs::remove_file(&prepared).unwrap();
    let err = expect_code(&bake(t, &round2), 7);
    assert!(err.contains("transport-prepared.0-of-1.shard"), "{err}");
    std::fs::write(&prepared, &bytes).unwrap();
    expect_code(&bake(t, &round2), 0);
}

#[test]
fn a_killed_shard_run_again_writes_the_same_file_and_leaves_no_temporary() {
    let tmp = tempfile::tempdir().unwrap();
    let t = tmp.path();
    let p = pipeline(t, "box", 1500, "Hemisphere", 4096, "Infinite");
    let out = t.join("out");
    let clean = t.join("clean");
    let args = |dir: &Path| {
        vec![
            "-q".to_string(),
            "run".into(),
            s(&p).into(),
            "--out".into(),
            s(&out).into(),
            "--shard".into(),
            "1/2".into(),
            "--shard-dir".into(),
            s(dir).into(),
        ]
    };
    let a = args(&clean);
    let a: Vec<&str> = a.iter().map(String::as_str).collect();
    let t0 = std::time::Instant::now();
    expect_code(&bake(t, &a), 0);
    let full = t0.elapsed().as_secs_f64();
    let want = std::fs::read(clean.join("form_factors.1-of-2.shard")).unwrap();
    let killed = t.join("killed");
    let b = args(&killed);
    let b: Vec<&str> = b.iter().map(String::as_str).collect();
    for k in 0..6 {
        bake_killed_after(t, &b, full * (k as f64 + 0.5) / 6.0);
    }
    expect_code(&bake(t, &b), 0);
    assert_eq!(
        std::fs::read(killed.join("form_factors.1-of-2.shard")).unwrap(),
        want
    );
    let names: Vec<String> = std::fs::read_dir(&killed)
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names, ["form_factors.1-of-2.shard"], "no temporaries left");
}

#[test]
fn the_scheduler_environment_selects_the_shard() {
    let tmp = tempfile::tempdir().unwrap();
    let t = tmp.path();
    let p = pipeline(t, "box", 150, "Hemisphere", 128, "Finite(2)");
    let out = t.join("out");
    let dir = t.join("shards");
    let run = |env: &[(&str, &str)], extra: &[&str]| {
        let mut c = Command::new(env!("CARGO_BIN_EXE_relume-bake"));
        c.args(["run", s(&p), "--out", s(&out), "--shard-dir", s(&dir)])
            .args(extra)
            .current_dir(t);
        for (k, v) in env {
            c.env(k, v);
        }
        c.output().unwrap()
    };
    let o = run(
        &[
            ("SLURM_ARRAY_TASK_ID", "1"),
            ("SLURM_ARRAY_TASK_COUNT", "2"),
        ],
        &[],
    );
    let err = expect_code(&o, 0);
    assert!(err.contains("SLURM_ARRAY_TASK_ID"), "{err}");
    assert!(dir.join("form_factors.1-of-2.shard").is_file());
    let o = run(&[("JOB_COMPLETION_INDEX", "0")], &["--shards", "2"]);
    expect_code(&o, 0);
    assert!(dir.join("form_factors.0-of-2.shard").is_file());
    // Kubernetes without --shards, an index past the count, and --no-cache are refused.
    expect_code(&run(&[("JOB_COMPLETION_INDEX", "0")], &[]), 3);
    expect_code(
        &run(
            &[
                ("SLURM_ARRAY_TASK_ID", "2"),
                ("SLURM_ARRAY_TASK_COUNT", "2"),
            ],
            &[],
        ),
        3,
    );
    expect_code(&run(&[], &["--shard", "0/2", "--no-cache"]), 3);
    expect_code(&run(&[], &["--shard", "2/2"]), 2);
    // --no-shard bakes whole inside an array job.
    let o = run(
        &[
            ("SLURM_ARRAY_TASK_ID", "1"),
            ("SLURM_ARRAY_TASK_COUNT", "2"),
        ],
        &["--no-shard"],
    );
    expect_code(&o, 0);
    assert!(out.join("manifest.ron").is_file());
    // The merge finishes the same bake from the two shards.
    let merged = t.join("merged");
    std::fs::create_dir(&merged).unwrap();
    expect_code(&bake(t, &["-q", "merge", s(&merged), s(&dir)]), 0);
    assert!(
        contents(&merged) == contents(&out),
        "the merge equals the whole bake"
    );
}

#[test]
fn row_blocks_and_transport_parts_assemble_exactly_for_any_split() {
    let scene = relume::scene::load_scene(
        &data("scenes/cornell-box/cornell_box.obj"),
        relume::scene::SceneOptions { scale: 0.001 },
    )
    .unwrap()
    .0;
    let set = voxelize(
        &scene,
        &VoxelizeParams {
            resolution: Resolution::TargetPatches(150),
            samples_per_patch: 1,
        },
    )
    .unwrap();
    let n = set.len();
    for (estimator, samples) in [
        (Estimator::Hemisphere, 128),
        (Estimator::HemisphereReciprocal, 128),
        (Estimator::Pairwise, 4),
    ] {
        let params = FormFactorParams {
            estimator,
            samples,
            seed: 3,
        };
        let whole = form_factors(&scene, &set, &params, &Silent).unwrap();
        for count in [1, 2, 5, 7, n] {
            let blocks: Vec<_> = (0..count)
                .map(|i| {
                    let rows = shard_rows(estimator, n, i, count);
                    form_factor_rows(&scene, &set, &params, rows, &Silent).unwrap()
                })
                .collect();
            let got = assemble(&set, &params, &blocks).unwrap();
            assert!(got == whole, "{estimator:?} in {count} blocks");
        }
        // Out of order or incomplete blocks are refused.
        if n > 2 {
            let a = form_factor_rows(&scene, &set, &params, 0..n / 2, &Silent).unwrap();
            let b = form_factor_rows(&scene, &set, &params, n / 2..n, &Silent).unwrap();
            assert!(assemble(&set, &params, &[b.clone(), a.clone()]).is_err());
            assert!(assemble(&set, &params, &[a]).is_err());
        }
    }
    let f = form_factors(
        &scene,
        &set,
        &FormFactorParams {
            estimator: Estimator::Hemisphere,
            samples: 256,
            seed: 0,
        },
        &Silent,
    )
    .unwrap();
    let albedo: Vec<[f32; 3]> = set.patches.iter().map(|p| p.albedo).collect();
    let whole = transport(
        &f.values,
        n,
        &albedo,
        &TransportParams {
            bounces: Bounces::Infinite,
            power: Power::Auto,
            max_memory: u64::MAX,
            solver: Default::default(),
        },
        &Silent,
    )
    .unwrap();
    let factors = factor_channels(&f.values, &albedo, Default::default(), u64::MAX).unwrap();
    let solvers: Vec<_> = factors.iter().map(|c| (c.solver, c.error)).collect();
    for count in [1, 2, 3, 16, 40] {
        let parts: Vec<_> = (0..count)
            .map(|i| {
                factors
                    .iter()
                    .enumerate()
                    .map(|(c, fc)| solve_part(&f.values, &albedo, c, fc, i, count).unwrap())
                    .collect()
            })
            .collect();
        let got = assemble_infinite(&f.values, &albedo, &solvers, parts).unwrap();
        assert!(got == whole, "transport in {count} parts");
    }
}

/// faer partitions its work by the parallelism it is given: the transport fixes it, so that a
/// bake is the same for any pool size at real sizes too. With the pool's size it was not:
/// door-ajar.ron (2,000 patches, two rooms) gave a different transport.npy with -j 1 and -j 2,
/// and so did every shard run with fewer threads than the single process.
#[test]
fn door_ajar_bakes_are_identical_for_any_thread_count() {
    let tmp = tempfile::tempdir().unwrap();
    let p = data("pipelines/door-ajar.ron");
    let mut bakes = Vec::new();
    for j in ["1", "2", "3"] {
        let out = tmp.path().join(format!("door-{j}"));
        expect_code(
            &bake(
                tmp.path(),
                &["-q", "-j", j, "run", s(&p), "--out", s(&out), "--no-cache"],
            ),
            0,
        );
        bakes.push(contents(&out));
    }
    for (k, b) in bakes.iter().enumerate().skip(1) {
        for (x, y) in bakes[0].iter().zip(b) {
            assert!(
                x.0 == y.0 && x.1 == y.1,
                "{} differs between -j 1 and -j {}",
                x.0,
                k + 1
            );
        }
    }
}

mod mutated_shard_files {
    use proptest::prelude::*;
    use relume::baked::shard::{self, Mapped, Payload, ShardHeader};
    use std::path::Path;

    fn original(dir: &Path) -> (std::path::PathBuf, Payload) {
        let pipeline = relume::pipeline::parse::parse_str(
            Path::new("p.ron"),
            "Pipeline(input: Scene(path: \"x.obj\"), stages: [Voxelize(), FormFactors()])",
        )
        .unwrap();
        let mut p = Payload::default();
        p.f32s
            .insert("values".into(), (0..300).map(|i| i as f32 * 0.25).collect());
        p.u64s.insert("rows".into(), vec![0, 3]);
        p.f64s.insert("upper".into(), vec![1.5; 40]);
        p.u32s.insert("columns".into(), (0..17).collect());
        let header = ShardHeader::new(
            "b".into(),
            "form_factors".into(),
            (0, 1),
            &"k".repeat(64),
            &pipeline,
            "rows 0..3 of 100".into(),
        );
        (shard::write(dir, header, &p).unwrap(), p)
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(300))]
        /// A damaged shard never panics a reader, and a shard that still reads holds exactly the
        /// arrays that were written (the payload's hash and the length checks catch the rest).
        #[test]
        fn damaged_shards_are_refused_or_read_exactly(
            flips in proptest::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 0..4),
            cut in proptest::option::of(any::<prop::sample::Index>()),
        ) {
            let tmp = tempfile::tempdir().unwrap();
            let (path, want) = original(tmp.path());
            let mut bytes = std::fs::read(&path).unwrap();
            for (at, x) in flips {
                let i = at.index(bytes.len());
                bytes[i] ^= x;
            }
            if let Some(c) = cut {
                bytes.truncate(c.index(bytes.len()));
            }
            std::fs::write(&path, &bytes).unwrap();
            if let Ok((_, got)) = shard::read(&path) {
                prop_assert_eq!(got, want.clone());
            }
            if let Ok(m) = Mapped::open(&path) {
                prop_assert_eq!(m.f32s("values").ok(), Some(want.f32s["values"].clone()));
                prop_assert_eq!(m.u64s("rows").ok(), Some(want.u64s["rows"].clone()));
            }
        }
    }
}
