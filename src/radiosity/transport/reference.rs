//! Reference solver: Gauss–Seidel iteration of `B = E + diag(ρ) F B` in f64, per channel, for
//! tests and the speed/accuracy study. Converges whenever the spectral radius of `diag(ρ)F` is
//! below 1 (every ρ < 1, or an open scene).

use crate::error::{Error, Result};

/// The solution and how many sweeps it took.
#[derive(Clone, Debug, PartialEq)]
pub struct Solution {
    /// Total exitance B (emission included).
    pub b: Vec<f64>,
    pub sweeps: u32,
}

/// Solve `B = E + diag(ρ) F B` by Gauss–Seidel until no entry changes by more than
/// `tolerance · max|B|`. `f` is `[n, n]` row-major.
pub fn gauss_seidel(
    f: &[f32],
    rho: &[f64],
    e: &[f64],
    tolerance: f64,
    max_sweeps: u32,
) -> Result<Solution> {
    let n = e.len();
    if f.len() != n * n || rho.len() != n {
        return Err(Error::Internal("gauss_seidel: sizes disagree".into()));
    }
    let mut b = e.to_vec();
    for sweep in 1..=max_sweeps {
        let mut change = 0f64;
        let mut scale = 0f64;
        for i in 0..n {
            let row = &f[i * n..(i + 1) * n];
            // Exclude the diagonal and solve for B_i exactly (F_ii may be non-zero).
            let mut h = 0.0;
            for (j, &fij) in row.iter().enumerate() {
                if j != i {
                    h += fij as f64 * b[j];
                }
            }
            let fii = row[i] as f64;
            let new = (e[i] + rho[i] * h) / (1.0 - rho[i] * fii);
            change = change.max((new - b[i]).abs());
            scale = scale.max(new.abs());
            b[i] = new;
        }
        if !change.is_finite() {
            break;
        }
        if change <= tolerance * scale.max(f64::MIN_POSITIVE) {
            return Ok(Solution { b, sweeps: sweep });
        }
    }
    Err(Error::knob(format!(
        "reference solver did not converge to {tolerance} in {max_sweeps} sweeps (albedo 1 in a closed scene?)"
    )))
}

/// Indirect light `B − E` of a solution.
pub fn indirect(solution: &Solution, e: &[f64]) -> Vec<f64> {
    solution.b.iter().zip(e).map(|(b, e)| b - e).collect()
}
