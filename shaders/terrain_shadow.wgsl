// Hard relief shadows on the GPU: the exact traversal (A1) and the accelerated traversal over
// the min/max mipmap (A2), line by line ports of relume::terrain::{exact_traversal,
// accelerated_traversal} in f32 (the CPU decides in f64; docs/terrain.md "Precision and the GPU
// port" says why they agree except for samples within f32 rounding of the sun ray).
// Included with `//! include terrain_shadow.wgsl`; bindings live in group 1.

const TRACK_RAY: u32 = 0u;
const TRACK_ZENITH: u32 = 1u;
const TRACK_BELOW: u32 = 2u;
// Stands in for +∞ (an axis the track does not move along never exits).
const NEVER: f32 = 1.0e30;

struct TerrainParams {
    width: u32,
    height: u32,
    levels: u32,
    kind: u32,            // TRACK_RAY, TRACK_ZENITH, TRACK_BELOW
    step_x: i32,
    step_y: i32,
    _pad0: u32,
    _pad1: u32,
    ux: f32,
    uy: f32,
    inv_ux: f32,
    inv_uy: f32,
    rise_per_t: f32,      // metres the sun ray rises per unit of t
    max_height: f32,      // the map's maximum (the mipmap's top)
    min_height: f32,      // the map's minimum
    metres_per_t: f32,    // horizontal metres per unit of t
    // Soft shadows: sun angular radius α (rad), planet radius (m, 0 = flat), sin and cos of
    // the sun's elevation at the map's centre and of its azimuth, cell size x and y (m), tan α
    // (trigonometry of the sun is done on the CPU in f64: GPU transcendentals may be loose).
    alpha: f32,
    planet_radius: f32,
    sin_elevation0: f32,
    cos_elevation0: f32,
    sin_azimuth: f32,
    cos_azimuth: f32,
    cell_x: f32,
    cell_y: f32,
    tan_alpha: f32,
    // Horizon-map shadows: the weight of the second of the two planes in `horizon_pair`, the
    // sun's elevation in degrees, and 1 when `horizon_pair` holds them (0: a placeholder).
    horizon_w: f32,
    elevation_deg: f32,
    has_horizon: u32,
}

@group(1) @binding(0) var<uniform> terrain: TerrainParams;
@group(1) @binding(1) var<storage, read> heights: array<f32>;
@group(1) @binding(2) var<storage, read> mip: array<f32>;            // (max, min) per texel, levels concatenated
@group(1) @binding(3) var<storage, read> mip_levels: array<vec4<u32>>; // (width, height, offset, 0) per level
// The two horizon-map planes around the sun's azimuth, per texel: the plane before in the low
// 16 bits, the plane after in the high 16 (relume::terrain::horizon_map).
@group(1) @binding(4) var<storage, read> horizon_pair: array<u32>;

fn height_at(col: i32, row: i32) -> f32 {
    return heights[u32(row) * terrain.width + u32(col)];
}

fn crossing(p: f32, boundary: i32, inv_u: f32) -> f32 {
    return (f32(boundary) - p) * inv_u;
}

fn exit_time(p: f32, c: i32, step: i32, inv_u: f32) -> f32 {
    if (step > 0) { return crossing(p, c + 1, inv_u); }
    if (step < 0) { return crossing(p, c, inv_u); }
    return NEVER;
}

fn entry_time(p: f32, c: i32, step: i32, inv_u: f32) -> f32 {
    if (step > 0) { return crossing(p, c, inv_u); }
    if (step < 0) { return crossing(p, c + 1, inv_u); }
    return -NEVER;
}

