// Thematic textures (docs/themes.md): the class lookup with fractal / natural / blend borders
// and the theme texel, twin of relume::theme::compose (`Lookup::class_at`, `class`,
// `theme_texel`, `albedo`), reading the index levels Colour Cell Compressed (twin of
// relume::theme::ccc::Ccc::at).
//
// Everything lives in one u32 buffer (`theme_data`) at the offsets of `theme`: index words
// (all levels), exception blocks (4 words each), theme texels (RGBA8), the turbulence map (f32
// pairs, bitcast), the sRGB table (256 f32), the classes (8 words each: theme, kind,
// amplitude, scale, width, tile, warp, warp_scale) and the level table (4 words each: word
// offset, width, height, exception offset). Included with `//! include theme.wgsl`; bindings
// live in group 2.

struct ThemeParams {
    words_at: u32,
    exceptions_at: u32,
    textures_at: u32,
    noise_at: u32,
    lut_at: u32,
    classes_at: u32,
    levels_at: u32,
    index_levels: u32,
    tex_size: u32,
    tex_levels: u32,
    per_theme: u32,
    noise_size: u32,
    shift: vec2<f32>,
    index_size: vec2<f32>,
}
@group(2) @binding(0) var<uniform> theme: ThemeParams;
@group(2) @binding(1) var<storage, read> theme_data: array<u32>;

const BLEND_TAPS = array<vec2<f32>, 9>(
    vec2<f32>(1.0, 0.0),
    vec2<f32>(0.70710677, 0.70710677),
    vec2<f32>(0.0, 1.0),
    vec2<f32>(-0.70710677, 0.70710677),
    vec2<f32>(-1.0, 0.0),
    vec2<f32>(-0.70710677, -0.70710677),
    vec2<f32>(0.0, -1.0),
    vec2<f32>(0.70710677, -0.70710677),
    vec2<f32>(0.0, 0.0),
);

fn theme_f32(i: u32) -> f32 {
    return bitcast<f32>(theme_data[i]);
}

// The index level for a footprint: nearest, never blended.
fn theme_level(footprint: f32) -> u32 {
    let lod = log2(max(footprint, 1.0));
    return min(u32(floor(lod + 0.5)), theme.index_levels - 1u);
}

// The class at p (level-0 texels, clamped) on `level`, decoded from its CCC word.
fn theme_class_at(level: u32, p: vec2<f32>) -> u32 {
    let l = theme.levels_at + level * 4u;
    let words = theme_data[l];
    let w = theme_data[l + 1u];
    let h = theme_data[l + 2u];
    let exceptions = theme_data[l + 3u];
    let scale = f32(1u << level);
    let col = u32(clamp(floor(p.x / scale), 0.0, f32(w - 1u)));
    let row = u32(clamp(floor(p.y / scale), 0.0, f32(h - 1u)));
    let bw = (w + 3u) / 4u;
    let word = theme_data[theme.words_at + words + (row / 4u) * bw + col / 4u];
    let k = (row % 4u) * 4u + col % 4u;
    if ((word & 0xffu) == 255u) {
        let block = theme.exceptions_at + (exceptions + (word >> 8u)) * 4u;
        return (theme_data[block + k / 4u] >> ((k % 4u) * 8u)) & 0xffu;
    }
    if (((word >> (16u + k)) & 1u) == 1u) {
        return (word >> 8u) & 0xffu;
    }
    return word & 0xffu;
}

// Where a bilinear sample of an n×n grid that wraps falls at uv (periods, texel centres at
// (i + ½)/n): the corner texel and the weights. Twin of relume::theme::noise::wrap_bilinear.
struct WrapBilinear {
    c0: i32,
    r0: i32,
    fx: f32,
    fy: f32,
}

fn wrap_bilinear(uv: vec2<f32>, n: i32) -> WrapBilinear {
    let nf = f32(n);
    let x = (uv.x - floor(uv.x)) * nf - 0.5;
    let y = (uv.y - floor(uv.y)) * nf - 0.5;
    let x0 = floor(x);
    let y0 = floor(y);
    return WrapBilinear(i32(x0), i32(y0), x - x0, y - y0);
}

fn wrap_i(v: i32, m: i32) -> i32 {
    return ((v % m) + m) % m;
}

// Bilinear sample (wrap) of the turbulence map at (u, v), period 1.
fn theme_noise(uv: vec2<f32>) -> vec2<f32> {
    let m = i32(theme.noise_size);
    let w = wrap_bilinear(uv, m);
    let a = theme_noise_at(w.c0, w.r0, m);
    let b = theme_noise_at(w.c0 + 1, w.r0, m);
    let c = theme_noise_at(w.c0, w.r0 + 1, m);
    let d = theme_noise_at(w.c0 + 1, w.r0 + 1, m);
    let top = a + (b - a) * w.fx;
    let bottom = c + (d - c) * w.fx;
    return top + (bottom - top) * w.fy;
}

