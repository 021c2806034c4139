//! relume's freeform multilevel caster (RMLRC, CPU) against fidget's voxel renderer on the
//! same scenes, same camera, same pixel count, same thread count.
//!
//! fidget renders a voxel grid in its screen space (columns of `depth` voxels under each
//! pixel); its `world_to_model` matrix is applied with a homogeneous divide, so a projective
//! matrix turns the columns into the pixel rays of relume's pinhole camera, depth voxels
//! uniform in 1/z between a near and a far plane.
//!
//! `cargo run --release [-- --size WxH --threads N --runs N --no-vm --no-blobs]`

mod translate;

use fidget::context::{Context, Node};
use fidget::eval::{Function, MathFunction};
use fidget::jit::JitShape;
use fidget::raster::voxel::{self, EvalConfig, RenderConfig};
use fidget::render::{RenderHints, ThreadPool, VoxelSize};
use fidget::shape::{EzShape, Shape};
use fidget::vm::VmShape;
use nalgebra::Matrix4;
use relume::freeform::rmlrc::{cast, RmlrcParams};
use relume::freeform::{Field, View};
use relume::scene::freeform::FreeformScene;
use std::path::{Path, PathBuf};
use std::time::Instant;

type Error = translate::Error;

struct Args {
    width: u32,
    height: u32,
    threads: usize,
    runs: usize,
    vm: bool,
    blobs: bool,
}

fn parse_args() -> Result<Args, Error> {
    let mut args = Args {
        width: 640,
        height: 480,
        threads: std::thread::available_parallelism().map_or(1, |n| n.get()),
        runs: 3,
        vm: true,
        blobs: true,
    };
    let mut it = std::env::args().skip(1);
    while let Some(a) = it.next() {
        let mut value = || it.next().ok_or_else(|| format!("{a} needs a value"));
        match a.as_str() {
            "--size" => {
                let v = value()?;
                let (w, h) = v.split_once('x').ok_or("--size is WxH")?;
                (args.width, args.height) = (w.parse()?, h.parse()?);
            }
            "--threads" => args.threads = value()?.parse()?,
            "--runs" => args.runs = value()?.parse()?,
            "--no-vm" => args.vm = false,
            "--no-blobs" => args.blobs = false,
            _ => return Err(format!("unknown argument {a}").into()),
        }
    }
    Ok(args)
}

/// The wall time of `f` and its result.
fn timed<T>(f: impl FnOnce() -> T) -> (f64, T) {
    let t = Instant::now();
    let r = f();
    (t.elapsed().as_secs_f64(), r)
}

/// splitmix64, for reproducible sample points without another dependency.
struct Rng(u64);

impl Rng {
    fn next_f64(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// A box around the scene's perturbations (their supports), widened by a quarter.
fn sample_box(field: &Field) -> ([f64; 3], [f64; 3]) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for (l, h) in field.bumps.iter().filter_map(|b| b.support) {
        for k in 0..3 {
            lo[k] = lo[k].min(l[k]);
            hi[k] = hi[k].max(h[k]);
        }
    }
    if lo[0] > hi[0] {
        return ([-2.0; 3], [2.0; 3]);
    }
    for k in 0..3 {
        let m = 0.125 * (hi[k] - lo[k]);
        lo[k] -= m;
        hi[k] += m;
    }
    (lo, hi)
}

/// Evaluate relume's field (f64) and the fidget shape (f32, point evaluator) at `n` random
/// points of the scene box; the largest error relative to `max(|f|, 1)`.
fn check_translation<F: Function + Clone>(
    field: &Field,
    shape: &Shape<F>,
    n: usize,
) -> Result<f64, Error> {
    let (lo, hi) = sample_box(field);
    let tape = shape.ez_point_tape();
    let mut eval = Shape::<F>::new_point_eval();
    let mut rng = Rng(0x5eed);
    let mut worst = 0.0f64;
    for _ in 0..n {
        let p: [f64; 3] = std::array::from_fn(|k| lo[k] + (hi[k] - lo[k]) * rng.next_f64());
        let want = field.eval(p);
        let (got, _) = eval.eval(&tape, p[0] as f32, p[1] as f32, p[2] as f32)?;
        let err = (got as f64 - want).abs() / want.abs().max(1.0);
        if !err.is_finite() {
            return Err(format!("non-finite value at {p:?}: fidget {got}, relume {want}").into());
        }
        worst = worst.max(err);
    }
    Ok(worst)
}

/// The frustum of relume's `view` as fidget's voxel grid: voxel `(i, j, k)` is the point at
/// view depth `z` on the ray through the centre of pixel `(i, j)`, with `1/z` uniform over
/// `k` from `far` (k = 0, the back) to `near` (k = depth, the front; fidget fills columns
/// front to back from high k).
struct Frustum {
    depth: u32,
    near: f64,
    far: f64,
}

impl Frustum {
    /// `1/z` at the (fractional) voxel coordinate `k`.
    fn inv_z(&self, k: f64) -> f64 {
        let t = (k + 0.5) / self.depth as f64;
        1.0 / self.far + t * (1.0 / self.near - 1.0 / self.far)
    }