// Bilinear height at texel-space (qx, qy), clamped at the border and to the range of its four
// texels (sample_bilinear).
fn sample_bilinear(qx: f32, qy: f32) -> f32 {
    let w = i32(terrain.width);
    let h = i32(terrain.height);
    let fx = clamp(qx - 0.5, 0.0, f32(w - 1));
    let fy = clamp(qy - 0.5, 0.0, f32(h - 1));
    let x0 = min(i32(fx), w - 1);
    let y0 = min(i32(fy), h - 1);
    let x1 = min(x0 + 1, w - 1);
    let y1 = min(y0 + 1, h - 1);
    let tx = fx - f32(x0);
    let ty = fy - f32(y0);
    let a = height_at(x0, y0);
    let b = height_at(x1, y0);
    let c = height_at(x0, y1);
    let d = height_at(x1, y1);
    let top = a + (b - a) * tx;
    let bottom = c + (d - c) * tx;
    let v = top + (bottom - top) * ty;
    return clamp(v, min(min(a, b), min(c, d)), max(max(a, b), max(c, d)));
}

// Bilinear height relative to P (sample_bilinear − zp) at texel-space position (col + lx,
// row + ly), i.e. relative to P's texel corner: absolute positions near x ≈ 1000 carry ~6e-5
// texel of f32 rounding, which moves a steep sample next to P by millimetres and the lit
// fraction by 1e-3; local coordinates keep nearby samples exact. Differences of nearby f32
// heights are exact too, so the small relative heights keep their precision.
fn sample_bilinear_relative(col: i32, row: i32, lx: f32, ly: f32, zp: f32) -> f32 {
    let w = i32(terrain.width);
    let h = i32(terrain.height);
    let fx = clamp(lx - 0.5, f32(-col), f32(w - 1 - col));
    let fy = clamp(ly - 0.5, f32(-row), f32(h - 1 - row));
    let flx = floor(fx);
    let fly = floor(fy);
    let x0 = min(col + i32(flx), w - 1);
    let y0 = min(row + i32(fly), h - 1);
    let x1 = min(x0 + 1, w - 1);
    let y1 = min(y0 + 1, h - 1);
    let tx = fx - flx;
    let ty = fy - fly;
    let a = height_at(x0, y0) - zp;
    let b = height_at(x1, y0) - zp;
    let c = height_at(x0, y1) - zp;
    let d = height_at(x1, y1) - zp;
    let top = a + (b - a) * tx;
    let bottom = c + (d - c) * tx;
    let v = top + (bottom - top) * ty;
    return clamp(v, min(min(a, b), min(c, d)), max(max(a, b), max(c, d)));
}

// (t_mid, height) of the track's sample in texel (ix, iy) (texel_sample).
fn texel_sample(px: f32, py: f32, ix: i32, iy: i32, t_in: f32, t_out: f32) -> vec2<f32> {
    let t_mid = 0.5 * (t_in + t_out);
    let qx = clamp(px + terrain.ux * t_mid, f32(ix), f32(ix + 1));
    let qy = clamp(py + terrain.uy * t_mid, f32(iy), f32(iy + 1));
    return vec2<f32>(t_mid, sample_bilinear(qx, qy));
}

// Algorithm A1: every texel on the track (shadowed_exact).
fn shadowed_exact(col: i32, row: i32) -> bool {
    if (terrain.kind == TRACK_ZENITH) { return false; }
    if (terrain.kind == TRACK_BELOW) { return true; }
    let w = i32(terrain.width);
    let h = i32(terrain.height);
    let px = f32(col) + 0.5;
    let py = f32(row) + 0.5;
    let zp = height_at(col, row);
    let headroom = terrain.max_height - zp;
    var ix = col;
    var iy = row;
    var t_in = 0.0;
    for (var k = 0; k < w + h; k = k + 1) {
        let tx = exit_time(px, ix, terrain.step_x, terrain.inv_ux);
        let ty = exit_time(py, iy, terrain.step_y, terrain.inv_uy);
        let t_out = min(tx, ty);
        let s = texel_sample(px, py, ix, iy, t_in, t_out);
        if (s.y - zp > terrain.rise_per_t * s.x) { return true; }
        if (tx <= ty) { ix = ix + terrain.step_x; }
        if (ty <= tx) { iy = iy + terrain.step_y; }
        t_in = t_out;
        if (ix < 0 || iy < 0 || ix >= w || iy >= h || terrain.rise_per_t * t_in >= headroom) { return false; }
    }
    return false;
}

