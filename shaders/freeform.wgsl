// Recursive multilevel ray casting of freeform surfaces (quadric + perturbations, CSG): one
// `tile` dispatch per level (coarse to fine), then `pixel`. Rust twin, operation for operation:
// relume::freeform::twin (bounds, widening) and relume::freeform::twin_cast (the passes).
// The scene is eye-relative; every f32 bound is widened so that it contains the f64 bound
// (see twin.rs for the argument). Shape textures: freeform_texture.wgsl, records after the
// program in `ops` (a textured leaf has range = (0, 0, 1, record offset after the program)).
//! include freeform_affine.wgsl
//! include freeform_texture.wgsl

struct Quad { r0: vec4<f32>, r1: vec4<f32>, r2: vec4<f32> }
struct Bump { q: Quad, lo_weight: vec4<f32>, hi_flag: vec4<f32> }
struct Leaf { base: Quad, range: vec4<u32>, material: vec4<f32> }

struct Frame {
    forward: vec4<f32>,   // xyz, tan_x
    right: vec4<f32>,     // xyz, tan_y
    up: vec4<f32>,        // xyz, theta (one pixel's angle)
    depth: vec4<f32>,     // near_ln, far_ln, min_cell, depth cells per tile pass
    size: vec4<u32>,      // width, height, ops, prune
    level: vec4<u32>,     // tile size (pixel passes: unused), cols (pixel passes: round), parent_cols, is_top
    sun: vec4<f32>,       // unit direction toward the sun, scene scale (shadow pass)
}

@group(0) @binding(0) var<uniform> frame: Frame;
@group(0) @binding(1) var<storage, read> leaves: array<Leaf>;
@group(0) @binding(2) var<storage, read> bumps: array<Bump>;
// @group(0) @binding(3): `ops`, the CSG program then the shape-texture records, declared in
// freeform_texture.wgsl (which is also compiled on its own).
// Per tile: (log-depth lo, hi, next depth cell, state: 0 new, 1 walking, 2 done).
@group(0) @binding(4) var<storage, read> parent_ranges: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read_write> out_ranges: array<vec4<f32>>;
@group(0) @binding(6) var<storage, read_write> hits: array<vec4<f32>>;
// The pixel pass only: each pixel's place in its search (node depth, node index, candidate,
// limit) between rounds, and per round the number of pixels that did not finish in it.
@group(0) @binding(7) var<storage, read_write> search: array<vec4<f32>>;
@group(0) @binding(8) var<storage, read_write> unfinished: array<atomic<u32>>;

const MAX_STACK: u32 = 8u;
const MAX_DEPTH: u32 = 24u;
const REFINE_STEPS: i32 = 24;
const KQ: f32 = 1.52587890625e-5;
const INF: f32 = 3.0e38;

fn quad_a(q: Quad) -> mat3x3<f32> {
    return mat3x3<f32>(
        vec3<f32>(q.r0.x, q.r0.y, q.r0.z),
        vec3<f32>(q.r0.y, q.r0.w, q.r1.x),
        vec3<f32>(q.r0.z, q.r1.x, q.r1.y));
}

fn mat_vec(a: mat3x3<f32>, v: vec3<f32>) -> vec3<f32> {
    // Row i of the symmetric matrix is its column i: dot products in the twin's order.
    return vec3<f32>(dot3(a[0], v), dot3(a[1], v), dot3(a[2], v));
}

fn dot3(a: vec3<f32>, b: vec3<f32>) -> f32 {
    return a.x * b.x + a.y * b.y + a.z * b.z;
}

// Σ_k |vx·ax[k] + vy·ay[k] + vz·az[k]|: one row of the cell's generator Gram matrix under A.
fn row_abs(vx: f32, vy: f32, vz: f32, ax0: vec4<f32>, ax1: vec4<f32>, ay0: vec4<f32>, ay1: vec4<f32>, az0: vec4<f32>, az1: vec4<f32>) -> f32 {
    return sum8_abs(vx * ax0 + vy * ay0 + vz * az0, vx * ax1 + vy * ay1 + vz * az1);
}

