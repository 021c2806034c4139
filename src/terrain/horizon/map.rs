//! Horizon maps for N azimuths, quantised to u16 (built by the f32 line sweep,
//! [`crate::terrain::horizon::sweep::Sweeper::sweep_u16`]):
//! the sky-view factor, and hard shadows for any sun in O(1) per pixel by interpolating the
//! horizon between the two stored azimuths around the sun's (docs/algorithms.md §4.4).

use crate::heightmap::HeightMap;
use crate::terrain::horizon::sweep::Sweeper;
pub use crate::terrain::horizon::{decode, encode, STEP_DEG};
use crate::terrain::horizon::{directions, Direction};
use rayon::prelude::*;

/// What a horizon map is built for (the `horizon_maps` stage's knobs convert into it; their
/// ranges are checked there: 1..=360 directions, a positive finite radius).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HorizonSettings {
    /// Azimuths, near-uniform ([`directions`]).
    pub directions: usize,
    /// Planet radius in metres for curved ground (None = flat; Earth: 6371000).
    pub planet_radius: Option<f64>,
}

impl HorizonSettings {
    /// `directions` azimuths on flat ground.
    pub fn flat(directions: usize) -> Self {
        HorizonSettings {
            directions,
            planet_radius: None,
        }
    }
}

impl Default for HorizonSettings {
    fn default() -> Self {
        HorizonSettings::flat(64)
    }
}

/// Horizon angles for N directions, quantised to u16: angle = −90° + v·(180°/65535), an error
/// of at most 0.0014° (half a step).
#[derive(Clone, Debug, PartialEq)]
pub struct HorizonMap {
    pub width: usize,
    pub height: usize,
    /// Sorted by azimuth.
    pub directions: Vec<Direction>,
    /// One row-major plane per direction.
    pub angles: Vec<Vec<u16>>,
    /// The planet radius the map was built for (metres; None = flat ground).
    pub planet_radius: Option<f64>,
}

/// The horizon (degrees) interpolated with weight `w` between quantised angles `v0` and `v1`:
/// a sun below it is hidden.
#[inline]
pub fn horizon_at(v0: u16, v1: u16, w: f64) -> f64 {
    decode(v0) * (1.0 - w) + decode(v1) * w
}

/// The horizon test of the GPU (`shadowed_horizon` in `shaders/terrain_shadow.wgsl`), its f32 twin: shadowed when
/// `elevation_deg` is below the horizon interpolated with weight `w` between quantised angles
/// `v0` and `v1`. It differs from [`HorizonMap::shadow_mask`]'s f64 test only when the
/// elevation is within f32 rounding (≈ 1e-5°) of the interpolated horizon.
pub fn shadowed_f32(v0: u16, v1: u16, w: f32, elevation_deg: f32) -> bool {
    let step = STEP_DEG as f32;
    let (h0, h1) = (v0 as f32 * step - 90.0, v1 as f32 * step - 90.0);
    elevation_deg < h0 + (h1 - h0) * w
}

impl HorizonMap {
    /// The horizon map of `map` (one sweep per direction). The settings must be in range.
    pub fn build(map: &HeightMap, settings: &HorizonSettings) -> HorizonMap {
        Self::build_with_progress(map, settings, &crate::progress::Silent)
    }

    /// [`HorizonMap::build`], advancing `progress` by one unit per direction (the caller
    /// begins and finishes the phase).
    pub fn build_with_progress(
        map: &HeightMap,
        settings: &HorizonSettings,
        progress: &dyn crate::progress::Progress,
    ) -> HorizonMap {
        debug_assert!((1..=360).contains(&settings.directions));
        let directions = directions(settings.directions, map.cell_size);
        // One sweeper: the map's transpose is made once for all directions that need it; one
        // scratch plane for the transposed directions. The f32 sweep: within f32 rounding of
        // the exact f64 one (docs/terrain.md has the measured difference).
        let sweeper = Sweeper::new(map);
        let mut scratch = Vec::new();
        let angles = directions
            .iter()
            .map(|d| {
                let plane = sweeper.sweep_u16(d, settings.planet_radius, &mut scratch);
                progress.advance(1);
                plane
            })
            .collect();
        HorizonMap {
            width: map.width,
            height: map.height,
            directions,
            angles,
            planet_radius: settings.planet_radius,
        }
    }

    /// The two stored directions around `azimuth` and the weight of the second (linear in
    /// azimuth, on the circle).
    pub fn bracket(&self, azimuth: f64) -> (usize, usize, f64) {
        let n = self.directions.len();
        let az = azimuth.rem_euclid(360.0);
        let k1 = self
            .directions
            .iter()
            .position(|d| d.azimuth_deg > az)
            .unwrap_or(0);
        let k0 = (k1 + n - 1) % n;
        let (a0, a1) = (
            self.directions[k0].azimuth_deg,
            self.directions[k1].azimuth_deg,
        );
        let span = (a1 - a0).rem_euclid(360.0);
        let w = if span == 0.0 {
            0.0
        } else {
            (az - a0).rem_euclid(360.0) / span
        };
        (k0, k1, w)
    }

