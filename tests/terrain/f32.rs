//! The f32 twins of the hard-shadow kernels (what a GPU port evaluates): the accelerated and
//! the exact f32 traversals agree on every pixel, like their f64 originals, and f32 differs from
//! the f64 reference only on a few pixels in 10,000, those whose deciding sample lies within
//! f32 rounding (millimetres) of the sun ray.

use crate::terrain_common;

use proptest::prelude::*;
use rayon::prelude::*;
use relume::heightmap::HeightMap;
use relume::terrain::hard::exact_traversal::shadowed_exact;
use relume::terrain::hard::hard_f32::{shadowed_accelerated_f32, shadowed_exact_f32, TrackF32};
use relume::terrain::{MinMaxMipmap, Sun, Track};
use terrain_common::random_map;

/// (pixels where f32 exact ≠ f32 accelerated, pixels where f32 ≠ f64, pixels).
fn compare(map: &HeightMap, sun: &Sun) -> (usize, usize, usize) {
    let mip = MinMaxMipmap::build(map);
    let track = Track::new(sun, map.cell_size);
    let t32 = TrackF32::from(&track);
    let (_, max) = map.min_max();
    let (a, b) = (0..map.height)
        .into_par_iter()
        .map(|r| {
            let mut d = (0, 0);
            for c in 0..map.width {
                let e32 = shadowed_exact_f32(map, &t32, c, r, max);
                d.0 += (e32 != shadowed_accelerated_f32(map, &mip, &t32, c, r)) as usize;
                d.0 += (e32 != shadowed_exact_f32(map, &t32, c, r, f32::INFINITY)) as usize;
                d.1 += (e32 != shadowed_exact(map, &track, c, r, max)) as usize;
            }
            d
        })
        .reduce(|| (0, 0), |x, y| (x.0 + y.0, x.1 + y.1));
    (a, b, map.width * map.height)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    #[test]
    fn f32_accelerated_equals_f32_exact(
        w in 1usize..=200, h in 1usize..=100, seed in any::<u64>(),
        az in prop_oneof![Just(0.0), Just(90.0), Just(135.0), Just(270.0 + 1e-12), 0.0..360.0f64],
        el in prop_oneof![Just(1e-6), Just(89.999), 0.01..89.9f64],
        cell in prop::sample::select(vec![[1.0, 1.0], [30.0, 30.0], [1.0, 2.5]]),
    ) {
        let map = random_map(w, h, seed, cell, 1.0);
        let (differ, _, _) = compare(&map, &Sun::new(az, el).unwrap());
        prop_assert_eq!(differ, 0);
    }
}

#[test]
fn f32_stays_within_a_few_boundary_pixels_of_f64_on_real_dems() {
    let root = env!("CARGO_MANIFEST_DIR");
    for (file, factor) in [("bigtujunga.ron", 2), ("puget-sound.ron", 8)] {
        let p = relume::pipeline::parse_pipeline(std::path::Path::new(&format!(
            "{root}/pipelines/{file}"
        )))
        .unwrap();
        let map = match relume::load::load_input(&p.input).unwrap() {
            relume::load::LoadedInput::HeightMap(m, _) => m.downsample(factor),
            _ => unreachable!(),
        };
        let (mut flips, mut total) = (0, 0);
        for az in [0.0, 45.0, 135.0, 300.0] {
            for el in [5.0, 20.0] {
                let (differ, f32_vs_f64, n) = compare(&map, &Sun::new(az, el).unwrap());
                assert_eq!(differ, 0, "{file} az {az} el {el}");
                flips += f32_vs_f64;
                total += n;
            }
        }
        eprintln!("{file}: f32 differs from f64 on {flips} of {total} pixels");
        // Measured: about 3 in 10,000 on the SRTM map (f32 positions near x ≈ 600 carry 6e-5
        // texel of error, a few millimetres of height on steep slopes). Allow 1 in 1,000.
        assert!(
            flips * 1_000 <= total,
            "{file}: {flips} of {total} pixels flip in f32"
        );
    }
}
