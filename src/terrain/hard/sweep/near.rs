//! The certified sweep's near stencil ([`crate::terrain::hard::sweep`]): the exact test of the texels of a
//! pixel's track in its own major-axis line and the next one, for a whole row at once.
//!
//! **Why a stencil.** The exact traversal's event times are `(boundary − p)·(1/u)` with
//! `boundary − p` an exact half-integer ([`Track::crossing`]), so they — the texels a track
//! visits, their transit times t_in, t_out and t_mid — are the same numbers for every pixel,
//! bit for bit: every track is an integer translate of every other. The sample point
//! Q = p + u·t_mid of a texel is then the same offset from every pixel's texel (up to the
//! rounding of p + u·t_mid, about 1e-12 texel at 4K), and its bilinear sample a fixed linear
//! combination of four heights at fixed offsets. For the first S texels of the track the exact
//! test `h(Q) − z_P > rise·t_mid` ([`shadowed_exact`]) becomes a stencil:
//!
//! `v_k(P) = Σ_i c_ki·(h(P + o_ki) − z_P) − rise·t_mid_k`, shadowed by texel k iff v_k > 0.
//!
//! **Certified.** The stencil runs in f32 (four lanes, no branches). Its error against the
//! f64 value the traversal compares is below `margin` = 1e-6·(Δ + R) with Δ the map's height
//! range and R the largest rise·t_mid (the f32 roundings of the four differences, weights,
//! products and sums, ≤ 6·2⁻²⁴·Δ + 2·2⁻²⁴·R; the position rounding, ≤ 2⁻²⁸·2Δ for maps up to
//! 2²⁴ texels; 1e-6 ≈ 16.8·2⁻²⁴). So with v = max_k v_k: v > margin means some texel passes
//! the exact test (shadow, a test the traversal makes); v < −margin means none of the S texels
//! does; anything between is undecided (the caller walks that pixel exactly).
//!
//! **Preconditions.** All coordinates are the sweep's canonical frame (rows along the track's
//! major axis, `ucy` the major component, |ucx| ≤ |ucy|); `inv_x`, `inv_y`, `step_x`, `step_y`
//! are the track's own 1/u and steps for those axes (the traversal's numbers). A pixel may use
//! the stencil only where every tap lies inside the map ([`NearStencil::x_lo`] …): then the
//! traversal's border clamping is idle and it visits every stencil texel.
//!
//! [`shadowed_exact`]: crate::terrain::hard::exact_traversal::shadowed_exact

use crate::terrain::sun::Track;

/// One texel of the stencil: four bilinear taps relative to the pixel and the ray's rise.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NearTexel {
    /// Offset (column, row) of the first tap from the pixel; the taps are (ox, oy),
    /// (ox + 1, oy), (ox, oy + 1), (ox + 1, oy + 1).
    pub ox: i64,
    pub oy: i64,
    /// The taps' bilinear weights.
    pub c: [f32; 4],
    /// rise·t_mid, the exact test's right side.
    pub rise: f32,
}

impl NearTexel {
    /// v_k = Σ c_i·(h_i − z_P) − rise·t_mid for the taps' heights h and the pixel's z_P, in
    /// the order the margin argument (module docs) assumes; shared by the row and the per-line
    /// evaluations so that both are bit for bit the same.
    #[inline(always)]
    fn value(&self, [a, b, c, d]: [f32; 4], zp: f32) -> f32 {
        let [ca, cb, cc, cd] = self.c;
        ca * (a - zp) + cb * (b - zp) + cc * (c - zp) + cd * (d - zp) - self.rise
    }
}

/// The stencil of a track's texels in its first `lines` major-axis lines.
#[derive(Clone, Debug, PartialEq)]
pub struct NearStencil {
    pub texels: Vec<NearTexel>,
    /// Extent of the taps' offsets: columns x_lo..=x_hi, rows y_lo..=y_hi.
    pub x_lo: i64,
    pub x_hi: i64,
    pub y_lo: i64,
    pub y_hi: i64,
    /// Decision margin (module docs).
    pub margin: f32,
    /// Line k's texels are `texels[line_start[k]..line_start[k + 1]]`.
    pub line_start: Vec<usize>,
}

/// The canonical frame's axes: (u, step, 1/u) for x (minor) and y (major).
#[derive(Clone, Copy, Debug)]
pub struct Axes {
    pub x: (f64, i64, f64),
    pub y: (f64, i64, f64),
}

