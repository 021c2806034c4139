//! The turbulence (perturbation) map: a tileable two-channel fractal noise that displaces the
//! index-map lookup (fractal borders) and the theme-texture lookup (tiling breaker).
//!
//! Each channel is a sum of `octaves` periodic gradient-noise (Perlin) octaves over the unit
//! square: octave k has `base_period · 2^k` lattice cells per side and amplitude 2^-k, so the
//! higher spatial frequencies have the smaller amplitude, the spectrum Vyatkin et al. (2018) ask
//! of "turbulent noise". The lattice gradients are hashed modulo the octave's period, so the sum is
//! exactly periodic with period 1 and the map wraps without a seam. The channels are scaled
//! together so that the largest |value| over the map is 1: an amplitude A then displaces by at
//! most A. (Perlin's "turbulence" sums |noise|, which is never negative; a displacement needs
//! signed values, so this is the signed fractal sum.)
//!
//! Sampling ([`TurbulenceMap::sample`]) is bilinear with wrap-around in f32: the twin of
//! `theme_noise` in `shaders/theme.wgsl`.

/// A `size`×`size` two-channel turbulence map over one period of the unit square.
#[derive(Clone, Debug, PartialEq)]
pub struct TurbulenceMap {
    pub size: usize,
    /// Row-major (x, y) displacement pairs in [-1, 1].
    pub values: Vec<[f32; 2]>,
}

/// How to generate a turbulence map.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NoiseSettings {
    /// Texels per side (the map's memory is size² · 8 bytes).
    pub size: usize,
    /// Octaves summed (1 = smooth gradient noise).
    pub octaves: u32,
    /// Lattice cells per side of the first octave.
    pub base_period: u32,
    /// Seed of the gradient hash.
    pub seed: u64,
}

impl Default for NoiseSettings {
    fn default() -> Self {
        NoiseSettings {
            size: 256,
            octaves: 5,
            base_period: 4,
            seed: 1,
        }
    }
}

