// Indirect exitance at every triangle corner: the weighted patches of the corner's transfer list
// (compressed rows). Writes the mesh shader's per-corner `indirect` vertex buffer.
// Rust twin: relume::radiosity::corners::interpolate (per channel).

struct TransferParams {
    corners: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

@group(0) @binding(0) var<uniform> params: TransferParams;
@group(0) @binding(1) var<storage, read> offsets: array<u32>;   // corners + 1
@group(0) @binding(2) var<storage, read> patches: array<u32>;
@group(0) @binding(3) var<storage, read> weights: array<f32>;
@group(0) @binding(4) var<storage, read> indirect: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read_write> corner_out: array<f32>;  // 3 per corner

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let c = id.x;
    if (c >= params.corners) {
        return;
    }
    var b = vec3<f32>(0.0);
    for (var k = offsets[c]; k < offsets[c + 1u]; k = k + 1u) {
        b = b + weights[k] * indirect[patches[k]].xyz;
    }
    corner_out[3u * c] = b.x;
    corner_out[3u * c + 1u] = b.y;
    corner_out[3u * c + 2u] = b.z;
}
