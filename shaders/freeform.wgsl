// Recursive multilevel ray casting of freeform surfaces (quadric + perturbations, CSG): one
// `tile` dispatch per level (coarse to fine), then `pixel`. Rust twin, operation for operation:
// relume::freeform::twin (bounds, widening) and relume::freeform::twin_cast (the passes).
// The scene is eye-relative; every f32 bound is widened so that it contains the f64 bound
// (see twin.rs for the argument).

struct Quad { r0: vec4<f32>, r1: vec4<f32>, r2: vec4<f32> }
struct Bump { q: Quad, lo_weight: vec4<f32>, hi_flag: vec4<f32> }
struct Leaf { base: Quad, range: vec4<u32>, material: vec4<f32> }

struct Frame {
    forward: vec4<f32>,   // xyz, tan_x
    right: vec4<f32>,     // xyz, tan_y
    up: vec4<f32>,        // xyz, theta (one pixel's angle)
    depth: vec4<f32>,     // near_ln, far_ln, min_cell, unused
    size: vec4<u32>,      // width, height, ops, prune
    level: vec4<u32>,     // tile size, cols, parent_cols, is_top
}

@group(0) @binding(0) var<uniform> frame: Frame;
@group(0) @binding(1) var<storage, read> leaves: array<Leaf>;
@group(0) @binding(2) var<storage, read> bumps: array<Bump>;
@group(0) @binding(3) var<storage, read> ops: array<u32>;
@group(0) @binding(4) var<storage, read> parent_ranges: array<vec2<f32>>;
@group(0) @binding(5) var<storage, read_write> out_ranges: array<vec2<f32>>;
@group(0) @binding(6) var<storage, read_write> hits: array<vec4<f32>>;

const SYM: u32 = 8u;
const MAX_STACK: u32 = 8u;
const MAX_DFS: u32 = 48u;
const KC: f32 = 9.5367431640625e-7;
const KQ: f32 = 1.52587890625e-5;
const KR: f32 = 9.5367431640625e-7;
const TINY: f32 = 1e-30;
const INF: f32 = 3.0e38;

struct Aff { x0: f32, g: array<f32, 8>, e: f32 }
struct Cell { c: vec3<f32>, v: array<vec3<f32>, 8> }

fn exp32(x: f32) -> f32 {
    let y = x * 1.442695040888963;
    let n = floor(y + 0.5);
    let f = (y - n) * 0.6931471805599453;
    let p = 1.0 + f * (1.0 + f * (0.5 + f * (1.0 / 6.0 + f * (1.0 / 24.0 + f * (1.0 / 120.0 + f * (1.0 / 720.0 + f * (1.0 / 5040.0)))))));
    return ldexp(p, i32(n));
}

fn make_cell(c: vec3<f32>, v0: vec3<f32>, v1: vec3<f32>, v2: vec3<f32>, v3: vec3<f32>, v4: vec3<f32>) -> Cell {
    var cell: Cell;
    cell.c = c;
    cell.v[0] = v0; cell.v[1] = v1; cell.v[2] = v2; cell.v[3] = v3; cell.v[4] = v4;
    let r = abs(c) + abs(v0) + abs(v1) + abs(v2) + abs(v3) + abs(v4);
    cell.v[5] = vec3<f32>(KC * r.x + TINY, 0.0, 0.0);
    cell.v[6] = vec3<f32>(0.0, KC * r.y + TINY, 0.0);
    cell.v[7] = vec3<f32>(0.0, 0.0, KC * r.z + TINY);
    return cell;
}

fn extent(cell: Cell) -> vec3<f32> {
    var e = vec3<f32>(0.0);
    for (var k = 0u; k < SYM; k++) { e += abs(cell.v[k]); }
    return e;
}

fn aff_range(a: Aff) -> vec2<f32> {
    var r = a.e;
    for (var k = 0u; k < SYM; k++) { r += abs(a.g[k]); }
    r = r + KR * (r + abs(a.x0)) + TINY;
    return vec2<f32>(a.x0 - r, a.x0 + r);
}

fn aff_widen(a: ptr<function, Aff>) {
    var m = abs((*a).x0) + (*a).e;
    for (var k = 0u; k < SYM; k++) { m += abs((*a).g[k]); }
    (*a).e += KR * m + TINY;
}

fn aff_const(x: f32) -> Aff {
    var a: Aff;
    a.x0 = x;
    a.e = 0.0;
    for (var k = 0u; k < SYM; k++) { a.g[k] = 0.0; }
    return a;
}

