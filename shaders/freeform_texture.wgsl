// Shape textures in the freeform kernel (included by freeform.wgsl): a record of words after
// the CSG program in `ops` (layout and widening argument: relume::freeform::twin_texture, the
// Rust twin, operation for operation). `at` is the record's absolute word index.

// The CSG program (frame.size.z words), then the shape-texture records.
@group(0) @binding(3) var<storage, read> ops: array<u32>;

const TEX_KR: f32 = 9.5367431640625e-7;
const TEX_TINY: f32 = 1e-30;
const TEX_INF: f32 = 3.0e38;
const TEX_APAD: f32 = 9.765625e-4;
const TEX_HEAD: u32 = 28u;
const TEX_PI: f32 = 3.14159265358979;

fn tw(i: u32) -> u32 { return ops[i]; }
fn tf(i: u32) -> f32 { return bitcast<f32>(ops[i]); }
fn tv3(i: u32) -> vec3<f32> { return vec3<f32>(tf(i), tf(i + 1u), tf(i + 2u)); }
fn tex_wrap(x: f32, m: f32) -> f32 { return x - m * floor(x / m); }
fn norm1(a: vec3<f32>) -> f32 { return abs(a.x) + abs(a.y) + abs(a.z); }
fn tdot(a: vec3<f32>, b: vec3<f32>) -> f32 { return a.x * b.x + a.y * b.y + a.z * b.z; }
fn len3(a: vec3<f32>) -> f32 { return sqrt(tdot(a, a)); }

fn tex_height(at: u32, i: u32, j: u32) -> f32 {
    return tf(at + tw(at + 4u) + j * tw(at + 1u) + i);
}

// (max, min) of mip m (5 heights, 6 and 7 slopes) over samples [x.x, x.y] × [y.x, y.y].
fn tex_mip_range(at: u32, m: u32, x: vec2<u32>, y: vec2<u32>) -> vec2<f32> {
    let span = max(x.y - x.x, y.y - y.x);
    var l = 0u;
    if (span > 1u) { l = firstLeadingBit(span - 1u); }
    if (l >= tw(at + 3u)) {
        if (m == 5u) { return vec2<f32>(tf(at + 24u), tf(at + 25u)); }
        return vec2<f32>(tf(at + 20u + m), 0.0);
    }
    let lt = at + TEX_HEAD + 3u * l;
    let off = tw(lt);
    let lw = tw(lt + 1u);
    let lh = tw(lt + 2u);
    let b = 2u << l;
    let bx0 = x.x / b;
    let bx1 = min(x.y / b, lw - 1u);
    let by0 = y.x / b;
    let by1 = min(y.y / b, lh - 1u);
    let base = at + tw(at + m);
    let ia = base + 2u * (off + by0 * lw + bx0);
    let ib = base + 2u * (off + by0 * lw + bx1);
    let ic = base + 2u * (off + by1 * lw + bx0);
    let id = base + 2u * (off + by1 * lw + bx1);
    return vec2<f32>(
        max(max(tf(ia), tf(ib)), max(tf(ic), tf(id))),
        min(min(tf(ia + 1u), tf(ib + 1u)), min(tf(ic + 1u), tf(id + 1u))));
}

fn tex_clampi(v: f32, n: u32) -> u32 { return u32(clamp(v, 0.0, f32(n - 1u))); }

fn tex_ranged(at: u32, m: u32, xl: f32, xh: f32, yl: f32, yh: f32) -> vec2<f32> {
    let w = tw(at + 1u);
    let h = tw(at + 2u);
    // NaN compares false both ways.
    if (!(xl == xl) || !(xh == xh) || !(yl == yl) || !(yh == yh)) {
        return tex_mip_range(at, m, vec2<u32>(0u, w - 1u), vec2<u32>(0u, h - 1u));
    }
    let y0 = tex_clampi(floor(yl), h);
    let ys = vec2<u32>(y0, max(tex_clampi(ceil(yh), h), y0));
    if (tw(at) == 0u) {
        let x0 = tex_clampi(floor(xl), w);
        return tex_mip_range(at, m, vec2<u32>(x0, max(tex_clampi(ceil(xh), w), x0)), ys);
    }
    let x0 = floor(xl);
    let x1 = ceil(xh);
    if (x1 - x0 >= f32(w - 1u)) {
        return tex_mip_range(at, m, vec2<u32>(0u, w - 1u), ys);
    }
    let a = u32(clamp(tex_wrap(x0, f32(w)), 0.0, f32(w - 1u)));
    let b = a + u32(x1 - x0);
    if (b < w) { return tex_mip_range(at, m, vec2<u32>(a, b), ys); }
    let r1 = tex_mip_range(at, m, vec2<u32>(a, w - 1u), ys);
    let r2 = tex_mip_range(at, m, vec2<u32>(0u, b - w), ys);
    return vec2<f32>(max(r1.x, r2.x), min(r1.y, r2.y));
}

