// Indirect exitance B = S·E for one colour channel from the uncompressed f32 transport matrix
// (the reference encoding). Rust twin: relume::render::direct::gather_dense.

struct GatherParams {
    n: u32,
    channel: u32,
    _pad0: u32,
    _pad1: u32,
}

@group(0) @binding(0) var<uniform> params: GatherParams;
@group(0) @binding(1) var<storage, read> matrix: array<f32>;            // row-major n x n
@group(0) @binding(2) var<storage, read> exitance: array<vec4<f32>>;    // E per patch
@group(0) @binding(3) var<storage, read_write> indirect: array<vec4<f32>>; // B per patch

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if (i >= params.n) {
        return;
    }
    var sum = 0.0;
    let row = i * params.n;
    for (var j = 0u; j < params.n; j = j + 1u) {
        sum = sum + matrix[row + j] * exitance[j][params.channel];
    }
    indirect[i][params.channel] = sum;
}
