//! Alpha masks in the tracer: a ray passes through a triangle where its material's mask cuts the
//! surface away, and stops where it is opaque (what an any-hit shader does on a GPU).
//!
//! Each masked material's mask is kept as one bit per texel (opaque or not, by the material's
//! [`AlphaMask`] rule, the same one the patches' coverage integrates in
//! [`crate::radiosity::patches::albedo`]). A hit on a masked triangle finds its barycentric
//! coordinates from the hit point, interpolates the triangle's image coordinates, and reads the
//! nearest texel. Triangles whose material is cut out everywhere (an alpha factor below the
//! cutoff with no texture) are left out of the tree altogether ([`Cutout::Everywhere`]).

use crate::scene::texture::{channel_value, wrap_index, AlphaMask, Channel, TextureRef, Wrap};
use crate::scene::Scene;
use glam::Vec3A;

/// How alpha affects one triangle.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Cutout {
    /// Opaque everywhere.
    Nowhere,
    /// Cut out everywhere: light passes as if it were not there.
    Everywhere,
    /// Cut out where its mask says so (index into [`AlphaMasks`]'s images).
    Masked(u32),
}

/// One mask as a bitmap of opaque texels.
struct MaskImage {
    width: u32,
    height: u32,
    wrap: [Wrap; 2],
    /// Bit `y·width + x` is set where the texel is opaque.
    opaque: Vec<u64>,
}

/// The masks of a scene's materials and how each triangle reads its mask.
pub struct AlphaMasks {
    /// Per material: how alpha affects its triangles.
    per_material: Vec<Cutout>,
    images: Vec<MaskImage>,
    /// Per material: the mask's texture reference (for its transform), when masked.
    refs: Vec<Option<TextureRef>>,
}

impl AlphaMasks {
    /// The masks of `scene`'s materials.
    pub fn new(scene: &Scene) -> Self {
        let mut images = Vec::new();
        let mut per_material = Vec::new();
        let mut refs = Vec::new();
        for m in &scene.materials {
            let (cut, r) = match &m.alpha {
                None => (Cutout::Nowhere, None),
                Some(a) => match &a.texture {
                    None if a.cuts(a.factor) => (Cutout::Everywhere, None),
                    None => (Cutout::Nowhere, None),
                    Some((r, channel)) => {
                        images.push(mask_image(scene, a, r, *channel));
                        (Cutout::Masked(images.len() as u32 - 1), Some(r.clone()))
                    }
                },
            };
            per_material.push(cut);
            refs.push(r);
        }
        AlphaMasks {
            per_material,
            images,
            refs,
        }
    }

    /// True when no material is masked (the tracer then skips every alpha test).
    pub fn is_empty(&self) -> bool {
        self.images.is_empty()
    }

    /// How alpha affects scene triangle `t`.
    pub fn cutout(&self, scene: &Scene, t: usize) -> Cutout {
        self.per_material
            .get(scene.triangle_material[t] as usize)
            .copied()
            .unwrap_or(Cutout::Nowhere)
    }

    /// The image coordinates of the corners of scene triangle `t` as its mask reads them.
    pub fn corner_uvs(&self, scene: &Scene, t: usize) -> [[f32; 2]; 3] {
        let r = self.refs[scene.triangle_material[t] as usize]
            .as_ref()
            .expect("a masked material has a mask reference");
        scene.triangles[t].map(|v| r.apply(scene.uvs[v as usize]))
    }

    /// True when mask `image` is opaque at image coordinates `uv` (nearest texel).
    pub fn opaque(&self, image: u32, uv: [f32; 2]) -> bool {
        let m = &self.images[image as usize];
        let x = (uv[0] as f64 * m.width as f64).floor() as i64;
        let y = (uv[1] as f64 * m.height as f64).floor() as i64;
        let x = wrap_index(x, m.width, m.wrap[0]) as usize;
        let y = wrap_index(y, m.height, m.wrap[1]) as usize;
        let bit = y * m.width as usize + x;
        m.opaque[bit / 64] >> (bit % 64) & 1 == 1
    }
}

fn mask_image(scene: &Scene, a: &AlphaMask, r: &TextureRef, channel: Channel) -> MaskImage {
    let tex = r.of(&scene.textures);
    let n = tex.width as usize * tex.height as usize;
    let mut opaque = vec![0u64; n.div_ceil(64)];
    for (i, t) in tex.texels.chunks_exact(4).enumerate() {
        if !a.cuts(a.factor * channel_value([t[0], t[1], t[2], t[3]], channel)) {
            opaque[i / 64] |= 1 << (i % 64);
        }
    }
    MaskImage {
        width: tex.width,
        height: tex.height,
        wrap: r.wrap,
        opaque,
    }
}

/// A masked triangle as the tracer keeps it: its mask and its corners' image coordinates.
#[derive(Clone, Copy, Debug)]
pub struct MaskedTriangle {
    pub image: u32,
    pub uv: [[f32; 2]; 3],
}

impl MaskedTriangle {
    /// True when the point `p` of triangle `v` (the point a ray hit) is opaque.
    pub fn opaque_at(&self, masks: &AlphaMasks, v: &[Vec3A; 3], p: Vec3A) -> bool {
        let [b0, b1, b2] = barycentric(v, p);
        let uv = [0, 1].map(|k| b0 * self.uv[0][k] + b1 * self.uv[1][k] + b2 * self.uv[2][k]);
        masks.opaque(self.image, uv)
    }
}

/// Barycentric coordinates of `p` (in the plane of `v`, within rounding) in triangle `v`.
fn barycentric(v: &[Vec3A; 3], p: Vec3A) -> [f32; 3] {
    let (e0, e1, e2) = (v[1] - v[0], v[2] - v[0], p - v[0]);
    let (d00, d01, d11) = (e0.dot(e0), e0.dot(e1), e1.dot(e1));
    let (d20, d21) = (e2.dot(e0), e2.dot(e1));
    let denom = d00 * d11 - d01 * d01;
    let b1 = (d11 * d20 - d01 * d21) / denom;
    let b2 = (d00 * d21 - d01 * d20) / denom;
    [1.0 - b1 - b2, b1, b2]
}
