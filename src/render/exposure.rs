//! Automatic exposure from the frame's log-average luminance (Reinhard et al. 2002, "Photographic
//! tone reproduction"): the exposure that maps the frame's geometric-mean luminance to middle
//! grey (`key` = 0.18) — the CPU twin of `shaders/exposure_histogram.wgsl`.
//!
//! The frame is read where it already is, in the 8-bit display target, not in a second
//! floating-point target: the display transform ([`crate::render::tonemap::tonemap`], sRGB of
//! `y = x·E / (1 + x·E)`) is strictly increasing, so each display byte maps back to one value of
//! `x·E` ([`display_lut`]). Byte 1 decodes to `x·E ≈ 3·10⁻⁴`, byte 254 to `x·E ≈ 250`: one frame
//! resolves 19 stops around the exposure it was drawn with, and a frame drawn too dark or too
//! bright is drawn again with a better guess ([`next_exposure`]; headless runs iterate to a fixed
//! point, the window follows over frames, [`smooth`]). Pixels that are black in every channel
//! carry no luminance (background, or below the first byte) and are left out.
//!
//! Luminance (Rec. 709 weights) goes into [`BINS`] bins of log₂ over [[`LOG2_MIN`],
//! [`LOG2_MAX`]) of `x·E`; the mean log₂ over the pixels between the `low` and `high` fractions
//! of the histogram (the darkest 10 % and brightest 10 % by default: a lamp or a black corner
//! does not set the picture's exposure) is the log-average.

use crate::scene::texture::srgb_to_linear;

/// Histogram bins.
pub const BINS: usize = 128;
/// log₂ of the smallest `x·E` binned (below byte 1's value: everything visible is inside).
pub const LOG2_MIN: f32 = -12.0;
/// log₂ of the largest `x·E` binned (above byte 254's value).
pub const LOG2_MAX: f32 = 8.0;

/// How the exposure is found.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AutoExposure {
    /// The display value the log-average maps to before the tone curve (Reinhard's key).
    pub key: f32,
    /// Fractions of the binned pixels left out at the dark and at the bright end.
    pub low: f32,
    pub high: f32,
    /// Stops added to the exposure found (the window's `[` `]` keys).
    pub compensation_ev: f32,
}

impl Default for AutoExposure {
    fn default() -> Self {
        AutoExposure {
            key: 0.18,
            low: 0.1,
            high: 0.9,
            compensation_ev: 0.0,
        }
    }
}

/// How a player sets the exposure: fixed (`--exposure X`), or found from each frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Exposure {
    Fixed(f32),
    Auto(AutoExposure),
}

impl Default for Exposure {
    fn default() -> Self {
        Exposure::Auto(AutoExposure::default())
    }
}

/// Exposures are kept within 2^±24 (a frame of nothing keeps the last one).
const EXPOSURE_RANGE: (f32, f32) = (5.96e-8, 1.68e7);

/// Display byte → `x·E` (inverse sRGB, inverse Reinhard), computed in f64. Byte 255 (the curve
/// reaches it only at infinity) maps to the top of the binned range.
pub fn display_lut() -> [f32; 256] {
    std::array::from_fn(|v| {
        if v == 255 {
            return LOG2_MAX.exp2();
        }
        let y = srgb_to_linear(v as f32 / 255.0) as f64;
        (y / (1.0 - y)) as f32
    })
}

/// The bin of a display pixel, None when it is black in every channel. Twin of `bin_of` in
/// exposure_histogram.wgsl.
pub fn bin_of(lut: &[f32; 256], rgb: [u8; 3]) -> Option<usize> {
    if rgb == [0, 0, 0] {
        return None;
    }
    let l = 0.2126 * lut[rgb[0] as usize]
        + 0.7152 * lut[rgb[1] as usize]
        + 0.0722 * lut[rgb[2] as usize];
    let b = ((l.log2() - LOG2_MIN) * (BINS as f32 / (LOG2_MAX - LOG2_MIN))).floor();
    Some(b.clamp(0.0, BINS as f32 - 1.0) as usize)
}

/// The histogram of an RGBA8 frame (rows of `width` pixels, 4 bytes each).
pub fn histogram(rgba: &[u8]) -> [u32; BINS] {
    let lut = display_lut();
    let mut h = [0u32; BINS];
    for p in rgba.chunks_exact(4) {
        if let Some(b) = bin_of(&lut, [p[0], p[1], p[2]]) {
            h[b] += 1;
        }
    }
    h
}