    /// The voxel-grid → world matrix (projective).
    fn voxel_to_world(&self, view: &View) -> Matrix4<f64> {
        let (w, h) = (view.width as f64, view.height as f64);
        let (sx, ox) = (2.0 * view.tan_x / w, (1.0 / w - 1.0) * view.tan_x);
        let (sy, oy) = (-2.0 * view.tan_y / h, (1.0 - 1.0 / h) * view.tan_y);
        let b = 1.0 / self.near - 1.0 / self.far;
        let (qk, q0) = (
            b / self.depth as f64,
            1.0 / self.far + 0.5 * b / self.depth as f64,
        );
        let (e, f, r, u) = (view.eye, view.forward, view.right, view.up);
        let row = |c: usize| {
            [
                sx * r[c],
                sy * u[c],
                e[c] * qk,
                ox * r[c] + oy * u[c] + f[c] + e[c] * q0,
            ]
        };
        let last = [0.0, 0.0, qk, q0];
        Matrix4::from_fn(|i, j| if i < 3 { row(i)[j] } else { last[j] })
    }

    fn config(&self, view: &View) -> Result<RenderConfig, Error> {
        let size = VoxelSize::new(view.width, view.height, self.depth);
        let screen_to_world = size.screen_to_world().cast::<f64>();
        let inv = screen_to_world
            .try_inverse()
            .ok_or("fidget's screen-to-world matrix is singular")?;
        Ok(RenderConfig {
            image_size: size,
            world_to_model: (self.voxel_to_world(view) * inv).cast::<f32>(),
        })
    }
}

/// One fidget render: per pixel the voxel depth (0 = no surface).
fn render_fidget<F: Function + RenderHints + Clone>(
    shape: &Shape<F>,
    config: &RenderConfig,
) -> Result<Vec<u32>, Error> {
    let bound = shape.clone().try_into()?;
    let eval = EvalConfig {
        threads: Some(&ThreadPool::Global), // the pool built in `main`
        ..Default::default()
    };
    let image = voxel::render(bound, config, &eval).ok_or("render cancelled")?;
    Ok(image.iter().map(|p| p.depth).collect())
}

struct Row {
    scene: String,
    perturbations: usize,
    pixels: u32,
    relume_s: f64,
    jit_s: f64,
    vm_s: Option<f64>,
    relume_hits: usize,
    fidget_hits: usize,
    depth_agree: f64,
    depth: u32,
    check_err: f64,
}

fn shape_of<F: MathFunction>(ctx: &Context, node: Node) -> Result<Shape<F>, Error> {
    Ok(Shape::<F>::new(ctx, node)?)
}

fn bench_scene(path: &Path, args: &Args) -> Result<Row, Error> {
    let scene = FreeformScene::load(path)?;
    let field = Field::compile(&scene.shape)?;
    let camera = scene.camera.as_ref().ok_or("the scene has no camera")?;
    let view = View::new(camera, args.width, args.height);

    let mut ctx = Context::new();
    let node = translate::field_node(&mut ctx, &field)?;
    let jit: JitShape = shape_of(&ctx, node)?;
    let vm: VmShape = shape_of(&ctx, node)?;
    let check_err =
        check_translation(&field, &jit, 4000)?.max(check_translation(&field, &vm, 1000)?);
    if check_err > 1e-4 {
        return Err(format!("fidget and relume disagree: relative error {check_err:.2e}").into());
    }

    // Near plane at a quarter of the camera-target distance (checked against relume's
    // nearest hit below), far plane relume's; depth voxels cubic at the target distance.
    let dist = (0..3)
        .map(|k| (camera.target[k] - camera.eye[k]).powi(2))
        .sum::<f64>()
        .sqrt();
    let near = 0.25 * dist;
    let depth = (dist / (near * view.pixel_angle())).ceil() as u32;
    let frustum = Frustum {
        depth: depth.div_ceil(64) * 64,
        near,
        far: view.far,
    };
    let config = frustum.config(&view)?;

    // Best of `runs`, the renderers interleaved so that both see the same load on a shared
    // machine.
    let params = RmlrcParams::default();
    let (mut relume_s, mut jit_s, mut vm_s) = (f64::INFINITY, f64::INFINITY, f64::INFINITY);
    let (mut hits, mut depths) = (Vec::new(), Vec::new());
    for _ in 0..args.runs.max(1) {
        let (s, (h, _stats)) = timed(|| cast(&field, &view, &params));
        (relume_s, hits) = (relume_s.min(s), h);
        let (s, d) = timed(|| render_fidget(&jit, &config));
        (jit_s, depths) = (jit_s.min(s), d?);
        if args.vm {
            let (s, d) = timed(|| render_fidget(&vm, &config));
            vm_s = vm_s.min(s);
            if d? != depths {
                eprintln!("note: {}: VM and JIT images differ", path.display());
            }
        }
    }
    let vm_s = args.vm.then_some(vm_s);

    // Sanity: hit counts, and whether relume's depth lies within a voxel of fidget's.
    let (mut relume_hits, mut fidget_hits, mut both, mut agree) = (0, 0, 0, 0);
    let mut nearest = f64::INFINITY;
    for (i, (&hit, &d)) in hits.iter().zip(&depths).enumerate() {
        let (px, py) = (i as u32 % view.width, i as u32 / view.width);
        let z = hit.map(|t| t / view.pixel_ray(px, py).1);
        relume_hits += z.is_some() as usize;
        fidget_hits += (d > 0) as usize;
        if let Some(z) = z {
            nearest = nearest.min(z);
            if d > 0 {
                both += 1;
                // Voxel d−1 is the first sample inside; the surface is between it and the
                // sample in front. One voxel of slack either side.
                let k = d as f64 - 1.0;
                let (z_front, z_back) = (
                    1.0 / frustum.inv_z(k + 2.0),
                    1.0 / frustum.inv_z((k - 1.0).max(-0.5)),
                );
                agree += (z >= z_front && z <= z_back) as usize;
            }
        }
    }
    if nearest < near {
        eprintln!(
            "warning: {}: relume hits at depth {nearest:.3}, in front of fidget's near plane {near:.3}",
            path.display()
        );
    }
    Ok(Row {
        scene: path
            .file_stem()
            .map_or_else(String::new, |s| s.to_string_lossy().into_owned()),
        perturbations: scene.counts().1,
        pixels: args.width * args.height,
        relume_s,
        jit_s,
        vm_s,
        relume_hits,
        fidget_hits,
        depth_agree: 100.0 * agree as f64 / both.max(1) as f64,
        depth: frustum.depth,
        check_err,
    })
}

fn main() -> Result<(), Error> {
    let args = parse_args()?;
    rayon::ThreadPoolBuilder::new()
        .num_threads(args.threads)
        .build_global()?;
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let mut scenes: Vec<PathBuf> = [16, 64, 256]
        .iter()
        .map(|n| root.join(format!("scenes/freeform/bench/terrain-{n}.ron")))
        .collect();
    if args.blobs {
        scenes.push(root.join("scenes/freeform/blobs-128.ron"));
    }
    println!(
        "{}x{} pixels, {} threads (one rayon pool for both), best of {} runs; fidget: JIT{}\n",
        args.width,
        args.height,
        args.threads,
        args.runs,
        if args.vm { " and VM" } else { "" }
    );
    println!(
        "| scene | perturbations | pixels | relume RMLRC CPU s | fidget JIT s | relume / JIT | fidget VM s | relume / VM | hit pixels relume | hit pixels fidget | depth within 1 voxel | depth voxels | max rel. error |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    for path in &scenes {
        let r = bench_scene(path, &args).map_err(|e| format!("{}: {e}", path.display()))?;
        let (vm, vm_ratio) = match r.vm_s {
            Some(s) => (format!("{s:.3}"), format!("{:.2}", r.relume_s / s)),
            None => ("not run".into(), "-".into()),
        };
        println!(
            "| {} | {} | {} | {:.3} | {:.3} | {:.2} | {vm} | {vm_ratio} | {} | {} | {:.1} % | {} | {:.1e} |",
            r.scene,
            r.perturbations,
            r.pixels,
            r.relume_s,
            r.jit_s,
            r.relume_s / r.jit_s,
            r.relume_hits,
            r.fidget_hits,
            r.depth_agree,
            r.depth,
            r.check_err,
        );
    }
    Ok(())
}
