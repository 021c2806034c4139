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
    _pad2: u32,
    _pad3: u32,
}

@group(1) @binding(0) var<uniform> terrain: TerrainParams;
@group(1) @binding(1) var<storage, read> heights: array<f32>;
@group(1) @binding(2) var<storage, read> mip: array<f32>;            // (max, min) per texel, levels concatenated
@group(1) @binding(3) var<storage, read> mip_levels: array<vec4<u32>>; // (width, height, offset, 0) per level

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
fn coordinate_after(p: f32, u: f32, step: i32, inv_u: f32, t: f32, from: i32, last: i32) -> i32 {
    if (step == 0) { return from; }
    let x = p + u * t;
    let truncated = i32(x);
    let estimate = truncated - select(0, 1, x < f32(truncated));
    var c: i32;
    if (step > 0) { c = clamp(estimate, from, last); } else { c = clamp(estimate, last, from); }
    loop {
        if (c == last || exit_time(p, c, step, inv_u) > t) { break; }
        c = c + step;
    }
    loop {
        if (c == from || entry_time(p, c, step, inv_u) <= t) { break; }
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