fn tex_height_at(at: u32, xin: f32, yin: f32) -> f32 {
    let w = tw(at + 1u);
    let h = tw(at + 2u);
    let y = clamp(yin, 0.0, f32(h - 1u));
    let j = min(u32(floor(y)), h - 2u);
    let fy = y - f32(j);
    var i0: u32;
    var i1: u32;
    var fx: f32;
    if (tw(at) != 0u) {
        let x = tex_wrap(xin, f32(w));
        i0 = min(u32(floor(x)), w - 1u);
        i1 = (i0 + 1u) % w;
        fx = x - f32(i0);
    } else {
        let x = clamp(xin, 0.0, f32(w - 1u));
        i0 = min(u32(floor(x)), w - 2u);
        i1 = i0 + 1u;
        fx = x - f32(i0);
    }
    let top = tex_height(at, i0, j) + fx * (tex_height(at, i1, j) - tex_height(at, i0, j));
    let bottom = tex_height(at, i0, j + 1u) + fx * (tex_height(at, i1, j + 1u) - tex_height(at, i0, j + 1u));
    return top + fy * (bottom - top);
}

fn tex_coords(at: u32, p: vec3<f32>) -> vec3<f32> {
    let q = p - tv3(at + 8u);
    if (tw(at) == 0u) {
        return vec3<f32>(tdot(tv3(at + 20u), q), tdot(tv3(at + 12u), q) * tf(at + 15u), tdot(tv3(at + 16u), q) * tf(at + 19u));
    }
    let w = f32(tw(at + 1u));
    let h = f32(tw(at + 2u));
    if (tw(at) == 2u) {
        return vec3<f32>(sqrt(q.x * q.x + q.z * q.z) - tf(at + 11u), (atan2(q.z, q.x) + TEX_PI) / (2.0 * TEX_PI) * w - 0.5, q.y * tf(at + 19u));
    }
    let rho = len3(q);
    let lon = atan2(q.z, q.x);
    var lat = 0.0;
    if (rho > 0.0) { lat = asin(clamp(q.y / rho, -1.0, 1.0)); }
    return vec3<f32>(rho - tf(at + 11u), (lon + TEX_PI) / (2.0 * TEX_PI) * w - 0.5, (0.5 * TEX_PI - lat) / TEX_PI * h - 0.5);
}

fn tex_value(at: u32, p: vec3<f32>) -> f32 {
    let c = tex_coords(at, p);
    return c.x - tex_height_at(at, c.y, c.z);
}

fn tex_gradient(at: u32, p: vec3<f32>) -> vec3<f32> {
    let w = tw(at + 1u);
    let h = tw(at + 2u);
    let q = p - tv3(at + 8u);
    var spacing = 1.0 / max(tf(at + 15u), tf(at + 19u));
    if (tw(at) == 1u) {
        spacing = max(len3(q), tf(at + 11u) * 1e-6) * TEX_PI / f32(max(h, w / 2u));
    } else if (tw(at) == 2u) {
        let axis = max(sqrt(q.x * q.x + q.z * q.z), tf(at + 11u) * 1e-6);
        spacing = min(axis * 2.0 * TEX_PI / f32(w), 1.0 / tf(at + 19u));
    }
    let step = 0.01 * spacing;
    var g: vec3<f32>;
    for (var k = 0; k < 3; k++) {
        var a = p;
        var b = p;
        a[k] += step;
        b[k] -= step;
        g[k] = (tex_value(at, a) - tex_value(at, b)) / (a[k] - b[k]);
    }
    return g;
}