fn quad_aff(q: Quad, cell: Cell) -> Aff {
    let a = quad_a(q);
    let b = vec3<f32>(q.r1.z, q.r1.w, q.r2.x);
    let c0 = q.r2.y;
    let ac = mat_vec(a, cell.c);
    let gc = ac + b;
    var out: Aff;
    out.g0 = 2.0 * (gc.x * cell.x0 + gc.y * cell.y0 + gc.z * cell.z0);
    out.g1 = 2.0 * (gc.x * cell.x1 + gc.y * cell.y1 + gc.z * cell.z1);
    // A·v_k for the eight generators, by component.
    let ax0 = a[0].x * cell.x0 + a[0].y * cell.y0 + a[0].z * cell.z0;
    let ax1 = a[0].x * cell.x1 + a[0].y * cell.y1 + a[0].z * cell.z1;
    let ay0 = a[1].x * cell.x0 + a[1].y * cell.y0 + a[1].z * cell.z0;
    let ay1 = a[1].x * cell.x1 + a[1].y * cell.y1 + a[1].z * cell.z1;
    let az0 = a[2].x * cell.x0 + a[2].y * cell.y0 + a[2].z * cell.z0;
    let az1 = a[2].x * cell.x1 + a[2].y * cell.y1 + a[2].z * cell.z1;
    let d0 = cell.x0 * ax0 + cell.y0 * ay0 + cell.z0 * az0;
    let d1 = cell.x1 * ax1 + cell.y1 * ay1 + cell.z1 * az1;
    out.x0 = (dot3(ac, cell.c) + 2.0 * dot3(b, cell.c) + c0) + 0.5 * (sum4(d0) + sum4(d1));
    var total = row_abs(cell.x0.x, cell.y0.x, cell.z0.x, ax0, ax1, ay0, ay1, az0, az1);
    total += row_abs(cell.x0.y, cell.y0.y, cell.z0.y, ax0, ax1, ay0, ay1, az0, az1);
    total += row_abs(cell.x0.z, cell.y0.z, cell.z0.z, ax0, ax1, ay0, ay1, az0, az1);
    total += row_abs(cell.x0.w, cell.y0.w, cell.z0.w, ax0, ax1, ay0, ay1, az0, az1);
    total += row_abs(cell.x1.x, cell.y1.x, cell.z1.x, ax0, ax1, ay0, ay1, az0, az1);
    total += row_abs(cell.x1.y, cell.y1.y, cell.z1.y, ax0, ax1, ay0, ay1, az0, az1);
    total += row_abs(cell.x1.z, cell.y1.z, cell.z1.z, ax0, ax1, ay0, ay1, az0, az1);
    total += row_abs(cell.x1.w, cell.y1.w, cell.z1.w, ax0, ax1, ay0, ay1, az0, az1);
    // ½Σ|M_jj| + 2Σ_{j<k}|M_jk| = Σ_jk|M_jk| − ½Σ|M_jj|.
    out.e = total - 0.5 * sum8_abs(d0, d1);
    let x = abs(cell.c) + extent(cell);
    let ab = abs(b);
    let ax = vec3<f32>(
        abs(a[0].x) * x.x + abs(a[0].y) * x.y + abs(a[0].z) * x.z,
        abs(a[1].x) * x.x + abs(a[1].y) * x.y + abs(a[1].z) * x.z,
        abs(a[2].x) * x.x + abs(a[2].y) * x.y + abs(a[2].z) * x.z);
    let m = abs(c0) + 2.0 * (ab.x * x.x + ab.y * x.y + ab.z * x.z) + (x.x * ax.x + x.y * ax.y + x.z * ax.z);
    out.e += KQ * m + TINY;
    return out;
}

fn cube0(t: f32) -> f32 {
    let u = max(t, 0.0);
    return u * u * u;
}