/// A 64-bit mix of lattice coordinates and seed (splitmix64 finaliser).
fn hash(x: u32, y: u32, seed: u64) -> u64 {
    let mut z = seed ^ ((x as u64) << 32 | y as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// The unit gradient at lattice point (x, y).
fn gradient(x: u32, y: u32, seed: u64) -> [f64; 2] {
    let a = (hash(x, y, seed) >> 11) as f64 / (1u64 << 53) as f64 * std::f64::consts::TAU;
    [a.cos(), a.sin()]
}

/// Periodic 2-D gradient noise at (x, y) in lattice units with `period` cells per side.
pub fn perlin(x: f64, y: f64, period: u32, seed: u64) -> f64 {
    let (fx, fy) = (x.floor(), y.floor());
    let (tx, ty) = (x - fx, y - fy);
    let p = period as i64;
    let wrap = |v: f64| (v as i64).rem_euclid(p) as u32;
    let fade = |t: f64| t * t * t * (t * (t * 6.0 - 15.0) + 10.0);
    let corner = |dx: f64, dy: f64| {
        let g = gradient(wrap(fx + dx), wrap(fy + dy), seed);
        g[0] * (tx - dx) + g[1] * (ty - dy)
    };
    let (u, v) = (fade(tx), fade(ty));
    let a = corner(0.0, 0.0) + u * (corner(1.0, 0.0) - corner(0.0, 0.0));
    let b = corner(0.0, 1.0) + u * (corner(1.0, 1.0) - corner(0.0, 1.0));
    a + v * (b - a)
}

/// The fractal sum of `octaves` periodic octaves at (u, v) in the unit square.
pub fn fractal(u: f64, v: f64, s: &NoiseSettings, channel: u64) -> f64 {
    let seed = s.seed.wrapping_mul(0x2545_F491_4F6C_DD1D) ^ channel;
    (0..s.octaves)
        .map(|k| {
            let period = s.base_period << k;
            let f = period as f64;
            perlin(u * f, v * f, period, seed.wrapping_add(k as u64)) / (1u64 << k) as f64
        })
        .sum()
}

impl TurbulenceMap {
    /// Generate the map (deterministic for given settings).
    pub fn generate(s: &NoiseSettings) -> TurbulenceMap {
        let n = s.size.max(1);
        let mut values: Vec<[f32; 2]> = Vec::with_capacity(n * n);
        let mut raw = Vec::with_capacity(n * n);
        for row in 0..n {
            for col in 0..n {
                let (u, v) = ((col as f64 + 0.5) / n as f64, (row as f64 + 0.5) / n as f64);
                raw.push([fractal(u, v, s, 0), fractal(u, v, s, 1)]);
            }
        }
        let peak = raw
            .iter()
            .flat_map(|p| [p[0].abs(), p[1].abs()])
            .fold(0.0f64, f64::max);
        let scale = if peak > 0.0 { 1.0 / peak } else { 0.0 };
        values.extend(
            raw.iter()
                .map(|p| [(p[0] * scale) as f32, (p[1] * scale) as f32]),
        );
        TurbulenceMap { size: n, values }
    }

    /// Bilinear sample with wrap-around at (u, v) (period 1): twin of `theme_noise`.
    pub fn sample(&self, u: f32, v: f32) -> [f32; 2] {
        let m = self.size as i32;
        wrap_bilinear(m, u, v, |c, r| self.values[(r * m + c) as usize])
    }
}

/// Bilinear interpolation of an n×n grid that wraps, at (u, v) in periods (texel centres at
/// (i + ½)/n), fetching wrapped texels (column, row) from `fetch`: the arithmetic of
/// `wrap_bilinear` in `shaders/theme.wgsl`, shared by the turbulence map and theme textures.
pub fn wrap_bilinear<const K: usize>(
    n: i32,
    u: f32,
    v: f32,
    fetch: impl Fn(i32, i32) -> [f32; K],
) -> [f32; K] {
    let nf = n as f32;
    let x = (u - u.floor()) * nf - 0.5;
    let y = (v - v.floor()) * nf - 0.5;
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = (x - x0, y - y0);
    let at = |c: i32, r: i32| fetch(c.rem_euclid(n), r.rem_euclid(n));
    let (c0, r0) = (x0 as i32, y0 as i32);
    let (a, b, c, d) = (
        at(c0, r0),
        at(c0 + 1, r0),
        at(c0, r0 + 1),
        at(c0 + 1, r0 + 1),
    );
    std::array::from_fn(|k| {
        let top = a[k] + (b[k] - a[k]) * fx;
        let bottom = c[k] + (d[k] - c[k]) * fx;
        top + (bottom - top) * fy
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn perlin_is_periodic_and_zero_on_the_lattice() {
        for &(x, y) in &[(0.3, 0.7), (2.9, 1.1), (3.5, 0.25)] {
            let a = perlin(x, y, 4, 7);
            assert!((a - perlin(x + 4.0, y, 4, 7)).abs() < 1e-12);
            assert!((a - perlin(x, y - 8.0, 4, 7)).abs() < 1e-12);
        }
        assert_eq!(perlin(2.0, 3.0, 4, 7), 0.0);
    }

    #[test]
    fn map_is_normalised_and_wraps_without_a_seam() {
        let m = TurbulenceMap::generate(&NoiseSettings {
            size: 64,
            ..Default::default()
        });
        let peak = m.values.iter().flat_map(|p| [p[0].abs(), p[1].abs()]);
        assert!((peak.fold(0.0f32, f32::max) - 1.0).abs() < 1e-6);
        // Across the wrap the step between neighbours is no larger than inside the map.
        let step = |a: [f32; 2], b: [f32; 2]| (a[0] - b[0]).abs().max((a[1] - b[1]).abs());
        let n = m.size;
        let inner = (0..n)
            .flat_map(|r| (0..n - 1).map(move |c| (r, c)))
            .map(|(r, c)| step(m.values[r * n + c], m.values[r * n + c + 1]))
            .fold(0.0f32, f32::max);
        let seam = (0..n)
            .map(|r| step(m.values[r * n + n - 1], m.values[r * n]))
            .fold(0.0f32, f32::max);
        assert!(seam <= inner * 1.01, "seam {seam} vs inner {inner}");
    }
}
