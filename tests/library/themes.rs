//! Thematic textures (docs/themes.md): borders, animation, index mips, compression,
//! tiling, loaders and the `theme` command — each against an independent brute-force value.

use proptest::prelude::*;
use relume::theme::ccc::Ccc;
use relume::theme::compose::compose;
use relume::theme::index_map::{rasterize, IndexMap, Polygon};
use relume::theme::mip::IndexMips;
use relume::theme::spec::{MapSpec, TextureSource, ThemeDef, ThemeSpec};
use relume::theme::textures::Procedural;
use relume::theme::{Border, ThemeSet, Tiling};

/// A set of `n` flat themes (distinct colours) over `map`, every theme with `border` and
/// `tiling`.
fn set_of(
    map: IndexMap,
    n: usize,
    border: Border,
    tiling: Tiling,
    texture: Procedural,
) -> ThemeSet {
    let colours = [
        [0.8, 0.1, 0.1],
        [0.1, 0.8, 0.1],
        [0.1, 0.1, 0.8],
        [0.7, 0.7, 0.1],
    ];
    let spec = ThemeSpec {
        themes: (0..n)
            .map(|i| ThemeDef {
                name: format!("t{i}"),
                texture: TextureSource::Procedural(match texture {
                    Procedural::Flat(_) => Procedural::Flat(colours[i % 4]),
                    k => k,
                }),
                border,
                tiling,
            })
            .collect(),
        map: MapSpec::Rules {
            heightmap: None,
            rules: vec![],
            otherwise: "t0".into(),
        },
        texture_size: 16,
        noise: Default::default(),
        drift: [0.013, 0.007],
    };
    spec.check().unwrap();
    spec.assemble(map, vec![], &[])
}

/// Three regions: a disc, a band and the rest, on a w×w map.
fn regions(w: usize) -> IndexMap {
    let c = w as f64 / 2.0;
    let disc: Vec<[f64; 2]> = (0..64)
        .map(|k| {
            let a = k as f64 / 64.0 * std::f64::consts::TAU;
            [c + 0.3 * c * a.cos(), c + 0.3 * c * a.sin()]
        })
        .collect();
    let band = vec![
        [0.0, 0.1 * c],
        [w as f64, 0.25 * c],
        [w as f64, 0.4 * c],
        [0.0, 0.3 * c],
    ];
    rasterize(
        w,
        w,
        0,
        &[
            Polygon {
                class: 1,
                rings: vec![disc],
            },
            Polygon {
                class: 2,
                rings: vec![band],
            },
        ],
    )
}

/// Distance (texels, Euclidean between centres) from each texel to the nearest texel of
/// another class, capped at `cap` — brute force.
fn border_distance(m: &IndexMap, cap: i64) -> Vec<f64> {
    let (w, h) = (m.width as i64, m.height as i64);
    let mut out = vec![f64::INFINITY; m.data.len()];
    for r in 0..h {
        for c in 0..w {
            let v = m.at(c as usize, r as usize);
            let mut best = f64::INFINITY;
            for dr in -cap..=cap {
                for dc in -cap..=cap {
                    let (x, y) = (c + dc, r + dr);
                    if x >= 0 && y >= 0 && x < w && y < h && m.at(x as usize, y as usize) != v {
                        best = best.min(((dc * dc + dr * dr) as f64).sqrt());
                    }
                }
            }
            out[(r * w + c) as usize] = best;
        }
    }
    out
}

fn centre(i: usize, w: usize) -> [f32; 2] {
    [(i % w) as f32 + 0.5, (i / w) as f32 + 0.5]
}

#[test]
fn amplitude_zero_gives_the_raw_index_map() {
    let map = regions(128);
    let set = set_of(
        map.clone(),
        3,
        Border::Fractal {
            amplitude: 0.0,
            scale: 16.0,
        },
        Tiling::default(),
        Procedural::Flat([0.0; 3]),
    );
    let look = set.lookup(5);
    for i in 0..map.data.len() {
        assert_eq!(look.class(centre(i, 128), 1.0), map.data[i], "texel {i}");
    }
}

#[test]
fn raising_the_amplitude_moves_border_texels_only() {
    let map = regions(128);
    let dist = border_distance(&map, 8);
    for amplitude in [1.0f32, 3.0, 6.0] {
        let set = set_of(
            map.clone(),
            3,
            Border::Fractal {
                amplitude,
                scale: 16.0,
            },
            Tiling::default(),
            Procedural::Flat([0.0; 3]),
        );
        let look = set.lookup(0);
        let mut moved = 0;
        for (i, (&raw, &d)) in map.data.iter().zip(&dist).enumerate() {
            if look.class(centre(i, 128), 1.0) != raw {
                moved += 1;
                // The lookup moves by at most amplitude·√2 (|noise| ≤ 1 per axis); a texel
                // changes only if a texel of another class lies within that reach (+ half a
                // texel either side for the texel-centre distance).
                assert!(
                    d <= amplitude as f64 * 2f64.sqrt() + 1.0,
                    "amplitude {amplitude}: texel {i} at {d} texels from a border changed"
                );
            }
        }
        assert!(moved > 0, "amplitude {amplitude} moved no texel");
    }
}