fn relu_cube(x: Aff) -> Aff {
    let r = aff_range(x);
    let lo = r.x;
    let hi = r.y;
    if (hi <= 0.0) { return aff_const(0.0); }
    let flo = cube0(lo);
    let fhi = cube0(hi);
    var alpha = 0.0;
    if (hi > lo) { alpha = (fhi - flo) / (hi - lo); }
    let u = clamp(sqrt(alpha / 3.0), max(lo, 0.0), hi);
    let zeta = 0.5 * ((flo + alpha * (u - lo)) + cube0(u)) - alpha * u;
    let delta = max(max(abs(cube0(lo) - (alpha * lo + zeta)), abs(cube0(hi) - (alpha * hi + zeta))), abs(cube0(u) - (alpha * u + zeta)));
    var out: Aff;
    out.x0 = alpha * x.x0 + zeta;
    out.g0 = alpha * x.g0;
    out.g1 = alpha * x.g1;
    out.e = alpha * x.e + delta + KR * (fhi + alpha * max(abs(lo), abs(hi)) + abs(zeta));
    aff_widen(&out);
    return out;
}

fn field_range(cell: Cell) -> vec2<f32> {
    let ext = extent(cell);
    let lo = cell.c - ext;
    let hi = cell.c + ext;
    var stack: array<Aff, 8>;
    for (var o = 0u; o < frame.size.z; o++) {
        let op = ops[o];
        let kind = op >> 24u;
        let slot = (op >> 16u) & 0xffu;
        let arg = op & 0xffffu;
        if (kind == 0u) {
            let leaf = leaves[arg];
            if (leaf.range.z != 0u) {
                let t = tex_range(frame.size.z + leaf.range.w, lo, hi);
                stack[slot] = aff_hull(t.x, t.y);
                continue;
            }
            var r = quad_aff(leaf.base, cell);
            for (var i = leaf.range.x; i < leaf.range.x + leaf.range.y; i++) {
                let b = bumps[i];
                if (b.hi_flag.w != 0.0 && any((b.hi_flag.xyz < lo) | (b.lo_weight.xyz > hi))) { continue; }
                let q = quad_aff(b.q, cell);
                if (aff_range(q).y > 0.0) {
                    let c = relu_cube(q);
                    let w = b.lo_weight.w;
                    r.x0 += w * c.x0;
                    r.g0 += w * c.g0;
                    r.g1 += w * c.g1;
                    r.e += abs(w) * c.e;
                    aff_widen(&r);
                }
            }
            stack[slot] = r;
        } else if (kind == 3u) {
            stack[slot].x0 = -stack[slot].x0;
            stack[slot].g0 = -stack[slot].g0;
            stack[slot].g1 = -stack[slot].g1;
        } else {
            // A binary min or max of the two top values.
            let x = stack[slot];
            let y = stack[slot + 1u];
            let rx = aff_range(x);
            let ry = aff_range(y);
            var r = x;
            if (kind == 1u) {
                if (rx.y <= ry.x) { } else if (ry.y <= rx.x) { r = y; } else { r = aff_hull(min(rx.x, ry.x), min(rx.y, ry.y)); }
            } else {
                if (rx.x >= ry.y) { } else if (ry.x >= rx.y) { r = y; } else { r = aff_hull(max(rx.x, ry.x), max(rx.y, ry.y)); }
            }
            stack[slot] = r;
        }
    }
    return aff_range(stack[0]);
}

fn screen_x(ex: f32) -> f32 { return (ex / f32(frame.size.x) * 2.0 - 1.0) * frame.forward.w; }
fn screen_y(ey: f32) -> f32 { return (1.0 - ey / f32(frame.size.y) * 2.0) * frame.right.w; }

fn pyramid_cell(x0: f32, x1: f32, y0: f32, y1: f32, s0: f32, s1: f32) -> Cell {
    let z0 = exp32(s0);
    let z1 = exp32(s1);
    let zc = 0.5 * (z0 + z1);
    let zr = 0.5 * (z1 - z0);
    let xc = 0.5 * (x0 + x1);
    let xr = 0.5 * (x1 - x0);
    let yc = 0.5 * (y0 + y1);
    let yr = 0.5 * (y1 - y0);
    let f = frame.forward.xyz;
    let r = frame.right.xyz;
    let u = frame.up.xyz;
    let dc = vec3<f32>(f.x + xc * r.x + yc * u.x, f.y + xc * r.y + yc * u.y, f.z + xc * r.z + yc * u.z);
    return make_cell(dc * zc, dc * zr, r * (zc * xr), u * (zc * yr), r * (zr * xr), u * (zr * yr));
}

