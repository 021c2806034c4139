// Scattered light in the air: the kernels that build Hillaire 2020's tables (transmittance,
// multiple scattering, sky view, aerial-perspective volume) into atmo_out, one table per
// dispatch. Bindings in group 0. The renderer's lookups are in atmosphere_lookup.wgsl (group 3).
// Kilometres and 1/km; +Y up, the eye at (0, ground + altitude, 0).
//! include atmosphere_common.wgsl

@group(0) @binding(0) var<uniform> atmo: AtmosphereParams;
@group(0) @binding(1) var<storage, read> transmittance_lut: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read> multi_lut: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read_write> atmo_out: array<vec4<f32>>;

fn atmo_medium(h: f32) -> MediumSample {
    return atmo_medium_of(atmo, h);
}

fn distance_to_top(r: f32, mu: f32) -> f32 {
    let top = atmo.radii.y;
    let disc = r * r * (mu * mu - 1.0) + top * top;
    return max(-r * mu + sqrt(max(disc, 0.0)), 0.0);
}

fn transmittance_uv(r: f32, mu: f32) -> vec2<f32> {
    let g = atmo.radii.x;
    let t = atmo.radii.y;
    let h = sqrt((t - g) * (t + g));
    let rho = sqrt(max((r - g) * (r + g), 0.0));
    let d = distance_to_top(r, mu);
    let d_min = t - r;
    let d_max = rho + h;
    return vec2<f32>((d - d_min) / max(d_max - d_min, 1e-6), rho / h);
}

fn transmittance_r_mu(x_mu: f32, x_r: f32) -> vec2<f32> {
    let g = atmo.radii.x;
    let t = atmo.radii.y;
    let h = sqrt((t - g) * (t + g));
    let rho = h * x_r;
    let r = sqrt(rho * rho + g * g);
    let d_min = t - r;
    let d_max = rho + h;
    let d = d_min + x_mu * (d_max - d_min);
    var mu = 1.0;
    if (d != 0.0) {
        mu = (h * h - rho * rho - d * d) / (2.0 * r * d);
    }
    return vec2<f32>(r, clamp(mu, -1.0, 1.0));
}

fn frame_dir(theta: f32, phi: f32) -> vec3<f32> {
    let sun = atmo.sun.xyz;
    let ls = sqrt(sun.x * sun.x + sun.z * sun.z);
    var cx = 1.0;
    var cz = 0.0;
    if (ls > 1e-6) {
        cx = sun.x / ls;
        cz = sun.z / ls;
    }
    let s = sin(theta);
    let d = vec3<f32>(s * cos(phi), cos(theta), s * sin(phi));
    return vec3<f32>(d.x * cx - d.z * cz, d.y, d.x * cz + d.z * cx);
}

fn atmo_eye() -> vec3<f32> {
    return vec3<f32>(0.0, atmo.radii.x + atmo.radii.z, 0.0);
}

// Transmittance from radius r along zenith cosine mu to the top of the air.
fn atmo_transmittance(r: f32, mu: f32) -> vec3<f32> {
    let uv = transmittance_uv(r, mu);
    let b = atmo_bilinear(TRANSMITTANCE_W, TRANSMITTANCE_H, uv.x, uv.y);
    return atmo_mix_bilinear(b, transmittance_lut[b.i00].xyz, transmittance_lut[b.i10].xyz,
        transmittance_lut[b.i01].xyz, transmittance_lut[b.i11].xyz);
}

fn atmo_multi_scattering(r: f32, mu_s: f32) -> vec3<f32> {
    let y = sqrt(max((r - atmo.radii.x) / (atmo.radii.y - atmo.radii.x), 0.0));
    let b = atmo_bilinear(MULTI_W, MULTI_H, 0.5 * mu_s + 0.5, y);
    return atmo_mix_bilinear(b, multi_lut[b.i00].xyz, multi_lut[b.i10].xyz, multi_lut[b.i01].xyz,
        multi_lut[b.i11].xyz);
}

struct SunLight {
    shadow: f32,
    transmittance: vec3<f32>,
    mu_s: f32,
}

// Cosine of the horizon's zenith angle seen from radius r: 0 on the ground, negative above
// (twin: twin::horizon_cosine).
fn horizon_cosine(r: f32) -> f32 {
    let q = atmo.radii.x / max(r, atmo.radii.x);
    return -sqrt(max(1.0 - q * q, 0.0));
}

fn sun_light(x: vec3<f32>, sun: vec3<f32>) -> SunLight {
    let r = length(x);
    let mu_s = dot(x, sun) / r;
    // Below the local horizon the planet hides the sun (twin: lut::sun_light).
    var shadow = 1.0;
    if (mu_s < horizon_cosine(r)) {
        shadow = 0.0;
    }
    return SunLight(shadow, atmo_transmittance(r, mu_s), mu_s);
}

