// Scattered light in the air: the binding-free part shared by the table builders
// (atmosphere.wgsl, group 0) and the renderer's lookups (atmosphere_lookup.wgsl, group 3):
// the parameter struct, table sizes, the medium, phase functions, the tables' uv
// parameterisations, bilinear weights and the constant-density fog. Nothing here reads a binding;
// the functions that need the parameters take them (or their radii) as arguments.
// Kilometres and 1/km; +Y up, the eye at (0, ground + altitude, 0). Tables are storage buffers
// of vec4 texels, row-major; an axis of N texels covers unit x in [0, 1] with texel i at
// i / (N - 1). Rust twins: relume::atmosphere::{twin, lut} (same arithmetic, line for line).

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
// The multiple-scattering sphere: azimuths x zenith-cosine bands (twin.rs MULTI_AZIMUTHS,
// MULTI_BANDS; the bands split at the horizon and crowd toward it, lut.rs band).
const MULTI_AZIMUTHS: u32 = 4u;
const MULTI_BANDS: u32 = 16u;
const STEPS_SKY: u32 = 30u;
const STEPS_AERIAL: u32 = 20u;

struct MediumSample {
    rayleigh: vec3<f32>,
    mie: vec3<f32>,
    extinction: vec3<f32>,
}

fn atmo_medium_of(p: AtmosphereParams, h_in: f32) -> MediumSample {
    let h = max(h_in, 0.0);
    let dr = exp(-h / p.rayleigh.w);
    let dm = exp(-h / p.mie_scattering.w);
    let d_o = max(1.0 - abs(h - p.ozone.w) / p.ground_albedo.w, 0.0);
    let sr = p.rayleigh.xyz * dr;
    let sm = p.mie_scattering.xyz * dm;
    return MediumSample(sr, sm, sr + p.mie_extinction.xyz * dm + p.ozone.xyz * d_o);
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
    // On or outside the sphere heading away: no hit (not the root t = 0 of a ray leaving the
    // ground, which would make every direction from the ground see the ground).
    if (disc < 0.0 || (c >= 0.0 && b >= 0.0)) {
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

// Zenith angle of the horizon from radius r (ground radius g), and beta = PI - that.
fn atmo_horizon(r: f32, g: f32) -> vec2<f32> {
    let v_h = sqrt(max((r - g) * (r + g), 0.0));
    let beta = acos(clamp(v_h / r, -1.0, 1.0));
    return vec2<f32>(PI - beta, beta);
}

fn sky_view_uv(r: f32, g: f32, theta: f32, phi: f32) -> vec2<f32> {
    let hb = atmo_horizon(r, g);
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

fn sky_view_angles(r: f32, g: f32, u: f32, v: f32) -> vec2<f32> {
    let hb = atmo_horizon(r, g);
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
fn atmo_view_angles(dir: vec3<f32>, sun: vec3<f32>) -> vec2<f32> {
    let theta = acos(clamp(dir.y, -1.0, 1.0));
    let lv = sqrt(dir.x * dir.x + dir.z * dir.z);
    let ls = sqrt(sun.x * sun.x + sun.z * sun.z);
    var c = 1.0;
    if (lv > 1e-6 && ls > 1e-6) {
        c = (dir.x * sun.x + dir.z * sun.z) / (lv * ls);
    }
    return vec2<f32>(theta, acos(clamp(c, -1.0, 1.0)));
}

fn atmo_unit_of(i: u32, n: u32) -> f32 {
    return f32(i) / f32(n - 1u);
}

// Bilinear weights; the lookups themselves (one per table) live beside their bindings, since
// WGSL cannot pass storage arrays to functions.
struct AtmoBilinear {
    i00: u32,
    i10: u32,
    i01: u32,
    i11: u32,
    ax: f32,
    ay: f32,
}

fn atmo_bilinear(nx: u32, ny: u32, x: f32, y: f32) -> AtmoBilinear {
    let fx = clamp(x, 0.0, 1.0) * f32(nx - 1u);
    let fy = clamp(y, 0.0, 1.0) * f32(ny - 1u);
    let x0 = min(u32(floor(fx)), nx - 1u);
    let y0 = min(u32(floor(fy)), ny - 1u);
    let x1 = min(x0 + 1u, nx - 1u);
    let y1 = min(y0 + 1u, ny - 1u);
    return AtmoBilinear(y0 * nx + x0, y0 * nx + x1, y1 * nx + x0, y1 * nx + x1, fx - f32(x0), fy - f32(y0));
}

fn atmo_mix_bilinear(b: AtmoBilinear, t00: vec3<f32>, t10: vec3<f32>, t01: vec3<f32>, t11: vec3<f32>) -> vec3<f32> {
    let a = t00 + (t10 - t00) * b.ax;
    let c = t01 + (t11 - t01) * b.ax;
    return a + (c - a) * b.ay;
}

// In-scattering (xyz) and transmittance of the eye's ray along dir over [0, t_max].
struct Marched {
    inscatter: vec3<f32>,
    transmittance: vec3<f32>,
}

// The constant-density fog (Vyatkin et al. 2018): L0 seen through s km of air with extinction ext
// and Rayleigh / Mie scattering sr, sm (1/km), Mie g, sun illuminance e, view-sun cosine mu.
fn fog(l0: vec3<f32>, s: f32, mu: f32, ext: vec3<f32>, sr: vec3<f32>, sm: vec3<f32>, g: f32, e: vec3<f32>) -> vec3<f32> {
    let t = exp(-ext * s);
    let sc = sr * rayleigh_phase(mu) + sm * cornette_shanks_phase(mu, g);
    return l0 * t + e * sc / max(ext, vec3<f32>(1e-12)) * (vec3<f32>(1.0) - t);
}