fn theme_noise_at(c: i32, r: i32, m: i32) -> vec2<f32> {
    let i = theme.noise_at + u32(wrap_i(r, m) * m + wrap_i(c, m)) * 2u;
    return vec2<f32>(theme_f32(i), theme_f32(i + 1u));
}

fn theme_texel_rgb(base: u32, c: i32, r: i32, n: i32) -> vec3<f32> {
    let p = theme_data[theme.textures_at + base + u32(wrap_i(r, n) * n + wrap_i(c, n))];
    return vec3<f32>(
        theme_f32(theme.lut_at + (p & 0xffu)),
        theme_f32(theme.lut_at + ((p >> 8u) & 0xffu)),
        theme_f32(theme.lut_at + ((p >> 16u) & 0xffu)),
    );
}

fn theme_level_offset(l: u32) -> u32 {
    var o = 0u;
    for (var k = 0u; k < l; k++) {
        let s = theme.tex_size >> k;
        o += s * s;
    }
    return o;
}

fn theme_bilinear(t: u32, l: u32, st: vec2<f32>) -> vec3<f32> {
    let n = i32(theme.tex_size >> l);
    let base = t * theme.per_theme + theme_level_offset(l);
    let w = wrap_bilinear(st, n);
    let a = theme_texel_rgb(base, w.c0, w.r0, n);
    let b = theme_texel_rgb(base, w.c0 + 1, w.r0, n);
    let c = theme_texel_rgb(base, w.c0, w.r0 + 1, n);
    let d = theme_texel_rgb(base, w.c0 + 1, w.r0 + 1, n);
    let top = a + (b - a) * w.fx;
    let bottom = c + (d - c) * w.fx;
    return top + (bottom - top) * w.fy;
}

fn theme_trilinear(t: u32, lod_in: f32, st: vec2<f32>) -> vec3<f32> {
    let top = f32(theme.tex_levels - 1u);
    let lod = clamp(lod_in, 0.0, top);
    let l0 = floor(lod);
    let f = lod - l0;
    let a = theme_bilinear(t, u32(l0), st);
    if (f == 0.0 || l0 >= top) {
        return a;
    }
    let b = theme_bilinear(t, u32(l0) + 1u, st);
    return a + (b - a) * f;
}

// Word k of class c.
fn theme_class_word(c: u32, k: u32) -> u32 {
    return theme_data[theme.classes_at + c * 8u + k];
}

// The border-perturbed lookup position of class c0's border at p.
fn theme_perturbed(c0: u32, p: vec2<f32>) -> vec2<f32> {
    if (theme_class_word(c0, 1u) == 0u) {
        let amplitude = bitcast<f32>(theme_class_word(c0, 2u));
        let scale = bitcast<f32>(theme_class_word(c0, 3u));
        let n = theme_noise(vec2<f32>(p.x / scale + theme.shift.x, p.y / scale + theme.shift.y));
        return vec2<f32>(p.x + amplitude * n.x, p.y + amplitude * n.y);
    }
    return p;
}

// The texel of class c's theme at p.
fn theme_texel(c: u32, p: vec2<f32>, footprint: f32) -> vec3<f32> {
    let tile = bitcast<f32>(theme_class_word(c, 5u));
    let warp = bitcast<f32>(theme_class_word(c, 6u));
    let warp_scale = bitcast<f32>(theme_class_word(c, 7u));
    let n = theme_noise(vec2<f32>(p.x / warp_scale + 0.37, p.y / warp_scale + 0.61));
    let st = vec2<f32>(p.x / tile + warp * n.x, p.y / tile + warp * n.y);
    let lod_tex = log2(max(footprint * f32(theme.tex_size) / tile, 1.0));
    return theme_trilinear(theme_class_word(c, 0u), lod_tex, st);
}

// Linear-RGB albedo at p (level-0 index texels) for a pixel spanning `footprint` texels.
fn theme_albedo(p: vec2<f32>, footprint: f32) -> vec3<f32> {
    let level = theme_level(footprint);
    let c0 = theme_class_at(level, p);
    if (theme_class_word(c0, 1u) == 2u) {
        let width = bitcast<f32>(theme_class_word(c0, 4u));
        var sum = vec3<f32>(0.0);
        for (var k = 0u; k < 9u; k++) {
            let q = vec2<f32>(p.x + width * BLEND_TAPS[k].x, p.y + width * BLEND_TAPS[k].y);
            sum += theme_texel(theme_class_at(level, q), p, footprint);
        }
        return sum / 9.0;
    }
    let c = theme_class_at(level, theme_perturbed(c0, p));
    return theme_texel(c, p, footprint);
}
