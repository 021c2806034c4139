//! The theme lookup (`shaders/theme.wgsl`) on the GPU against its CPU twin
//! (`relume::theme::compose::Lookup`), on whatever adapter exists (Mesa lavapipe in CI).

use crate::common;

use common::gpu;

fn bundled() -> relume::theme::ThemeSet {
    relume::load::themes::load_themes(&common::data("themes/puget-sound.ron"), None).unwrap()
}

#[test]
fn theme_albedo_kernel_matches_cpu_twin() {
    let Some(gpu) = gpu() else { return };
    let set = bundled();
    let base = &set.index.levels[0];
    // Points over the whole map, off the texel grid, at footprints that pick index levels 0,
    // 1, 2 and 4 and magnify (0.25).
    let mut points = vec![];
    let mut state = 12345u64;
    let mut next = || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 40) as f32 / (1u64 << 24) as f32
    };
    for footprint in [0.25f32, 1.0, 2.5, 3.0, 17.0] {
        for _ in 0..4000 {
            points.push([
                next() * base.width as f32,
                next() * base.height as f32,
                footprint,
            ]);
        }
    }
    for frame in [0u32, 9] {
        let out = relume::gpu::themes::albedo_at(&gpu, &set, frame, &points).unwrap();
        let look = set.lookup(frame);
        let mut worst = 0.0f32;
        let mut flipped = 0;
        for (p, g) in points.iter().zip(&out) {
            let q = [p[0], p[1]];
            assert_eq!(
                g[3] as u8,
                look.class_at(look.level(p[2]), q),
                "class at {p:?}"
            );
            let c = look.albedo(q, p[2]);
            let d = (0..3).map(|k| (c[k] - g[k]).abs()).fold(0.0f32, f32::max);
            // A lookup that lands within float rounding of a class border may pick the other
            // class on one side: counted, not bounded.
            if d > 1e-6 {
                flipped += 1;
            } else {
                worst = worst.max(d);
            }
        }
        eprintln!("frame {frame}: max |GPU − CPU| {worst:.2e} off borders, {flipped} of {} points differ by more", points.len());
        // Measured on lavapipe: max 3.0e-8, 0 points over 1e-6 (a 33x margin).
        assert!(flipped * 1000 <= points.len(), "{flipped} points differ");
    }
}

#[test]
fn the_packed_buffer_holds_every_level_losslessly() {
    // The CCC words decode (CPU twin of the shader's decode) to the index levels.
    let set = bundled();
    for (l, c) in set.compressed_levels().iter().enumerate() {
        assert_eq!(c.decode(), set.index.levels[l], "level {l}");
    }
}