/// Roughness of the border x(row) of a vertical split: mean squared step between rows over
/// the variance — high for a high-frequency border.
fn border_roughness(scale: f32) -> f64 {
    let w = 256;
    let map = IndexMap {
        width: w,
        height: w,
        data: (0..w * w).map(|i| u8::from(i % w >= w / 2)).collect(),
    };
    let set = set_of(
        map,
        2,
        Border::Fractal {
            amplitude: 8.0,
            scale,
        },
        Tiling::default(),
        Procedural::Flat([0.0; 3]),
    );
    let look = set.lookup(0);
    let x: Vec<f64> = (0..w)
        .map(|r| {
            (0..w)
                .filter(|&c| look.class(centre(r * w + c, w), 1.0) == 0)
                .count() as f64
        })
        .collect();
    let mean = x.iter().sum::<f64>() / w as f64;
    let var = x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / w as f64;
    let step = x.windows(2).map(|p| (p[1] - p[0]).powi(2)).sum::<f64>() / (w - 1) as f64;
    step / var
}

#[test]
fn the_noise_scale_sets_the_border_spectrum() {
    let fine = border_roughness(8.0);
    let coarse = border_roughness(64.0);
    eprintln!("border roughness: scale 8 → {fine:.3}, scale 64 → {coarse:.3}");
    // Measured 2.01 (scale 8) vs 0.28 (scale 64), 7.2x; ask for 3x.
    assert!(fine > 3.0 * coarse, "fine {fine} vs coarse {coarse}");
}

#[test]
fn animation_moves_border_texels_and_no_interior_texel() {
    let map = regions(96);
    let dist = border_distance(&map, 8);
    let amplitude = 3.0f32;
    let set = set_of(
        map.clone(),
        3,
        Border::Fractal {
            amplitude,
            scale: 16.0,
        },
        Tiling::default(),
        Procedural::Grass,
    );
    let a = compose(&set, 96, 96, 0);
    let b = compose(&set, 96, 96, 7);
    let mut changed = 0;
    for i in 0..a.len() {
        if a[i] != b[i] {
            changed += 1;
            assert!(
                dist[i] <= amplitude as f64 * 2f64.sqrt() + 1.0,
                "interior texel {i} changed"
            );
        }
    }
    assert!(changed > 0, "frame 7 changed nothing");
}

#[test]
fn in_region_noise_lowers_the_tiling_autocorrelation() {
    // One theme everywhere; 8 pixels per index texel, the texture repeats every 8 index
    // texels = 64 pixels.
    let autocorr = |warp: f32| {
        let tiling = Tiling {
            tile: 8.0,
            warp,
            warp_scale: 24.0,
        };
        let set = set_of(
            IndexMap::filled(32, 32, 0),
            1,
            Border::Natural,
            tiling,
            Procedural::Rock,
        );
        let img = compose(&set, 256, 256, 0);
        let lum: Vec<f64> = img.iter().map(|c| (c[0] + c[1] + c[2]) as f64).collect();
        let mean = lum.iter().sum::<f64>() / lum.len() as f64;
        let var = lum.iter().map(|v| (v - mean).powi(2)).sum::<f64>();
        let mut cov = 0.0;
        for r in 0..256 {
            for c in 0..256 - 64 {
                cov += (lum[r * 256 + c] - mean) * (lum[r * 256 + c + 64] - mean);
            }
        }
        cov / var * 256.0 / 192.0
    };
    let (plain, broken) = (autocorr(0.0), autocorr(0.35));
    eprintln!(
        "autocorrelation at the tile period: plain {plain:.3}, with in-region noise {broken:.3}"
    );
    assert!(plain > 0.95, "plain tiling repeats exactly: {plain}");
    assert!(
        broken < 0.5 * plain,
        "in-region noise kept the period: {broken}"
    );
}

