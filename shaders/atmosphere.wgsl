// Scattered light in the air: Hillaire 2020's tables (built by the kernels below) and the
// lookups a renderer calls, plus the seed's constant-density fog. Kilometres and 1/km; +Y up,
// the eye at (0, ground + altitude, 0). Tables are storage buffers of vec4 texels, row-major;
// an axis of N texels covers unit x in [0, 1] with texel i at i / (N - 1).
// Rust twins: relume::atmosphere::{twin, lut} (same arithmetic, line for line).

struct AtmosphereParams {
    rayleigh: vec4<f32>,        // scattering RGB, w: scale height
    mie_scattering: vec4<f32>,  // RGB, w: scale height
    mie_extinction: vec4<f32>,  // RGB, w: anisotropy g
    ozone: vec4<f32>,           // absorption RGB, w: centre altitude
    ground_albedo: vec4<f32>,   // RGB, w: ozone half width
    sun_illuminance: vec4<f32>, // RGB, w: 0
    radii: vec4<f32>,           // ground, top, eye altitude, aerial range s_max
    sun: vec4<f32>,             // unit direction toward the sun, w: 0
}

const TRANSMITTANCE_W: u32 = 256u;
const TRANSMITTANCE_H: u32 = 64u;
const MULTI_W: u32 = 32u;
const MULTI_H: u32 = 32u;
const SKY_W: u32 = 192u;
const SKY_H: u32 = 108u;
const AERIAL_N: u32 = 32u;
const STEPS_TRANSMITTANCE: u32 = 40u;
const STEPS_MULTI: u32 = 20u;
const STEPS_SKY: u32 = 30u;
const STEPS_AERIAL: u32 = 20u;

@group(0) @binding(0) var<uniform> atmo: AtmosphereParams;
@group(0) @binding(1) var<storage, read> transmittance_lut: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read> multi_lut: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read> sky_lut: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read> aerial_lut: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read_write> atmo_out: array<vec4<f32>>;
@group(0) @binding(6) var<storage, read> atmo_queries: array<vec4<f32>>;

struct MediumSample {
    rayleigh: vec3<f32>,
    mie: vec3<f32>,
    extinction: vec3<f32>,
}

fn atmo_medium(h_in: f32) -> MediumSample {
    let h = max(h_in, 0.0);
    let dr = exp(-h / atmo.rayleigh.w);
    let dm = exp(-h / atmo.mie_scattering.w);
    let d_o = max(1.0 - abs(h - atmo.ozone.w) / atmo.ground_albedo.w, 0.0);
    let sr = atmo.rayleigh.xyz * dr;
    let sm = atmo.mie_scattering.xyz * dm;
    return MediumSample(sr, sm, sr + atmo.mie_extinction.xyz * dm + atmo.ozone.xyz * d_o);
}

fn rayleigh_phase(mu: f32) -> f32 {
    return 3.0 / (16.0 * PI) * (1.0 + mu * mu);
}

fn cornette_shanks_phase(mu: f32, g: f32) -> f32 {
    let d = 1.0 + g * g - 2.0 * g * mu;
    return 3.0 / (8.0 * PI) * (1.0 - g * g) * (1.0 + mu * mu) / ((2.0 + g * g) * d * sqrt(d));
}

