//! Files relume writes, read by decoders not written here: the BC1, BC4 and BC6H
//! blocks of `transfer.dds` by `texture2ddecoder` (PyPI; Perfare's Texture2DDecoder, the C++
//! decoders of AssetStudio), headless player frames and shadow masks by Pillow. The DDS header
//! is parsed in Python from the DDS specification, not by relume or `ddsfile`. (KTX2 is read by
//! the `ktx2` crate in compress_cli.rs, EXR by OpenEXR in terrain_cli.rs, BC1 also by Pillow.)

use crate::common;

use common::{bake, data, expect_code, python, require_python};
use relume::compress::{bc1, bc4, bc6h, containers, DenseEncoding};
use std::path::Path;

/// Bake the Cornell box at about 60 patches with `encoding`; returns the bake directory.
fn bake_encoded(dir: &Path, encoding: &str) -> std::path::PathBuf {
    let ron = dir.join(format!("{encoding}.ron"));
    let scene = data("scenes/cornell-box/cornell_box.obj");
    std::fs::write(
        &ron,
        format!(
            "Pipeline(input: Scene(path: {:?}, scale: 0.001), stages: [\
             Voxelize(resolution: TargetPatches(60), samples_per_patch: 1), \
             FormFactors(samples: 64), Transport(bounces: Infinite), \
             Encode(encoding: {encoding}, fill_holes: false)])",
            scene.to_str().unwrap()
        ),
    )
    .unwrap();
    let out = dir.join(encoding);
    let o = bake(
        dir,
        &[
            "run",
            "-q",
            ron.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ],
    );
    expect_code(&o, 0);
    out
}

/// Decode every layer of a DDS with relume's block decoders: f32 values, layer-major, then
/// rows, columns and (RGB encodings) 3 channels; BC1 and BC4 as 0..255, BC6H as halfs.
fn ours(path: &Path, enc: DenseEncoding) -> (u32, Vec<f32>) {
    let bytes = std::fs::read(path).unwrap();
    let (w, h, layers) = containers::parse_dds(path, &bytes, enc).unwrap();
    let (bw, bh) = (w as usize / 4, h as usize / 4);
    let ch = if enc == DenseEncoding::Bc4Log { 1 } else { 3 };
    let mut out = Vec::new();
    for layer in &layers {
        let bb = enc.block_bytes();
        let mut img = vec![0f32; w as usize * h as usize * ch];
        for by in 0..bh {
            for bx in 0..bw {
                let block = &layer[(by * bw + bx) * bb..][..bb];
                let texels: Vec<[f32; 3]> = match enc {
                    DenseEncoding::Bc1Log => bc1::decode_block(block)
                        .iter()
                        .map(|t| t.map(f32::from))
                        .collect(),
                    DenseEncoding::Bc4Log => bc4::bc4_decode_block(block)
                        .iter()
                        .map(|&v| [v, 0.0, 0.0])
                        .collect(),
                    _ => bc6h::bc6h_decode_block(block).to_vec(),
                };
                for (i, t) in texels.iter().enumerate() {
                    let (x, y) = (bx * 4 + i % 4, by * 4 + i / 4);
                    let at = (y * w as usize + x) * ch;
                    img[at..at + ch].copy_from_slice(&t[..ch]);
                }
            }
        }
        out.extend(img);
    }
    (w, out)
}

const COMPARE_DDS: &str = r#"
import sys, struct, numpy as np, texture2ddecoder as t2d
path, ours_path, kind = sys.argv[1], sys.argv[2], sys.argv[3]
d = open(path, "rb").read()
assert d[:4] == b"DDS ", "magic"
height, width = struct.unpack_from("<II", d, 12)
fourcc = d[84:88]
if fourcc == b"DX10":
    dxgi, _, _, layers, _ = struct.unpack_from("<IIIII", d, 128)
    off = 148
else:
    dxgi, layers, off = fourcc.decode(), 1, 128
