// Scattered light in the air: the lookups a renderer calls, on tables built by
// atmosphere.wgsl (relume::gpu::atmosphere::AtmosphereTables). Include with
// `//! include atmosphere_lookup.wgsl` (it includes atmosphere_common.wgsl).
//
// Binding contract, all in group 3 (AtmosphereTables::bind_group / layout_entries):
//   @binding(0) var<uniform> atmo: AtmosphereParams            (AtmosphereTables::params)
//   @binding(1) var<storage, read> atmo_sky_view: array<vec4<f32>>  (::sky_view, 192 x 108)
//   @binding(2) var<storage, read> atmo_aerial: array<vec4<f32>>    (::aerial, 32^3 x 2 texels)
//
// Frame and units: dir and atmo.sun are unit vectors in the eye's frame, +Y up (the local
// vertical at the eye; x and z horizontal, any azimuth convention shared by dir and sun); the
// eye is at altitude atmo.radii.z km above the ground. distance_km is in kilometres. Radiance
// comes out in the units of atmo.sun_illuminance (per steradian). The tables hold one eye
// altitude and sun: rebuild them (AtmosphereTables::update) when either changes.

//! include atmosphere_common.wgsl

@group(3) @binding(0) var<uniform> atmo: AtmosphereParams;
@group(3) @binding(1) var<storage, read> atmo_sky_view: array<vec4<f32>>;
@group(3) @binding(2) var<storage, read> atmo_aerial: array<vec4<f32>>;

// Sky radiance (in-scattering from the eye to the ground or space) along unit dir.
fn sky_radiance(dir: vec3<f32>) -> vec3<f32> {
    let ang = atmo_view_angles(dir, atmo.sun.xyz);
    let uv = sky_view_uv(atmo.radii.x + atmo.radii.z, atmo.radii.x, ang.x, ang.y);
    let b = atmo_bilinear(SKY_W, SKY_H, uv.x, uv.y);
    return atmo_mix_bilinear(b, atmo_sky_view[b.i00].xyz, atmo_sky_view[b.i10].xyz, atmo_sky_view[b.i01].xyz, atmo_sky_view[b.i11].xyz);
}

// In-scattering and transmittance over distance_km from the eye along unit dir (clamped to
// the volume's range). A surface of radiance L0 is seen as L0 * transmittance + inscatter.
fn aerial_perspective(dir: vec3<f32>, distance_km: f32) -> Marched {
    let ang = atmo_view_angles(dir, atmo.sun.xyz);
    let uv = sky_view_uv(atmo.radii.x + atmo.radii.z, atmo.radii.x, ang.x, ang.y);
    let w = sqrt(clamp(distance_km / atmo.radii.w, 0.0, 1.0));
    let f = vec3<f32>(uv.x * f32(AERIAL_N - 1u), uv.y * f32(AERIAL_N - 1u), w * f32(AERIAL_N - 1u));
    let i0 = min(vec3<u32>(floor(f)), vec3<u32>(AERIAL_N - 1u));
    let i1 = min(i0 + vec3<u32>(1u), vec3<u32>(AERIAL_N - 1u));
    let a = f - vec3<f32>(i0);
    var l = vec3<f32>(0.0);
    var t = vec3<f32>(0.0);
    for (var corner = 0u; corner < 8u; corner++) {
        let px = (corner & 1u) == 1u;
        let py = ((corner >> 1u) & 1u) == 1u;
        let pz = ((corner >> 2u) & 1u) == 1u;
        let ix = select(i0.x, i1.x, px);
        let iy = select(i0.y, i1.y, py);
        let iz = select(i0.z, i1.z, pz);
        let wgt = select(1.0 - a.x, a.x, px) * select(1.0 - a.y, a.y, py) * select(1.0 - a.z, a.z, pz);
        let texel = 2u * ((iz * AERIAL_N + iy) * AERIAL_N + ix);
        l += atmo_aerial[texel].xyz * wgt;
        t += atmo_aerial[texel + 1u].xyz * wgt;
    }
    return Marched(l, t);
}