// One pass over one level: each tile walks at most `frame.depth.w` depth cells of its parent's
// range and keeps its place in `out_ranges`; the host records as many passes as the longest
// possible walk needs, so every tile is done before the next level reads it. (Lavapipe ends an
// invocation's loops after 65,535 back-edges; a pass stays below that. On a GPU, short passes
// also keep a frame clear of the driver's watchdog.)
@compute @workgroup_size(8, 8)
fn tile(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = frame.level.x;
    let cols = frame.level.y;
    let w = frame.size.x;
    let h = frame.size.y;
    let rows = (h + size - 1u) / size;
    if (id.x >= cols || id.y >= rows) { return; }
    let idx = id.y * cols + id.x;
    let state = out_ranges[idx];
    if (state.w == 2.0) { return; }
    var parent: vec2<f32>;
    if (frame.level.w == 1u) {
        parent = parent_ranges[0].xy;
    } else {
        parent = parent_ranges[(id.y / 2u) * frame.level.z + id.x / 2u].xy;
    }
    if (parent.x > parent.y) {
        out_ranges[idx] = vec4<f32>(INF, -INF, 0.0, 2.0);
        return;
    }
    let ds = frame.up.w * f32(size);
    let near_ln = frame.depth.x;
    let x0 = screen_x(f32(id.x * size));
    let x1 = screen_x(f32(min((id.x + 1u) * size, w)));
    let y0 = screen_y(f32(min((id.y + 1u) * size, h)));
    let y1 = screen_y(f32(id.y * size));
    let first = i32(floor((parent.x - near_ln) / ds));
    let end = max(i32(ceil((parent.y - near_ln) / ds)), first + 1);
    var out = vec2<f32>(INF, -INF);
    var k = first;
    if (state.w == 1.0) {
        out = state.xy;
        k = i32(state.z);
    }
    let stop = min(end, k + i32(frame.depth.w));
    var done = false;
    for (; k < stop; k++) {
        let s0 = max(near_ln + f32(k) * ds, parent.x);
        let s1 = min(near_ln + f32(k + 1) * ds, parent.y);
        if (s1 <= s0) { continue; }
        let r = field_range(pyramid_cell(x0, x1, y0, y1, s0, s1));
        if (r.x <= 0.0 && r.y >= 0.0) {
            if (out.x == INF) { out.x = s0; }
            out.y = s1;
        }
        if (frame.size.w == 1u && r.y < 0.0) {
            if (out.x != INF) { out.y = s1; }
            done = true;
            break;
        }
    }
    if (k >= end) { done = true; }
    var st = 1.0;
    if (done) { st = 2.0; }
    out_ranges[idx] = vec4<f32>(out, f32(k), st);
    // Never true: keeps `hits` in this entry's automatic layout (both entries share one).
    if (frame.size.x == 0u) { hits[0] = vec4<f32>(0.0); }
}

fn quad_eval(q: Quad, p: vec3<f32>) -> f32 {
    let x = p.x;
    let y = p.y;
    let z = p.z;
    return q.r0.x * x * x + q.r0.w * y * y + q.r1.y * z * z
        + 2.0 * (q.r0.y * x * y + q.r0.z * x * z + q.r1.x * y * z)
        + 2.0 * (q.r1.z * x + q.r1.w * y + q.r2.x * z)
        + q.r2.y;
}

fn quad_grad(q: Quad, p: vec3<f32>) -> vec3<f32> {
    return 2.0 * vec3<f32>(
        q.r0.x * p.x + q.r0.y * p.y + q.r0.z * p.z + q.r1.z,
        q.r0.y * p.x + q.r0.w * p.y + q.r1.x * p.z + q.r1.w,
        q.r0.z * p.x + q.r1.x * p.y + q.r1.y * p.z + q.r2.x);
}

