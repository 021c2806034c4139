//! Textures in the scene description: decoded images, how a material refers to one (a texture
//! coordinate transform and wrap modes), and alpha masks.
//!
//! Images are kept as the file stores them, 8-bit RGBA: RGB sRGB-encoded, alpha linear (glTF 2.0
//! §3.9.2; OBJ colour textures are sRGB by convention). 16-bit images are rounded to 8 bits and
//! float images sRGB-encoded to 8 bits: an albedo needs no more than 8 sRGB bits.
//! [`srgb_to_linear`] decodes a channel.
//!
//! Texture coordinates follow glTF: (0, 0) is the top-left corner of the image, u grows to the
//! right and v downwards, one unit per image. The OBJ loader flips OBJ's v (origin bottom-left).
//! A texel covers `[x, x+1) × [y, y+1)` in texel units `(u·width, v·height)`: lookups here are
//! nearest-texel, the texture read as a piecewise-constant function (what
//! [`crate::radiosity::patches::albedo`] integrates exactly).

use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// A decoded image.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Texture {
    /// Where it came from: the file's path, or `<scene file>#image N` for an embedded image.
    pub name: String,
    pub width: u32,
    pub height: u32,
    /// `width · height` RGBA8 texels, row-major from the top row; RGB sRGB-encoded, alpha linear.
    pub texels: Vec<u8>,
}

/// What a lookup outside `[0, 1)` reads (glTF sampler `wrapS` / `wrapT`; OBJ `-clamp on`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum Wrap {
    /// The image tiles the plane.
    #[default]
    Repeat,
    /// Coordinates are clamped to the edge texels.
    ClampToEdge,
    /// The image tiles the plane, every other copy mirrored.
    MirroredRepeat,
}

/// Which channel of an image a scalar texture (an alpha mask) reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Channel {
    Red,
    Green,
    Blue,
    Alpha,
    /// The mean of the three colour channels' stored values (a grey image's grey).
    Luminance,
}

/// A material's reference to a texture.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TextureRef {
    /// Index into `Scene::textures`.
    pub texture: u32,
    /// Affine map from vertex texture coordinates to image coordinates:
    /// `(u', v') = (t[0]·(u, v, 1), t[1]·(u, v, 1))` (glTF `KHR_texture_transform`; OBJ `-o`, `-s`).
    pub transform: [[f32; 3]; 2],
    /// Wrap modes along u and v.
    pub wrap: [Wrap; 2],
}

impl TextureRef {
    /// The identity transform, repeating: how most files use a texture.
    pub fn new(texture: u32) -> Self {
        TextureRef {
            texture,
            transform: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            wrap: [Wrap::Repeat; 2],
        }
    }

    /// The texture this reference names.
    pub fn of<'a>(&self, textures: &'a [Texture]) -> &'a Texture {
        &textures[self.texture as usize]
    }

    /// Image coordinates of vertex texture coordinates `uv`.
    pub fn apply(&self, uv: [f32; 2]) -> [f32; 2] {
        let [a, b] = self.transform;
        [
            a[0] * uv[0] + a[1] * uv[1] + a[2],
            b[0] * uv[0] + b[1] * uv[1] + b[2],
        ]
    }
}

/// How a material's alpha cuts its surface away. Light passes where alpha is below `cutoff`;
/// everything else is opaque (glTF `MASK`; glTF `BLEND` and OBJ `d` / `map_d` are read as masks
/// at 0.5, because a radiosity patch is either there or not).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct AlphaMask {
    /// Alpha factor: OBJ `d`, glTF `baseColorFactor`'s alpha.
    pub factor: f32,
    /// The texture and channel alpha is read from, multiplied by `factor` (None: `factor` alone).
    pub texture: Option<(TextureRef, Channel)>,
    /// Alpha below this is cut out.
    pub cutoff: f32,
}

impl AlphaMask {
    /// True when `alpha` (already multiplied by the factor) is cut out.
    pub fn cuts(&self, alpha: f32) -> bool {
        alpha < self.cutoff
    }
}

