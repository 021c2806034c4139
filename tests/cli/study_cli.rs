//! `relume-bake study` end to end with the real binary, in `--quick` mode: the JSON has the
//! expected settings with finite errors and zero error for the settings that are their own
//! reference, the Markdown has a table per sweep, the PNG plots decode and are not blank, the
//! terrain sweep finds 0 differing pixels, the report does not depend on the thread count, and
//! bad arguments are refused with clear messages.

use crate::common;

use common::study::{check_numbers, err, labels, setting, settings, study, sweep};
use common::{bake, data, expect_code};
use serde_json::Value;

/// RMS relative error of the light gathered with `pairwise 16` form factors against the
/// `hemisphere 4096` reference in the quick radiosity study: 4x the 0.065 measured.
const PAIRWISE_VS_REFERENCE: f64 = 0.26;

#[test]
fn radiosity_quick_sweeps_patches_estimators_and_bounces() {
    let dir = tempfile::tempdir().unwrap();
    let j = study(dir.path(), &["radiosity"]);
    assert_eq!(j["study"], "radiosity");
    assert_eq!(j["quick"], true);
    check_numbers(&j);

    let p = sweep(&j, "radiosity_patches");
    assert_eq!(labels(p), ["target 50", "target 150", "target 400"]);
    assert_eq!(setting(p, "target 400")["reference"], true);
    let e50 = err(setting(p, "target 50"), "gathered_light", "rms_rel");
    assert!(e50 > 0.0 && e50 < 1.0, "coarse patches: {e50}");
    assert_eq!(
        p["plots"].as_array().unwrap().len(),
        2,
        "error vs time and vs bytes"
    );

    let e = sweep(&j, "radiosity_estimator");
    assert_eq!(
        labels(e),
        [
            "hemisphere 64",
            "hemisphere 256",
            "hemisphere 1024",
            "hemisphere reciprocal 64",
            "hemisphere reciprocal 256",
            "hemisphere reciprocal 1024",
            "pairwise 4",
            "pairwise 16",
            "hemisphere 4096"
        ]
    );
    let r = setting(e, "hemisphere 4096");
    assert_eq!(r["reference"], true);
    // More rays, less error (against a reference 4x denser than the densest swept).
    let f = |l| err(setting(e, l), "form_factors", "sum");
    assert!(f("hemisphere 64") > f("hemisphere 256") && f("hemisphere 256") > f("hemisphere 1024"));
    // Reciprocity averaging combines each pair's two independent estimates (inverse-variance
    // weights): less error in the gathered light than the same rays unaveraged, at every count
    // (measured 15.4 / 8.0 / 3.9 % against 19.6 / 12.3 / 4.7 % at 64 / 256 / 1024 rays).
    let b = |l: &str| err(setting(e, l), "gathered_light", "rms_rel");
    for rays in [64, 256, 1024] {
        let (plain, avg) = (
            b(&format!("hemisphere {rays}")),
            b(&format!("hemisphere reciprocal {rays}")),
        );
        assert!(
            avg < plain,
            "{rays} rays: reciprocal {avg} vs plain {plain}"
        );
    }
    // The reference against an independent estimator: pairwise area-to-area integration shares no
    // rays with the hemisphere, and the light gathered with its form factors (16² samples per
    // pair) lands within PAIRWISE_VS_REFERENCE of the reference's.
    let pairwise = err(setting(e, "pairwise 16"), "gathered_light", "rms_rel");
    eprintln!("pairwise 16 vs the hemisphere-4096 reference: gathered light {pairwise:.4e}");
    assert!(pairwise < PAIRWISE_VS_REFERENCE, "{pairwise}");

    let b = sweep(&j, "radiosity_bounces");
    assert_eq!(
        labels(b),
        [
            "gauss-seidel f64",
            "k = 1",
            "k = 2",
            "k = 3",
            "k = 8",
            "k = inf",
            "auto 1e-3"
        ]
    );
    let g = |l| err(setting(b, l), "gathered_light", "rms_rel");
    // Every bounce adds light the reference has: the error falls monotonically with k, and
    // k = ∞ matches the f64 Gauss–Seidel solution to f32 rounding.
    assert!(g("k = 1") > g("k = 2") && g("k = 2") > g("k = 3") && g("k = 3") > g("k = 8"));
    assert!(
        g("k = inf") < 1e-5,
        "k = inf vs Gauss–Seidel: {}",
        g("k = inf")
    );
    assert!(g("auto 1e-3") < g("k = 8"));

    // The settings marked as relume's default are exactly those of the knob defaults
    // (hemisphere reciprocal at 4096 rays, which the quick sweep does not reach — its 4096-ray
    // reference is the plain hemisphere; infinite bounces; the quick patch sweep does not
    // reach 1000).
    let defaults = |s: &Value| -> Vec<String> {
        s["settings"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|x| x["default"] == true)
            .map(|x| x["label"].as_str().unwrap().to_string())
            .collect()
    };
    assert_eq!(defaults(p), Vec::<String>::new());
    assert_eq!(defaults(e), Vec::<String>::new());
    assert_eq!(defaults(b), ["k = inf"]);
    let md = std::fs::read_to_string(dir.path().join("out/study.md")).unwrap();
    assert_eq!(md.matches("◀ default").count(), 1, "{md}");
}

