//! Accelerated relief-shadow traversal over the min/max mipmap: algorithm A2 of the relief-shadow paper
//! (Timokhin & Mikhaylyuk 2021, §4), with the same answer as [`shadowed_exact`] on every
//! pixel.
//!
//! The state is the exact traversal's: the current texel (ix, iy) and the time t_in at which
//! the track entered it; plus the current level (−1 = texels, 0.. = mipmap levels). At a level
//! L ≥ 0 the block of side B = 2^(L+1) containing (ix, iy) is tested against the sun ray:
//!
//! - **max test** `max − z_P ≤ rise·t_in`: every later sample in the block is at most `max`
//!   and sits at t ≥ t_in, where the ray is at least as high: nothing in the block can shadow
//!   P. Skip to the block's exit time T = min(txb, tyb) (the block's x and y exit events, by the
//!   same expression as the texel events) and to the texel the exact traversal is in just after
//!   T: the exiting axis moves to the first texel past the block boundary (both on a tie), the
//!   other axis to the texel whose transit contains T (an estimate corrected with the exact event
//!   times, so it is bit-for-bit the exact traversal's). Then climb one level.
//! - **min test** `min − z_P > rise·T`: the current texel lies in the block and its sample sits
//!   at t_mid ≤ T with height ≥ min, so the exact traversal finds it above the ray: shadowed.
//! - otherwise descend one level; at level −1 do the exact texel test and step one texel,
//!   then climb to level 0.
//!
//! The mipmap's bounds cover every value the exact traversal samples in a block (see
//! [`crate::terrain::minmax_mipmap`]) and every comparison is monotone in floating point (subtracting
//! z_P, multiplying by rise ≥ 0, t_mid within [t_in, T]), so the two answers are equal, not
//! merely close. No recursion, no allocation: a loop bounded by (W + H + 1)·(levels + 2)
//! iterations — each iteration descends one level or moves the texel forward.
//!
//! [`shadowed_exact`]: crate::terrain::hard::exact_traversal::shadowed_exact

use crate::heightmap::HeightMap;
use crate::terrain::hard::exact_traversal::texel_sample;
use crate::terrain::minmax_mipmap::MinMaxMipmap;
use crate::terrain::sun::{Track, TrackKind};

/// Time at which the track from `p` leaves block `b` (of side `1 << shift`) on one axis.
#[inline]
pub fn block_exit_time(p: f64, b: i64, shift: i64, step: i64, inv_u: f64) -> f64 {
    if step > 0 {
        Track::crossing(p, (b + 1) << shift, inv_u)
    } else if step < 0 {
        Track::crossing(p, b << shift, inv_u)
    } else {
        f64::INFINITY
    }
}

/// The texel coordinate on one axis that the exact traversal occupies just after time `t`,
/// knowing it lies between `from` (the current one) and `last` (the block's last one in the
/// direction of travel): the c with entry(c) ≤ t < exit(c). Starts from the estimate
/// floor(p + u·t) and corrects it with the exact event times; both loops are bounded by the
/// block size.
#[inline]
pub fn coordinate_after(
    p: f64,
    u: f64,
    step: i64,
    inv_u: f64,
    t: f64,
    from: i64,
    last: i64,
) -> i64 {
    if step == 0 {
        return from;
    }
    // floor without a libm call: truncate, then correct negatives.
    let x = p + u * t;
    let truncated = x as i64;
    let estimate = truncated - ((x < truncated as f64) as i64);
    let mut c = if step > 0 {
        estimate.clamp(from, last)
    } else {
        estimate.clamp(last, from)
    };
    while c != last && Track::exit_time(p, c, step, inv_u) <= t {
        c += step;
    }
    while c != from && Track::entry_time(p, c, step, inv_u) > t {
        c -= step;
    }
    c
}
/// The texel the track enters after leaving block (bx, by) of 2^`shift` texels at
/// `t_exit = min(txb, tyb)` ([`block_exit_time`] per axis): one step past the block's last
/// texel on the axis whose boundary the track crosses first (both at a corner), and on the other
/// axis the coordinate the track has at `t_exit` ([`coordinate_after`], from the current texel
/// `i`). Shared by the accelerated hard-shadow walk and the soft-shadow branch and bound.
#[inline]
pub fn texel_after_block(
    track: &Track,
    p: [f64; 2],
    i: [i64; 2],
    b: [i64; 2],
    shift: i64,
    [txb, tyb]: [f64; 2],
) -> [i64; 2] {
    let (sx, sy) = (track.step_x, track.step_y);
    let t_exit = txb.min(tyb);
    let last = |b: i64, s: i64| {
        if s > 0 {
            ((b + 1) << shift) - 1
        } else {
            b << shift
        }
    };
    let (last_x, last_y) = (last(b[0], sx), last(b[1], sy));
    let nx = if txb <= tyb {
        last_x + sx
    } else {
        coordinate_after(p[0], track.ux, sx, track.inv_ux, t_exit, i[0], last_x)
    };
    let ny = if tyb <= txb {
        last_y + sy
    } else {
        coordinate_after(p[1], track.uy, sy, track.inv_uy, t_exit, i[1], last_y)
    };
    [nx, ny]
}