/// The sRGB transfer function's inverse (IEC 61966-2-1).
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// The sRGB transfer function (IEC 61966-2-1), negative values encoded as 0: the one encoder
/// of the library (`render::tonemap` re-exports it), twin of `linear_to_srgb` in
/// `shaders/common.wgsl`.
pub fn linear_to_srgb(c: f32) -> f32 {
    if c <= 0.0031308 {
        12.92 * c.max(0.0)
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}

/// Linear values of the 256 sRGB-encoded 8-bit levels.
pub fn srgb_table() -> [f32; 256] {
    std::array::from_fn(|i| srgb_to_linear(i as f32 / 255.0))
}

/// The texel index a possibly out-of-range integer coordinate reads along an axis of `n` texels.
pub fn wrap_index(i: i64, n: u32, wrap: Wrap) -> u32 {
    let n = n as i64;
    (match wrap {
        Wrap::Repeat => i.rem_euclid(n),
        Wrap::ClampToEdge => i.clamp(0, n - 1),
        Wrap::MirroredRepeat => {
            let k = i.rem_euclid(2 * n);
            if k < n {
                k
            } else {
                2 * n - 1 - k
            }
        }
    }) as u32
}

impl Texture {
    /// A texture from RGBA8 texels; errors when the sizes disagree or the image is empty.
    pub fn from_rgba8(name: String, width: u32, height: u32, texels: Vec<u8>) -> Result<Self> {
        if width == 0 || height == 0 || texels.len() != 4 * width as usize * height as usize {
            return Err(Error::input(
                &name,
                format!(
                    "texture is {width}×{height} but holds {} bytes of RGBA8",
                    texels.len()
                ),
            ));
        }
        Ok(Texture {
            name,
            width,
            height,
            texels,
        })
    }

    /// Decode an image file (PNG or JPEG). A file that cannot be read or decoded is an error
    /// naming it; grey and grey-alpha images become RGB(A) with R = G = B.
    pub fn decode(path: &Path) -> Result<Self> {
        let bytes = std::fs::read(path).map_err(|e| Error::io(path, "cannot read texture", e))?;
        let image = image::load_from_memory(&bytes)
            .map_err(|e| Error::input(path, format!("cannot decode texture: {e}")))?;
        Self::from_image(path.display().to_string(), image)
    }

    /// A texture from a decoded image (8-bit kept, 16-bit rounded, float sRGB-encoded).
    pub fn from_image(name: String, image: image::DynamicImage) -> Result<Self> {
        use image::DynamicImage as D;
        let rgba = match image {
            D::ImageRgb32F(_) | D::ImageRgba32F(_) => {
                let f = image.to_rgba32f();
                let (w, h) = f.dimensions();
                let texels = f
                    .pixels()
                    .flat_map(|p| {
                        let [r, g, b, a] = p.0;
                        [linear_to_srgb(r), linear_to_srgb(g), linear_to_srgb(b), a]
                            .map(|c| (c.clamp(0.0, 1.0) * 255.0).round() as u8)
                    })
                    .collect();
                return Self::from_rgba8(name, w, h, texels);
            }
            other => other.to_rgba8(),
        };
        let (w, h) = rgba.dimensions();
        Self::from_rgba8(name, w, h, rgba.into_raw())
    }

    /// The stored RGBA8 texel at (x, y) after wrapping.
    pub fn texel(&self, x: i64, y: i64, wrap: [Wrap; 2]) -> [u8; 4] {
        let x = wrap_index(x, self.width, wrap[0]) as usize;
        let y = wrap_index(y, self.height, wrap[1]) as usize;
        let i = 4 * (y * self.width as usize + x);
        [
            self.texels[i],
            self.texels[i + 1],
            self.texels[i + 2],
            self.texels[i + 3],
        ]
    }

    /// True when every texel has R = G = B.
    pub fn is_grey(&self) -> bool {
        self.texels
            .chunks_exact(4)
            .all(|t| t[0] == t[1] && t[1] == t[2])
    }

    /// The mean linear RGB over the whole image.
    pub fn mean_linear_rgb(&self) -> [f32; 3] {
        let lut = srgb_table();
        let mut sum = [0.0f64; 3];
        for t in self.texels.chunks_exact(4) {
            for c in 0..3 {
                sum[c] += lut[t[c] as usize] as f64;
            }
        }
        let n = (self.width as f64) * (self.height as f64);
        sum.map(|s| (s / n) as f32)
    }
}

/// The value of a scalar channel of a stored texel, in [0, 1] (alpha and masks are linear).
pub fn channel_value(texel: [u8; 4], channel: Channel) -> f32 {
    let v = match channel {
        Channel::Red => texel[0] as f32,
        Channel::Green => texel[1] as f32,
        Channel::Blue => texel[2] as f32,
        Channel::Alpha => texel[3] as f32,
        Channel::Luminance => (texel[0] as f32 + texel[1] as f32 + texel[2] as f32) / 3.0,
    };
    v / 255.0
}