fn arb_map() -> impl Strategy<Value = IndexMap> {
    (
        1usize..40,
        1usize..40,
        prop::collection::vec((0.0f64..40.0, 0.0f64..40.0, 1.0f64..15.0, 0u8..5), 0..6),
    )
        .prop_map(|(w, h, discs)| {
            let polys: Vec<Polygon> = discs
                .into_iter()
                .map(|(x, y, r, class)| Polygon {
                    class,
                    rings: vec![(0..12)
                        .map(|k| {
                            let a = k as f64 / 12.0 * std::f64::consts::TAU;
                            [x + r * a.cos(), y + r * a.sin()]
                        })
                        .collect()],
                })
                .collect();
            rasterize(w, h, 7, &polys)
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn index_mips_keep_only_what_covers_them(map in arb_map()) {
        let mips = IndexMips::build(map.clone());
        for (l, level) in mips.levels.iter().enumerate().skip(1) {
            let s = 1usize << l;
            for r in 0..level.height {
                for c in 0..level.width {
                    let mut counts = [0usize; 256];
                    for y in r * s..((r + 1) * s).min(map.height) {
                        for x in c * s..((c + 1) * s).min(map.width) {
                            counts[map.at(x, y) as usize] += 1;
                        }
                    }
                    let v = level.at(c, r) as usize;
                    prop_assert!(counts[v] > 0, "level {l} holds {v}, absent from its footprint");
                    // The majority, ties to the smaller index (brute force).
                    let best = (0..256).max_by(|&a, &b| counts[a].cmp(&counts[b]).then(b.cmp(&a))).unwrap();
                    prop_assert_eq!(v, best);
                }
            }
        }
        let top = mips.levels.last().unwrap();
        prop_assert_eq!((top.width, top.height), (1, 1));
    }

    #[test]
    fn ccc_with_exceptions_is_lossless_and_plain_ccc_counts_its_losses(map in arb_map()) {
        let exact = Ccc::encode(&map, true);
        prop_assert_eq!(exact.decode(), map.clone());
        prop_assert_eq!(exact.lossy_texels, 0);
        let blocks = map.width.div_ceil(4) * map.height.div_ceil(4);
        prop_assert_eq!(exact.bytes(), blocks * 4 + exact.exceptions.len() * 16);
        let lossy = Ccc::encode(&map, false);
        let differ = lossy.decode().data.iter().zip(&map.data).filter(|(a, b)| a != b).count();
        prop_assert_eq!(lossy.lossy_texels, differ);
        prop_assert!(lossy.exceptions.is_empty());
    }
}

#[test]
fn a_one_texel_island_vanishes_at_level_one() {
    let mut map = IndexMap::filled(16, 16, 2);
    map.data[5 * 16 + 9] = 4;
    let mips = IndexMips::build(map);
    assert_eq!(mips.levels[0].histogram()[4], 1);
    assert_eq!(mips.levels[1].histogram()[4], 0);
    assert_eq!(mips.mixed(1), 1);
}

#[test]
fn procedural_theme_textures_tile_without_a_seam() {
    for kind in [
        Procedural::Water,
        Procedural::Sand,
        Procedural::Grass,
        Procedural::Forest,
        Procedural::Rock,
        Procedural::Snow,
    ] {
        let n = 64;
        let t = relume::theme::textures::procedural(kind, n, 3);
        let step =
            |a: [f32; 3], b: [f32; 3]| (0..3).map(|k| (a[k] - b[k]).abs()).fold(0.0f32, f32::max);
        let inner = (0..n)
            .flat_map(|r| (0..n - 1).map(move |c| (r, c)))
            .map(|(r, c)| step(t[r * n + c], t[r * n + c + 1]))
            .fold(0.0f32, f32::max);
        let inner_v = (0..n - 1)
            .flat_map(|r| (0..n).map(move |c| (r, c)))
            .map(|(r, c)| step(t[r * n + c], t[(r + 1) * n + c]))
            .fold(0.0f32, f32::max);
        let seam = (0..n)
            .map(|r| step(t[r * n + n - 1], t[r * n]))
            .fold(0.0f32, f32::max);
        let seam_v = (0..n)
            .map(|c| step(t[(n - 1) * n + c], t[c]))
            .fold(0.0f32, f32::max);
        assert!(
            seam <= inner * 1.01 && seam_v <= inner_v * 1.01,
            "{kind:?}: seam {seam}/{seam_v} vs {inner}/{inner_v}"
        );
    }
}

#[test]
fn themes_bin_round_trips_and_refuses_truncation() {
    let set = set_of(
        regions(64),
        3,
        Border::Fractal {
            amplitude: 2.0,
            scale: 8.0,
        },
        Tiling::default(),
        Procedural::Sand,
    );
    let bytes = relume::baked::themes::encode(&set);
    let back = relume::baked::themes::decode(&bytes).unwrap();
    assert_eq!(back.index, set.index);
    assert_eq!(back.classes, set.classes);
    assert_eq!(back.textures, set.textures);
    assert_eq!(back.noise, set.noise);
    assert_eq!((back.themes, back.drift), (set.themes.clone(), set.drift));
    for cut in [0, 11, 40, bytes.len() / 2, bytes.len() - 1] {
        assert!(
            relume::baked::themes::decode(&bytes[..cut]).is_err(),
            "cut at {cut}"
        );
    }
    let mut longer = bytes.clone();
    longer.push(0);
    assert!(relume::baked::themes::decode(&longer).is_err());
}

#[test]
fn theme_texels_encode_to_the_nearest_srgb_byte() {
    let table = relume::theme::textures::srgb_table();
    for k in 0..=10_000 {
        let v = k as f32 / 10_000.0;
        let e = relume::theme::textures::encode_srgb8(&table, v) as usize;
        // Nearest in linear light among all 256 bytes (brute force)...
        let best = (0..256)
            .min_by(|&a, &b| (table[a] - v).abs().total_cmp(&(table[b] - v).abs()))
            .unwrap();
        assert!(
            (table[e] - v).abs() <= (table[best] - v).abs(),
            "v {v}: {e} vs {best}"
        );
        // ...and within one step of the player's sRGB encoder (which rounds in sRGB space).
        let other = relume::render::tonemap::linear_to_srgb8(v) as i32;
        assert!((e as i32 - other).abs() <= 1, "v {v}: {e} vs {other}");
    }
}