#[test]
fn compression_quick_sweeps_reorder_split_and_encodings() {
    let dir = tempfile::tempdir().unwrap();
    let j = study(dir.path(), &["compression"]);
    check_numbers(&j);
    let r = sweep(&j, "compression_reorder");
    assert_eq!(
        labels(r),
        [
            "0 passes",
            "1 passes Linear",
            "1 passes Log",
            "2 passes Linear",
            "2 passes Log",
            "1 passes Linear bounded",
            "1 passes Linear budgeted",
            "2 passes Linear bounded",
            "2 passes Linear budgeted"
        ]
    );
    // The bounded walk finds the thesis's greedy order: the same errors as the full one.
    for p in ["1", "2"] {
        let (f, b) = (
            setting(r, &format!("{p} passes Linear")),
            setting(r, &format!("{p} passes Linear bounded")),
        );
        assert_eq!(
            err(f, "matrix", "sum"),
            err(b, "matrix", "sum"),
            "{p} passes"
        );
    }
    for s in settings(r) {
        // The radiosity thesis's three numbers are all there.
        for m in ["mean", "max", "sum"] {
            assert!(err(s, "matrix", m) > 0.0);
        }
    }
    let e = sweep(&j, "compression_encoding");
    assert_eq!(settings(e).len(), 1 + 5 * 5 + 1);
    assert_eq!(setting(e, "uncompressed f32")["reference"], true);
    // F32 without a sidecar stores S exactly: the decoded matrix has no error at all.
    assert_eq!(err(setting(e, "f32 p=0"), "matrix", "sum"), 0.0);
    assert!(err(setting(e, "f32 p=0"), "gathered_light", "rms_rel") < 1e-5);
    let bytes = |l| setting(e, l)["bytes"].as_u64().unwrap();
    assert!(bytes("f32 p=0") > bytes("f16 p=0") && bytes("f16 p=0") > bytes("bc6h p=0"));
    assert!(bytes("bc6h p=0") > bytes("bc1_log p=0"));
    // A bigger sidecar costs bytes.
    assert!(bytes("bc6h p=8") > bytes("bc6h p=1"));
    assert_eq!(e["baseline"], "seed: bc1_log p=4 zeroed holes");
}