    /// Hard shadows for any sun in O(1) per pixel: shadowed when the elevation is below the
    /// horizon interpolated between the two stored azimuths around the sun's.
    pub fn shadow_mask(&self, sun: &crate::terrain::sun::Sun) -> Vec<bool> {
        self.mask(sun, |v0, v1, w| sun.elevation_deg < horizon_at(v0, v1, w))
    }

    /// Every texel's test `shadowed(v0, v1, w)` on the two planes around the sun's azimuth
    /// (lit at the zenith, shadowed at or below the horizon: the cases of
    /// [`crate::terrain::sun::TrackKind`], which the GPU decides the same way).
    fn mask(
        &self,
        sun: &crate::terrain::sun::Sun,
        shadowed: impl Fn(u16, u16, f64) -> bool + Sync,
    ) -> Vec<bool> {
        let n = self.width * self.height;
        if sun.elevation_deg >= 90.0 {
            return vec![false; n];
        }
        if sun.elevation_deg <= 0.0 {
            return vec![true; n];
        }
        let (k0, k1, w) = self.bracket(sun.azimuth_deg);
        let (p0, p1) = (&self.angles[k0], &self.angles[k1]);
        (0..n)
            .into_par_iter()
            .map(|i| shadowed(p0[i], p1[i], w))
            .collect()
    }

    /// Planes `k0` and `k1` packed per texel as the GPU reads them (`horizon_pair` of
    /// `shaders/terrain_shadow.wgsl`): `k0`'s value in the low 16 bits, `k1`'s in the high.
    pub fn packed_pair(&self, k0: usize, k1: usize) -> Vec<u32> {
        self.angles[k0]
            .par_iter()
            .zip(&self.angles[k1])
            .map(|(&a, &b)| a as u32 | (b as u32) << 16)
            .collect()
    }

    /// The GPU's horizon mask (`shadowed_horizon` in `shaders/terrain_shadow.wgsl`), its f32
    /// twin: the bracket and weight in f64 as the renderer computes them, the test in f32.
    pub fn shadow_mask_f32(&self, sun: &crate::terrain::sun::Sun) -> Vec<bool> {
        let e = sun.elevation_deg as f32;
        self.mask(sun, |v0, v1, w| shadowed_f32(v0, v1, w as f32, e))
    }

    /// The sky-view factor of a horizontal surface: the part of the sky hemisphere's
    /// projected area above the horizon, Σ_k w_k (1 − sin max(H_k, 0)), each direction weighted
    /// by half the azimuth gap to its neighbours (1 on flat ground; 1 − sin H under a uniform
    /// horizon H).
    pub fn sky_view(&self) -> Vec<f32> {
        let n = self.directions.len();
        let weights: Vec<f64> = (0..n)
            .map(|k| {
                let prev = self.directions[(k + n - 1) % n].azimuth_deg;
                let next = self.directions[(k + 1) % n].azimuth_deg;
                let gap = (next - prev).rem_euclid(360.0);
                let gap = if n == 1 { 720.0 } else { gap };
                0.5 * gap / 360.0
            })
            .collect();
        (0..self.width * self.height)
            .into_par_iter()
            .map(|i| {
                let mut v = 0.0;
                for (k, w) in weights.iter().enumerate() {
                    v += w * (1.0 - decode(self.angles[k][i]).max(0.0).to_radians().sin());
                }
                v as f32
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `encode` is `f64::round` of the step count for every angle: at every step's midpoint and
    /// the floats around it (where rounding half away from zero decides), at ±90°, beyond,
    /// ±∞ and NaN, and at 200,000 pseudo-random angles.
    #[test]
    fn encode_rounds_as_f64_round() {
        let reference = |deg: f64| ((deg.clamp(-90.0, 90.0) + 90.0) / STEP_DEG).round() as u16;
        let mut angles = vec![
            -90.0,
            90.0,
            -1e9,
            1e9,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
        ];
        for k in 0..=65535u32 {
            let mid = (k as f64 + 0.5) * STEP_DEG - 90.0;
            let mut x = mid;
            for _ in 0..3 {
                x = x.next_down();
            }
            for _ in 0..7 {
                angles.push(x);
                x = x.next_up();
            }
        }
        let mut s = 0x2545_F491_4F6C_DD1Du64;
        for _ in 0..200_000 {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            angles.push((s >> 11) as f64 / (1u64 << 53) as f64 * 200.0 - 100.0);
        }
        for deg in angles {
            assert_eq!(encode(deg), reference(deg), "{deg:e}");
        }
    }
}