block = 8 if kind in ("bc1", "bc4") else 16
size = (width // 4) * (height // 4) * block
ch = 1 if kind == "bc4" else 3
ours = np.fromfile(ours_path, dtype="<f4").reshape(layers, height, width, ch)
worst, bad_blocks, blocks_total = 0.0, 0, 0
for l in range(layers):
    blocks = d[off + l * size: off + (l + 1) * size]
    fn = {"bc1": t2d.decode_bc1, "bc4": t2d.decode_bc4, "bc6h": t2d.decode_bc6}[kind]
    bgra = np.frombuffer(fn(blocks, width, height), np.uint8).reshape(height, width, 4)
    rgb = bgra[:, :, [2, 1, 0]].astype(np.float64)
    if kind == "bc1":
        want = ours[l]
    elif kind == "bc4":
        rgb = rgb[:, :, :1]
        want = ours[l]
    else:
        h = ours[l].astype(np.float16).view(np.uint16).astype(np.float64)
        want = np.clip(ours[l], 0, 1) * 255
    bad = np.abs(rgb - want).max(axis=2) >= 1
    bad_blocks += int(bad.reshape(height // 4, 4, width // 4, 4).any(axis=(1, 3)).sum())
    blocks_total += (height // 4) * (width // 4)
    worst = max(worst, float(np.where(bad[:, :, None], 0, np.abs(rgb - want)).max()))
print("format", dxgi, "layers", layers, "size", width, height)
print("max_abs_diff", worst)
print("blocks_differing", bad_blocks, "of", blocks_total)
"#;

#[test]
fn texture2ddecoder_decodes_our_dds_blocks_like_our_decoders() {
    if !require_python(&["numpy", "texture2ddecoder"]) {
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    // BC1: both decoders make the same 8-bit palette, exactly. BC4: relume keeps the palette's
    // interpolated codes as reals (as the GPU's unorm filtering does), Texture2DDecoder stores
    // them in 8 bits: they differ by less than one code (measured 0.857), never by a whole one.
    // BC6H: Texture2DDecoder's output is 8-bit (round(clamp(x, 0, 1) * 255)), relume's decoder
    // (bcdec_rs) gives halfs: within one code on every block but 3 of 289 (measured), all of
    // mode 0x1E, where Texture2DDecoder's port of bimg's decoder disagrees with bcdec and with
    // the GPU's hardware decoding (gpu_gather.rs checks bcdec against lavapipe's). Allowed: 2x.
    for (encoding, enc, kind, tolerance, differing_blocks) in [
        ("Bc1Log", DenseEncoding::Bc1Log, "bc1", 0.0, 0),
        ("Bc4Log", DenseEncoding::Bc4Log, "bc4", 0.999, 0),
        ("Bc6h", DenseEncoding::Bc6h, "bc6h", 0.999, 6),
    ] {
        let dir = bake_encoded(tmp.path(), encoding);
        let dds = dir.join("transfer.dds");
        let (_, values) = ours(&dds, enc);
        let ours_path = tmp.path().join(format!("{kind}.f32"));
        std::fs::write(&ours_path, bytemuck::cast_slice(&values)).unwrap();
        let out = python(
            COMPARE_DDS,
            &[dds.to_str().unwrap(), ours_path.to_str().unwrap(), kind],
        );
        let diff: f64 = out
            .lines()
            .find_map(|l| l.strip_prefix("max_abs_diff "))
            .unwrap_or_else(|| panic!("{out}"))
            .parse()
            .unwrap();
        assert!(diff <= tolerance, "{kind}: {out}");
        let blocks: usize = out
            .lines()
            .find_map(|l| l.strip_prefix("blocks_differing "))
            .and_then(|l| l.split(' ').next())
            .unwrap()
            .parse()
            .unwrap();
        assert!(blocks <= differing_blocks, "{kind}: {out}");
    }
}

const COMPARE_PNG: &str = r#"
import sys, numpy as np
from PIL import Image
im = Image.open(sys.argv[1]); im.load()
a = np.asarray(im)
b = np.fromfile(sys.argv[2], dtype=np.uint8).reshape(a.shape)
print(im.format, im.mode, im.size, "differing", int((a != b).sum()))
"#;

#[test]
fn pillow_reads_our_pngs_with_the_values_we_wrote() {
    if !require_python(&["numpy", "PIL"]) {
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    // A shadow mask: relume's own decoder (the `image` crate) against Pillow, byte for byte.
    let mask = tmp.path().join("mask.png");
    let o = bake(
        tmp.path(),
        &[
            "shadow",
            "-q",
            data("pipelines/puget-sound-512.ron").to_str().unwrap(),
            "--sun-azimuth",
            "300",
            "--sun-elevation",
            "10",
            "--out",
            mask.to_str().unwrap(),
        ],
    );
    expect_code(&o, 0);
    // What relume meant to write: the library's exact mask (white lit, black shadowed).
    let map = relume::heightmap::load_heightmap(
        &data("scenes/dem/puget_sound_4k.jpg"),
        &relume::heightmap::HeightMapOptions {
            cell_size: Some([40.0, 40.0]),
            height_scale: Some(10.0),
            downsample: 8,
            ..Default::default()
        },
    )
    .unwrap()
    .0;
    let sun = relume::terrain::Sun::new(300.0, 10.0).unwrap();
    let mask_values: Vec<u8> = relume::terrain::hard::relief::shadow_mask(
        &map,
        &sun,
        relume::terrain::hard::relief::HardMethod::Exact,
        None,
        &relume::progress::Silent,
    )
    .iter()
    .map(|&s| if s { 0 } else { 255 })
    .collect();
    let raw = tmp.path().join("mask.raw");
    std::fs::write(&raw, &mask_values).unwrap();
    let out = python(
        COMPARE_PNG,
        &[mask.to_str().unwrap(), raw.to_str().unwrap()],
    );
    assert!(
        out.starts_with("PNG L (512, 512)") && out.contains("differing 0"),
        "{out}"
    );
}
