//! Sharded bakes: the time and peak memory of each shard and merge for N shards, against a
//! single-process run of the same pipeline in the same run, and the wall time of all N shards
//! run at once on this machine; every merged bake is checked byte-identical to the single run.
//! Shards run as real `relume-bake` processes (the release binary), one round after another.
//!
//! Run: `cargo build --release && cargo bench --bench scale_out -- [PIPELINE] [N,N,...]`
//! (default: pipelines/cornell-4k.ron, 1,2,4). Each shard runs with `-j 1` in the sequential
//! pass (its cost per core) and in the parallel pass (N processes on this machine's cores).

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::Instant;

fn bin() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("target/release/relume-bake")
}

fn run(args: &[&str]) -> (f64, Value) {
    let t = Instant::now();
    let o = Command::new(bin())
        .arg("--json")
        .args(args)
        .output()
        .unwrap();
    let secs = t.elapsed().as_secs_f64();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    (secs, serde_json::from_slice(&o.stdout).unwrap())
}

fn mib(v: &Value) -> f64 {
    v["peak_rss_bytes"].as_f64().unwrap_or(0.0) / (1 << 20) as f64
}

fn files(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut v: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .flatten()
        .map(|e| {
            (
                e.file_name().to_string_lossy().into_owned(),
                std::fs::read(e.path()).unwrap(),
            )
        })
        .collect();
    v.sort();
    v
}

fn main() {
    let args: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with("--"))
        .collect();
    let pipeline = args
        .first()
        .cloned()
        .unwrap_or_else(|| "pipelines/cornell-4k.ron".into());
    let counts: Vec<usize> = args
        .get(1)
        .map(|s| s.split(',').map(|n| n.parse().unwrap()).collect())
        .unwrap_or_else(|| vec![1, 2, 4]);
    let tmp = tempfile::tempdir().unwrap();
    let t = tmp.path();
    let single = t.join("single");
    let (secs, report) = run(&[
        "run",
        &pipeline,
        "--out",
        single.to_str().unwrap(),
        "--no-cache",
    ]);
    let n = report["stages"]
        .as_array()
        .unwrap()
        .iter()
        .find(|s| s["stage"] == "voxelize")
        .and_then(|s| s["report"]["patches"].as_f64())
        .unwrap_or(0.0);
    println!(
        "{pipeline}: n = {n} patches, {} cores\n",
        std::thread::available_parallelism().map_or(1, |c| c.get())
    );
    println!(
        "single process: {secs:.2} s, peak RSS {:.0} MiB\n",
        mib(&report)
    );
    let want = files(&single);
    println!("| N | round | stage | slowest shard (-j 1) | sum of shards (-j 1) | largest shard RSS | shard file | merge | merge RSS |");
    println!("|---|---|---|---|---|---|---|---|---|");
    let mut parallel = Vec::new();
    for &count in &counts {
        let out = t.join(format!("seq-{count}"));
        let dir = t.join(format!("seq-{count}.shards"));
        for round in 1..=3 {
            let (mut slowest, mut sum, mut rss, mut bytes, mut stage) =
                (0f64, 0f64, 0f64, 0u64, String::new());
            for i in 0..count {
                let shard = format!("{i}/{count}");
                let (s, r) = run(&[
                    "-j",
                    "1",
                    "run",
                    &pipeline,
                    "--out",
                    out.to_str().unwrap(),
                    "--shard",
                    &shard,
                    "--shard-dir",
                    dir.to_str().unwrap(),
                ]);
                slowest = slowest.max(s);
                sum += s;
                rss = rss.max(mib(&r));
                if let Some(p) = r["shard"]["path"].as_str() {
                    bytes = bytes.max(std::fs::metadata(p).unwrap().len());
                    stage = r["shard"]["stage"].as_str().unwrap().into();
                }
            }
            let (ms, mr) = run(&["merge", out.to_str().unwrap(), dir.to_str().unwrap()]);
            println!(
                "| {count} | {round} | {stage} | {slowest:.2} s | {sum:.2} s | {rss:.0} MiB | {:.1} MiB | {ms:.2} s | {:.0} MiB |",
                bytes as f64 / (1 << 20) as f64,
                mib(&mr)
            );
            if mr["needs_shards"].is_null() {
                break;
            }
        }
        assert!(
            files(&out) == want,
            "{count} shards: the merge differs from the single run"
        );
        // All N shards at once on this machine, then the merge, per round.
        let out = t.join(format!("par-{count}"));
        let dir = t.join(format!("par-{count}.shards"));
        let t0 = Instant::now();
        for _ in 1..=3 {
            let kids: Vec<Child> = (0..count)
                .map(|i| {
                    Command::new(bin())
                        .args([
                            "-q",
                            "run",
                            &pipeline,
                            "--out",
                            out.to_str().unwrap(),
                            "--shard",
                            &format!("{i}/{count}"),
                            "--shard-dir",
                            dir.to_str().unwrap(),
                        ])
                        .stdout(Stdio::null())
                        .spawn()
                        .unwrap()
                })
                .collect();
            for mut k in kids {
                assert!(k.wait().unwrap().success());
            }
            let (_, mr) = run(&["merge", out.to_str().unwrap(), dir.to_str().unwrap()]);
            if mr["needs_shards"].is_null() {
                break;
            }
        }
        parallel.push((count, t0.elapsed().as_secs_f64()));
        assert!(
            files(&out) == want,
            "{count} parallel shards: the merge differs"
        );
    }
    println!("\nAll N shards at once (one thread each, as Slurm tasks of one CPU), then the merge (all threads), every round; wall time, every merge byte-identical to the single run:\n");
    println!("| N | wall | speed-up over N = 1 | vs the single process |");
    println!("|---|---|---|---|");
    let one = parallel.first().map_or(1.0, |p| p.1);
    for (count, wall) in parallel {
        println!(
            "| {count} | {wall:.2} s | {:.2}x | {:.2}x |",
            one / wall,
            secs / wall
        );
    }
}
