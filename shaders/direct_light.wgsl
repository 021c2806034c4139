// Direct exitance of every patch for the current lights: the mean shadowed irradiance over the
// patch's sample points times its albedo, plus its own emission (π·L·scale).
// Rust twin: relume::render::direct::patch_exitance.
//! include lighting.wgsl

struct DirectParams {
    patches: u32,
    samples_per_patch: u32,
    emission_scale: f32,
    flags: u32,          // bit 0 direct, bit 2 shadows, bit 3 emission (FrameSettings::flags)
}

@group(0) @binding(0) var<uniform> params: DirectParams;
@group(0) @binding(1) var<storage, read> samples: array<vec4<f32>>;        // 2 per sample: position, normal
@group(0) @binding(2) var<storage, read> patch_albedo: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read> patch_emission: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read_write> exitance: array<vec4<f32>>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if (i >= params.patches) {
        return;
    }
    var e = vec3<f32>(0.0);
    if ((params.flags & 1u) != 0u && params.samples_per_patch > 0u) {
        var h = vec3<f32>(0.0);
        for (var s = 0u; s < params.samples_per_patch; s = s + 1u) {
            let k = 2u * (i * params.samples_per_patch + s);
            let p = samples[k].xyz;
            let n = samples[k + 1u].xyz;
            for (var l = 0u; l < min(lights.count, MAX_LIGHTS); l = l + 1u) {
                let light = lights.lights[l];
                let inc = light_irradiance(light, p, n);
                var vis = 1.0;
                if ((params.flags & 4u) != 0u && any(inc.irradiance > vec3<f32>(0.0))) {
                    vis = shadow_visibility(light, p, n);
                }
                h = h + inc.irradiance * vis;
            }
        }
        e = patch_albedo[i].xyz * h / f32(params.samples_per_patch);
    }
    if ((params.flags & 8u) != 0u) {
        e = e + PI * patch_emission[i].xyz * params.emission_scale;
    }
    exitance[i] = vec4<f32>(e, 0.0);
}