fn leaf_value(i: u32, p: vec3<f32>) -> f32 {
    let leaf = leaves[i];
    if (leaf.range.z != 0u) { return tex_value(frame.size.z + leaf.range.w, p); }
    var v = quad_eval(leaf.base, p);
    for (var k = leaf.range.x; k < leaf.range.x + leaf.range.y; k++) {
        let q = quad_eval(bumps[k].q, p);
        if (q > 0.0) { v += bumps[k].lo_weight.w * q * q * q; }
    }
    return v;
}

// The field at p: (value, active leaf, CSG sign).
fn eval_point(p: vec3<f32>) -> vec3<f32> {
    var vals: array<f32, 8>;
    var ids: array<u32, 8>;
    var signs: array<f32, 8>;
    for (var o = 0u; o < frame.size.z; o++) {
        let op = ops[o];
        let kind = op >> 24u;
        let slot = (op >> 16u) & 0xffu;
        let arg = op & 0xffffu;
        if (kind == 0u) {
            vals[slot] = leaf_value(arg, p);
            ids[slot] = arg;
            signs[slot] = 1.0;
        } else if (kind == 3u) {
            vals[slot] = -vals[slot];
            signs[slot] = -signs[slot];
        } else {
            // A binary min or max of slots (slot, slot + 1).
            let x = vals[slot];
            let y = vals[slot + 1u];
            if ((kind == 1u && y < x) || (kind == 2u && y > x)) {
                vals[slot] = y;
                ids[slot] = ids[slot + 1u];
                signs[slot] = signs[slot + 1u];
            }
        }
    }
    return vec3<f32>(vals[0], f32(ids[0]), signs[0]);
}

fn normal_at(p: vec3<f32>) -> vec3<f32> {
    let e = eval_point(p);
    let leaf = leaves[u32(e.y)];
    var g = quad_grad(leaf.base, p);
    if (leaf.range.z != 0u) { g = tex_gradient(frame.size.z + leaf.range.w, p); }
    for (var k = leaf.range.x; k < leaf.range.x + leaf.range.y; k++) {
        let q = quad_eval(bumps[k].q, p);
        if (q > 0.0) { g += (3.0 * bumps[k].lo_weight.w * q * q) * quad_grad(bumps[k].q, p); }
    }
    let len = sqrt(g.x * g.x + g.y * g.y + g.z * g.z);
    if (len > 0.0) { return g * (e.z / len); }
    return vec3<f32>(0.0, 1.0, 0.0);
}

// A node of the search's binary subdivision of `range`: depth d, index i (exact in f32 below
// 2^24), bounds range.x + L·i·2^-d and range.x + L·(i+1)·2^-d.
fn node_bounds(range: vec2<f32>, d: u32, i: u32) -> vec2<f32> {
    let len = range.y - range.x;
    let scale = ldexp(1.0, -i32(d));
    return vec2<f32>(range.x + len * (f32(i) * scale), range.x + len * (f32(i + 1u) * scale));
}

struct Search { d: u32, i: u32, candidate: f32, limit: f32, done: bool, t: f32 }

