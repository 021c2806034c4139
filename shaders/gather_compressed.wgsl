// Indirect exitance B = S·E straight from the compressed transport (the format of
// docs/compression.md): the dense part decoded block by block — by the texture unit (hardware
// BC1/BC6H) or by the WGSL decoders below over a storage buffer (BC1, BC4, F16, F32) — plus the
// sparse sidecar, with the reordering undone (E'[k] = E[perm[k]], B[perm[k]] = B'[k]).
// Rust twin: relume::compress::gather (CPU), whose block decoders these mirror
// (compress::bc1::decode_block, compress::blocks::bc4_palette, compress::dense::decode_block_at).
//
// One workgroup per block row (4 output rows); its 64 threads take every 64th block of the row
// and the partial sums are reduced in workgroup memory.

const ENC_BC1_LOG: u32 = 0u;
const ENC_BC4_LOG: u32 = 1u;
const ENC_BC6H: u32 = 2u;
const ENC_F16: u32 = 3u;
const ENC_F32: u32 = 4u;

struct GatherParams {
    n: u32,
    padded: u32,
    channels: u32,        // 1 (grey: one matrix serves R, G, B) or 3
    encoding: u32,
    hardware: u32,        // 1: decode with the texture unit (BC1, BC6H)
    layer_words: u32,     // u32 words per layer in `blocks`
    log_range: f32,       // R of the log mapping (BC4)
    _pad: u32,
    scale: vec4<f32>,     // per channel: the log map's scale, or the value stored as 1.0
    lut: array<vec4<f32>, 192>,   // BC1: decode table per channel, entry 256·c + q
}

@group(0) @binding(0) var<uniform> params: GatherParams;
@group(0) @binding(1) var<storage, read> blocks: array<u32>;
@group(0) @binding(2) var dense_texture: texture_2d<f32>;
@group(0) @binding(3) var<storage, read> perm: array<u32>;
@group(0) @binding(4) var<storage, read> exitance: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read> sidecar_rows: array<u32>;
@group(0) @binding(6) var<storage, read> sidecar_cols: array<u32>;
@group(0) @binding(7) var<storage, read> sidecar_values: array<f32>;
@group(0) @binding(8) var<storage, read_write> indirect: array<vec4<f32>>;

fn lut_value(c: u32, q: u32) -> f32 {
    let k = 256u * c + q;
    return params.lut[k / 4u][k % 4u];
}

// BC1: 5:6:5 endpoints expanded by bit replication, palette by truncating integer division
// (compress::bc1::palette). Returns the 8-bit codes of texel t.
fn bc1_codes(word0: u32, word1: u32, t: u32) -> vec3<u32> {
    let c0 = word0 & 0xffffu;
    let c1 = word0 >> 16u;
    let a = vec3<u32>(((c0 >> 11u) & 31u), ((c0 >> 5u) & 63u), c0 & 31u);
    let b = vec3<u32>(((c1 >> 11u) & 31u), ((c1 >> 5u) & 63u), c1 & 31u);
    let ea = vec3<u32>((a.x << 3u) | (a.x >> 2u), (a.y << 2u) | (a.y >> 4u), (a.z << 3u) | (a.z >> 2u));
    let eb = vec3<u32>((b.x << 3u) | (b.x >> 2u), (b.y << 2u) | (b.y >> 4u), (b.z << 3u) | (b.z >> 2u));
    let idx = (word1 >> (2u * t)) & 3u;
    if (idx == 0u) { return ea; }
    if (idx == 1u) { return eb; }
    if (c0 > c1) {
        if (idx == 2u) { return (2u * ea + eb) / 3u; }
        return (ea + 2u * eb) / 3u;
    }
    if (idx == 2u) { return (ea + eb) / 2u; }
    return vec3<u32>(0u);
}

// BC4 palette value (a real code in [0, 255]) of index `idx` (compress::blocks::bc4_palette).
fn bc4_value(r0: u32, r1: u32, idx: u32) -> f32 {
    let a = f32(r0);
    let b = f32(r1);
    if (idx == 0u) { return a; }
    if (idx == 1u) { return b; }
    if (r0 > r1) {
        let k = f32(idx - 1u);
        return ((7.0 - k) * a + k * b) / 7.0;
    }
    if (idx <= 5u) {
        let k = f32(idx - 1u);
        return ((5.0 - k) * a + k * b) / 5.0;
    }
    return select(255.0, 0.0, idx == 6u);
}

// The log mapping's decode of a real code (compress::logmap::LogMap::decode_real).
fn log_decode(c: u32, q: f32) -> f32 {
    if (q < 0.5 || params.scale[c] <= 0.0) {
        return 0.0;
    }
    return params.scale[c] * exp(q * params.log_range / 255.0 - params.log_range);
}