fn block_exit_time(p: f32, b: i32, shift: i32, step: i32, inv_u: f32) -> f32 {
    if (step > 0) { return crossing(p, (b + 1) << u32(shift), inv_u); }
    if (step < 0) { return crossing(p, b << u32(shift), inv_u); }
    return NEVER;
}

// The texel coordinate the exact traversal occupies just after time t (coordinate_after).
fn coordinate_after(p: f32, u: f32, step: i32, inv_u: f32, t: f32, first: i32, last: i32) -> i32 {
    if (step == 0) { return first; }
    let x = p + u * t;
    let truncated = i32(x);
    let estimate = truncated - select(0, 1, x < f32(truncated));
    var c: i32;
    if (step > 0) { c = clamp(estimate, first, last); } else { c = clamp(estimate, last, first); }
    loop {
        if (c == last || exit_time(p, c, step, inv_u) > t) { break; }
        c = c + step;
    }
    loop {
        if (c == first || entry_time(p, c, step, inv_u) <= t) { break; }
        c = c - step;
    }
    return c;
}

// Algorithm A2 over the min/max mipmap (shadowed_accelerated).
fn shadowed_accelerated(col: i32, row: i32) -> bool {
    if (terrain.kind == TRACK_ZENITH) { return false; }
    if (terrain.kind == TRACK_BELOW) { return true; }
    let w = i32(terrain.width);
    let h = i32(terrain.height);
    let sx = terrain.step_x;
    let sy = terrain.step_y;
    let px = f32(col) + 0.5;
    let py = f32(row) + 0.5;
    let zp = height_at(col, row);
    let rise = terrain.rise_per_t;
    let top = i32(terrain.levels) - 1;
    var level = -1;
    var ix = col;
    var iy = row;
    var t_in = 0.0;
    let headroom = terrain.max_height - zp;
    let max_iterations = (w + h + 1) * (top + 3);
    for (var k = 0; k < max_iterations; k = k + 1) {
        if (level < 0) {
            let tx = exit_time(px, ix, sx, terrain.inv_ux);
            let ty = exit_time(py, iy, sy, terrain.inv_uy);
            let t_out = min(tx, ty);
            let s = texel_sample(px, py, ix, iy, t_in, t_out);
            if (s.y - zp > rise * s.x) { return true; }
            if (tx <= ty) { ix = ix + sx; }
            if (ty <= tx) { iy = iy + sy; }
            t_in = t_out;
            if (ix < 0 || iy < 0 || ix >= w || iy >= h || rise * t_in >= headroom) { return false; }
            level = 0;
            continue;
        }
        let shift = level + 1;
        let bx = ix >> u32(shift);
        let by = iy >> u32(shift);
        let lv = mip_levels[level];
        let mi = 2u * (lv.z + u32(by) * lv.x + u32(bx));
        let bmax = mip[mi];
        let bmin = mip[mi + 1u];
        let txb = block_exit_time(px, bx, shift, sx, terrain.inv_ux);
        let tyb = block_exit_time(py, by, shift, sy, terrain.inv_uy);
        let t_exit = min(txb, tyb);
        if (bmax - zp <= rise * t_in) {
            var last_x: i32;
            var last_y: i32;
            if (sx > 0) { last_x = ((bx + 1) << u32(shift)) - 1; } else { last_x = bx << u32(shift); }
            if (sy > 0) { last_y = ((by + 1) << u32(shift)) - 1; } else { last_y = by << u32(shift); }
            var nx: i32;
            var ny: i32;
            if (txb <= tyb) { nx = last_x + sx; } else { nx = coordinate_after(px, terrain.ux, sx, terrain.inv_ux, t_exit, ix, last_x); }
            if (tyb <= txb) { ny = last_y + sy; } else { ny = coordinate_after(py, terrain.uy, sy, terrain.inv_uy, t_exit, iy, last_y); }
            ix = nx;
            iy = ny;
            t_in = t_exit;
            if (ix < 0 || iy < 0 || ix >= w || iy >= h || rise * t_in >= headroom) { return false; }
            if (level < top) { level = level + 1; }
        } else if (bmin - zp > rise * t_exit) {
            return true;
        } else {
            level = level - 1;
        }
    }
    return false;
}

