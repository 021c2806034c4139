//! Freeform helpers shared by the GPU tests: a bundled scene, and one view cast three ways.

use relume::freeform::field::Field;
use relume::freeform::rmlrc::{camera_outside, cast, RmlrcParams};
use relume::freeform::twin::{GpuField, View32};
use relume::freeform::twin_cast::cast32;
use relume::freeform::{Bound, View};
use relume::gpu::freeform_caster::FreeformCaster;
use relume::gpu::Gpu;
use relume::scene::freeform::FreeformCamera;
use std::path::Path;

/// `scenes/freeform/NAME` (height files read), compiled, with its camera.
pub fn bundled(name: &str) -> (Field, FreeformCamera) {
    let s = relume::load::freeform_scene(&Path::new("scenes/freeform").join(name)).unwrap();
    (Field::compile(&s.shape).unwrap(), s.camera.unwrap())
}

/// One view cast by the f32 twin, the GPU kernel and the f64 multilevel caster (default knobs).
pub struct ThreeCasts {
    pub twin: Vec<Option<(f32, [f32; 3])>>,
    pub gpu: Vec<[f32; 4]>,
    pub f64: Vec<Option<f64>>,
}

pub fn three_casts(
    gpu: &Gpu,
    caster: &FreeformCaster,
    field: &Field,
    camera: &FreeformCamera,
    size: (u32, u32),
) -> ThreeCasts {
    let params = RmlrcParams::default();
    let view = View::new(camera, size.0, size.1);
    let v32 = View32::of(&view);
    let gf = GpuField::upload(field, view.eye).unwrap();
    let prune = camera_outside(field, &view, Bound::Affine);
    let twin = cast32(&gf, &v32, params.top_level, params.refine, prune);
    let hits = caster
        .cast(gpu, &gf, &v32, params.top_level, params.refine, prune)
        .unwrap();
    let (f64_hits, _) = cast(field, &view, &params);
    ThreeCasts {
        twin,
        gpu: hits,
        f64: f64_hits,
    }
}
