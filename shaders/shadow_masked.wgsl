// Depth-only pass of alpha-masked materials into one shadow-map layer (the instance index):
// fragments the mask cuts away are discarded, so light passes through a leaf's cut-out texels.
// Rust twin: relume::render::material_maps::SceneMaps::opaque_at.
//! include lighting.wgsl
//! include material.wgsl

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) uv: vec2<f32>,
}

@vertex
fn vs_main(@location(0) position: vec3<f32>, @location(1) uv: vec2<f32>, @builtin(instance_index) layer: u32) -> VertexOut {
    var o: VertexOut;
    o.clip = lights.layer_view_proj[layer] * vec4<f32>(position, 1.0);
    o.uv = uv;
    return o;
}

@fragment
fn fs_main(v: VertexOut) {
    if (masked_out(v.uv)) {
        discard;
    }
}
