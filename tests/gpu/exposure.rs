//! Automatic exposure: the GPU histogram against its CPU twin (`render::exposure`), and the
//! player's one-shot headless exposure against the log-average of its own frame computed here
//! without the histogram.

use crate::common::{expect_code, gpu};
use relume::gpu::exposure::ExposureMeter;
use relume::render::exposure::{histogram, BINS, LOG2_MAX, LOG2_MIN, SETTLED_EV};
use wgpu::util::DeviceExt;

/// A deterministic frame: every byte value in every channel, black pixels (no luminance), and
/// saturated ones.
fn test_frame(w: u32, h: u32) -> Vec<u8> {
    let mut x = 0x2545_f491_u32;
    let mut next = || {
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        x
    };
    (0..w * h)
        .flat_map(|i| match i % 11 {
            0 => [0, 0, 0, 255],
            1 => [255, 255, 255, 255],
            2 => [(i % 256) as u8, (i % 256) as u8, (i % 256) as u8, 255],
            _ => {
                let r = next();
                [r as u8, (r >> 8) as u8, (r >> 16) as u8, 255]
            }
        })
        .collect()
}

#[test]
fn gpu_histogram_matches_its_cpu_twin() {
    let Some(gpu) = gpu() else { return };
    let (w, h) = (257u32, 131u32);
    let pixels = test_frame(w, h);
    let texture = gpu.device.create_texture_with_data(
        &gpu.queue,
        &wgpu::TextureDescriptor {
            label: Some("exposure test frame"),
            size: wgpu::Extent3d {
                width: w,
                height: h,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba8Unorm,
            usage: wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        },
        wgpu::util::TextureDataOrder::LayerMajor,
        &pixels,
    );
    let view = texture.create_view(&Default::default());
    let meter = ExposureMeter::new(&gpu).unwrap();
    let on_gpu = meter.histogram(&gpu, &view, w, h).unwrap();
    let on_cpu = histogram(&pixels);
    let counted: u32 = on_cpu.iter().sum();
    assert_eq!(on_gpu.iter().sum::<u32>(), counted, "pixels counted");
    let lit = pixels.chunks(4).filter(|p| p[..3] != [0, 0, 0]).count() as u32;
    assert_eq!(counted, lit, "black pixels left out");
    // Each pixel's bin may differ only where log2 of its luminance sits on a bin edge within
    // the GPU's log2 error (a few ulp): measured 0 pixels of 30,594 on lavapipe. Bound: 0.1 %.
    let moved: u32 = on_gpu
        .iter()
        .zip(&on_cpu)
        .map(|(a, b)| a.abs_diff(*b))
        .sum::<u32>()
        / 2;
    eprintln!("pixels in another bin: {moved} of {counted}");
    assert!(
        moved * 1000 <= counted,
        "{moved} of {counted} pixels binned differently"
    );
}

/// sRGB display value (0..=1) → linear, IEC 61966-2-1, written out here independently.
fn decode_srgb(v: f64) -> f64 {
    if v <= 0.04045 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

#[test]
fn headless_auto_exposure_is_the_log_average_of_its_frame() {
    if gpu().is_none() {
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    let baked = crate::player::bake_pipeline(tmp.path(), "pipelines/cornell.ron");
    let render = |name: &str, extra: &[&str]| {
        let out = tmp.path().join(name);
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_relume-player"))
            .arg(&baked)
            .args(["--headless", "--size", "160x120", "-q", "--out"])
            .arg(&out)
            .args(extra)
            .output()
            .unwrap();
        expect_code(&o, 0);
        let j: serde_json::Value =
            serde_json::from_slice(&std::fs::read(out.join("frames.json")).unwrap()).unwrap();
        let img = image::open(out.join("frame_0000.png")).unwrap().to_rgba8();
        (j, img)
    };
    let (j, img) = render("auto", &[]);
    assert_eq!(j["exposure_mode"], "auto");
    let e = j["exposure"].as_f64().unwrap();
    // The log-average of the frame, from its pixels: display bytes → x·E (inverse sRGB, inverse
    // Reinhard), Rec. 709 luminance, black pixels left out, the darkest and brightest 10 %
    // dropped, mean of log2. No histogram: its bins are what this checks.
    let mut logs: Vec<f64> = img
        .pixels()
        .filter(|p| p[0] != 0 || p[1] != 0 || p[2] != 0)
        .map(|p| {
            let x = |c: u8| {
                if c == 255 {
                    return (LOG2_MAX as f64).exp2();
                }
                let y = decode_srgb(c as f64 / 255.0);
                y / (1.0 - y)
            };
            (0.2126 * x(p[0]) + 0.7152 * x(p[1]) + 0.0722 * x(p[2])).log2()
        })
        .collect();
    logs.sort_by(f64::total_cmp);
    let n = logs.len();
    let kept = &logs[n / 10..n * 9 / 10];
    let mean = kept.iter().sum::<f64>() / kept.len() as f64;
    let wanted = e * 0.18 / mean.exp2();
    // The search stops within SETTLED_EV of its fixed point; the histogram's bin centres move
    // the mean by at most half a bin (0.078 stops); the percentile cut by whole pixels here
    // against fractions of bins there: 0.02 stops of margin.
    let half_bin = 0.5 * ((LOG2_MAX - LOG2_MIN) / BINS as f32) as f64;
    let off = (wanted / e).log2().abs();
    eprintln!("auto exposure {e:.4}, log-average asks for {wanted:.4} ({off:.4} stops)");
    assert!(off <= SETTLED_EV as f64 + half_bin + 0.02, "{off} stops");
    // The frame reads well: median luma in the middle of the range.
    let mut luma: Vec<u32> = img
        .pixels()
        .map(|p| (2126 * p[0] as u32 + 7152 * p[1] as u32 + 722 * p[2] as u32) / 10000)
        .collect();
    luma.sort_unstable();
    let median = luma[luma.len() / 2];
    assert!((60..=190).contains(&median), "median luma {median}");
    // --exposure fixes it.
    let (j, _) = render("fixed", &["--exposure", "0.5"]);
    assert_eq!(j["exposure_mode"], "fixed");
    assert_eq!(j["exposure"].as_f64().unwrap(), 0.5);
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_relume-player"))
        .arg(&baked)
        .args(["--headless", "--exposure", "0"])
        .output()
        .unwrap();
    let err = expect_code(&o, 2);
    assert!(
        err.contains("--exposure") && err.contains("positive"),
        "{err}"
    );
}