fn aff_hull(lo: f32, hi: f32) -> Aff {
    var a = aff_const(0.5 * (lo + hi));
    a.e = 0.5 * (hi - lo);
    aff_widen(&a);
    return a;
}

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

fn quad_aff(q: Quad, cell: Cell) -> Aff {
    let a = quad_a(q);
    let b = vec3<f32>(q.r1.z, q.r1.w, q.r2.x);
    let c0 = q.r2.y;
    let ac = mat_vec(a, cell.c);
    let gc = ac + b;
    var out = aff_const(dot3(ac, cell.c) + 2.0 * dot3(b, cell.c) + c0);
    var av: array<vec3<f32>, 8>;
    for (var k = 0u; k < SYM; k++) {
        out.g[k] = 2.0 * dot3(gc, cell.v[k]);
        av[k] = mat_vec(a, cell.v[k]);
    }
    for (var j = 0u; j < SYM; j++) {
        let mjj = dot3(cell.v[j], av[j]);
        out.x0 += 0.5 * mjj;
        out.e += 0.5 * abs(mjj);
        for (var k = j + 1u; k < SYM; k++) {
            out.e += 2.0 * abs(dot3(cell.v[j], av[k]));
        }
    }
    let x = abs(cell.c) + extent(cell);
    var m = abs(c0);
    for (var i = 0u; i < 3u; i++) {
        m += 2.0 * abs(b[i]) * x[i];
        for (var j = 0u; j < 3u; j++) {
            m += abs(a[i][j]) * x[i] * x[j];
        }
    }
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
    for (var k = 0u; k < SYM; k++) { out.g[k] = alpha * x.g[k]; }
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
            var r = quad_aff(leaf.base, cell);
            for (var i = leaf.range.x; i < leaf.range.x + leaf.range.y; i++) {
                let b = bumps[i];
                if (b.hi_flag.w != 0.0 && any((b.hi_flag.xyz < lo) | (b.lo_weight.xyz > hi))) { continue; }
                let q = quad_aff(b.q, cell);
                if (aff_range(q).y > 0.0) {
                    let c = relu_cube(q);
                    let w = b.lo_weight.w;
                    r.x0 += w * c.x0;
                    for (var k = 0u; k < SYM; k++) { r.g[k] += w * c.g[k]; }
                    r.e += abs(w) * c.e;
                    aff_widen(&r);
                }
            }
            stack[slot] = r;
        } else if (kind == 3u) {
            stack[slot].x0 = -stack[slot].x0;
            for (var k = 0u; k < SYM; k++) { stack[slot].g[k] = -stack[slot].g[k]; }
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

@compute @workgroup_size(8, 8)
fn tile(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = frame.level.x;
    let cols = frame.level.y;
    let w = frame.size.x;
    let h = frame.size.y;
    let rows = (h + size - 1u) / size;
    if (id.x >= cols || id.y >= rows) { return; }
    var parent: vec2<f32>;
    if (frame.level.w == 1u) {
        parent = parent_ranges[0];
    } else {
        parent = parent_ranges[(id.y / 2u) * frame.level.z + id.x / 2u];
    }
    var out = vec2<f32>(INF, -INF);
    if (parent.x <= parent.y) {
        let ds = frame.up.w * f32(size);
        let near_ln = frame.depth.x;
        let x0 = screen_x(f32(id.x * size));
        let x1 = screen_x(f32(min((id.x + 1u) * size, w)));
        let y0 = screen_y(f32(min((id.y + 1u) * size, h)));
        let y1 = screen_y(f32(id.y * size));
        let first = i32(floor((parent.x - near_ln) / ds));
        let last = i32(ceil((parent.y - near_ln) / ds));
        for (var k = first; k < max(last, first + 1); k++) {
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
                break;
            }
        }
    }
    out_ranges[id.y * cols + id.x] = out;
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
    for (var k = leaf.range.x; k < leaf.range.x + leaf.range.y; k++) {
        let q = quad_eval(bumps[k].q, p);
        if (q > 0.0) { g += (3.0 * bumps[k].lo_weight.w * q * q) * quad_grad(bumps[k].q, p); }
    }
    let len = sqrt(g.x * g.x + g.y * g.y + g.z * g.z);
    if (len > 0.0) { return g * (e.z / len); }
    return vec3<f32>(0.0, 1.0, 0.0);
}

