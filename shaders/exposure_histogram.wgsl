// The log-luminance histogram of a display frame, for automatic exposure. CPU twin:
// `render::exposure` (`bin_of`, `histogram`); constants and the byte → x·E table come from it.
// Each workgroup counts its 16×16 pixels in workgroup memory, then adds its counts to the frame's.

const BINS: u32 = 128u;
const LOG2_MIN: f32 = -12.0;
const LOG2_MAX: f32 = 8.0;

@group(0) @binding(0) var frame: texture_2d<f32>;
// Display byte → x·E (inverse sRGB, inverse Reinhard), from `render::exposure::display_lut`.
@group(0) @binding(1) var<storage, read> lut: array<f32, 256>;
@group(0) @binding(2) var<storage, read_write> histogram: array<atomic<u32>, 128>;

var<workgroup> local_bins: array<atomic<u32>, 128>;

// The bin of a pixel's display bytes, or BINS for a pixel black in every channel.
fn bin_of(rgb: vec3<u32>) -> u32 {
    if (all(rgb == vec3<u32>(0u))) {
        return BINS;
    }
    let l = 0.2126 * lut[rgb.x] + 0.7152 * lut[rgb.y] + 0.0722 * lut[rgb.z];
    let b = floor((log2(l) - LOG2_MIN) * (f32(BINS) / (LOG2_MAX - LOG2_MIN)));
    return u32(clamp(b, 0.0, f32(BINS) - 1.0));
}

@compute @workgroup_size(16, 16)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    if (li < BINS) {
        atomicStore(&local_bins[li], 0u);
    }
    workgroupBarrier();
    let size = textureDimensions(frame);
    if (id.x < size.x && id.y < size.y) {
        let c = textureLoad(frame, vec2<i32>(id.xy), 0).rgb;
        let b = bin_of(vec3<u32>(round(c * 255.0)));
        if (b < BINS) {
            atomicAdd(&local_bins[b], 1u);
        }
    }
    workgroupBarrier();
    if (li < BINS) {
        let n = atomicLoad(&local_bins[li]);
        if (n > 0u) {
            atomicAdd(&histogram[li], n);
        }
    }
}
