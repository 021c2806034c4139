//! The radiosity thesis's log mapping of the dense part (its §4.2; docs/algorithms.md §3 "Compression" step 3):
//! divide by the largest remaining value, take ln, add the range R (the thesis's 25), scale [0, R]
//! to [0, 255]. Code 0 is reserved for exact zero: values at or below `scale · e^-R` (and zeros,
//! negatives, NaN) encode to 0 and decode to exactly 0.0; every other value gets a code in
//! 1..=255.
//!
//! Decoding is a 256-entry table per channel: `decode(q) = scale · exp(q · R/255 − R)` for
//! `q ≥ 1`. The relative step between codes is `e^(R/255)`: 10.3 % for R = 25.

use serde::{Deserialize, Serialize};

/// The radiosity thesis's range: values below e^-25 of the largest are dropped.
pub const SEED_RANGE: f32 = 25.0;

/// One channel's log mapping.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct LogMap {
    /// The largest value of the channel's dense part (decodes from code 255). 0 for an all-zero
    /// channel (every code decodes to 0).
    pub scale: f32,
    /// Natural-log range R covered by codes 1..=255.
    pub range: f32,
}

impl LogMap {
    /// The radiosity thesis's mapping for a channel whose largest value is `scale`.
    pub fn seed(scale: f32) -> Self {
        LogMap {
            scale: if scale.is_finite() && scale > 0.0 {
                scale
            } else {
                0.0
            },
            range: SEED_RANGE,
        }
    }

    /// Code of `x`: 0 for zero and anything at or below `scale · e^-R`, else 1..=255.
    #[inline]
    pub fn encode(&self, x: f32) -> u8 {
        // `!(x > 0)` also catches NaN.
        if self.scale <= 0.0 || x.is_nan() || x <= 0.0 {
            return 0;
        }
        let t = (x as f64 / self.scale as f64).ln() + self.range as f64;
        if t <= 0.0 {
            return 0;
        }
        (t * 255.0 / self.range as f64).round().clamp(1.0, 255.0) as u8
    }

    /// The code as a real number in [0, 255] before rounding (0 for values that map to zero).
    #[inline]
    pub fn encode_real(&self, x: f32) -> f32 {
        if self.scale <= 0.0 || x.is_nan() || x <= 0.0 {
            return 0.0;
        }
        let t = (x as f64 / self.scale as f64).ln() + self.range as f64;
        if t <= 0.0 {
            0.0
        } else {
            (t * 255.0 / self.range as f64).clamp(0.0, 255.0) as f32
        }
    }

    /// Value of code `q` (0 → exactly 0.0).
    #[inline]
    pub fn decode(&self, q: u8) -> f32 {
        if q == 0 || self.scale <= 0.0 {
            return 0.0;
        }
        (self.scale as f64 * (q as f64 * self.range as f64 / 255.0 - self.range as f64).exp())
            as f32
    }

    /// Value of a fractional code (BC4/BC1 palette entries decoded without rounding); codes
    /// below 0.5 decode to exactly 0.
    #[inline]
    pub fn decode_real(&self, q: f32) -> f32 {
        if q < 0.5 || self.scale <= 0.0 {
            return 0.0;
        }
        (self.scale as f64 * (q as f64 * self.range as f64 / 255.0 - self.range as f64).exp())
            as f32
    }

    /// The decode table: `lut[q] = decode(q)`.
    pub fn lut(&self) -> [f32; 256] {
        let mut t = [0.0f32; 256];
        for (q, v) in t.iter_mut().enumerate() {
            *v = self.decode(q as u8);
        }
        t
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zero_and_tiny_values_decode_to_exact_zero() {
        let m = LogMap::seed(2.0);
        for x in [0.0f32, -1.0, f32::NAN, 2.0 * (-25.0f32).exp() * 0.999] {
            assert_eq!(m.encode(x), 0, "{x}");
        }
        assert_eq!(m.decode(0), 0.0);
        assert_eq!(m.lut()[0].to_bits(), 0);
    }

    #[test]
    fn max_maps_to_255_and_back() {
        let m = LogMap::seed(0.37);
        assert_eq!(m.encode(0.37), 255);
        assert!((m.decode(255) - 0.37).abs() < 1e-7);
        assert_eq!(m.encode(1e6), 255);
    }

    #[test]
    fn relative_error_is_half_a_step() {
        let m = LogMap::seed(1.0);
        let half_step = (25.0f64 / 255.0 / 2.0).exp() - 1.0;
        let mut x = 1.0f32;
        while x > 1e-10 {
            let r = (m.decode(m.encode(x)) as f64 - x as f64).abs() / x as f64;
            assert!(r <= half_step + 1e-6, "{x}: {r}");
            x *= 0.77;
        }
    }

    #[test]
    fn all_zero_channel_is_zero() {
        let m = LogMap::seed(0.0);
        assert_eq!(m.encode(1.0), 0);
        assert_eq!(m.decode(200), 0.0);
    }
}
