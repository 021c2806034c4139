// Test kernel for atmosphere_lookup.wgsl (group 3) — compared with the CPU twins in
// tests/gpu_atmosphere.rs. Its own buffers are in group 0; groups 1 and 2 are empty.
//! include atmosphere_lookup.wgsl

@group(0) @binding(0) var<storage, read_write> atmo_out: array<vec4<f32>>;
@group(0) @binding(1) var<storage, read> atmo_queries: array<vec4<f32>>;

// Test kernel: per query (dir.xyz, distance_km) -> sky radiance, aerial in-scattering,
// aerial transmittance, and the fog of the eye's air (l0 = 0.25) — four texels per query.
@compute @workgroup_size(64)
fn evaluate(@builtin(global_invocation_id) id: vec3<u32>) {
    let n = id.x;
    if (n >= arrayLength(&atmo_queries)) {
        return;
    }
    let q = atmo_queries[n];
    let dir = q.xyz;
    let ap = aerial_perspective(dir, q.w);
    let m = atmo_medium_of(atmo, atmo.radii.z);
    let fg = fog(vec3<f32>(0.25), q.w, dot(dir, atmo.sun.xyz), m.extinction, m.rayleigh, m.mie,
        atmo.mie_extinction.w, atmo.sun_illuminance.xyz);
    atmo_out[4u * n] = vec4<f32>(sky_radiance(dir), 0.0);
    atmo_out[4u * n + 1u] = vec4<f32>(ap.inscatter, 0.0);
    atmo_out[4u * n + 2u] = vec4<f32>(ap.transmittance, 0.0);
    atmo_out[4u * n + 3u] = vec4<f32>(fg, 0.0);
}
