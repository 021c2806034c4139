//! One harness per fuzz target. Each takes arbitrary bytes, hands them to relume's readers the
//! way a user's file would reach them, and ignores the result: any `Err` is a correct answer; a
//! panic, an abort (e.g. an allocation the input made up), or a hang is a bug.
//!
//! The first byte of the input selects the reader within a target, so that one coverage-guided
//! run explores all of them. Inputs that need a file are written to a per-process scratch
//! directory (`/dev/shm` when it exists), because the readers take paths, like the CLI.
//!
//! This file depends only on `relume` and `std`: `tests/cli/fuzz_corpus.rs` includes it to replay
//! every corpus and crash input as a regression test.

use std::path::{Path, PathBuf};

/// A harness: arbitrary bytes in, nothing out.
pub type Harness = fn(&[u8]);

/// The fuzz targets, by name (the `src/bin/` files and `fuzz/corpus/<name>/`).
pub const TARGETS: &[(&str, Harness)] = &[
    ("scene", scene),
    ("material", material),
    ("heightmap", heightmap),
    ("text", text),
    ("baked", baked),
];

fn scratch() -> PathBuf {
    let base = if Path::new("/dev/shm").is_dir() {
        PathBuf::from("/dev/shm")
    } else {
        std::env::temp_dir()
    };
    let dir = base.join(format!("relume-fuzz-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("scratch directory");
    dir
}

/// Write `bytes` to a fresh scratch file named `name` (in a directory of its own).
fn file(name: &str, bytes: &[u8]) -> PathBuf {
    let dir = scratch().join("f");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch directory");
    let path = dir.join(name);
    std::fs::write(&path, bytes).expect("scratch file");
    path
}

fn split(data: &[u8]) -> Option<(u8, &[u8])> {
    data.split_first().map(|(s, rest)| (*s, rest))
}

/// OBJ, glTF (JSON) and GLB scenes through `load_scene`.
pub fn scene(data: &[u8]) {
    let Some((sel, rest)) = split(data) else {
        return;
    };
    let name = ["scene.obj", "scene.gltf", "scene.glb"][sel as usize % 3];
    let path = file(name, rest);
    let _ = relume::scene::load_scene(&path, relume::scene::SceneOptions::default());
}

/// Textured materials: with selector 0 the bytes are the MTL beside a fixed textured OBJ (its
/// texture statements, options and paths; `tex.png` exists), with 1 they are the image a fixed
/// MTL names as `map_Kd` and `map_d`. A scene that loads is voxelized too, so that its texture
/// coordinates, transforms and masks reach the albedo integral and the tracer's alpha test.
pub fn material(data: &[u8]) {
    let Some((sel, rest)) = split(data) else {
        return;
    };
    let obj = file(
        "quad.obj",
        b"mtllib quad.mtl\no quad\nv 0 0 0\nv 0 0 2\nv 2 0 2\nv 2 1 0\n\
          vt 0 1\nvt 0 0\nvt 3.5 -2\nvt 1 1\nusemtl m\nf 1/1 2/2 3/3 4/4\n",
    );
    let dir = obj.parent().expect("scratch folder");
    // A 2 × 1 RGBA PNG: one opaque texel, one cut out.
    const PNG: &[u8] = &[
        0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a, 0x00, 0x00, 0x00, 0x0d, 0x49, 0x48, 0x44,
        0x52, 0x00, 0x00, 0x00, 0x02, 0x00, 0x00, 0x00, 0x01, 0x08, 0x06, 0x00, 0x00, 0x00, 0xf4,
        0x22, 0x7f, 0x8a, 0x00, 0x00, 0x00, 0x0f, 0x49, 0x44, 0x41, 0x54, 0x78, 0x9c, 0x63, 0xf8,
        0xcf, 0xc0, 0xf0, 0x1f, 0x08, 0x19, 0x00, 0x0f, 0xf9, 0x02, 0xfe, 0x2d, 0x47, 0x81, 0xf4,
        0x00, 0x00, 0x00, 0x00, 0x49, 0x45, 0x4e, 0x44, 0xae, 0x42, 0x60, 0x82,
    ];
    let (mtl, png): (&[u8], &[u8]) = if sel % 2 == 0 {
        (rest, PNG)
    } else {
        (
            b"newmtl m\nKd 0.8 0.8 0.8\nmap_Kd -s 2 2 tex.png\nmap_d -imfchan m tex.png\n",
            rest,
        )
    };
    std::fs::write(dir.join("quad.mtl"), mtl).expect("scratch file");
    std::fs::write(dir.join("tex.png"), png).expect("scratch file");
    let opts = relume::scene::SceneOptions::default();
    if let Ok((scene, _)) = relume::scene::load_scene(&obj, opts) {
        let params = relume::radiosity::patches::voxelize::VoxelizeParams {
            resolution: relume::radiosity::patches::voxelize::Resolution::VoxelSize(1.0),
            samples_per_patch: 1,
        };
        let _ = relume::radiosity::patches::voxelize::voxelize(&scene, &params);
    }
}

/// Every height-map reader (PNG, JPEG, EXR, GeoTIFF, raw f32) through `load_heightmap`, with a
/// no-data policy from the selector byte.
pub fn heightmap(data: &[u8]) {
    use relume::heightmap::{HeightMapOptions, NoDataPolicy};
    let Some((sel, rest)) = split(data) else {
        return;
    };
    let name = ["h.png", "h.jpg", "h.exr", "h.tif", "h.raw"][sel as usize % 5];
    let mut opts = HeightMapOptions {
        nodata: [
            NoDataPolicy::Error,
            NoDataPolicy::FillMin,
            NoDataPolicy::FillNearest,
        ][(sel as usize / 5) % 3],
        downsample: [1, 2, 3][(sel as usize / 15) % 3],
        ..Default::default()
    };
    let mut body = rest;
    if name == "h.raw" {
        if rest.len() < 2 {
            return;
        }
        opts.raw_size = Some([rest[0] as usize + 1, rest[1] as usize + 1]);
        body = &rest[2..];
    }
    let path = file(name, body);
    let _ = relume::heightmap::load_heightmap(&path, &opts);
}

/// Pipeline RON (parsed and checked, as `run` does before any work) and bake manifests.
pub fn text(data: &[u8]) {
    let Some((sel, rest)) = split(data) else {
        return;
    };
    let Ok(text) = std::str::from_utf8(rest) else {
        return;
    };
    let path = Path::new("fuzz.ron");
    match sel % 3 {
        0 => {
            if let Ok(p) = relume::pipeline::parse::parse_str(path, text) {
                let _ = relume::pipeline::check_order(path, &p);
            }
        }
        1 => {
            let _ = relume::baked::Manifest::from_ron(path, text);
        }
        _ => {
            freeform(path, text);
            themes(path, text);
        }
    }
}

/// A theme set: parsed and checked (`relume-bake theme` before it reads any file).
fn themes(path: &Path, text: &str) {
    drop(relume::load::themes::parse_themes(path, text));
}

/// A freeform scene: parsed and checked, compiled (shape textures included), uploaded for the
/// GPU, evaluated at a few points and bounded over a few boxes — what `freeform render` does
/// before casting.
fn freeform(path: &Path, text: &str) {
    use relume::freeform::bounds::{field_range, Bound, Cell, Work};
    let Ok(scene) = relume::scene::freeform::FreeformScene::parse(path, text) else {
        return;
    };
    let Ok(field) = relume::freeform::Field::compile(&scene.shape) else {
        return;
    };
    let gpu = relume::freeform::twin::GpuField::upload(&field, [0.1, 0.2, 0.3]).ok();
    for p in [[0.0, 0.0, 0.0], [1.0, -2.0, 0.5], [1e3, 1e-3, -7.0]] {
        // The kernel's f32 evaluation and bound (its twin), shape textures included.
        if let Some(g) = &gpu {
            let q = p.map(|v| v as f32);
            let _ = relume::freeform::twin_cast::eval32(g, q);
            let cell = relume::freeform::twin::Cell32::new(
                q,
                [
                    [0.5, 0.0, 0.0],
                    [0.0, 0.25, 0.0],
                    [0.1, 0.0, 1.0],
                    [0.0; 3],
                    [0.0; 3],
                ],
            );
            let _ = relume::freeform::twin::field_range32(g, &cell);
        }
        let _ = field.eval(p);
        let _ = field.normal(p);
        let mut cell = Cell {
            c: p,
            v: [[0.0; 3]; relume::freeform::bounds::SYMBOLS],
        };
        cell.v[0] = [0.5, 0.0, 0.0];
        cell.v[1] = [0.0, 0.25, 0.0];
        cell.v[2] = [0.1, 0.0, 1.0];
        for bound in [Bound::Interval, Bound::Affine] {
            let _ = field_range(&field, &cell, bound, &mut Work::default());
        }
    }
}

/// The player's readers of a baked directory: patches, scene, transfer info, sidecar, shard
/// files, the `.npy` matrices (and the horizon maps' u16 / i32 arrays), the permutation, the mipmap EXR, and the DDS / KTX2 texture parsers for
/// every encoding.
pub fn baked(data: &[u8]) {
    use relume::baked;
    use relume::compress::{containers, DenseEncoding};
    let Some((sel, rest)) = split(data) else {
        return;
    };
    let encodings = [
        DenseEncoding::Bc6h,
        DenseEncoding::Bc1Log,
        DenseEncoding::Bc4Log,
        DenseEncoding::F16,
        DenseEncoding::F32,
    ];
    let enc = encodings[(sel as usize / 10) % encodings.len()];
    match sel % 10 {
        0 => drop(baked::patches::read_file(&file(baked::patches::FILE, rest))),
        1 => {
            let p = file(baked::scene::FILE, rest);
            drop(baked::scene::read(p.parent().unwrap()));
        }
        2 => drop(baked::encoded::read(
            file(baked::encoded::TRANSFER_FILE, rest).parent().unwrap(),
        )),
        3 => drop(baked::encoded::read_sidecar(&file(
            baked::encoded::SIDECAR_FILE,
            rest,
        ))),
        4 => {
            drop(baked::transport::read_file(&file(
                baked::transport::FILE,
                rest,
            )));
            // The same header parser for the horizon maps' u16 planes and i32 directions.
            drop(baked::npy::parse_npy::<u16>(rest));
            drop(baked::npy::parse_npy::<i32>(rest));
        }
        5 => {
            drop(baked::form_factors::read_file(&file(
                baked::form_factors::FILE,
                rest,
            )));
            // Shard files (form factors, transport panels, prepared factors): whole and mapped.
            let p = file("part.0-of-1.shard", rest);
            drop(baked::shard::read(&p));
            if let Ok(m) = baked::shard::Mapped::open(&p) {
                let names: Vec<_> = m.header.sections.iter().map(|s| s.name.clone()).collect();
                for n in names {
                    drop(m.f32s(&n));
                    drop(m.f64s(&n));
                    drop(m.u32s(&n));
                    drop(m.u64s(&n));
                }
            }
        }
        6 => {
            drop(baked::permutation::read_file(&file(
                baked::permutation::FILE,
                rest,
            )));
            // A theme set: decoded, then looked up as the player's twin does.
            if let Ok(set) = baked::themes::decode(rest) {
                let look = set.lookup(3);
                for p in [[0.5f32, 0.5], [-3.0, 1e6], [17.25, 2.5]] {
                    for footprint in [0.5f32, 1.0, 1e9] {
                        let _ = look.albedo(p, footprint);
                    }
                }
            }
        }
        7 => drop(baked::mipmap::read_file(&file(baked::mipmap::FILE, rest))),
        8 => drop(containers::parse_dds(Path::new("t.dds"), rest, enc)),
        _ => {
            let layers = 1 + (sel as usize / 50) % 3;
            drop(containers::parse_ktx2(
                Path::new("t.ktx2"),
                rest,
                enc,
                layers,
            ))
        }
    }
}