// Depth-first log-depth search along o + t·d; returns t, or -1 when nothing is found.
fn line_search(o: vec3<f32>, d: vec3<f32>, range: vec2<f32>, min_cell: f32, any_solid: bool) -> f32 {
    var stack: array<vec2<f32>, 48>;
    var sp = 1u;
    stack[0] = range;
    let pixel_cells = min((range.y - range.x) / min_cell, 64.0);
    var candidate = -1.0;
    var limit = INF;
    loop {
        if (sp == 0u) { break; }
        sp -= 1u;
        let s = stack[sp];
        if (candidate >= 0.0 && s.x >= limit) { break; }
        let t0 = exp32(s.x);
        let t1 = exp32(s.y);
        let tc = 0.5 * (t0 + t1);
        let tr = 0.5 * (t1 - t0);
        let zero = vec3<f32>(0.0);
        let r = field_range(make_cell(o + tc * d, d * tr, zero, zero, zero, zero));
        if (!(r.x <= 0.0 && r.y >= 0.0)) {
            if (any_solid && r.y < 0.0) { return tc; }
            continue;
        }
        if (s.y - s.x > min_cell && sp + 2u <= MAX_DFS) {
            let m = 0.5 * (s.x + s.y);
            stack[sp] = vec2<f32>(m, s.y);
            stack[sp + 1u] = vec2<f32>(s.x, m);
            sp += 2u;
            continue;
        }
        var a = t0;
        var b = t1;
        var fa = eval_point(o + a * d).x;
        var fb = eval_point(o + b * d).x;
        if ((fa <= 0.0) != (fb <= 0.0)) {
            var side = 0;
            for (var it = 0; it < 24; it++) {
                var c = (a * fb - b * fa) / (fb - fa);
                if (!(c > a && c < b)) { c = 0.5 * (a + b); }
                let fc = eval_point(o + c * d).x;
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
            return 0.5 * (a + b);
        }
        if (any_solid || fa <= 0.0) {
            if (fa <= 0.0) { return a; }
            return tc;
        }
        if (candidate < 0.0) {
            candidate = tc;
            limit = s.y + pixel_cells * min_cell;
        }
    }
    return candidate;
}

// Per pixel: (distance along the unit ray, normal) or (-1, 0, 0, 0).
@compute @workgroup_size(8, 8)
fn pixel(@builtin(global_invocation_id) id: vec3<u32>) {
    let w = frame.size.x;
    let h = frame.size.y;
    if (id.x >= w || id.y >= h) { return; }
    var r: vec2<f32>;
    if (frame.level.w == 1u) {
        r = parent_ranges[0];
    } else {
        r = parent_ranges[(id.y / 2u) * frame.level.z + id.x / 2u];
    }
    let i = id.y * w + id.x;
    hits[i] = vec4<f32>(-1.0, 0.0, 0.0, 0.0);
    // Never true: keeps `out_ranges` in this entry's automatic layout.
    if (w == 0u) { out_ranges[0] = vec2<f32>(0.0); }
    if (r.x > r.y) { return; }
    let x = screen_x(f32(id.x) + 0.5);
    let y = screen_y(f32(id.y) + 0.5);
    let f = frame.forward.xyz;
    let rt = frame.right.xyz;
    let u = frame.up.xyz;
    let d = vec3<f32>(f.x + x * rt.x + y * u.x, f.y + x * rt.y + y * u.y, f.z + x * rt.z + y * u.z);
    let len = sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
    let z = line_search(vec3<f32>(0.0), d, r, frame.depth.z, false);
    if (z < 0.0) { return; }
    hits[i] = vec4<f32>(z * len, 0.0, 0.0, 0.0);
}

// Per hit pixel: the normal, in a dispatch of its own (computed after `line_search` in the same
// invocation, lavapipe returned wrong normals: a large live state there).
@compute @workgroup_size(8, 8)
fn normals(@builtin(global_invocation_id) id: vec3<u32>) {
    let w = frame.size.x;
    let h = frame.size.y;
    if (id.x >= w || id.y >= h) { return; }
    if (w == 0u) { out_ranges[0] = vec2<f32>(parent_ranges[0]); }
    let i = id.y * w + id.x;
    let t = hits[i].x;
    if (t < 0.0) { return; }
    let x = screen_x(f32(id.x) + 0.5);
    let y = screen_y(f32(id.y) + 0.5);
    let f = frame.forward.xyz;
    let rt = frame.right.xyz;
    let u = frame.up.xyz;
    let d = vec3<f32>(f.x + x * rt.x + y * u.x, f.y + x * rt.y + y * u.y, f.z + x * rt.z + y * u.z);
    let len = sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
    let z = t / len;
    var n = normal_at(d * z);
    if (n.x * d.x + n.y * d.y + n.z * d.z > 0.0) { n = -n; }
    hits[i] = vec4<f32>(t, n);
}
