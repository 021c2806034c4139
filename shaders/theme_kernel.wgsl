// Test kernel: the theme albedo at given points (x, y, footprint) — compared with
// relume::theme::compose::Lookup::albedo in tests/gpu_themes.rs.
//! include theme.wgsl

@group(0) @binding(0) var<storage, read> points: array<vec4<f32>>;
@group(0) @binding(1) var<storage, read_write> albedo_out: array<vec4<f32>>;

@compute @workgroup_size(64)
fn theme_albedo_kernel(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if (i >= arrayLength(&points)) {
        return;
    }
    let q = points[i];
    albedo_out[i] = vec4<f32>(theme_albedo(q.xy, q.z), f32(theme_class_at(theme_level(q.z), q.xy)));
}