// Linear values (up to 3 channels) of texel (x, y) of the dense part.
fn dense_value(x: u32, y: u32) -> vec3<f32> {
    let bw = params.padded / 4u;
    let blk = (y / 4u) * bw + (x / 4u);
    let t = 4u * (y % 4u) + (x % 4u);
    let ch = params.channels;
    var v = vec3<f32>(0.0);
    switch params.encoding {
        case 0u: {  // BC1 log
            var codes: vec3<u32>;
            if (params.hardware == 1u) {
                codes = vec3<u32>(round(textureLoad(dense_texture, vec2<u32>(x, y), 0).xyz * 255.0));
            } else {
                codes = bc1_codes(blocks[2u * blk], blocks[2u * blk + 1u], t);
            }
            if (ch == 1u) {
                v = vec3<f32>(lut_value(0u, codes.y));
            } else {
                v = vec3<f32>(lut_value(0u, codes.x), lut_value(1u, codes.y), lut_value(2u, codes.z));
            }
        }
        case 1u: {  // BC4 log, one layer per channel
            for (var c = 0u; c < ch; c = c + 1u) {
                let base = c * params.layer_words + 2u * blk;
                let w0 = blocks[base];
                let w1 = blocks[base + 1u];
                // 48 index bits start at byte 2: bits 16..32 of w0, then w1.
                let bit = 16u + 3u * t;
                var idx: u32;
                if (bit + 3u <= 32u) {
                    idx = (w0 >> bit) & 7u;
                } else if (bit >= 32u) {
                    idx = (w1 >> (bit - 32u)) & 7u;
                } else {
                    idx = ((w0 >> bit) | (w1 << (32u - bit))) & 7u;
                }
                v[c] = log_decode(c, bc4_value(w0 & 0xffu, (w0 >> 8u) & 0xffu, idx));
            }
            if (ch == 1u) { v = vec3<f32>(v.x); }
        }
        case 2u: {  // BC6H, hardware only (adapters without BC get F16 from the loader)
            let s = textureLoad(dense_texture, vec2<u32>(x, y), 0).xyz;
            if (ch == 1u) {
                v = vec3<f32>(s.y * params.scale.x);
            } else {
                v = s * params.scale.xyz;
            }
        }
        case 3u: {  // F16 texels, row-major, one layer per channel
            let texel = y * params.padded + x;
            for (var c = 0u; c < ch; c = c + 1u) {
                let w = blocks[c * params.layer_words + texel / 2u];
                v[c] = unpack2x16float(w)[texel % 2u] * params.scale[c];
            }
            if (ch == 1u) { v = vec3<f32>(v.x); }
        }
        default: {  // F32 texels
            let texel = y * params.padded + x;
            for (var c = 0u; c < ch; c = c + 1u) {
                v[c] = bitcast<f32>(blocks[c * params.layer_words + texel]) * params.scale[c];
            }
            if (ch == 1u) { v = vec3<f32>(v.x); }
        }
    }
    return v;
}

var<workgroup> partial: array<array<vec3<f32>, 4>, 64>;

@compute @workgroup_size(64)
fn main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) lid: u32) {
    let by = wg.x;
    let bw = params.padded / 4u;
    let n = params.n;
    var acc = array<vec3<f32>, 4>(vec3<f32>(0.0), vec3<f32>(0.0), vec3<f32>(0.0), vec3<f32>(0.0));
    for (var bx = lid; bx < bw; bx = bx + 64u) {
        for (var x = 0u; x < 4u; x = x + 1u) {
            let j = 4u * bx + x;
            if (j >= n) {
                break;
            }
            let e = exitance[perm[j]].xyz;
            for (var y = 0u; y < 4u; y = y + 1u) {
                acc[y] = acc[y] + dense_value(j, 4u * by + y) * e;
            }
        }
    }
    for (var y = 0u; y < 4u; y = y + 1u) {
        partial[lid][y] = acc[y];
    }
    workgroupBarrier();
    for (var stride = 32u; stride > 0u; stride = stride / 2u) {
        if (lid < stride) {
            for (var y = 0u; y < 4u; y = y + 1u) {
                partial[lid][y] = partial[lid][y] + partial[lid + stride][y];
            }
        }
        workgroupBarrier();
    }
    if (lid < 4u) {
        let i = 4u * by + lid;
        if (i < n) {
            var b = partial[0][lid];
            let ch = params.channels;
            for (var k = sidecar_rows[i]; k < sidecar_rows[i + 1u]; k = k + 1u) {
                let e = exitance[perm[sidecar_cols[k]]].xyz;
                if (ch == 1u) {
                    b = b + sidecar_values[k] * e;
                } else {
                    b = b + vec3<f32>(sidecar_values[3u * k], sidecar_values[3u * k + 1u], sidecar_values[3u * k + 2u]) * e;
                }
            }
            indirect[perm[i]] = vec4<f32>(b, 0.0);
        }
    }
}