fn tex_slopes(at: u32, xs: vec2<f32>, ys: vec2<f32>) -> vec2<f32> {
    let x0 = xs.x - 1.0;
    let x1 = xs.y + 1.0;
    let y0 = ys.x - 1.0;
    let y1 = ys.y + 1.0;
    return vec2<f32>(tex_ranged(at, 6u, x0, x1, y0, y1).x, tex_ranged(at, 7u, x0, x1, y0, y1).x);
}

// The sample x range (padded by px) of atan2(z, x) over the xz-rectangle of [lo, hi], which
// does not contain the axis: the extremes are at its corners.
fn tex_angle_range(lo: vec3<f32>, hi: vec3<f32>, w: f32, px: f32) -> vec2<f32> {
    let mid = atan2(0.5 * (lo.z + hi.z), 0.5 * (lo.x + hi.x));
    let d0 = tex_wrap(atan2(lo.z, lo.x) - mid + TEX_PI, 2.0 * TEX_PI) - TEX_PI;
    let d1 = tex_wrap(atan2(hi.z, lo.x) - mid + TEX_PI, 2.0 * TEX_PI) - TEX_PI;
    let d2 = tex_wrap(atan2(lo.z, hi.x) - mid + TEX_PI, 2.0 * TEX_PI) - TEX_PI;
    let d3 = tex_wrap(atan2(hi.z, hi.x) - mid + TEX_PI, 2.0 * TEX_PI) - TEX_PI;
    let a = min(min(d0, d1), min(d2, d3));
    let b = max(max(d0, d1), max(d2, d3));
    let k = w / (2.0 * TEX_PI);
    return vec2<f32>((mid + a + TEX_PI) * k - 0.5 - px, (mid + b + TEX_PI) * k - 0.5 + px);
}

