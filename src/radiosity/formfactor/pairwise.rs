//! Pairwise area-to-area estimation. For each unordered pair of patches (i, j): `m = ⌊√N⌋`
//! points on each (jittered-stratified over the patch's area) and all `m²` point pairs between
//! them, one visibility ray per pair. Each point x on i contributes
//!
//! `F_{x→j} = F^unoccluded_{x→j} · V̄(x, j)`
//!
//! where `F^unoccluded` is exact (Lambert's contour formula over j's pieces, clipped to the
//! hemisphere above x — see [`point_to_triangle`]) and `V̄` is the kernel-weighted visible fraction
//! of x's rays to the m points on j (weights `cosθ_x cosθ_y / (π r² + ΔA)`,
//! `ΔA = (A_i + A_j) / (2m²)`). The exact inner integral removes the 1/r² singularity that makes
//! plain point-pair sampling converge like N^(−1/4) next to a shared edge; the visibility ratio is
//! bounded in [0, 1]. A point none of whose rays to the other patch is unoccluded counts 0.
//!
//! Both directions use the same rays (visibility is symmetric): `G_ij = A_i F_ij` is estimated
//! from each side (`A_i·mean_x F_{x→j}` and `A_j·mean_y F_{y→i}`) and the two are combined with
//! inverse-variance weights (sample variances), so the side with the smoother integrand dominates;
//! one G per pair makes reciprocity `A_i F_ij = A_j F_ji` exact. Pairs with a cosine ≤ 1e-6
//! (coplanar or facing away) add nothing, so a planar patch has `F_ii = 0` exactly.

use crate::progress::Progress;
use crate::radiosity::formfactor::{Context, FormFactors};
use crate::radiosity::geometry::{item_rng, point_to_triangle, AreaSampler, Rng};
use glam::DVec3;
use rayon::prelude::*;
use std::ops::Range;

/// Cosines at or below this count as zero (grazing, coplanar, facing away).
const MIN_COSINE: f64 = 1e-6;

/// Estimate F with `samples` point pairs per patch pair; pair (i, j ≥ i) uses the random stream
/// `(seed, i, j)`.
pub fn estimate(ctx: &Context, samples: u32, seed: u64, progress: &dyn Progress) -> FormFactors {
    let n = ctx.samplers.len();
    let upper = upper_rows(ctx, 0..n, samples, seed, progress);
    let areas: Vec<f64> = ctx.samplers.iter().map(|s| s.area).collect();
    assemble(&areas, &upper, samples)
}

/// Rows `rows` of the upper triangle of the throughput, concatenated: row i holds
/// `A_i F_ij` for j = i..n (grid units²). Each pair is a function of (scene, patches, samples,
/// seed, i, j) alone.
pub fn upper_rows(
    ctx: &Context,
    rows: Range<usize>,
    samples: u32,
    seed: u64,
    progress: &dyn Progress,
) -> Vec<f64> {
    let n = ctx.samplers.len();
    let k = samples as usize;
    progress.begin("form factors (pairwise)", rows.len() as u64);
    let upper: Vec<Vec<f64>> = rows
        .into_par_iter()
        .map(|i| {
            let row = (i..n).map(|j| throughput(ctx, i, j, k, seed)).collect();
            progress.advance(1);
            row
        })
        .collect();
    progress.finish();
    upper.concat()
}

/// F from the whole upper triangle (rows 0..n of [`upper_rows`], concatenated).
pub fn assemble(areas: &[f64], upper: &[f64], samples: u32) -> FormFactors {
    let n = areas.len();
    let mut values = vec![0f32; n * n];
    let mut at = 0;
    for i in 0..n {
        let ai = areas[i];
        for (d, &g) in upper[at..at + n - i].iter().enumerate() {
            let j = i + d;
            let aj = areas[j];
            if ai > 0.0 {
                values[i * n + j] = (g / ai) as f32;
            }
            if aj > 0.0 {
                values[j * n + i] = (g / aj) as f32;
            }
        }
        at += n - i;
    }
    let pairs = (n * (n + 1) / 2) as u64;
    FormFactors {
        n,
        values,
        rays: pairs * points_per_patch(samples as usize).pow(2) as u64,
        unassigned_hits: 0,
    }
}

/// The first row of shard `index` of `count` when rows are split so that each shard gets about
/// the same number of pairs (row i has n − i).
pub fn balanced_row(n: usize, index: usize, count: usize) -> usize {
    let total = (n * (n + 1) / 2) as f64;
    let want = total * index as f64 / count as f64;
    // Pairs before row r: r·n − r(r − 1)/2; the first r whose count reaches `want`.
    (0..=n)
        .find(|&r| (r * n) as f64 - (r * r.saturating_sub(1)) as f64 / 2.0 >= want)
        .unwrap_or(n)
}

/// Points per patch for `samples` pairs: `m = ⌊√samples⌋`, giving `m²` pairs.
pub fn points_per_patch(samples: usize) -> usize {
    ((samples as f64).sqrt().floor() as usize).max(1)
}