// ---- Soft shadows (relume::terrain::soft): the sun disc's lit fraction by branch-and-bound
// over the max mipmap, the exact maximum of the occluders' slopes (f32 port).

const HALF_PI: f32 = 1.5707963267948966;

// tan of the elevation angle of a point `dh` above P at horizontal distance d (model::slope
// with h = zp + dh), flat or on a planet of radius R.
fn soft_slope(dh: f32, zp: f32, d: f32) -> f32 {
    let r = terrain.planet_radius;
    if (r <= 0.0) {
        return dh / d;
    }
    let phi = d / r;
    let s = sin(0.5 * phi);
    let rh = r + (zp + dh);
    return (dh - rh * 2.0 * s * s) / (rh * sin(phi));
}

// Upper bound of soft_slope over heights [hmin, hmax] and distances [d_in, d_out]
// (model::slope_upper_bound).
fn soft_slope_upper_bound(hmax: f32, hmin: f32, zp: f32, d_in: f32, d_out: f32) -> f32 {
    let r = terrain.planet_radius;
    var vert = hmax - zp;
    var horiz_in = d_in;
    var horiz_out = d_out;
    if (r > 0.0) {
        let phi_in = d_in / r;
        let s = sin(0.5 * phi_in);
        vert = (hmax - zp) - (r + hmax) * 2.0 * s * s;
        horiz_in = (r + hmin) * sin(phi_in);
        horiz_out = (r + hmax) * sin(d_out / r);
    }
    if (vert >= 0.0) {
        if (horiz_in > 0.0) { return vert / horiz_in; }
        return NEVER;
    }
    return vert / horiz_out;
}

// Nothing at distance ≥ d_in can beat `best` (model::beyond_reach).
fn soft_beyond_reach(hmax: f32, hmin: f32, zp: f32, d_in: f32, best: f32) -> bool {
    let r = terrain.planet_radius;
    var vert = hmax - zp;
    var horiz_in = d_in;
    if (r > 0.0) {
        let phi_in = d_in / r;
        let s = sin(0.5 * phi_in);
        vert = (hmax - zp) - (r + hmax) * 2.0 * s * s;
        horiz_in = (r + hmin) * sin(phi_in);
    }
    return vert < 0.0 || (horiz_in > 0.0 && vert / horiz_in <= best);
}

struct PixelSun {
    zp: f32,
    tan_e: f32,           // tan of the sun's elevation at P
    zenith: bool,         // the sun is at or past P's zenith
    slope_lit: f32,       // tan(e − α)
    slope_dark: f32,      // tan(e + α), NEVER past the zenith
    best_init: f32,
}

