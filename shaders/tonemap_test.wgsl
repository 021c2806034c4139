// Applies `tonemap` to an array of linear RGB values: the GPU half of the tonemap twin test.

struct Params { count: u32, exposure: f32 }
@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> input: array<f32>;
@group(0) @binding(2) var<storage, read_write> output: array<f32>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if (i >= params.count) { return; }
    let c = tonemap(vec3<f32>(input[3u * i], input[3u * i + 1u], input[3u * i + 2u]), params.exposure);
    output[3u * i] = c.x;
    output[3u * i + 1u] = c.y;
    output[3u * i + 2u] = c.z;
}