@compute @workgroup_size(64)
fn build_transmittance(@builtin(global_invocation_id) id: vec3<u32>) {
    let n = id.x;
    if (n >= TRANSMITTANCE_W * TRANSMITTANCE_H) {
        return;
    }
    let rm = transmittance_r_mu(atmo_unit_of(n % TRANSMITTANCE_W, TRANSMITTANCE_W), atmo_unit_of(n / TRANSMITTANCE_W, TRANSMITTANCE_H));
    let r = rm.x;
    let mu = rm.y;
    let d = distance_to_top(r, mu);
    let dir = vec3<f32>(sqrt(max(1.0 - mu * mu, 0.0)), mu, 0.0);
    let o = vec3<f32>(0.0, r, 0.0);
    let dt = d / f32(STEPS_TRANSMITTANCE);
    var tau = vec3<f32>(0.0);
    for (var k = 0u; k < STEPS_TRANSMITTANCE; k++) {
        let x = o + dir * ((f32(k) + 0.5) * dt);
        tau += atmo_medium(length(x) - atmo.radii.x).extinction * dt;
    }
    atmo_out[n] = vec4<f32>(exp(-tau), 1.0);
}

@compute @workgroup_size(64)
fn build_multi_scattering(@builtin(global_invocation_id) id: vec3<u32>) {
    let n = id.x;
    if (n >= MULTI_W * MULTI_H) {
        return;
    }
    let mu_s = 2.0 * atmo_unit_of(n % MULTI_W, MULTI_W) - 1.0;
    let y = atmo_unit_of(n / MULTI_W, MULTI_H);
    let r = atmo.radii.x + y * y * (atmo.radii.y - atmo.radii.x);
    let o = vec3<f32>(0.0, r, 0.0);
    let sun = vec3<f32>(sqrt(max(1.0 - mu_s * mu_s, 0.0)), mu_s, 0.0);
    let iso = 1.0 / (4.0 * PI);
    let mu_h = horizon_cosine(r);
    let half = MULTI_BANDS / 2u;
    var l2 = vec3<f32>(0.0);
    var fms = vec3<f32>(0.0);
    for (var a = 0u; a < MULTI_AZIMUTHS; a++) {
        let theta = 2.0 * PI * (f32(a) + 0.5) / f32(MULTI_AZIMUTHS);
        for (var bb = 0u; bb < MULTI_BANDS; bb++) {
            // Band bb: half above the horizon, half below, crowded toward it (twin: band).
            var kb = bb - half;
            var span = 1.0 + mu_h;
            var sign = -1.0;
            if (bb < half) {
                kb = half - 1u - bb;
                span = 1.0 - mu_h;
                sign = 1.0;
            }
            let sb = (f32(kb) + 0.5) / f32(half);
            let cos_phi = mu_h + sign * span * sb * sb;
            let share = span * sb / f32(half) / f32(MULTI_AZIMUTHS);
            let sin_phi = sqrt(max(1.0 - cos_phi * cos_phi, 0.0));
            let dir = vec3<f32>(cos(theta) * sin_phi, cos_phi, sin(theta) * sin_phi);
            let t_ground = ray_sphere_nearest(o, dir, atmo.radii.x);
            let t_top = ray_sphere_nearest(o, dir, atmo.radii.y);
            var t_max = max(t_top, 0.0);
            if (t_ground >= 0.0) {
                t_max = t_ground;
            }
            var l = vec3<f32>(0.0);
            var f = vec3<f32>(0.0);
            var thr = vec3<f32>(1.0);
            for (var k = 0u; k < STEPS_MULTI; k++) {
                // Quadratic steps, crowded toward the point (twin: step_span).
                let u0 = f32(k) / f32(STEPS_MULTI);
                let u1 = f32(k + 1u) / f32(STEPS_MULTI);
                let t0 = u0 * u0 * t_max;
                let t1 = u1 * u1 * t_max;
                let dt = t1 - t0;
                let x = o + dir * (0.5 * (t0 + t1));
                let m = atmo_medium(length(x) - atmo.radii.x);
                let sl = sun_light(x, sun);
                let scat = m.rayleigh + m.mie;
                let step_t = exp(-m.extinction * dt);
                let s = sl.transmittance * scat * (sl.shadow * iso);
                let inv = vec3<f32>(1.0) / max(m.extinction, vec3<f32>(1e-12));
                l += thr * (s - s * step_t) * inv;
                f += thr * (scat - scat * step_t) * inv;
                thr *= step_t;
            }
            if (t_ground >= 0.0) {
                let x = o + dir * t_ground;
                let up = x / length(x);
                let sl = sun_light(x, sun);
                let c = clamp(dot(up, sun), 0.0, 1.0);
                l += thr * sl.transmittance * atmo.ground_albedo.xyz * (c / PI);
            }
            l2 += l * share;
            fms += f * share;
        }
    }
    atmo_out[n] = vec4<f32>(l2 / (vec3<f32>(1.0) - fms), 1.0);
}

