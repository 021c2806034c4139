//! Hemisphere shooting: from each patch, N rays with origins stratified over the patch's area and
//! cosine-distributed directions about the local surface normal; `F_ij ≈ hits_j / N`. Rays start
//! a ray epsilon above the surface (never on it) and a ray epsilon in from the patch's edges
//! (never on the adjoining wall's plane), so a ray leaving a concave corner hits the adjoining
//! wall instead of slipping out behind it.
//!
//! A cosine-distributed direction has density cosθ/π, which is exactly the form-factor kernel of
//! a differential area, so each hit counts 1/N (Malley's method). Origins (over the patch's
//! area) and directions (over the unit square before the cosine warp) are each jittered-stratified,
//! and paired at random. A ray that
//! hits a back face (the inside of a closed object, the outside of a wall) is absorbed: nobody
//! receives it, and by reciprocity nothing there could see patch i. Rows of a closed scene sum
//! to 1 by construction.

use crate::progress::Progress;
use crate::radiosity::formfactor::{Context, FormFactors};
use crate::radiosity::geometry::{cosine_direction, item_rng};
use glam::DVec3;
use rayon::prelude::*;
use std::ops::Range;
use std::sync::atomic::{AtomicU64, Ordering};

/// Estimate F with `samples` rays per patch; patch i uses the random stream `(seed, i)`.
pub fn estimate(ctx: &Context, samples: u32, seed: u64, progress: &dyn Progress) -> FormFactors {
    let n = ctx.samplers.len();
    let (values, unassigned) = estimate_rows(ctx, 0..n, samples, seed, progress);
    FormFactors {
        n,
        values,
        rays: n as u64 * samples as u64,
        unassigned_hits: unassigned,
    }
}

/// Rows `rows` of F (`[rows.len(), n]` row-major) and the hits that found no patch: each row is
/// a function of (scene, patches, samples, seed, its index) alone, so rows computed by
/// different processes assemble into the matrix [`estimate`] makes.
pub fn estimate_rows(
    ctx: &Context,
    rows: Range<usize>,
    samples: u32,
    seed: u64,
    progress: &dyn Progress,
) -> (Vec<f32>, u64) {
    let n = ctx.samplers.len();
    let k = samples as usize;
    let unassigned = AtomicU64::new(0);
    let mut values = vec![0f32; rows.len() * n];
    progress.begin("form factors (hemisphere)", rows.len() as u64);
    values
        .par_chunks_mut(n.max(1))
        .enumerate()
        .for_each(|(r, row)| {
            let counts = shoot(ctx, rows.start + r, k, seed, &unassigned);
            for (v, c) in row.iter_mut().zip(counts) {
                *v = (c as f64 / k as f64) as f32;
            }
            progress.advance(1);
        });
    progress.finish();
    (values, unassigned.into_inner())
}

/// The `k` rays patch `i` shoots (grid coordinates): origins lifted one ray epsilon off the
/// surface and kept one in from its edges, unit cosine-distributed directions; empty for a
/// patch without area. Exactly the rays [`shoot`] traces (an independent tracer can be given
/// the same ones).
pub fn rays(ctx: &Context, i: usize, k: usize, seed: u64) -> Vec<(DVec3, DVec3)> {
    let sampler = &ctx.samplers[i];
    if sampler.is_empty() {
        return Vec::new();
    }
    let mut rng = item_rng(seed, i as u64, u64::MAX);
    let origins = rng.jittered(k);
    let directions = rng.jittered(k);
    let lift = ctx.vis.epsilon as f64;
    (0..k)
        .map(|s| {
            let (origin, normal) = sampler.sample_square_inset(origins[s].0, origins[s].1, lift);
            let dir = cosine_direction(normal, directions[s].0, directions[s].1);
            (origin + normal * lift, dir)
        })
        .collect()
}

/// Hit counts per receiving patch for `k` rays from patch `i`.
pub fn shoot(ctx: &Context, i: usize, k: usize, seed: u64, unassigned: &AtomicU64) -> Vec<u32> {
    let n = ctx.samplers.len();
    let mut counts = vec![0u32; n];
    let mut lost = 0;
    for (origin, dir) in rays(ctx, i, k, seed) {
        let Some(hit) = ctx.vis.closest_hit(origin, dir) else {
            continue;
        };
        if !hit.front {
            continue;
        }
        let p = origin + dir * hit.t as f64;
        match ctx.locator.locate_hit(p, hit.triangle) {
            Some(j) => counts[j as usize] += 1,
            None => lost += 1,
        }
    }
    if lost > 0 {
        unassigned.fetch_add(lost, Ordering::Relaxed);
    }
    counts
}
