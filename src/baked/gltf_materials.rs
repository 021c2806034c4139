//! The materials of a lit glTF export: untextured surfaces share one unlit material whose vertex
//! colour is the baked radiance; each textured or alpha-masked scene material gets an unlit
//! material of its own whose base colour is the material's factor × its albedo texture, so that
//! a viewer shows texture × baked light (the vertex colour is then the light per unit albedo).
//!
//! Images are embedded as PNG (lossless: the decoded texels of `scene.bin`, not the source
//! files). An alpha mask travels in the image's alpha channel with `alphaMode: MASK` and the
//! material's cutoff; a mask read from another image (OBJ `map_d`) is copied into the albedo
//! image's alpha, resampled to its size by nearest texel. A mask whose texture transform
//! differs from the albedo texture's cannot share its texture coordinates and is left out
//! (counted in the report). Texture transforms are applied to `TEXCOORD_0` itself, exact for
//! any affine map (glTF's `KHR_texture_transform` has no shear).

use crate::error::{Error, Result};
use crate::scene::texture::{channel_value, AlphaMask, Channel, Texture, TextureRef, Wrap};
use crate::scene::{Material, Scene};
use serde_json::{json, Value};

/// How a scene material is exported.
#[derive(Clone, Debug)]
pub enum Look {
    /// Shared unlit material 0; vertex colour = radiance.
    Plain,
    /// Its own glTF material; vertex colour = light per unit albedo, texture coordinates read
    /// through `uv` (the albedo texture's reference, else the mask's).
    Textured { material: usize, uv: TextureRef },
    /// Cut away everywhere: not exported.
    Hidden,
}

/// The glTF `materials`, `images`, `textures` and `samplers` arrays and each scene material's look.
pub struct Materials {
    pub materials: Vec<Value>,
    pub images: Vec<Value>,
    pub textures: Vec<Value>,
    pub samplers: Vec<Value>,
    pub looks: Vec<Look>,
    /// Masks that could not travel (a transform other than the albedo texture's).
    pub masks_left_out: usize,
    /// glTF texture of each scene texture and wrap used as an albedo without a mask (shared by
    /// every material that uses it so).
    plain_textures: Vec<((u32, [Wrap; 2]), usize)>,
}

/// Build the materials of `scene`; `push_image(png bytes)` stores an image in the binary
/// buffer and returns its buffer view.
pub fn materials(scene: &Scene, push_image: &mut dyn FnMut(Vec<u8>) -> usize) -> Result<Materials> {
    let mut out = Materials {
        materials: vec![json!({
            "name": "baked light (unlit)",
            "pbrMetallicRoughness": {"baseColorFactor": [1.0, 1.0, 1.0, 1.0], "metallicFactor": 0.0, "roughnessFactor": 1.0},
            "doubleSided": true,
            "extensions": {"KHR_materials_unlit": {}},
        })],
        images: vec![],
        textures: vec![],
        samplers: vec![],
        looks: vec![],
        masks_left_out: 0,
        plain_textures: vec![],
    };
    for m in &scene.materials {
        let look = material(scene, m, &mut out, push_image)?;
        out.looks.push(look);
    }
    Ok(out)
}