fn atmo_march(dir: vec3<f32>, t_max: f32, n: u32, quadratic: bool) -> Marched {
    let o = atmo_eye();
    let sun = atmo.sun.xyz;
    let mu = dot(dir, sun);
    let pr = rayleigh_phase(mu);
    let pm = cornette_shanks_phase(mu, atmo.mie_extinction.w);
    let e = atmo.sun_illuminance.xyz;
    var l = vec3<f32>(0.0);
    var thr = vec3<f32>(1.0);
    for (var k = 0u; k < n; k++) {
        let a = f32(k) / f32(n);
        let b = f32(k + 1u) / f32(n);
        var t0 = a * t_max;
        var t1 = b * t_max;
        if (quadratic) {
            t0 = a * a * t_max;
            t1 = b * b * t_max;
        }
        let dt = t1 - t0;
        let x = o + dir * (0.5 * (t0 + t1));
        let r = length(x);
        let m = atmo_medium(r - atmo.radii.x);
        let sl = sun_light(x, sun);
        let psi = atmo_multi_scattering(r, sl.mu_s);
        let s = e * ((m.rayleigh * pr + m.mie * pm) * sl.transmittance * sl.shadow + psi * (m.rayleigh + m.mie));
        let step_t = exp(-m.extinction * dt);
        let inv = vec3<f32>(1.0) / max(m.extinction, vec3<f32>(1e-12));
        l += thr * (s - s * step_t) * inv;
        thr *= step_t;
    }
    return Marched(l, thr);
}

fn exit_distance(dir: vec3<f32>) -> f32 {
    let o = atmo_eye();
    let t_ground = ray_sphere_nearest(o, dir, atmo.radii.x);
    if (t_ground >= 0.0) {
        return t_ground;
    }
    return max(ray_sphere_nearest(o, dir, atmo.radii.y), 0.0);
}

@compute @workgroup_size(64)
fn build_sky_view(@builtin(global_invocation_id) id: vec3<u32>) {
    let n = id.x;
    if (n >= SKY_W * SKY_H) {
        return;
    }
    let ang = sky_view_angles(atmo_eye().y, atmo.radii.x, atmo_unit_of(n % SKY_W, SKY_W), atmo_unit_of(n / SKY_W, SKY_H));
    let dir = frame_dir(ang.x, ang.y);
    let m = atmo_march(dir, exit_distance(dir), STEPS_SKY, true);
    atmo_out[n] = vec4<f32>(m.inscatter, (m.transmittance.x + m.transmittance.y + m.transmittance.z) / 3.0);
}

@compute @workgroup_size(64)
fn build_aerial(@builtin(global_invocation_id) id: vec3<u32>) {
    let n = id.x;
    if (n >= AERIAL_N * AERIAL_N * AERIAL_N) {
        return;
    }
    let i = n % AERIAL_N;
    let j = (n / AERIAL_N) % AERIAL_N;
    let k = n / (AERIAL_N * AERIAL_N);
    let ang = sky_view_angles(atmo_eye().y, atmo.radii.x, atmo_unit_of(i, AERIAL_N), atmo_unit_of(j, AERIAL_N));
    let dir = frame_dir(ang.x, ang.y);
    let w = atmo_unit_of(k, AERIAL_N);
    // A cell under the ground is lifted onto it (twin: lut::aerial_target).
    let o = atmo_eye();
    var target_dir = dir;
    var s = atmo.radii.w * w * w;
    let t_ground = ray_sphere_nearest(o, dir, atmo.radii.x);
    if (t_ground < 0.0 || s <= t_ground) {
        s = min(s, exit_distance(dir));
    } else {
        let x = o + dir * s;
        let v = x * ((atmo.radii.x + 1e-3) / length(x)) - o;
        s = length(v);
        target_dir = v / max(s, 1e-12);
    }
    let m = atmo_march(target_dir, s, STEPS_AERIAL, false);
    atmo_out[2u * n] = vec4<f32>(m.inscatter, 0.0);
    atmo_out[2u * n + 1u] = vec4<f32>(m.transmittance, 0.0);
}

