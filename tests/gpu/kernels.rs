//! Every WGSL kernel against its Rust twin, on whatever adapter exists (Mesa lavapipe in CI).
//! Without an adapter the GPU tests print a visible SKIP line, or fail under `CI=true` / `RELUME_REQUIRE_ALL=1`; `make test` installs lavapipe.

use crate::common;

use common::gpu;

use relume::gpu::{compute, readback, shader_source, SHADERS};

/// The GPU, or None with a visible message when no adapter exists at all.
#[test]
fn every_wgsl_file_validates_with_naga() {
    // Every file in shaders/ must be registered (embedded) and valid with common.wgsl prepended.
    let dir = common::data("shaders");
    let mut on_disk: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".wgsl"))
        .collect();
    on_disk.sort();
    let mut registered: Vec<String> = SHADERS.iter().map(|(n, _)| n.to_string()).collect();
    registered.sort();
    assert_eq!(
        on_disk, registered,
        "shaders/ and relume::gpu::SHADERS disagree"
    );
    for (name, _) in SHADERS {
        let src = shader_source(name).unwrap();
        let module = naga::front::wgsl::parse_str(&src)
            .unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(&src)));
        naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::all(),
        )
        .validate(&module)
        .unwrap_or_else(|e| panic!("{name}: {e:?}"));
    }
}

#[test]
fn tonemap_kernel_matches_cpu_twin() {
    let Some(gpu) = gpu() else { return };
    eprintln!(
        "adapter: {} ({}, {})",
        gpu.info.name, gpu.info.backend, gpu.info.device_type
    );
    // Extremes included: zero, negative, tiny, the sRGB knee, huge.
    let mut input: Vec<f32> = vec![
        0.0,
        -1.0,
        1e-9,
        0.0031308,
        0.004,
        0.5,
        1.0,
        7.5,
        1e6,
        f32::MAX / 4.0,
        3.0,
        0.01,
    ];
    for i in 0..300 {
        input.push((i as f32 * 0.37).sin().abs() * 10f32.powi(i % 7 - 3));
    }
    let count = input.len() as u32 / 3;
    let exposure = 1.7f32;
    let p = compute::pipeline(&gpu, "tonemap_test.wgsl", "main").unwrap();
    let params = compute::uniform(&gpu, "params", &[count, exposure.to_bits()]);
    let inb = compute::storage(&gpu, "in", &input);
    let out = compute::output(&gpu, "out", input.len() as u64 * 4);
    let g = compute::bind(
        &gpu,
        &p,
        &[
            params.as_entire_binding(),
            inb.as_entire_binding(),
            out.as_entire_binding(),
        ],
    );
    compute::dispatch(&gpu, &p, &g, [count.div_ceil(64), 1, 1]);
    let got = readback::read_f32(&gpu, &out).unwrap();
    for i in 0..count as usize {
        let want = relume::render::tonemap::tonemap(
            [input[3 * i], input[3 * i + 1], input[3 * i + 2]],
            exposure,
        );
        for c in 0..3 {
            let (g, w) = (got[3 * i + c], want[c]);
            // pow/exp on GPUs are accurate to a few ulp; 8-bit output never differs.
            assert!((g - w).abs() <= 2e-6, "texel {i} ch {c}: gpu {g} cpu {w}");
            assert_eq!(
                relume::render::tonemap::to_u8(g),
                relume::render::tonemap::to_u8(w)
            );
        }
    }
}