/// One visibility ray of a patch pair: point `a` on i to point `b` on j, its kernel weight
/// `cosθ_x cosθ_y / (π r² + ΔA)`, and the segment tested for occlusion (both ends lifted off
/// their surfaces by the ray epsilon along their normals; the points keep one ray epsilon in
/// from their patches' edges).
#[derive(Clone, Copy, Debug)]
pub struct PairRay {
    pub a: usize,
    pub b: usize,
    pub weight: f64,
    pub from: DVec3,
    pub to: DVec3,
}

/// The points of pair (i, j) on each patch (position, normal) and the rays between them whose
/// cosines are both above [`MIN_COSINE`]: what [`throughput`] traces, in its order. Empty when
/// a patch has no area sampler.
pub fn pair_rays(ctx: &Context, i: usize, j: usize, k: usize, seed: u64) -> PairPoints {
    let (si, sj) = (&ctx.samplers[i], &ctx.samplers[j]);
    if si.is_empty() || sj.is_empty() {
        return PairPoints::default();
    }
    let m = points_per_patch(k);
    let mut rng = item_rng(seed, i as u64, j as u64);
    let lift = ctx.vis.epsilon as f64;
    let xs = points(si, m, lift, &mut rng);
    let ys = points(sj, m, lift, &mut rng);
    let disc = (si.area + sj.area) / (2.0 * (m * m) as f64);
    let mut rays = Vec::with_capacity(m * m);
    for (a, (x, nx)) in xs.iter().enumerate() {
        for (b, (y, ny)) in ys.iter().enumerate() {
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
            rays.push(PairRay {
                a,
                b,
                weight: ci * cj / (std::f64::consts::PI * r2 + disc),
                from: *x + *nx * lift,
                to: *y + *ny * lift,
            });
        }
    }
    PairPoints { xs, ys, rays }
}

/// What [`pair_rays`] returns.
#[derive(Default)]
pub struct PairPoints {
    pub xs: Vec<(DVec3, DVec3)>,
    pub ys: Vec<(DVec3, DVec3)>,
    pub rays: Vec<PairRay>,
}

/// `A_i F_ij` for one unordered pair.
pub fn throughput(ctx: &Context, i: usize, j: usize, k: usize, seed: u64) -> f64 {
    let PairPoints { xs, ys, rays } = pair_rays(ctx, i, j, k, seed);
    if xs.is_empty() || ys.is_empty() {
        return 0.0;
    }
    let (si, sj) = (&ctx.samplers[i], &ctx.samplers[j]);
    // Kernel-weighted visibility per point: (weight of visible rays, weight of all rays).
    let mut vx = vec![(0.0, 0.0); xs.len()];
    let mut vy = vec![(0.0, 0.0); ys.len()];
    for r in &rays {
        let seen = !ctx.vis.occluded(r.from, r.to);
        for acc in [&mut vx[r.a], &mut vy[r.b]] {
            acc.1 += r.weight;
            if seen {
                acc.0 += r.weight;
            }
        }
    }
    let (gi, vi) = side(&xs, &vx, si.area, sj);
    let (gj, vj) = side(&ys, &vy, sj.area, si);
    // Inverse-variance weighting of the two sides (the smoother integrand counts more).
    let floor = 1e-12 * (gi * gi + gj * gj) + f64::MIN_POSITIVE;
    let (wi, wj) = (1.0 / (vi + floor), 1.0 / (vj + floor));
    (wi * gi + wj * gj) / (wi + wj)
}

/// `G` estimated from one side: (A · mean over its points of F_{point→target}, the variance of
/// that mean).
fn side(pts: &[(DVec3, DVec3)], vis: &[(f64, f64)], area: f64, target: &AreaSampler) -> (f64, f64) {
    let m = pts.len() as f64;
    let terms: Vec<f64> = pts
        .iter()
        .zip(vis)
        .map(|((x, n), &(seen, all))| {
            if seen <= 0.0 {
                return 0.0;
            }
            let unoccluded: f64 = target
                .triangles()
                .iter()
                .map(|&(a, b, c, tn)| point_to_triangle(*x, *n, [a, b, c], tn))
                .sum();
            area * unoccluded * seen / all
        })
        .collect();
    let mean = terms.iter().sum::<f64>() / m;
    let var = terms.iter().map(|t| (t - mean) * (t - mean)).sum::<f64>() / (m * (m - 1.0).max(1.0));
    (mean, var)
}

/// `k` stratified points of `s`, kept `inset` in from its edges (see
/// [`AreaSampler::sample_square_inset`]).
fn points(s: &AreaSampler, k: usize, inset: f64, rng: &mut Rng) -> Vec<(DVec3, DVec3)> {
    rng.jittered(k)
        .into_iter()
        .map(|(u, v)| s.sample_square_inset(u, v, inset))
        .collect()
}
