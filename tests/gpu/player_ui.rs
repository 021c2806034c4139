//! What the player shows a person: a glTF file's camera as the first view, and the window's
//! panel driven through egui's input path under xvfb.

use crate::common::{self, bake, expect_code, gpu};
use crate::player::bake_pipeline;

#[test]
fn a_gltf_camera_is_the_first_view_and_travels_in_the_bake() {
    let tmp = tempfile::tempdir().unwrap();
    let gltf = crate::gltf_cameras::room_with_cameras(tmp.path());
    let pipeline = tmp.path().join("p.ron");
    std::fs::write(
        &pipeline,
        format!("Pipeline(input: Scene(path: {:?}), stages: [])", gltf),
    )
    .unwrap();
    let out = tmp.path().join("bake");
    let o = bake(
        tmp.path(),
        &[
            "run",
            "-q",
            pipeline.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ],
    );
    expect_code(&o, 0);
    let views = relume::baked::scene::read_views(&out).unwrap();
    assert_eq!(views.len(), 1);
    if gpu().is_none() {
        return;
    }
    let frames = tmp.path().join("frames");
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_relume-player"))
        .arg(&out)
        .args(["--headless", "--size", "64x48", "-q", "--out"])
        .arg(&frames)
        .output()
        .unwrap();
    expect_code(&o, 0);
    let j: serde_json::Value =
        serde_json::from_slice(&std::fs::read(frames.join("frames.json")).unwrap()).unwrap();
    // The node's world eye (1, 1, 2) looking along −x, yfov 0.8 rad.
    let numbers: Vec<f32> = j["camera"]
        .as_str()
        .unwrap()
        .split(',')
        .map(|v| v.parse().unwrap())
        .collect();
    let want = [1.0, 1.0, 2.0, 0.0, 1.0, 2.0, 0.8f32.to_degrees()];
    assert!(
        numbers.iter().zip(want).all(|(a, b)| (a - b).abs() < 1e-4),
        "{numbers:?}"
    );
}

/// The window's panel driven through egui's input path (`--panel-script`) under xvfb: moving
/// the sun by its buttons moves the light, switching the sun off darkens the frame, the panel
/// is drawn over the window but never into the player's frame, and the bake is untouched.
#[test]
fn the_panel_moves_and_switches_the_sun_in_a_window() {
    if gpu().is_none() {
        return;
    }
    if std::process::Command::new("xvfb-run")
        .arg("--help")
        .output()
        .is_err()
    {
        common::missing("xvfb-run for the panel test (apt-get install xvfb xauth)");
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    let dir = bake_pipeline(tmp.path(), "pipelines/cornell.ron");
    let before = common::contents(&dir);
    let script = tmp.path().join("script.txt");
    std::fs::write(
        &script,
        "3 screenshot a.png\n\
         5 click Sun +15°\n7 click Sun +15°\n9 click Sun +15°\n\
         12 screenshot b.png\n\
         14 click Sun\n\
         17 screenshot c.png\n17 window w.png\n",
    )
    .unwrap();
    let o = std::process::Command::new("xvfb-run")
        .args(["-a", env!("CARGO_BIN_EXE_relume-player")])
        .arg(&dir)
        .args(["--size", "320x240", "--sun", "20,30", "--exposure", "1"])
        .arg("--panel-script")
        .arg(&script)
        .args(["--exit-after", "19"])
        .output()
        .unwrap();
    expect_code(&o, 0);
    let load = |n: &str| image::open(tmp.path().join(n)).unwrap().to_rgb8();
    let (a, b, c) = (load("a.png"), load("b.png"), load("c.png"));
    let mean = |i: &image::RgbImage| {
        i.pixels()
            .map(|p| p.0.iter().map(|&v| v as f64).sum::<f64>())
            .sum::<f64>()
            / (3 * i.pixels().len()) as f64
    };
    let diff = |x: &image::RgbImage, y: &image::RgbImage| {
        x.pixels()
            .zip(y.pixels())
            .map(|(p, q)| (0..3).map(|k| p[k].abs_diff(q[k]) as f64).sum::<f64>())
            .sum::<f64>()
            / (3 * x.pixels().len()) as f64
    };
    // The sun 45° further round lights other parts of the box (measured 17.9/255 mean change);
    // switched off, only the ceiling light is left (mean 53.9 → 37.9).
    let moved = diff(&a, &b);
    eprintln!(
        "sun moved: {moved:.1}/255; means {:.1} {:.1} {:.1}",
        mean(&a),
        mean(&b),
        mean(&c)
    );
    assert!(moved > 5.0, "the sun buttons changed nothing ({moved})");
    assert!(
        mean(&c) < mean(&b) - 5.0,
        "the sun checkbox did not switch the sun off"
    );
    // What the window showed (lavapipe's X11 surfaces allow copies): the panel over the left
    // part, the frame elsewhere.
    {
        let w = load("w.png");
        assert_eq!(w.dimensions(), c.dimensions());
        let column = |img: &image::RgbImage, x: u32| {
            (0..img.height())
                .map(|y| img.get_pixel(x, y).0)
                .collect::<Vec<_>>()
        };
        assert_ne!(column(&w, 20), column(&c, 20), "no panel in the window");
        assert_eq!(
            column(&w, 315),
            column(&c, 315),
            "the panel reached the right edge"
        );
    }
    assert_eq!(
        common::contents(&dir),
        before,
        "the window changed the bake"
    );
}
