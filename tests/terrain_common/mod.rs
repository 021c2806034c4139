//! Random height maps for the terrain tests: plateaus, cliffs, noise and spikes, from a seed.
#![allow(dead_code)]

use relume::heightmap::HeightMap;

/// A small deterministic generator (SplitMix64).
pub struct Rng(pub u64);

impl Rng {
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [0, 1).
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
    pub fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n as u64) as usize
    }
}

/// A random map of `w`×`h` texels in one of several styles: quantised plateaus with cliffs,
/// smooth noise, sparse tall spikes, or a mix; `scale` multiplies the heights.
pub fn random_map(w: usize, h: usize, seed: u64, cell: [f64; 2], scale: f32) -> HeightMap {
    let mut rng = Rng(seed);
    let style = rng.below(4);
    let mut heights = vec![0.0f32; w * h];
    // Plateaus: random rectangles of constant height (cliffs at their edges).
    let rects = 1 + rng.below(12);
    for _ in 0..rects {
        let (x0, y0) = (rng.below(w), rng.below(h));
        let (x1, y1) = (
            (x0 + 1 + rng.below(w)).min(w),
            (y0 + 1 + rng.below(h)).min(h),
        );
        let level = rng.below(8) as f32 * 4.0;
        for y in y0..y1 {
            for x in x0..x1 {
                heights[y * w + x] = if style == 1 {
                    heights[y * w + x].max(level)
                } else {
                    level
                };
            }
        }
    }
    match style {
        0 => {} // pure plateaus
        1 => {
            // spikes
            for _ in 0..(1 + rng.below(8)) {
                let i = rng.below(w * h);
                heights[i] = 20.0 + rng.unit() as f32 * 100.0;
            }
        }
        2 => {
            // smooth noise on top
            let (fx, fy) = (rng.unit() * 0.3, rng.unit() * 0.3);
            for y in 0..h {
                for x in 0..w {
                    heights[y * w + x] +=
                        (8.0 * ((x as f64 * fx).sin() + (y as f64 * fy).cos())) as f32;
                }
            }
        }
        _ => {
            // white noise on some texels
            for v in heights.iter_mut() {
                if rng.unit() < 0.3 {
                    *v += (rng.unit() * 10.0) as f32;
                }
            }
        }
    }
    for v in heights.iter_mut() {
        *v *= scale;
    }
    HeightMap::new(w, h, heights, cell)
}

/// Proptest strategies for suns and cells at the numerical extremes: azimuths on the axes and
/// diagonals, 1e-12 and 1e-10 off an axis; elevations near the horizon and the zenith
/// (`with_ends`: exactly 0° and 90° too); square and anisotropic cells.
pub mod strategies {
    use proptest::prelude::*;

    pub fn azimuth() -> impl Strategy<Value = f64> {
        prop_oneof![
            prop::sample::select(vec![0.0, 90.0, 180.0, 270.0, 45.0, 135.0, 225.0, 315.0]),
            prop::sample::select(vec![0.0, 90.0, 180.0, 270.0]).prop_map(|a| a + 1e-12),
            prop::sample::select(vec![0.0, 90.0, 180.0, 270.0]).prop_map(|a| a - 1e-10),
            0.0..360.0f64,
        ]
    }

    pub fn elevation(with_ends: bool) -> impl Strategy<Value = f64> {
        let mut fixed = vec![1e-9, 1e-3, 0.5, 89.999, 89.999_999, 45.0];
        if with_ends {
            fixed.extend([0.0, 90.0]);
        }
        prop_oneof![prop::sample::select(fixed), 0.01..89.9f64]
    }

    pub fn cell() -> impl Strategy<Value = [f64; 2]> {
        prop::sample::select(vec![
            [1.0, 1.0],
            [30.0, 30.0],
            [1.0, 2.5],
            [0.7, 0.2],
            [40.0, 40.0],
        ])
    }
}