#[test]
fn terrain_quick_accelerated_and_sweep_equal_exact_and_report_is_thread_independent() {
    let dir = tempfile::tempdir().unwrap();
    let j = study(dir.path(), &["terrain", "-j", "1"]);
    check_numbers(&j);
    let h = sweep(&j, "terrain_hard_shadows");
    assert_eq!(
        settings(h).len(),
        2 * 2 * 3,
        "2 sizes x 2 elevations x 3 methods (exact, accelerated, sweep)"
    );
    for s in settings(h) {
        assert_eq!(
            err(s, "shadow_mask", "sum"),
            0.0,
            "differing pixels in {}",
            s["label"]
        );
        assert_eq!(s["reference"], s["knobs"]["method"] == "exact");
    }
    assert!(
        setting(h, "512 5° exact")["extra"]["shadowed_fraction"]
            .as_f64()
            .unwrap()
            > 0.01
    );
    let m = sweep(&j, "terrain_mipmap");
    assert_eq!(labels(m), ["256x256", "512x512"]);
    assert!(settings(m)[1]["bytes"].as_u64() > settings(m)[0]["bytes"].as_u64());

    // Soft shadows: branch-and-bound is exact, uniform stepping and coarse dynamic programming
    // are not, on pixels that are really in penumbra.
    let soft = sweep(&j, "terrain_soft_shadows");
    for size in ["256x256", "512x512"] {
        let s = |m: &str| setting(soft, &format!("{size} 5° {m}"));
        assert_eq!(s("exhaustive")["reference"], true);
        assert!(
            s("exhaustive")["extra"]["penumbra_fraction"]
                .as_f64()
                .unwrap()
                > 0.001
        );
        assert!(err(s("branch and bound"), "lit_fraction", "max") < 1e-6);
        assert!(err(s("uniform 32"), "lit_fraction", "max") > 0.01);
        assert!(
            err(
                s("dynamic programming, start level 4"),
                "lit_fraction",
                "mean"
            ) > 1e-4
        );
        assert_eq!(
            s("uniform 32")["baseline"],
            format!("{size} 5° uniform 100")
        );
    }

    // Everything but the times is the same with two and with eight threads.
    let base = strip_times(j);
    for threads in ["2", "8"] {
        let dir2 = tempfile::tempdir().unwrap();
        let j2 = study(dir2.path(), &["terrain", "-j", threads]);
        assert_eq!(base, strip_times(j2), "-j {threads}");
    }
}

#[test]
fn terrain_dp_rows_sweep_start_levels_and_interval_caps() {
    let dir = tempfile::tempdir().unwrap();
    let j = study(
        dir.path(),
        &["terrain", "--dp-levels", "1", "--dp-intervals", "0,1,3"],
    );
    let soft = sweep(&j, "terrain_soft_shadows");
    for size in ["256x256", "512x512"] {
        let mean = |label: &str| {
            err(
                setting(
                    soft,
                    &format!("{size} 5° dynamic programming, start level 1{label}"),
                ),
                "lit_fraction",
                "mean",
            )
        };
        let (one, three, all) = (mean(", 1 intervals"), mean(", 3 intervals"), mean(""));
        // A capped run looks at a prefix of the uncapped run's intervals, and dynamic
        // programming is never darker than the exhaustive walk: fewer intervals, lighter
        // pixels, a larger mean error.
        assert!(one >= three && three >= all, "{size}: {one} {three} {all}");
        assert!(
            one > all,
            "{size}: the cap changes nothing ({one} vs {all})"
        );
        assert!(
            !labels(soft).iter().any(|l| l.contains("start level 4")),
            "--dp-levels replaces the default levels"
        );
    }
}

/// The report without measured times (and numbers derived from them) and the thread count.
fn strip_times(mut j: Value) -> Value {
    j["threads"] = Value::Null;
    for sw in j["sweeps"].as_array_mut().unwrap() {
        for s in sw["settings"].as_array_mut().unwrap() {
            s["seconds"] = Value::Null;
            let extra = s["extra"].as_object_mut().unwrap();
            extra.retain(|k, _| {
                !(k.contains("second") || k.contains("speedup") || k.contains("per_pixel"))
            });
        }
    }
    j
}