// The sun as texel (col, row) sees it (model::SoftSun::at_pixel), without inverse
// trigonometry: tan(e) = sin e / √(1 − sin² e) and the tangent addition formula for e ± α.
fn pixel_sun(col: i32, row: i32, zp: f32) -> PixelSun {
    var sin_e = terrain.sin_elevation0;
    let r = terrain.planet_radius;
    if (r > 0.0) {
        let ax = (f32(col) + 0.5 - f32(terrain.width) / 2.0) * terrain.cell_x;
        let ay = -(f32(row) + 0.5 - f32(terrain.height) / 2.0) * terrain.cell_y;
        let len = sqrt(ax * ax + ay * ay);
        let ang = len / r;
        var along = 0.0;
        if (len > 0.0) {
            along = (terrain.sin_azimuth * ax + terrain.cos_azimuth * ay) / len;
        }
        sin_e = clamp(terrain.sin_elevation0 * cos(ang) + terrain.cos_elevation0 * sin(ang) * along, -1.0, 1.0);
    }
    let cos_e = sqrt(max(1.0 - sin_e * sin_e, 0.0));
    let zenith = cos_e <= 0.0;
    let tan_e = select(sin_e / cos_e, NEVER, zenith);
    let ta = terrain.tan_alpha;
    // e − α ≤ −90° only for a sun near the nadir; tan(e − α) is then hugely negative.
    let den_lit = 1.0 + tan_e * ta;
    let slope_lit = select((tan_e - ta) / den_lit, -NEVER, den_lit <= 0.0 && tan_e < 0.0);
    let den_dark = 1.0 - tan_e * ta;
    let slope_dark = select(NEVER, (tan_e + ta) / den_dark, den_dark > 0.0 && !zenith);
    return PixelSun(zp, tan_e, zenith, slope_lit, slope_dark, max(slope_lit, 0.0));
}

// acos to 2e-8 (Abramowitz & Stegun 4.4.46): WGSL lets acos be as loose as its atan2-based
// definition.
fn acos_accurate(x_in: f32) -> f32 {
    let x = abs(x_in);
    let p = 1.5707963050 + x * (-0.2145988016 + x * (0.0889789874 + x * (-0.0501743046
        + x * (0.0308918810 + x * (-0.0170881256 + x * (0.0066700901 + x * -0.0012624911))))));
    let r = sqrt(max(1.0 - x, 0.0)) * p;
    return select(r, PI - r, x_in < 0.0);
}

// lit(d) = 1 − (acos d − d·√(1 − d²))/π, d clamped to [−1, 1] (model::lit).
fn disc_lit(d_in: f32) -> f32 {
    let d = clamp(d_in, -1.0, 1.0);
    return clamp(1.0 - (acos_accurate(d) - d * sqrt(max(1.0 - d * d, 0.0))) / PI, 0.0, 1.0);
}

// The lit fraction for the largest slope `best` (PixelSun::lit_fraction): θ = e − atan(best)
// is the angle whose tangent is x = (tan e − best)/(1 + tan e·best); inside the penumbra
// |θ| ≤ α is small and atan(x) is its series (error < x⁹/9), outside the disc is all or nothing.
fn lit_fraction(ps: PixelSun, best: f32) -> f32 {
    let b = max(best, 0.0);
    let den = 1.0 + ps.tan_e * b;
    if (den <= 0.0) {
        return 0.0;
    }
    let x = (ps.tan_e - b) / den;
    var theta: f32;
    if (abs(x) < 0.1) {
        let x2 = x * x;
        theta = x * (1.0 - x2 * (1.0 / 3.0 - x2 * (0.2 - x2 / 7.0)));
    } else {
        theta = atan(x);
    }
    return disc_lit(theta / terrain.alpha);
}

