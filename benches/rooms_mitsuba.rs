//! Per-object irradiance of a bundled scene against Mitsuba 3, by patch count: how close
//! radiosity comes to a path tracer (door-ajar: where light enters a room only through a gap;
//! cornell: the Cornell box).
//!
//! The references are Mitsuba's irradiance meters (`tests/support/mitsuba_objects.py`; its
//! standard error is printed beside each object):
//! `tests/reference/door-ajar.mitsuba.json` from
//! `python3 tests/support/mitsuba_objects.py scenes/generated/door-ajar.obj 1000000 6 dark. bright.`
//! and `tests/reference/cornell.mitsuba.json` from
//! `RELUME_EMITTER_DROP=0.1 python3 tests/support/mitsuba_objects.py scenes/cornell-box/cornell_box.obj 1000000 4`
//! (the light lowered 0.1 mm out of the ceiling's plane; Mitsuba's ceiling then includes the
//! 4.4 % of its area hidden above the light, which relume cuts away), and
//! `tests/reference/furnished-room.mitsuba.json` from
//! `python3 tests/support/mitsuba_objects.py scenes/generated/furnished-room.obj 1000000 4`
//! (14 min on 2 cores).
//!
//! Run: `cargo bench --bench rooms_mitsuba` (`PATCHES=1000,2000,4000,8000`,
//! `SCENE=door-ajar|cornell|furnished-room`, `ADAPTIVE=1` for `Resolution::Adaptive` instead of
//! `TargetPatches`, `BASE_SHARE=0.5` its base grid's share of the target, `ESTIMATOR=hemisphere|
//! pairwise` and `SAMPLES=n` for another form-factor estimator than the default reciprocal
//! hemisphere with 4,096 rays).

#[path = "../tests/support/room_light.rs"]
mod room_light;
mod util;

use relume::radiosity::formfactor::{Estimator, FormFactorParams};
use relume::radiosity::patches::adaptive::AdaptiveParams;
use relume::radiosity::patches::voxelize::Resolution;
use std::time::Instant;

fn main() {
    let root = env!("CARGO_MANIFEST_DIR");
    let name: String = util::env("SCENE", "door-ajar".to_string());
    let targets: Vec<u32> = util::env_list("PATCHES", "1000,2000,4000,8000");
    let adaptive = util::env("ADAPTIVE", 0u32) == 1;
    let base_share: f64 = util::env("BASE_SHARE", AdaptiveParams::new(1).base_share);
    let estimator = match util::env("ESTIMATOR", "reciprocal".to_string()).as_str() {
        "hemisphere" => Estimator::Hemisphere,
        "pairwise" => Estimator::Pairwise,
        "reciprocal" => Estimator::HemisphereReciprocal,
        other => panic!("ESTIMATOR={other}: expected reciprocal, hemisphere or pairwise"),
    };
    let ff = FormFactorParams {
        estimator,
        samples: util::env("SAMPLES", estimator.default_samples()),
        seed: 0,
    };
    let scene = room_light::room(&name);
    let reference: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(format!("{root}/tests/reference/{name}.mitsuba.json")).unwrap(),
    )
    .unwrap();
    let objects: Vec<&String> = reference.as_object().unwrap().keys().collect();
    println!(
        "{name}: {} triangles; relume per-object irradiance (patches | corner-interpolated) vs \
         Mitsuba, relative error, mean over RGB; {} patches; {:?} form factors, {} samples; {} \
         threads\n",
        scene.triangles.len(),
        if adaptive { "adaptive" } else { "uniform" },
        ff.estimator,
        ff.samples,
        rayon::current_num_threads()
    );
    print!("| object | Mitsuba (rel. std. error) |");
    for t in &targets {
        print!(" {t} |");
    }
    println!();
    let mut rows: Vec<String> = objects
        .iter()
        .map(|o| {
            let r = &reference[o.as_str()];
            let se: f64 = (0..3)
                .map(|c| r["stderr"][c].as_f64().unwrap() / r["mean"][c].as_f64().unwrap())
                .sum::<f64>()
                / 3.0;
            format!("| {o} | {:.2} % |", 100.0 * se)
        })
        .collect();
    let mut summary = Vec::new();
    for &target in &targets {
        let t0 = Instant::now();
        let resolution = if adaptive {
            Resolution::Adaptive(AdaptiveParams {
                base_share,
                ..AdaptiveParams::new(target)
            })
        } else {
            Resolution::TargetPatches(target)
        };
        let (light, patches) = room_light::object_light_by(&scene, resolution, &ff);
        let seconds = t0.elapsed().as_secs_f64();
        let mut worst = (0f64, 0f64);
        for (row, o) in rows.iter_mut().zip(&objects) {
            let r = &reference[o.as_str()];
            let got = light.iter().find(|l| &&l.name == o).unwrap();
            let err = |v: [f64; 3]| room_light::relative_error(v, r).iter().sum::<f64>() / 3.0;
            let (ep, ec) = (err(got.irradiance_patches), err(got.irradiance));
            if o.starts_with("dark.") || !name.starts_with("door") {
                worst = (worst.0.max(ep.abs()), worst.1.max(ec.abs()));
            }
            row.push_str(&format!(" {:+.1} % / {:+.1} % |", 100.0 * ep, 100.0 * ec));
        }
        summary.push(format!(
            "| {target} | {} | {:.1} s | {:.1} % | {:.1} % |",
            patches,
            seconds,
            100.0 * worst.0,
            100.0 * worst.1
        ));
    }
    for row in rows {
        println!("{row}");
    }
    println!("\n| target | patches | bake time | worst object (door scenes: of the dark room), patches | corners |");
    for s in summary {
        println!("{s}");
    }
}
