//! What fewer sweep lines would cost in accuracy (docs/terrain.md, "Horizon maps"). The exact sweep
//! runs one line through every pixel centre, so a direction (a, b) costs |a| + |b| samples per
//! pixel. Timonen & Westerholm's sweep runs about one line per texel of spacing: for |b| ≥ |a| the
//! lines through the pixel centres of one row (every |b|-th of the exact family), about (|a| +
//! |b|)/|b| samples per pixel (under 2), and each pixel takes its horizon from the line that
//! crosses its row nearest to it, up to half a texel to the side.
//!
//! This measures that sideways shift on Puget Sound, per pixel and direction, against the
//! exact horizon ([`horizon_exact`]): the far samples (beyond D texels along the track) are
//! taken on the shifted line, the near ones (within D) on the pixel's own line — an exact near
//! field, as a hybrid would compute it by brute force at about 1.3·D samples per pixel. D = 0
//! is the plain thinned sweep. Random pixels, all 64 directions.
//!
//! `cargo bench --bench terrain_horizon_lines` (env: RELUME_BENCH_SIZES, default "1024,4096";
//! RELUME_BENCH_PIXELS, default 2000).

use rayon::prelude::*;
use relume::heightmap::HeightMap;
use relume::terrain::hard::exact_traversal::sample_bilinear;
use relume::terrain::horizon::{directions, horizon_exact, Direction};
use util::{env, env_list, load};

#[allow(unused_imports)]
mod util;

/// Near-field depths D (texels along the track).
const DEPTHS: [f64; 5] = [0.0, 4.0, 16.0, 64.0, 256.0];

/// A line of the sweep: from `start` (texel coordinates) along the unit (ux, uy); `shift` is
/// the along-track position of the pixel's foot on it (so a sample at t lies `t + shift` from
/// the pixel).
struct Line {
    start: [f64; 2],
    u: [f64; 2],
    shift: f64,
}

impl Line {
    /// The steepest tangent (metres up per metre along) from height `zp` to the line's samples
    /// (the bilinear height at each texel transit's midpoint, as the exact traversal samples)
    /// whose distance from the pixel lies in (lo, hi], starting from `best`; stops once the
    /// map's maximum `top` cannot be steeper.
    fn steepest(
        &self,
        map: &HeightMap,
        zp: f64,
        (lo, hi): (f64, f64),
        top: f64,
        m: f64,
        best: f64,
    ) -> f64 {
        let [sx, sy] = self.start;
        let [ux, uy] = self.u;
        let step = |u: f64| (u > 0.0) as i64 - (u < 0.0) as i64;
        let (stx, sty) = (step(ux), step(uy));
        let exit = |s: f64, i: i64, st: i64, u: f64| match st {
            1 => ((i + 1) as f64 - s) / u,
            -1 => (i as f64 - s) / u,
            _ => f64::INFINITY,
        };
        let (mut ix, mut iy) = (sx.floor() as i64, sy.floor() as i64);
        let (mut t_in, mut best) = (0.0, best);
        while ix >= 0 && iy >= 0 && ix < map.width as i64 && iy < map.height as i64 {
            let (tx, ty) = (exit(sx, ix, stx, ux), exit(sy, iy, sty, uy));
            let t_out = tx.min(ty);
            let t_mid = 0.5 * (t_in + t_out);
            let d = t_mid + self.shift;
            if d > hi || (t_in + self.shift > 0.0 && top - zp <= best * (t_in + self.shift) * m) {
                break;
            }
            if d > lo && d > 0.0 {
                let qx = (sx + ux * t_mid).clamp(ix as f64, (ix + 1) as f64);
                let qy = (sy + uy * t_mid).clamp(iy as f64, (iy + 1) as f64);
                let h = sample_bilinear(&map.heights, map.width, map.height, qx, qy);
                best = best.max((h - zp) / (d * m));
            }
            ix += stx * (tx <= ty) as i64;
            iy += sty * (ty <= tx) as i64;
            t_in = t_out;
        }
        best
    }
}