fn material(
    scene: &Scene,
    m: &Material,
    out: &mut Materials,
    push_image: &mut dyn FnMut(Vec<u8>) -> usize,
) -> Result<Look> {
    let mask = m.alpha.as_ref();
    if mask.is_some_and(|a| a.texture.is_none() && a.cuts(a.factor)) {
        return Ok(Look::Hidden);
    }
    let mask_tex = mask.and_then(|a| a.texture.as_ref().map(|(r, c)| (a, r, *c)));
    if m.albedo_texture.is_none() && mask_tex.is_none() {
        return Ok(Look::Plain);
    }
    let base = m.albedo_texture.as_ref();
    let shared = match (base, mask_tex) {
        (Some(r), None) => Some((r.texture, r.wrap)),
        _ => None,
    };
    let known = shared.and_then(|k| out.plain_textures.iter().find(|(t, _)| *t == k));
    let (texture, uv) = match known {
        Some(&(_, texture)) => (texture, base.expect("an albedo texture").clone()),
        None => {
            let (texture, uv) = texture(scene, base, mask_tex, out, push_image)?;
            if let Some(k) = shared {
                out.plain_textures.push((k, texture));
            }
            (texture, uv)
        }
    };
    let alpha_mode = mask_tex.and_then(|(a, r, _)| {
        base.is_none_or(|b| b.transform == r.transform)
            .then_some(a.cutoff)
    });
    let mut mat = json!({
        "name": m.name,
        "pbrMetallicRoughness": {
            "baseColorFactor": [m.albedo[0], m.albedo[1], m.albedo[2], 1.0],
            "baseColorTexture": {"index": texture},
            "metallicFactor": 0.0, "roughnessFactor": 1.0,
        },
        "doubleSided": true,
        "extensions": {"KHR_materials_unlit": {}},
    });
    if let Some(cutoff) = alpha_mode {
        mat["alphaMode"] = json!("MASK");
        mat["alphaCutoff"] = json!(cutoff);
    }
    out.materials.push(mat);
    Ok(Look::Textured {
        material: out.materials.len() - 1,
        uv,
    })
}

/// Embed the image of a textured material (the albedo texels or white, alpha from the mask
/// where it can travel) with its sampler; the glTF texture index and the coordinates' reference.
fn texture(
    scene: &Scene,
    base: Option<&TextureRef>,
    mask_tex: Option<(&AlphaMask, &TextureRef, Channel)>,
    out: &mut Materials,
    push_image: &mut dyn FnMut(Vec<u8>) -> usize,
) -> Result<(usize, TextureRef)> {
    // The image: the albedo texels (or white), alpha from the mask where it can travel.
    let (mut img, uv) = match base {
        Some(r) => {
            let t = r.of(&scene.textures);
            (image_of(t), r.clone())
        }
        None => {
            let (_, r, _) = mask_tex.expect("a mask texture");
            let t = r.of(&scene.textures);
            let white = image::RgbaImage::from_pixel(t.width, t.height, image::Rgba([255; 4]));
            (white, r.clone())
        }
    };
    if let Some((a, r, channel)) = mask_tex {
        if base.is_none_or(|b| b.transform == r.transform) {
            let t = r.of(&scene.textures);
            let (w, h) = img.dimensions();
            for (x, y, p) in img.enumerate_pixels_mut() {
                let (mx, my) = (
                    (x as u64 * t.width as u64 / w as u64) as i64,
                    (y as u64 * t.height as u64 / h as u64) as i64,
                );
                let v = a.factor * channel_value(t.texel(mx, my, r.wrap), channel);
                p[3] = (v.clamp(0.0, 1.0) * 255.0).round() as u8;
            }
        } else {
            out.masks_left_out += 1;
        }
    } else {
        for p in img.pixels_mut() {
            p[3] = 255;
        }
    }
    let mut png = Vec::new();
    img.write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .map_err(|e| Error::Internal(format!("cannot encode a texture as PNG: {e}")))?;
    let view = push_image(png);
    out.images
        .push(json!({"bufferView": view, "mimeType": "image/png"}));
    let wrap = uv.wrap;
    out.samplers.push(json!({
        "magFilter": 9729, "minFilter": 9987,
        "wrapS": gl_wrap(wrap[0]), "wrapT": gl_wrap(wrap[1]),
    }));
    out.textures
        .push(json!({"source": out.images.len() - 1, "sampler": out.samplers.len() - 1}));
    Ok((out.textures.len() - 1, uv))
}

fn image_of(t: &Texture) -> image::RgbaImage {
    image::RgbaImage::from_raw(t.width, t.height, t.texels.clone()).expect("RGBA8 of its size")
}

fn gl_wrap(w: Wrap) -> u32 {
    match w {
        Wrap::Repeat => 10497,
        Wrap::ClampToEdge => 33071,
        Wrap::MirroredRepeat => 33648,
    }
}