// Lit fraction of texel (col, row) (branch_and_bound::lit_branch_and_bound).
fn lit_branch_and_bound(col: i32, row: i32) -> f32 {
    let zp = height_at(col, row);
    let ps = pixel_sun(col, row, zp);
    // PixelSun::settled
    if (ps.tan_e <= -terrain.tan_alpha || ps.best_init >= ps.slope_dark) { return 0.0; }
    if (ps.zenith) { return 1.0; }
    let w = i32(terrain.width);
    let h = i32(terrain.height);
    let sx = terrain.step_x;
    let sy = terrain.step_y;
    let px = f32(col) + 0.5;
    let py = f32(row) + 0.5;
    let m = terrain.metres_per_t;
    let top = i32(terrain.levels) - 1;
    var level = -1;
    var ix = col;
    var iy = row;
    var t_in = 0.0;
    var best = ps.best_init;
    let max_iterations = (w + h + 1) * (top + 3);
    for (var k = 0; k < max_iterations; k = k + 1) {
        if (level < 0) {
            let tx = exit_time(px, ix, sx, terrain.inv_ux);
            let ty = exit_time(py, iy, sy, terrain.inv_uy);
            let t_out = min(tx, ty);
            let t_mid = 0.5 * (t_in + t_out);
            // The sample point relative to P's texel corner (see sample_bilinear_relative).
            let lx = clamp(0.5 + terrain.ux * t_mid, f32(ix - col), f32(ix - col + 1));
            let ly = clamp(0.5 + terrain.uy * t_mid, f32(iy - row), f32(iy - row + 1));
            let sl = soft_slope(sample_bilinear_relative(col, row, lx, ly, zp), zp, m * t_mid);
            if (sl > best) {
                best = sl;
                if (best >= ps.slope_dark) { return 0.0; }
            }
            if (tx <= ty) { ix = ix + sx; }
            if (ty <= tx) { iy = iy + sy; }
            t_in = t_out;
            level = 0;
        } else {
            let shift = level + 1;
            let bx = ix >> u32(shift);
            let by = iy >> u32(shift);
            let lv = mip_levels[level];
            let mi = 2u * (lv.z + u32(by) * lv.x + u32(bx));
            let txb = block_exit_time(px, bx, shift, sx, terrain.inv_ux);
            let tyb = block_exit_time(py, by, shift, sy, terrain.inv_uy);
            let t_exit = min(txb, tyb);
            let ub = soft_slope_upper_bound(mip[mi], mip[mi + 1u], zp, m * t_in, m * t_exit);
            if (ub > best) {
                level = level - 1;
                continue;
            }
            var last_x: i32;
            var last_y: i32;
            if (sx > 0) { last_x = ((bx + 1) << u32(shift)) - 1; } else { last_x = bx << u32(shift); }
            if (sy > 0) { last_y = ((by + 1) << u32(shift)) - 1; } else { last_y = by << u32(shift); }
            var nx: i32;
            var ny: i32;
            if (txb <= tyb) { nx = last_x + sx; } else { nx = coordinate_after(px, terrain.ux, sx, terrain.inv_ux, t_exit, ix, last_x); }
            if (tyb <= txb) { ny = last_y + sy; } else { ny = coordinate_after(py, terrain.uy, sy, terrain.inv_uy, t_exit, iy, last_y); }
            ix = nx;
            iy = ny;
            t_in = t_exit;
            if (level < top) { level = level + 1; }
        }
        if (ix < 0 || iy < 0 || ix >= w || iy >= h || soft_beyond_reach(terrain.max_height, terrain.min_height, zp, m * t_in, best)) {
            break;
        }
    }
    return lit_fraction(ps, best);
}

// Degrees per step of a quantised horizon angle: relume::terrain::horizon_map::STEP_DEG.
const HORIZON_STEP_DEG: f32 = 180.0 / 65535.0;

// Hard shadow from the horizon maps in O(1): below the horizon interpolated between the two
// stored azimuths around the sun's. Rust twin: relume::terrain::horizon_map::shadowed_f32 (with
// HorizonMap::shadow_mask_f32 for the sun at the zenith or below the horizon).
fn shadowed_horizon(col: i32, row: i32) -> bool {
    if (terrain.has_horizon == 0u) {
        return shadowed_accelerated(col, row);
    }
    if (terrain.kind == TRACK_ZENITH) {
        return false;
    }
    if (terrain.kind == TRACK_BELOW) {
        return true;
    }
    let v = horizon_pair[u32(row) * terrain.width + u32(col)];
    let h0 = f32(v & 0xffffu) * HORIZON_STEP_DEG - 90.0;
    let h1 = f32(v >> 16u) * HORIZON_STEP_DEG - 90.0;
    return terrain.elevation_deg < h0 + (h1 - h0) * terrain.horizon_w;
}
