// Depth-only pass that fills one shadow-map layer; the layer is the instance index.
//! include lighting.wgsl

@vertex
fn vs_main(@location(0) position: vec3<f32>, @builtin(instance_index) layer: u32) -> @builtin(position) vec4<f32> {
    return lights.layer_view_proj[layer] * vec4<f32>(position, 1.0);
}
