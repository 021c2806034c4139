// Affine forms and view cells of the freeform kernel (included by freeform.wgsl; Rust twin:
// relume::freeform::twin, `Aff32`, `Cell32`, widening constants and argument there).

const KC: f32 = 9.5367431640625e-7;
const KR: f32 = 9.5367431640625e-7;
const TINY: f32 = 1e-30;

// The eight noise symbols are held as pairs of vec4s, and nothing loops over them: Mesa's
// lavapipe stops every loop of an invocation after 65,535 back-edges in all (gallivm's
// LP_MAX_TGSI_LOOP_ITERATIONS), so the only loops left are over perturbations, depth cells and
// subdivision steps, and the host splits those into passes (see `tile`).
struct Aff { x0: f32, e: f32, g0: vec4<f32>, g1: vec4<f32> }
// A cell: centre and the x, y, z components of the eight generators (0..3 in *0, 4..7 in *1).
struct Cell { c: vec3<f32>, x0: vec4<f32>, x1: vec4<f32>, y0: vec4<f32>, y1: vec4<f32>, z0: vec4<f32>, z1: vec4<f32> }

fn sum4(v: vec4<f32>) -> f32 { return (v.x + v.y) + (v.z + v.w); }
fn sum8_abs(a: vec4<f32>, b: vec4<f32>) -> f32 { return sum4(abs(a)) + sum4(abs(b)); }

fn exp32(x: f32) -> f32 {
    let y = x * 1.442695040888963;
    let n = floor(y + 0.5);
    let f = (y - n) * 0.6931471805599453;
    let p = 1.0 + f * (1.0 + f * (0.5 + f * (1.0 / 6.0 + f * (1.0 / 24.0 + f * (1.0 / 120.0 + f * (1.0 / 720.0 + f * (1.0 / 5040.0)))))));
    return ldexp(p, i32(n));
}

fn make_cell(c: vec3<f32>, v0: vec3<f32>, v1: vec3<f32>, v2: vec3<f32>, v3: vec3<f32>, v4: vec3<f32>) -> Cell {
    let r = abs(c) + abs(v0) + abs(v1) + abs(v2) + abs(v3) + abs(v4);
    let k = KC * r + TINY;
    var cell: Cell;
    cell.c = c;
    cell.x0 = vec4<f32>(v0.x, v1.x, v2.x, v3.x);
    cell.y0 = vec4<f32>(v0.y, v1.y, v2.y, v3.y);
    cell.z0 = vec4<f32>(v0.z, v1.z, v2.z, v3.z);
    cell.x1 = vec4<f32>(v4.x, k.x, 0.0, 0.0);
    cell.y1 = vec4<f32>(v4.y, 0.0, k.y, 0.0);
    cell.z1 = vec4<f32>(v4.z, 0.0, 0.0, k.z);
    return cell;
}

fn extent(cell: Cell) -> vec3<f32> {
    return vec3<f32>(sum8_abs(cell.x0, cell.x1), sum8_abs(cell.y0, cell.y1), sum8_abs(cell.z0, cell.z1));
}

fn aff_range(a: Aff) -> vec2<f32> {
    var r = a.e + sum8_abs(a.g0, a.g1);
    r = r + KR * (r + abs(a.x0)) + TINY;
    return vec2<f32>(a.x0 - r, a.x0 + r);
}

fn aff_widen(a: ptr<function, Aff>) {
    let m = (abs((*a).x0) + (*a).e) + sum8_abs((*a).g0, (*a).g1);
    (*a).e += KR * m + TINY;
}

fn aff_const(x: f32) -> Aff {
    return Aff(x, 0.0, vec4<f32>(0.0), vec4<f32>(0.0));
}

fn aff_hull(lo: f32, hi: f32) -> Aff {
    var a = Aff(0.5 * (lo + hi), 0.5 * (hi - lo), vec4<f32>(0.0), vec4<f32>(0.0));
    aff_widen(&a);
    return a;
}