#[test]
fn compression_study_of_an_existing_bake_uses_its_emitters() {
    let dir = tempfile::tempdir().unwrap();
    let pipeline = dir.path().join("small.ron");
    std::fs::write(
        &pipeline,
        format!(
            "Pipeline(input: Scene(path: {:?}, scale: 0.001), stages: [Voxelize(resolution: TargetPatches(60)), FormFactors(samples: 256), Transport()])",
            data("scenes/cornell-box/cornell_box.obj")
        ),
    )
    .unwrap();
    expect_code(
        &bake(dir.path(), &["run", "small.ron", "--out", "baked", "-q"]),
        0,
    );
    let j = study(dir.path(), &["compression", "--baked", "baked"]);
    check_numbers(&j);
    let e = sweep(&j, "compression_encoding");
    assert!(e["reference"].as_str().unwrap().contains("`emitters`"));
    assert!(setting(e, "bc6h p=1")["extra"]["gather_rms_rel_emitters"]
        .as_f64()
        .is_some());
}

/// The quick atmosphere study: a setting per model and sun, the plot, and Hillaire's sky view at
/// a 90° sun within a measured bound of the reference (quadrature + Monte Carlo).
#[test]
fn atmosphere_quick_plots_error_against_sun_elevation() {
    let d = tempfile::tempdir().unwrap();
    let j = study(d.path(), &["atmosphere"]);
    assert_eq!(j["study"], "atmosphere");
    let sw = sweep(&j, "atmosphere");
    assert_eq!(settings(sw).len(), 15, "{:?}", labels(sw));
    let e = |label: &str| setting(sw, label)["extra"]["error"].as_f64().unwrap();
    for el in ["90°", "60°", "30°", "10°", "2°"] {
        let (fog, aerial) = (
            e(&format!("constant fog {el}")),
            e(&format!("Hillaire aerial {el}")),
        );
        assert!(
            aerial.is_finite() && aerial < fog,
            "{el}: {aerial} vs {fog}"
        );
    }
    // Measured 10.6 % (1,000 paths per ray, the reference's Monte Carlo SE 8.4 %); 1.25× as
    // the error table's test allows.
    let sky = e("Hillaire sky 90°");
    assert!(sky > 0.0 && sky < 0.133, "Hillaire sky at 90°: {sky}");
    assert!(d
        .path()
        .join("out/atmosphere_error_vs_elevation.png")
        .is_file());
}

#[test]
fn bad_arguments_are_refused_clearly_and_leave_no_report() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let no_json = |o: &std::process::Output| {
        assert!(
            !d.join("o/study.json").exists(),
            "no report after a refusal"
        );
        let _ = o;
    };
    // Usage errors (clap): exit 2.
    expect_code(&bake(d, &["study"]), 2);
    let e = expect_code(&bake(d, &["study", "terrain", "--quick"]), 2);
    assert!(e.contains("--out"), "{e}");
    let e = expect_code(
        &bake(
            d,
            &["study", "terrain", "--out", "o", "--elevations", "5,95"],
        ),
        2,
    );
    assert!(e.contains("not in [-90, 90]"), "{e}");
    let e = expect_code(
        &bake(
            d,
            &[
                "study",
                "compression",
                "--out",
                "o",
                "--baked",
                "b",
                "--scene",
                "s.obj",
            ],
        ),
        2,
    );
    assert!(e.contains("cannot be used with"), "{e}");
    expect_code(
        &bake(d, &["study", "radiosity", "--out", "o", "--patches", "0"]),
        2,
    );
    // Invalid inputs and knobs: exit 3, naming the problem.
    let o = bake(
        d,
        &[
            "study", "terrain", "--quick", "--out", "o", "--sizes", "10000",
        ],
    );
    let e = expect_code(&o, 3);
    assert!(e.contains("study size 10000"), "{e}");
    no_json(&o);
    let puget = data("pipelines/puget-sound.ron");
    let o = bake(
        d,
        &[
            "study",
            "radiosity",
            "--quick",
            "--out",
            "o",
            "--pipeline",
            puget.to_str().unwrap(),
        ],
    );
    let e = expect_code(&o, 3);
    assert!(e.contains("input is a height map"), "{e}");
    no_json(&o);
    // An output path that is a file: exit 4, before any work.
    std::fs::write(d.join("file"), "x").unwrap();
    let e = expect_code(
        &bake(d, &["study", "terrain", "--quick", "--out", "file"]),
        4,
    );
    assert!(e.contains("not a directory"), "{e}");
}