fn ray_sphere_nearest(o: vec3<f32>, d: vec3<f32>, r: f32) -> f32 {
    let b = dot(o, d);
    let c = dot(o, o) - r * r;
    let disc = b * b - c;
    if (disc < 0.0) {
        return -1.0;
    }
    let q = sqrt(disc);
    let t0 = -b - q;
    let t1 = -b + q;
    if (t0 >= 0.0) {
        return t0;
    }
    if (t1 >= 0.0) {
        return t1;
    }
    return -1.0;
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

// Zenith angle of the horizon from radius r, and beta = PI - that.
fn atmo_horizon(r: f32) -> vec2<f32> {
    let g = atmo.radii.x;
    let v_h = sqrt(max((r - g) * (r + g), 0.0));
    let beta = acos(clamp(v_h / r, -1.0, 1.0));
    return vec2<f32>(PI - beta, beta);
}

fn sky_view_uv(r: f32, theta: f32, phi: f32) -> vec2<f32> {
    let hb = atmo_horizon(r);
    var v: f32;
    if (theta < hb.x) {
        let c = sqrt(max(1.0 - theta / hb.x, 0.0));
        v = 0.5 * (1.0 - c);
    } else {
        let c = sqrt(max((theta - hb.x) / hb.y, 0.0));
        v = 0.5 + 0.5 * c;
    }
    return vec2<f32>(sqrt(clamp(phi / PI, 0.0, 1.0)), clamp(v, 0.0, 1.0));
}

fn sky_view_angles(r: f32, u: f32, v: f32) -> vec2<f32> {
    let hb = atmo_horizon(r);
    var theta: f32;
    if (v < 0.5) {
        let c = 1.0 - 2.0 * v;
        theta = hb.x * (1.0 - c * c);
    } else {
        let c = 2.0 * v - 1.0;
        theta = hb.x + hb.y * c * c;
    }
    return vec2<f32>(theta, PI * u * u);
}

// Zenith angle and azimuth from the sun of a direction.
fn view_angles(dir: vec3<f32>, sun: vec3<f32>) -> vec2<f32> {
    let theta = acos(clamp(dir.y, -1.0, 1.0));
    let lv = sqrt(dir.x * dir.x + dir.z * dir.z);
    let ls = sqrt(sun.x * sun.x + sun.z * sun.z);
    var c = 1.0;
    if (lv > 1e-6 && ls > 1e-6) {
        c = (dir.x * sun.x + dir.z * sun.z) / (lv * ls);
    }
    return vec2<f32>(theta, acos(clamp(c, -1.0, 1.0)));
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

fn unit_of(i: u32, n: u32) -> f32 {
    return f32(i) / f32(n - 1u);
}

fn atmo_eye() -> vec3<f32> {
    return vec3<f32>(0.0, atmo.radii.x + atmo.radii.z, 0.0);
}

// Bilinear lookups, one per table (WGSL cannot pass storage arrays to functions).
struct Bilinear {
    i00: u32,
    i10: u32,
    i01: u32,
    i11: u32,
    ax: f32,
    ay: f32,
}

fn bilinear(nx: u32, ny: u32, x: f32, y: f32) -> Bilinear {
    let fx = clamp(x, 0.0, 1.0) * f32(nx - 1u);
    let fy = clamp(y, 0.0, 1.0) * f32(ny - 1u);
    let x0 = min(u32(floor(fx)), nx - 1u);
    let y0 = min(u32(floor(fy)), ny - 1u);
    let x1 = min(x0 + 1u, nx - 1u);
    let y1 = min(y0 + 1u, ny - 1u);
    return Bilinear(y0 * nx + x0, y0 * nx + x1, y1 * nx + x0, y1 * nx + x1, fx - f32(x0), fy - f32(y0));
}

fn mix_bilinear(b: Bilinear, t00: vec3<f32>, t10: vec3<f32>, t01: vec3<f32>, t11: vec3<f32>) -> vec3<f32> {
    let a = t00 + (t10 - t00) * b.ax;
    let c = t01 + (t11 - t01) * b.ax;
    return a + (c - a) * b.ay;
}

// Transmittance from radius r along zenith cosine mu to the top of the air.
fn atmo_transmittance(r: f32, mu: f32) -> vec3<f32> {
    let uv = transmittance_uv(r, mu);
    let b = bilinear(TRANSMITTANCE_W, TRANSMITTANCE_H, uv.x, uv.y);
    return mix_bilinear(b, transmittance_lut[b.i00].xyz, transmittance_lut[b.i10].xyz,
        transmittance_lut[b.i01].xyz, transmittance_lut[b.i11].xyz);
}

fn atmo_multi_scattering(r: f32, mu_s: f32) -> vec3<f32> {
    let y = (r - atmo.radii.x) / (atmo.radii.y - atmo.radii.x);
    let b = bilinear(MULTI_W, MULTI_H, 0.5 * mu_s + 0.5, y);
    return mix_bilinear(b, multi_lut[b.i00].xyz, multi_lut[b.i10].xyz, multi_lut[b.i01].xyz,
        multi_lut[b.i11].xyz);
}

struct SunLight {
    shadow: f32,
    transmittance: vec3<f32>,
    mu_s: f32,
}

fn sun_light(x: vec3<f32>, sun: vec3<f32>) -> SunLight {
    let r = length(x);
    let mu_s = dot(x, sun) / r;
    var shadow = 1.0;
    if (ray_sphere_nearest(x, sun, atmo.radii.x) >= 0.0) {
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
    let rm = transmittance_r_mu(unit_of(n % TRANSMITTANCE_W, TRANSMITTANCE_W), unit_of(n / TRANSMITTANCE_W, TRANSMITTANCE_H));
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
    let mu_s = 2.0 * unit_of(n % MULTI_W, MULTI_W) - 1.0;
    let r = atmo.radii.x + unit_of(n / MULTI_W, MULTI_H) * (atmo.radii.y - atmo.radii.x);
    let o = vec3<f32>(0.0, r, 0.0);
    let sun = vec3<f32>(sqrt(max(1.0 - mu_s * mu_s, 0.0)), mu_s, 0.0);
    let iso = 1.0 / (4.0 * PI);
    var l2 = vec3<f32>(0.0);
    var fms = vec3<f32>(0.0);
    for (var a = 0u; a < 8u; a++) {
        for (var bb = 0u; bb < 8u; bb++) {
            let theta = 2.0 * PI * (f32(a) + 0.5) / 8.0;
            let cos_phi = 1.0 - 2.0 * (f32(bb) + 0.5) / 8.0;
            let sin_phi = sqrt(max(1.0 - cos_phi * cos_phi, 0.0));
            let dir = vec3<f32>(cos(theta) * sin_phi, cos_phi, sin(theta) * sin_phi);
            let t_ground = ray_sphere_nearest(o, dir, atmo.radii.x);
            let t_top = ray_sphere_nearest(o, dir, atmo.radii.y);
            var t_max = max(t_top, 0.0);
            if (t_ground >= 0.0) {
                t_max = t_ground;
            }
            let dt = t_max / f32(STEPS_MULTI);
            var l = vec3<f32>(0.0);
            var f = vec3<f32>(0.0);
            var thr = vec3<f32>(1.0);
            for (var k = 0u; k < STEPS_MULTI; k++) {
                let x = o + dir * ((f32(k) + 0.5) * dt);
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
            l2 += l;
            fms += f;
        }
    }
    l2 /= 64.0;
    fms /= 64.0;
    atmo_out[n] = vec4<f32>(l2 / (vec3<f32>(1.0) - fms), 1.0);
}

// In-scattering (xyz) and transmittance of the eye's ray along dir over [0, t_max].
struct Marched {
    inscatter: vec3<f32>,
    transmittance: vec3<f32>,
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
    let ang = sky_view_angles(atmo_eye().y, unit_of(n % SKY_W, SKY_W), unit_of(n / SKY_W, SKY_H));
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
    let ang = sky_view_angles(atmo_eye().y, unit_of(i, AERIAL_N), unit_of(j, AERIAL_N));
    let dir = frame_dir(ang.x, ang.y);
    let w = unit_of(k, AERIAL_N);
    let s = min(atmo.radii.w * w * w, exit_distance(dir));
    let m = atmo_march(dir, s, STEPS_AERIAL, false);
    atmo_out[2u * n] = vec4<f32>(m.inscatter, 0.0);
    atmo_out[2u * n + 1u] = vec4<f32>(m.transmittance, 0.0);
}

// ---- What a renderer calls (bind the tables at bindings 1-4 and the parameters at 0).

// Sky radiance (in-scattering from the eye to the ground or space) along unit dir.
fn sky_radiance(dir: vec3<f32>) -> vec3<f32> {
    let ang = view_angles(dir, atmo.sun.xyz);
    let uv = sky_view_uv(atmo_eye().y, ang.x, ang.y);
    let b = bilinear(SKY_W, SKY_H, uv.x, uv.y);
    return mix_bilinear(b, sky_lut[b.i00].xyz, sky_lut[b.i10].xyz, sky_lut[b.i01].xyz, sky_lut[b.i11].xyz);
}

// In-scattering and transmittance over distance_km from the eye along unit dir (clamped to
// the volume's range). A surface of radiance L0 is seen as L0 * transmittance + inscatter.
fn aerial_perspective(dir: vec3<f32>, distance_km: f32) -> Marched {
    let ang = view_angles(dir, atmo.sun.xyz);
    let uv = sky_view_uv(atmo_eye().y, ang.x, ang.y);
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
        l += aerial_lut[texel].xyz * wgt;
        t += aerial_lut[texel + 1u].xyz * wgt;
    }
    return Marched(l, t);
}

// The seed's constant-density fog: L0 seen through s km of air with extinction ext and
// Rayleigh / Mie scattering sr, sm (1/km), Mie g, sun illuminance e, view-sun cosine mu.
fn fog(l0: vec3<f32>, s: f32, mu: f32, ext: vec3<f32>, sr: vec3<f32>, sm: vec3<f32>, g: f32, e: vec3<f32>) -> vec3<f32> {
    let t = exp(-ext * s);
    let sc = sr * rayleigh_phase(mu) + sm * cornette_shanks_phase(mu, g);
    return l0 * t + e * sc / max(ext, vec3<f32>(1e-12)) * (vec3<f32>(1.0) - t);
}

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
    let m = atmo_medium(atmo.radii.z);
    let fg = fog(vec3<f32>(0.25), q.w, dot(dir, atmo.sun.xyz), m.extinction, m.rayleigh, m.mie,
        atmo.mie_extinction.w, atmo.sun_illuminance.xyz);
    atmo_out[4u * n] = vec4<f32>(sky_radiance(dir), 0.0);
    atmo_out[4u * n + 1u] = vec4<f32>(ap.inscatter, 0.0);
    atmo_out[4u * n + 2u] = vec4<f32>(ap.transmittance, 0.0);
    atmo_out[4u * n + 3u] = vec4<f32>(fg, 0.0);
}