// Up to `steps` steps of the depth-first log-depth search along o + t·d, resuming `st`: a step
// bounds one node and either culls it, splits it, or tests its end points. The search is
// stackless (the next node follows from (d, i) alone), so a pixel can stop after any step and
// go on in the next round. A sign change is refined in the same invocation after the search
// loop (inside it, the refinement would run once per SIMD lane that reaches it, and lavapipe
// counts every one against its loop limit). Result in st.t: t, or -1 when nothing is found.
fn line_search(o: vec3<f32>, dir: vec3<f32>, range: vec2<f32>, min_cell: f32, any_solid: bool, st_in: Search, steps: u32) -> Search {
    var st = st_in;
    let pixel_cells = min((range.y - range.x) / min_cell, 64.0);
    var found = false;
    var a = 0.0;
    var b = 0.0;
    var fa = 0.0;
    var fb = 0.0;
    for (var n = 0u; n < steps; n++) {
        let s = node_bounds(range, st.d, st.i);
        if (st.candidate >= 0.0 && s.x >= st.limit) { st.done = true; break; }
        let t0 = exp32(s.x);
        let t1 = exp32(s.y);
        let tc = 0.5 * (t0 + t1);
        let tr = 0.5 * (t1 - t0);
        let zero = vec3<f32>(0.0);
        let r = field_range(make_cell(o + tc * dir, dir * tr, zero, zero, zero, zero));
        var next = true;
        if (!(r.x <= 0.0 && r.y >= 0.0)) {
            if (any_solid && r.y < 0.0) { st.t = tc; st.done = true; return st; }
        } else if (s.y - s.x > min_cell && st.d < MAX_DEPTH) {
            st.d += 1u;
            st.i *= 2u;
            next = false;
        } else {
            let ga = eval_point(o + t0 * dir).x;
            let gb = eval_point(o + t1 * dir).x;
            if ((ga <= 0.0) != (gb <= 0.0)) {
                a = t0; b = t1; fa = ga; fb = gb;
                found = true;
                break;
            }
            if (any_solid || ga <= 0.0) {
                st.t = tc;
                if (ga <= 0.0) { st.t = t0; }
                st.done = true;
                return st;
            }
            if (st.candidate < 0.0) {
                st.candidate = tc;
                st.limit = s.y + pixel_cells * min_cell;
            }
        }
        if (next) {
            // The next node in depth-first order: up past every level where this node is a
            // right child, then its right sibling; done when that climbs past the root.
            let up = countTrailingZeros(~st.i);
            if (up >= st.d) { st.done = true; break; }
            st.d -= up;
            st.i = (st.i >> up) + 1u;
        }
    }
    if (!found) {
        if (st.done) { st.t = st.candidate; }
        return st;
    }
    var side = 0;
    for (var it = 0; it < REFINE_STEPS; it++) {
        var c = (a * fb - b * fa) / (fb - fa);
        if (!(c > a && c < b)) { c = 0.5 * (a + b); }
        let fc = eval_point(o + c * dir).x;
        if ((fc < 0.0) == (fa < 0.0)) {
            a = c; fa = fc;
            if (side == -1) { fb *= 0.5; }
            side = -1;
        } else {
            b = c; fb = fc;
            if (side == 1) { fa *= 0.5; }
            side = 1;
        }
    }
    st.t = 0.5 * (a + b);
    st.done = true;
    return st;
}

// One round of the per-pixel search: (distance along the unit ray, state, 0, 0) in `hits`,
// state 1 while searching and 2 when done (the normals pass then writes the normal). A pixel
// takes at most `frame.depth.w` steps per round; the host runs rounds until none is left.
@compute @workgroup_size(8, 8)
fn pixel(@builtin(global_invocation_id) id: vec3<u32>) {
    let w = frame.size.x;
    let h = frame.size.y;
    if (id.x >= w || id.y >= h) { return; }
    let i = id.y * w + id.x;
    let prev = hits[i];
    if (prev.y == 2.0) { return; }
    var r: vec2<f32>;
    if (frame.level.w == 1u) {
        r = parent_ranges[0].xy;
    } else {
        r = parent_ranges[(id.y / 2u) * frame.level.z + id.x / 2u].xy;
    }
    // Never true: keeps `out_ranges` in this entry's automatic layout.
    if (w == 0u) { out_ranges[0] = vec4<f32>(0.0); }
    if (r.x > r.y) { hits[i] = vec4<f32>(-1.0, 2.0, 0.0, 0.0); return; }
    var st = Search(0u, 0u, -1.0, INF, false, -1.0);
    if (prev.y == 1.0) {
        let saved = search[i];
        st = Search(u32(saved.x), u32(saved.y), saved.z, saved.w, false, -1.0);
    }
    let d = pixel_dir(id.xy);
    let len = sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
    st = line_search(vec3<f32>(0.0), d, r, frame.depth.z, false, st, u32(frame.depth.w));
    if (!st.done) {
        search[i] = vec4<f32>(f32(st.d), f32(st.i), st.candidate, st.limit);
        hits[i] = vec4<f32>(-1.0, 1.0, 0.0, 0.0);
        atomicAdd(&unfinished[frame.level.y], 1u);
        return;
    }
    var t = -1.0;
    if (st.t >= 0.0) { t = st.t * len; }
    hits[i] = vec4<f32>(t, 2.0, 0.0, 0.0);
}