/// Is the pixel at (col, row) in shadow? Accelerated traversal A2 over `mip` (built from
/// `map`). Equal to `shadowed_exact(map, track, col, row, _)` for every pixel.
pub fn shadowed_accelerated(
    map: &HeightMap,
    mip: &MinMaxMipmap,
    track: &Track,
    col: usize,
    row: usize,
) -> bool {
    match track.kind {
        TrackKind::Zenith => return false,
        TrackKind::BelowHorizon => return true,
        TrackKind::Ray => {}
    }
    let (w, h) = (map.width as i64, map.height as i64);
    let (sx, sy) = (track.step_x, track.step_y);
    let px = col as f64 + 0.5;
    let py = row as f64 + 0.5;
    let zp = map.heights[row * map.width + col] as f64;
    let rise = track.rise_per_t;
    let top = mip.levels.len() as i64 - 1;
    // Start at the texel level: every block containing P has max ≥ z_P, so starting coarse
    // would only descend to P's texel first; climbing after each step reaches coarse levels.
    let mut level = -1i64;
    let (mut ix, mut iy) = (col as i64, row as i64);
    let mut t_in = 0.0f64;
    // The top level's maximum over all its texels = the map's maximum (border included).
    let headroom = mip.max_height as f64 - zp;
    let max_iterations = (w + h + 1) * (top + 3);
    for _ in 0..max_iterations {
        if level < 0 {
            // Texel level: the exact test, then one exact step.
            let tx = Track::exit_time(px, ix, sx, track.inv_ux);
            let ty = Track::exit_time(py, iy, sy, track.inv_uy);
            let t_out = tx.min(ty);
            let (t_mid, hq) = texel_sample(map, track, [px, py], [ix, iy], t_in, t_out);
            if hq - zp > rise * t_mid {
                return true;
            }
            if tx <= ty {
                ix += sx;
            }
            if ty <= tx {
                iy += sy;
            }
            t_in = t_out;
            if ix < 0 || iy < 0 || ix >= w || iy >= h || rise * t_in >= headroom {
                return false;
            }
            level = 0;
            continue;
        }
        let shift = level + 1;
        let (bx, by) = (ix >> shift, iy >> shift);
        let (bmax, bmin) = mip.texel(level as usize, bx as usize, by as usize);
        let txb = block_exit_time(px, bx, shift, sx, track.inv_ux);
        let tyb = block_exit_time(py, by, shift, sy, track.inv_uy);
        let t_exit = txb.min(tyb);
        if bmax as f64 - zp <= rise * t_in {
            // Max test passed: skip the block.
            [ix, iy] = texel_after_block(track, [px, py], [ix, iy], [bx, by], shift, [txb, tyb]);
            t_in = t_exit;
            if ix < 0 || iy < 0 || ix >= w || iy >= h || rise * t_in >= headroom {
                return false;
            }
            if level < top {
                level += 1;
            }
        } else if bmin as f64 - zp > rise * t_exit {
            // Min test: certain shadow.
            return true;
        } else {
            level -= 1;
        }
    }
    debug_assert!(false, "accelerated traversal exceeded its iteration bound");
    false
}
