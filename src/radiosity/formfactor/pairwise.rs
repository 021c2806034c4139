//! Pairwise area-to-area estimation: for each pair of patches (i, j), N point pairs (x on i,
//! y on j, each Latin-hypercube stratified over its patch's area and randomly paired), one
//! visibility ray per pair:
//!
//! `A_i F_ij ≈ A_i A_j / N · Σ_k V_k cosθ_i cosθ_j / (π r_k² + ΔA)`,  `ΔA = (A_i + A_j) / (2N)`
//!
//! The `ΔA` term treats each sample as a small disc of its share of the area (the point-to-disc
//! form `cos cos ΔA / (π r² + ΔA)`, Wallace et al. 1989) instead of a point: the estimate stays
//! bounded as r → 0 for adjacent patches, with a bias that vanishes as N grows. The symmetric
//! quantity `G_ij = A_i F_ij` is estimated once per unordered pair, so reciprocity
//! `A_i F_ij = A_j F_ji` holds exactly. Pairs with a cosine ≤ 1e-6 (coplanar or facing away)
//! contribute nothing, so a planar patch has `F_ii = 0` exactly.

use super::{Context, FormFactors};
use crate::progress::Progress;
use crate::radiosity::geometry::{item_rng, AreaSampler};
use rayon::prelude::*;

/// Cosines at or below this count as zero (grazing, coplanar, facing away).
const MIN_COSINE: f64 = 1e-6;

/// Estimate F with `samples` point pairs per patch pair; pair (i, j ≥ i) uses the random stream
/// `(seed, i, j)`.
pub fn estimate(ctx: &Context, samples: u32, seed: u64, progress: &dyn Progress) -> FormFactors {
    let n = ctx.samplers.len();
    let k = samples as usize;
    progress.begin("form factors (pairwise)", n as u64);
    // Upper triangle rows: g[i][j - i] = A_i F_ij (grid units²).
    let upper: Vec<Vec<f64>> = (0..n)
        .into_par_iter()
        .map(|i| {
            let row = (i..n).map(|j| throughput(ctx, i, j, k, seed)).collect();
            progress.advance(1);
            row
        })
        .collect();
    progress.finish();
    let mut values = vec![0f32; n * n];
    let mut rays = 0u64;
    for (i, row) in upper.iter().enumerate() {
        let ai = ctx.samplers[i].area;
        for (d, &g) in row.iter().enumerate() {
            let j = i + d;
            let aj = ctx.samplers[j].area;
            if ai > 0.0 {
                values[i * n + j] = (g / ai) as f32;
            }
            if aj > 0.0 {
                values[j * n + i] = (g / aj) as f32;
            }
        }
        rays += (row.len() * k) as u64;
    }
    FormFactors {
        n,
        values,
        rays,
        unassigned_hits: 0,
    }
}

/// `A_i F_ij` for one unordered pair.
pub fn throughput(ctx: &Context, i: usize, j: usize, k: usize, seed: u64) -> f64 {
    let (si, sj) = (&ctx.samplers[i], &ctx.samplers[j]);
    if si.is_empty() || sj.is_empty() {
        return 0.0;
    }
    let mut rng = item_rng(seed, i as u64, j as u64);
    let xs = points(si, k, &mut rng);
    let ys = points(sj, k, &mut rng);
    let disc = (si.area + sj.area) / (2.0 * k as f64);
    let mut sum = 0.0;
    for ((x, nx), (y, ny)) in xs.iter().zip(&ys) {
        let d = *y - *x;
        let r2 = d.length_squared();
        if r2 <= 0.0 {
            continue;
        }
        let r = r2.sqrt();
        let ci = nx.dot(d) / r;
        let cj = -ny.dot(d) / r;
        if ci <= MIN_COSINE || cj <= MIN_COSINE {
            continue;
        }
        if ctx.vis.occluded(*x, *y) {
            continue;
        }
        sum += ci * cj / (std::f64::consts::PI * r2 + disc);
    }
    si.area * sj.area * sum / k as f64
}

fn points(
    s: &AreaSampler,
    k: usize,
    rng: &mut crate::radiosity::geometry::Rng,
) -> Vec<(glam::DVec3, glam::DVec3)> {
    let (sel, u, v) = (rng.strata(k), rng.strata(k), rng.strata(k));
    (0..k).map(|m| s.sample(sel[m], u[m], v[m])).collect()
}