// Per hit pixel: the normal, in a dispatch of its own (computed after `line_search` in the same
// invocation, lavapipe returned wrong normals: a large live state there), and the surface hit
// into the shadow pass's state (status 0 = not searched yet, shadowed, leaf, 0).
@compute @workgroup_size(8, 8)
fn normals(@builtin(global_invocation_id) id: vec3<u32>) {
    let w = frame.size.x;
    let h = frame.size.y;
    if (id.x >= w || id.y >= h) { return; }
    if (w == 0u) { out_ranges[0] = parent_ranges[0]; }
    let i = id.y * w + id.x;
    let t = hits[i].x;
    if (t < 0.0) {
        hits[i] = vec4<f32>(-1.0, 0.0, 0.0, 0.0);
        out_ranges[i] = vec4<f32>(2.0, 0.0, 0.0, 0.0);
        return;
    }
    let d = pixel_dir(id.xy);
    let len = sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
    let z = t / len;
    let p = d * z;
    var n = normal_at(p);
    if (n.x * d.x + n.y * d.y + n.z * d.z > 0.0) { n = -n; }
    hits[i] = vec4<f32>(t, n);
    out_ranges[i] = vec4<f32>(0.0, 0.0, eval_point(p).y, 0.0);
}

// The ray through pixel `px` (not unit length).
fn pixel_dir(px: vec2<u32>) -> vec3<f32> {
    let x = screen_x(f32(px.x) + 0.5);
    let y = screen_y(f32(px.y) + 0.5);
    let f = frame.forward.xyz;
    let rt = frame.right.xyz;
    let u = frame.up.xyz;
    return vec3<f32>(f.x + x * rt.x + y * u.x, f.y + x * rt.y + y * u.y, f.z + x * rt.z + y * u.z);
}

// Per hit pixel facing the sun: is the sun blocked? The same search toward the sun (any solid
// cell ends it), from the hit point lifted off the surface, in rounds like `pixel`; state in
// `out_ranges` as the normals pass left it (status 0 new, 1 searching, 2 done; shadowed; leaf).
@compute @workgroup_size(8, 8)
fn shadow(@builtin(global_invocation_id) id: vec3<u32>) {
    let w = frame.size.x;
    let h = frame.size.y;
    if (id.x >= w || id.y >= h) { return; }
    if (w == 0u) { out_ranges[0] = parent_ranges[0]; }
    let i = id.y * w + id.x;
    let s = out_ranges[i];
    if (s.x == 2.0) { return; }
    let hit = hits[i];
    let l = frame.sun.xyz;
    let n = hit.yzw;
    if (dot3(n, l) <= 0.0) { out_ranges[i] = vec4<f32>(2.0, 0.0, s.z, 0.0); return; }
    let d = pixel_dir(id.xy);
    let len = sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
    let t = hit.x;
    let p = d * (t / len);
    // Lifted off the surface by half a pixel's footprint (at least the CPU caster's
    // 1e-5·max(t, scale·1e-3)): an f32 hit lies up to ~1e-4·t below the surface, and a ray
    // started there would find the solid it starts in.
    let eps = max(1e-5 * max(t, frame.sun.w * 1e-3), 0.5 * frame.up.w * t);
    let o = p + eps * n;
    let far = max(exp32(frame.depth.y), t) * 2.0;
    let range = vec2<f32>(log(eps), log(far));
    var st = Search(0u, 0u, -1.0, INF, false, -1.0);
    if (s.x == 1.0) {
        let saved = search[i];
        st = Search(u32(saved.x), u32(saved.y), saved.z, saved.w, false, -1.0);
    }
    st = line_search(o, l, range, frame.depth.z, true, st, u32(frame.depth.w));
    if (!st.done) {
        search[i] = vec4<f32>(f32(st.d), f32(st.i), st.candidate, st.limit);
        out_ranges[i] = vec4<f32>(1.0, 0.0, s.z, 0.0);
        atomicAdd(&unfinished[frame.level.y], 1u);
        return;
    }
    var shadowed = 0.0;
    if (st.t >= 0.0) { shadowed = 1.0; }
    out_ranges[i] = vec4<f32>(2.0, shadowed, s.z, 0.0);
}