/// Pixel (c, r)'s own line, and the thinned sweep's line nearest to it along `d`.
fn lines(d: &Direction, u: [f64; 2], c: usize, r: usize) -> (Line, Line) {
    let p = [c as f64 + 0.5, r as f64 + 0.5];
    let own = Line {
        start: p,
        u,
        shift: 0.0,
    };
    // Lines through the centres of row 0 (|b| ≥ |a|) or column 0: the one crossing the pixel's
    // row (column) nearest its centre, `off` texels to the side along that row (column).
    let (along, across) = if d.a.abs() <= d.b.abs() {
        (0, 1)
    } else {
        (1, 0)
    };
    let slope = [d.a, d.b][along] as f64 / [d.a, d.b][across] as f64;
    let (pa, pc) = ([c, r][along] as f64, [c, r][across] as f64);
    let cross = slope * pc;
    let off = (pa - cross).round() + cross - pa;
    let mut start = p;
    start[along] += off;
    let thinned = Line {
        start,
        u,
        shift: off * u[along],
    };
    (own, thinned)
}

fn main() {
    let full = load("puget-sound.ron");
    let sizes = env_list::<usize>("RELUME_BENCH_SIZES", "1024,4096");
    let count = env("RELUME_BENCH_PIXELS", 2000usize);
    println!("## Horizon maps from fewer lines, Puget Sound, 64 directions\n");
    println!("Error of the horizon against the exact one; near samples (within D texels) exact, far ones on the nearest thinned line.\n");
    println!("| size | pixels × directions | D | within 0.01° | within 0.1° | max error |");
    println!("|---|---|---|---|---|---|");
    for &n in &sizes {
        let map = full.downsample(4096 / n);
        let top = map.min_max().1 as f64;
        let dirs = directions(64, map.cell_size);
        let mut s = 0x9E37_79B9_7F4A_7C15u64;
        let pixels: Vec<(usize, usize)> = (0..count)
            .map(|_| {
                s ^= s << 13;
                s ^= s >> 7;
                s ^= s << 17;
                (
                    (s % map.width as u64) as usize,
                    ((s >> 32) % map.height as u64) as usize,
                )
            })
            .collect();
        // Per depth: (within 0.01°, within 0.1°, max error).
        let stats: Vec<[f64; 3]> = dirs
            .par_iter()
            .map(|d| {
                let track = d.track(map.cell_size);
                let (u, m) = ([track.ux, track.uy], track.metres_per_t);
                let mut acc = vec![[0.0f64; 3]; DEPTHS.len()];
                for &(c, r) in &pixels {
                    let exact = horizon_exact(&map, &track, c, r, top as f32);
                    let zp = map.heights[r * map.width + c] as f64;
                    let (own, thinned) = lines(d, u, c, r);
                    // The walk on the pixel's own line is the exact horizon's.
                    let whole =
                        own.steepest(&map, zp, (-1.0, f64::INFINITY), top, m, f64::NEG_INFINITY);
                    assert!(
                        (whole.atan().to_degrees() - exact).abs() < 1e-9,
                        "walk ≠ exact"
                    );
                    for (a, &depth) in acc.iter_mut().zip(&DEPTHS) {
                        let near = own.steepest(&map, zp, (-1.0, depth), top, m, f64::NEG_INFINITY);
                        let all = thinned.steepest(&map, zp, (depth, f64::INFINITY), top, m, near);
                        let err = (all.atan().to_degrees() - exact).abs();
                        a[0] += (err <= 0.01) as u8 as f64;
                        a[1] += (err <= 0.1) as u8 as f64;
                        a[2] = a[2].max(err);
                    }
                }
                acc
            })
            .reduce(
                || vec![[0.0; 3]; DEPTHS.len()],
                |a, b| {
                    a.iter()
                        .zip(&b)
                        .map(|(x, y)| [x[0] + y[0], x[1] + y[1], x[2].max(y[2])])
                        .collect()
                },
            );
        let total = (pixels.len() * dirs.len()) as f64;
        for (depth, st) in DEPTHS.iter().zip(&stats) {
            println!(
                "| {n}² | {} | {depth} | {:.2} % | {:.2} % | {:.3}° |",
                pixels.len() * dirs.len(),
                100.0 * st[0] / total,
                100.0 * st[1] / total,
                st[2]
            );
        }
    }
}