/// The mean log₂ of `x·E` over the histogram between the `low` and `high` fractions of its
/// pixels (bin centres; partial bins at the two cuts count by the fraction inside). None for an
/// empty histogram.
pub fn mean_log2(hist: &[u32; BINS], low: f32, high: f32) -> Option<f32> {
    let total: u64 = hist.iter().map(|&c| c as u64).sum();
    if total == 0 {
        return None;
    }
    let (lo, hi) = (low as f64 * total as f64, high as f64 * total as f64);
    let width = ((LOG2_MAX - LOG2_MIN) / BINS as f32) as f64;
    let (mut below, mut sum, mut weight) = (0.0f64, 0.0f64, 0.0f64);
    for (b, &c) in hist.iter().enumerate() {
        let (start, end) = (below, below + c as f64);
        below = end;
        let inside = (end.min(hi) - start.max(lo)).max(0.0);
        if inside > 0.0 {
            sum += inside * (LOG2_MIN as f64 + (b as f64 + 0.5) * width);
            weight += inside;
        }
    }
    // A histogram whose kept window holds no pixel (e.g. low = high): the median bin.
    if weight == 0.0 {
        let mut below = 0.0;
        for (b, &c) in hist.iter().enumerate() {
            below += c as f64;
            if below >= lo.max(1.0) {
                return Some((LOG2_MIN as f64 + (b as f64 + 0.5) * width) as f32);
            }
        }
    }
    Some((sum / weight) as f32)
}

/// The exposure that brings a frame drawn at exposure `used` (with histogram `hist`) to the key.
/// A frame with no lit pixel asks for 2¹⁰ times more light (it may have been drawn far too
/// dark); the result stays within 2^±24.
pub fn next_exposure(hist: &[u32; BINS], used: f32, a: &AutoExposure) -> f32 {
    let e = match mean_log2(hist, a.low, a.high) {
        Some(m) => used * a.key / m.exp2() * a.compensation_ev.exp2(),
        None => used * 1024.0,
    };
    e.clamp(EXPOSURE_RANGE.0, EXPOSURE_RANGE.1)
}

/// The window's exposure after `dt` seconds of following `target` from `current`: exponential
/// in stops with time constant `tau` seconds (an eye adapts in a fraction of a second to light,
/// more slowly to the dark: `tau` is the caller's).
pub fn smooth(current: f32, target: f32, dt: f32, tau: f32) -> f32 {
    if current.is_nan() || current <= 0.0 || current.is_infinite() {
        return target;
    }
    let k = 1.0 - (-dt.max(0.0) / tau.max(1e-3)).exp();
    (current.log2() + k * (target.log2() - current.log2())).exp2()
}

/// When a headless search stops: the next exposure within this many stops of the last.
pub const SETTLED_EV: f32 = 1.0 / 16.0;
/// At most this many frames are drawn to find a headless exposure.
pub const MAX_TRIES: usize = 5;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::tonemap::{to_u8, tonemap};

    #[test]
    fn lut_inverts_the_display_transform() {
        let lut = display_lut();
        for v in 1..255u8 {
            let [r, _, _] = tonemap([lut[v as usize], 0.0, 0.0], 1.0);
            assert_eq!(to_u8(r), v, "byte {v}");
        }
        assert!(lut[1] > LOG2_MIN.exp2() && lut[254] < LOG2_MAX.exp2());
    }

    #[test]
    fn grey_frame_maps_to_the_key() {
        // A uniform grey of radiance 0.01 drawn at exposure 1: the next exposure brings it to
        // 0.18 within the byte's quantisation and half a bin.
        let [v, _, _] = tonemap([0.01; 3], 1.0).map(to_u8);
        let frame: Vec<u8> = (0..100).flat_map(|_| [v, v, v, 255]).collect();
        let e = next_exposure(&histogram(&frame), 1.0, &AutoExposure::default());
        let half_bin = 0.5 * (LOG2_MAX - LOG2_MIN) / BINS as f32;
        // Half a bin from the bin centre, and up to half a display byte (≈ 0.06 stops at byte 25).
        assert!((e / 18.0).log2().abs() < half_bin + 0.1, "{e}");
    }

    #[test]
    fn black_frame_asks_for_more_light_and_smoothing_moves_in_stops() {
        let e = next_exposure(&[0; BINS], 2.0, &AutoExposure::default());
        assert_eq!(e, 2048.0);
        assert_eq!(smooth(1.0, 16.0, 1e9, 0.5), 16.0);
        assert_eq!(smooth(1.0, 16.0, 0.0, 0.5), 1.0);
        let half = smooth(1.0, 16.0, 0.5 * std::f32::consts::LN_2, 0.5);
        assert!((half - 4.0).abs() < 1e-4, "{half}");
    }
}