impl NearStencil {
    /// The stencil of the first `lines` major-axis lines for a map of height range `delta`.
    pub fn new(axes: Axes, rise_per_t: f64, lines: i64, delta: f64) -> NearStencil {
        let (ux, sx, ix) = axes.x;
        let (uy, sy, iy) = axes.y;
        assert!(sy != 0, "the major axis moves");
        let p = 0.5f64;
        let (mut cx, mut cy) = (0i64, 0i64);
        let mut t_in = 0.0f64;
        let mut tx = Track::exit_time(p, cx, sx, ix);
        let mut ty = Track::exit_time(p, cy, sy, iy);
        let mut texels = Vec::new();
        let mut line_start = vec![0];
        // The traversal's stepping (exact_traversal::shadowed_exact), from texel (0, 0).
        while cy * sy < lines {
            let t_out = tx.min(ty);
            let t_mid = 0.5 * (t_in + t_out);
            let qx = (p + ux * t_mid).clamp(cx as f64, (cx + 1) as f64);
            let qy = (p + uy * t_mid).clamp(cy as f64, (cy + 1) as f64);
            let (fx, fy) = (qx - 0.5, qy - 0.5);
            let (x0, y0) = (fx.floor(), fy.floor());
            let (a, b) = (fx - x0, fy - y0);
            texels.push(NearTexel {
                ox: x0 as i64,
                oy: y0 as i64,
                c: [
                    ((1.0 - a) * (1.0 - b)) as f32,
                    (a * (1.0 - b)) as f32,
                    ((1.0 - a) * b) as f32,
                    (a * b) as f32,
                ],
                rise: (rise_per_t * t_mid) as f32,
            });
            let (step_x, step_y) = (tx <= ty, ty <= tx);
            if step_x {
                cx += sx;
                tx = Track::exit_time(p, cx, sx, ix);
            }
            if step_y {
                cy += sy;
                ty = Track::exit_time(p, cy, sy, iy);
                line_start.push(texels.len());
            }
            t_in = t_out;
        }
        let r_max = texels.iter().fold(0.0f64, |m, t| m.max(t.rise as f64));
        NearStencil {
            x_lo: texels.iter().map(|t| t.ox).min().unwrap_or(0),
            x_hi: texels.iter().map(|t| t.ox + 1).max().unwrap_or(0),
            y_lo: texels.iter().map(|t| t.oy).min().unwrap_or(0),
            y_hi: texels.iter().map(|t| t.oy + 1).max().unwrap_or(0),
            texels,
            margin: (1e-6 * (delta + r_max) + 1e-30) as f32,
            line_start,
        }
    }

    /// Whether row y of an h-row map has every tap inside; then the columns `x_range` do.
    pub fn row_inside(&self, y: usize, h: usize) -> bool {
        y as i64 + self.y_lo >= 0 && y as i64 + self.y_hi < h as i64
    }

    /// The columns of a w-wide map whose taps are all inside (may be empty).
    pub fn x_range(&self, w: usize) -> (i64, i64) {
        (-self.x_lo, w as i64 - 1 - self.x_hi)
    }

    /// out[i] = v = max_k v_k for the pixels (xs + i, y), i < out.len(), of the w-wide
    /// row-major grid z; every pixel's taps must be inside (`row_inside`, `x_range`).
    pub fn row_max(&self, z: &[f32], w: usize, y: usize, xs: usize, out: &mut [f32]) {
        let n = out.len();
        out.fill(f32::NEG_INFINITY);
        let zc = &z[y * w + xs..][..n];
        for t in &self.texels {
            let r0 = ((y as i64 + t.oy) as usize) * w + (xs as i64 + t.ox) as usize;
            let (a, b) = (&z[r0..][..n], &z[r0 + 1..][..n]);
            let (c, d) = (&z[r0 + w..][..n], &z[r0 + w + 1..][..n]);
            for i in 0..n {
                let v = t.value([a[i], b[i], c[i], d[i]], zc[i]);
                out[i] = if v > out[i] { v } else { out[i] };
            }
        }
    }

    /// v = max v_k over the texels of line k alone (0 = the pixel's own) for the pixel (x, y)
    /// of the w×h row-major grid z, as [`NearStencil::row_max`] evaluates it (so [`decide`]
    /// applies with the same margin), or `None` when a tap of that line leaves the grid (the
    /// traversal's border clamping would then matter) or the stencil is shorter.
    pub fn line_max(
        &self,
        z: &[f32],
        (w, h): (usize, usize),
        (x, y): (i64, i64),
        k: usize,
    ) -> Option<f32> {
        let texels = &self.texels[*self.line_start.get(k)?..*self.line_start.get(k + 1)?];
        let zp = z[y as usize * w + x as usize];
        let mut out = f32::NEG_INFINITY;
        for t in texels {
            let (tx, ty) = (x + t.ox, y + t.oy);
            if tx < 0 || ty < 0 || tx + 1 >= w as i64 || ty + 1 >= h as i64 {
                return None;
            }
            let r0 = ty as usize * w + tx as usize;
            let v = t.value([z[r0], z[r0 + 1], z[r0 + w], z[r0 + w + 1]], zp);
            out = if v > out { v } else { out };
        }
        Some(out)
    }
}

/// The stencil's answer for one pixel from v (module docs): `Some(true)` shadowed by a texel
/// of the stencil, `Some(false)` by none of them, `None` undecided.
#[inline]
pub fn decide(v: f32, margin: f32) -> Option<bool> {
    if v > margin {
        Some(true)
    } else if v < -margin {
        Some(false)
    } else {
        None
    }
}