// The widened range of F over the box [lo, hi].
fn tex_range(at: u32, lo: vec3<f32>, hi: vec3<f32>) -> vec2<f32> {
    let c = 0.5 * (lo + hi);
    let e0 = 0.5 * (hi - lo);
    let e = e0 + TEX_KR * (abs(c) + e0) + TEX_TINY;
    let o = tv3(at + 8u);
    let w = f32(tw(at + 1u));
    let h = f32(tw(at + 2u));
    var dl: f32;
    var dh: f32;
    var xs: vec2<f32>;
    var ys: vec2<f32>;
    var grad: f32;
    var pad: vec2<f32>;
    if (tw(at) == 0u) {
        let q = c - o;
        let n = tv3(at + 20u);
        let u = tv3(at + 12u);
        let v = tv3(at + 16u);
        let sx = tf(at + 15u);
        let sy = tf(at + 19u);
        let mag = norm1(c) + norm1(o);
        let dc = tdot(n, q);
        let dr = tdot(abs(n), e);
        let ds = TEX_KR * (mag + dr) + TEX_TINY;
        let xc = tdot(u, q) * sx;
        let xr = tdot(abs(u), e) * sx;
        let yc = tdot(v, q) * sy;
        let yr = tdot(abs(v), e) * sy;
        let px = 0.02 + TEX_KR * (abs(xc) + xr + mag * sx);
        let py = 0.02 + TEX_KR * (abs(yc) + yr + mag * sy);
        xs = vec2<f32>(xc - xr - px, xc + xr + px);
        ys = vec2<f32>(yc - yr - py, yc + yr + py);
        let s = tex_slopes(at, xs, ys);
        grad = (s.x * sx + s.y * sy) * (1.0 + TEX_KR);
        dl = dc - dr - ds;
        dh = dc + dr + ds;
        pad = vec2<f32>(px, py);
    } else if (tw(at) == 2u) {
        let radius = tf(at + 11u);
        let sy = tf(at + 19u);
        let cs = TEX_KR * (norm1(c) + norm1(e) + norm1(o)) + TEX_TINY;
        let lo_r = (c - e) - o - vec3<f32>(cs);
        let hi_r = (c + e) - o + vec3<f32>(cs);
        let near = clamp(vec2<f32>(0.0), lo_r.xz, hi_r.xz);
        let far = max(abs(lo_r.xz), abs(hi_r.xz));
        let dmin = sqrt(near.x * near.x + near.y * near.y) * (1.0 - TEX_KR);
        let dmax = sqrt(far.x * far.x + far.y * far.y) * (1.0 + TEX_KR);
        let rs = TEX_KR * radius + TEX_TINY;
        let px = 0.02 + 4.0 * TEX_APAD * w / (2.0 * TEX_PI);
        let py = 0.02 + TEX_KR * (abs(lo_r.y) + abs(hi_r.y)) * sy;
        ys = vec2<f32>(lo_r.y * sy - py, hi_r.y * sy + py);
        xs = vec2<f32>(-1.0 - px, w + px);
        grad = TEX_INF;
        if (dmin > 0.0) {
            xs = tex_angle_range(lo_r, hi_r, w, px);
            let s = tex_slopes(at, xs, ys);
            grad = (s.x * w / (2.0 * TEX_PI * dmin) + s.y * sy) * (1.0 + TEX_KR);
        }
        dl = dmin - radius - rs;
        dh = dmax - radius + rs;
        pad = vec2<f32>(px, py);
    } else {
        let radius = tf(at + 11u);
        let cs = TEX_KR * (norm1(c) + norm1(e) + norm1(o)) + TEX_TINY;
        let lo_r = (c - e) - o - vec3<f32>(cs);
        let hi_r = (c + e) - o + vec3<f32>(cs);
        let near = clamp(vec3<f32>(0.0), lo_r, hi_r);
        let far = max(abs(lo_r), abs(hi_r));
        let dmin = len3(near) * (1.0 - TEX_KR);
        let dmax = len3(far) * (1.0 + TEX_KR);
        let rs = TEX_KR * radius + TEX_TINY;
        let px = 0.02 + 4.0 * TEX_APAD * w / (2.0 * TEX_PI);
        let py = 0.02 + 4.0 * TEX_APAD * h / TEX_PI;
        xs = vec2<f32>(-1.0 - px, w + px);
        ys = vec2<f32>(-1.0 - py, h + py);
        grad = TEX_INF;
        let axis = sqrt(near.x * near.x + near.z * near.z) * (1.0 - TEX_KR);
        if (dmin > 0.0) {
            if (axis > 0.0) {
                xs = tex_angle_range(lo_r, hi_r, w, px);
            }
            let up = 1.0 + TEX_KR;
            let dn = 1.0 - TEX_KR;
            var smax = hi_r.y / (dmax * up);
            if (hi_r.y > 0.0) { smax = hi_r.y / (dmin * dn); }
            var smin = lo_r.y / (dmax * up);
            if (lo_r.y < 0.0) { smin = lo_r.y / (dmin * dn); }
            let lat_hi = asin(clamp(smax, -1.0, 1.0));
            let lat_lo = asin(clamp(smin, -1.0, 1.0));
            let k = h / TEX_PI;
            ys = vec2<f32>((0.5 * TEX_PI - lat_hi) * k - 0.5 - py, (0.5 * TEX_PI - lat_lo) * k - 0.5 + py);
            if (axis > 0.0) {
                let s = tex_slopes(at, xs, ys);
                grad = (s.x * w / (2.0 * TEX_PI * axis) + s.y * h / (TEX_PI * dmin)) * (1.0 + TEX_KR);
            }
        }
        dl = dmin - radius - rs;
        dh = dmax - radius + rs;
        pad = vec2<f32>(px, py);
    }
    let hr = tex_ranged(at, 5u, xs.x, xs.y, ys.x, ys.y);
    let hmag = max(abs(hr.x), abs(hr.y));
    let slack = TEX_KR * (abs(dl) + abs(dh) + hmag) + TEX_TINY;
    let mip = vec2<f32>(dl - hr.x - slack, dh - hr.y + slack);
    let s = tex_slopes(at, xs, ys);
    let fc = tex_value(at, c);
    let rad = len3(e) * (1.0 + TEX_KR);
    let reach = (1.0 + grad) * rad;
    let fslack = s.x * pad.x + s.y * pad.y + TEX_KR * (abs(fc) + norm1(c) + norm1(o) + 4.0 * hmag) + TEX_TINY;
    var lip = vec2<f32>(-TEX_INF, TEX_INF);
    if (reach < TEX_INF) { lip = vec2<f32>(fc - reach - fslack, fc + reach + fslack); }
    return vec2<f32>(max(mip.x, lip.x), min(mip.y, lip.y));
}
