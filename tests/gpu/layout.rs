//! The memory layout of every struct Rust and WGSL share, against naga's layouter (no GPU).

use relume::gpu::mesh_renderer::LightsUniform;
use relume::gpu::shader_source;
use relume::render::lights::GpuLight;

// 5. Struct layouts shared by Rust and WGSL, against naga's layouter

/// A Rust type written into a WGSL struct: members (WGSL name, Rust byte offset, byte size).
struct Shared {
    shader: &'static str,
    wgsl: &'static str,
    rust: &'static str,
    size: usize,
    members: Vec<(&'static str, usize, usize)>,
}

/// (offset, size) of a Rust field.
macro_rules! field {
    ($t:ty, $f:ident) => {{
        let z: $t = bytemuck::Zeroable::zeroed();
        (std::mem::offset_of!($t, $f), std::mem::size_of_val(&z.$f))
    }};
}

/// (offset, size) of element `k` of a Rust padding array of u32.
macro_rules! pad {
    ($t:ty, $f:ident, $k:expr) => {{
        let z: $t = bytemuck::Zeroable::zeroed();
        assert_eq!(std::mem::size_of_val(&z.$f[0]), 4);
        assert!($k < z.$f.len());
        (std::mem::offset_of!($t, $f) + 4 * $k, 4)
    }};
}

macro_rules! shared {
    ($shader:literal, $wgsl:literal, $t:ty { $($m:literal : $v:expr),* $(,)? }) => {
        Shared {
            shader: $shader,
            wgsl: $wgsl,
            rust: stringify!($t),
            size: std::mem::size_of::<$t>(),
            members: vec![$({ let (o, s) = $v; ($m, o, s) }),*],
        }
    };
}

/// A uniform the driver writes as a plain `[u32; N]` (floats as their bits), member by member.
fn words(shader: &'static str, wgsl: &'static str, names: &[&'static str]) -> Shared {
    Shared {
        shader,
        wgsl,
        rust: "[u32; N]",
        size: 4 * names.len(),
        members: names
            .iter()
            .enumerate()
            .map(|(i, n)| (*n, 4 * i, 4))
            .collect(),
    }
}

fn shared_structs() -> Vec<Shared> {
    use relume::atmosphere::twin::AtmosphereGpu;
    use relume::freeform::twin::{GpuBump, GpuLeaf};
    use relume::gpu::compressed_gather::Params as GatherParams;
    use relume::gpu::freeform_caster::FrameU as FreeformFrame;
    use relume::gpu::freeform_shader::ShadeFrameU;
    use relume::gpu::mesh_materials::MaterialUniform;
    use relume::gpu::mesh_renderer::FrameUniform;
    use relume::gpu::terrain_renderer::{TerrainFrame, TerrainParams};
    use relume::gpu::themes::ThemeParams;
    vec![
        shared!("atmosphere_common.wgsl", "AtmosphereParams", AtmosphereGpu {
            "rayleigh": field!(AtmosphereGpu, rayleigh),
            "mie_scattering": field!(AtmosphereGpu, mie_scattering),
            "mie_extinction": field!(AtmosphereGpu, mie_extinction),
            "ozone": field!(AtmosphereGpu, ozone),
            "ground_albedo": field!(AtmosphereGpu, ground_albedo),
            "sun_illuminance": field!(AtmosphereGpu, sun_illuminance),
            "radii": field!(AtmosphereGpu, radii),
            "sun": field!(AtmosphereGpu, sun),
        }),
        shared!("lighting.wgsl", "GpuLight", GpuLight {
            "position": field!(GpuLight, position),
            "direction": field!(GpuLight, direction),
            "radiance": field!(GpuLight, radiance),
            "params": field!(GpuLight, params),
        }),
        shared!("lighting.wgsl", "Lights", LightsUniform {
            "count": field!(LightsUniform, count),
            "shadow_bias": field!(LightsUniform, shadow_bias),
            "_pad0": pad!(LightsUniform, pad, 0),
            "_pad1": pad!(LightsUniform, pad, 1),
            "lights": field!(LightsUniform, lights),
            "layer_view_proj": field!(LightsUniform, layer_view_proj),
        }),
        shared!("mesh_shade.wgsl", "Frame", FrameUniform {
            "view_proj": field!(FrameUniform, view_proj),
            "eye": field!(FrameUniform, eye),
            "exposure": field!(FrameUniform, exposure),
            "emission_scale": field!(FrameUniform, emission_scale),
            "flags": field!(FrameUniform, flags),
            "_pad": field!(FrameUniform, pad),
        }),
        shared!("material.wgsl", "Material", MaterialUniform {
            "albedo_u": field!(MaterialUniform, albedo_u),
            "albedo_v": field!(MaterialUniform, albedo_v),
            "mask_u": field!(MaterialUniform, mask_u),
            "mask_v": field!(MaterialUniform, mask_v),
            "factor": field!(MaterialUniform, factor),
            "flags": field!(MaterialUniform, flags),
        }),
        shared!("gather_compressed.wgsl", "GatherParams", GatherParams {
            "n": field!(GatherParams, n),
            "padded": field!(GatherParams, padded),
            "channels": field!(GatherParams, channels),
            "encoding": field!(GatherParams, encoding),
            "hardware": field!(GatherParams, hardware),
            "layer_words": field!(GatherParams, layer_words),
            "log_range": field!(GatherParams, log_range),
            "_pad": field!(GatherParams, pad),
            "scale": field!(GatherParams, scale),
            "lut": field!(GatherParams, lut),
        }),
        shared!("freeform.wgsl", "Frame", FreeformFrame {
            "forward": field!(FreeformFrame, forward),
            "right": field!(FreeformFrame, right),
            "up": field!(FreeformFrame, up),
            "depth": field!(FreeformFrame, depth),
            "size": field!(FreeformFrame, size),
            "level": field!(FreeformFrame, level),
            "sun": field!(FreeformFrame, sun),
        }),
        shared!("freeform_shade.wgsl", "ShadeFrame", ShadeFrameU {
            "forward": field!(ShadeFrameU, forward),
            "right": field!(ShadeFrameU, right),
            "up": field!(ShadeFrameU, up),
            "sun": field!(ShadeFrameU, sun),
            "background": field!(ShadeFrameU, background),
            "size": field!(ShadeFrameU, size),
            "eye": field!(ShadeFrameU, eye),
            "projection": field!(ShadeFrameU, projection),
            "air": field!(ShadeFrameU, air),
            "air_scale": field!(ShadeFrameU, air_scale),
            "sun_light": field!(ShadeFrameU, sun_light),
            "fog_ext": field!(ShadeFrameU, fog_ext),
            "fog_rayleigh": field!(ShadeFrameU, fog_rayleigh),
            "fog_mie": field!(ShadeFrameU, fog_mie),
            "fog_sun": field!(ShadeFrameU, fog_sun),
        }),
        shared!("freeform.wgsl", "Leaf", GpuLeaf {
            "base": field!(GpuLeaf, base),
            "range": field!(GpuLeaf, range),
            "material": field!(GpuLeaf, material),
        }),
        shared!("freeform.wgsl", "Bump", GpuBump {
            "q": field!(GpuBump, q),
            "lo_weight": field!(GpuBump, lo_weight),
            "hi_flag": field!(GpuBump, hi_flag),
        }),
        shared!("terrain_render.wgsl", "TerrainFrame", TerrainFrame {
            "view_proj": field!(TerrainFrame, view_proj),
            "inv_view_proj": field!(TerrainFrame, inv_view_proj),
            "eye": field!(TerrainFrame, eye),
            "sun": field!(TerrainFrame, sun),
            "cell": field!(TerrainFrame, cell),
            "sun_light": field!(TerrainFrame, sun_light),
            "fog_ext": field!(TerrainFrame, fog_ext),
            "fog_rayleigh": field!(TerrainFrame, fog_rayleigh),
            "fog_mie": field!(TerrainFrame, fog_mie),
            "fog_sun": field!(TerrainFrame, fog_sun),
            "exposure": field!(TerrainFrame, exposure),
            "flags": field!(TerrainFrame, flags),
            "min_height": field!(TerrainFrame, min_height),
            "max_height_tint": field!(TerrainFrame, max_height_tint),
            "model": field!(TerrainFrame, model),
            "pad0": pad!(TerrainFrame, pad, 0),
            "pad1": pad!(TerrainFrame, pad, 1),
            "pad2": pad!(TerrainFrame, pad, 2),
        }),
        shared!("theme.wgsl", "ThemeParams", ThemeParams {
            "words_at": field!(ThemeParams, words_at),
            "exceptions_at": field!(ThemeParams, exceptions_at),
            "textures_at": field!(ThemeParams, textures_at),
            "noise_at": field!(ThemeParams, noise_at),
            "lut_at": field!(ThemeParams, lut_at),
            "classes_at": field!(ThemeParams, classes_at),
            "levels_at": field!(ThemeParams, levels_at),
            "index_levels": field!(ThemeParams, index_levels),
            "tex_size": field!(ThemeParams, tex_size),
            "tex_levels": field!(ThemeParams, tex_levels),
            "per_theme": field!(ThemeParams, per_theme),
            "noise_size": field!(ThemeParams, noise_size),
            "shift": field!(ThemeParams, shift),
            "index_size": field!(ThemeParams, index_size),
        }),
        shared!("terrain_shadow.wgsl", "TerrainParams", TerrainParams {
            "width": field!(TerrainParams, width),
            "height": field!(TerrainParams, height),
            "levels": field!(TerrainParams, levels),
            "kind": field!(TerrainParams, kind),
            "step_x": field!(TerrainParams, step_x),
            "step_y": field!(TerrainParams, step_y),
            "_pad0": pad!(TerrainParams, pad0, 0),
            "_pad1": pad!(TerrainParams, pad0, 1),
            "ux": field!(TerrainParams, ux),
            "uy": field!(TerrainParams, uy),
            "inv_ux": field!(TerrainParams, inv_ux),
            "inv_uy": field!(TerrainParams, inv_uy),
            "rise_per_t": field!(TerrainParams, rise_per_t),
            "max_height": field!(TerrainParams, max_height),
            "min_height": field!(TerrainParams, min_height),
            "metres_per_t": field!(TerrainParams, metres_per_t),
            "alpha": field!(TerrainParams, alpha),
            "planet_radius": field!(TerrainParams, planet_radius),
            "sin_elevation0": field!(TerrainParams, sin_elevation0),
            "cos_elevation0": field!(TerrainParams, cos_elevation0),
            "sin_azimuth": field!(TerrainParams, sin_azimuth),
            "cos_azimuth": field!(TerrainParams, cos_azimuth),
            "cell_x": field!(TerrainParams, cell_x),
            "cell_y": field!(TerrainParams, cell_y),
            "tan_alpha": field!(TerrainParams, tan_alpha),
            "horizon_w": field!(TerrainParams, horizon_w),
            "elevation_deg": field!(TerrainParams, elevation_deg),
            "has_horizon": field!(TerrainParams, has_horizon),
        }),
        // Written as words by RadiosityRuntime, the dense gather, the corner transfer, the
        // terrain mask pass and the tone-map test.
        words(
            "direct_light.wgsl",
            "DirectParams",
            &["patches", "samples_per_patch", "emission_scale", "flags"],
        ),
        words(
            "gather_dense.wgsl",
            "GatherParams",
            &["n", "channel", "_pad0", "_pad1"],
        ),
        words(
            "corner_interpolate.wgsl",
            "TransferParams",
            &["corners", "_pad0", "_pad1", "_pad2"],
        ),
        words(
            "terrain_mask.wgsl",
            "MaskParams",
            &["method", "_pad0", "_pad1", "_pad2"],
        ),
        words("tonemap_test.wgsl", "Params", &["count", "exposure"]),
    ]
}

#[test]
fn shared_structs_have_the_layout_naga_computes() {
    let table = shared_structs();
    let mut checked = 0;
    for (shader, _) in relume::gpu::SHADERS {
        let src = shader_source(shader).unwrap();
        let module = naga::front::wgsl::parse_str(&src)
            .unwrap_or_else(|e| panic!("{shader}: {}", e.emit_to_string(&src)));
        let mut layouter = naga::proc::Layouter::default();
        layouter.update(module.to_ctx()).unwrap();
        // Every struct a uniform or storage binding holds (itself or as array elements) must
        // be in the table, except those only the GPU writes and reads.
        let mut bound = Vec::new();
        for (_, var) in module.global_variables.iter() {
            if !matches!(
                var.space,
                naga::AddressSpace::Uniform | naga::AddressSpace::Storage { .. }
            ) {
                continue;
            }
            let mut ty = var.ty;
            if let naga::TypeInner::Array { base, .. } = module.types[ty].inner {
                ty = base;
            }
            if let naga::TypeInner::Struct { .. } = module.types[ty].inner {
                bound.push(module.types[ty].name.clone().unwrap());
            }
        }
        for name in &bound {
            assert!(
                table.iter().any(|s| s.wgsl == name
                    && (s.shader == *shader
                        || shader_source(shader)
                            .unwrap()
                            .contains(&format!("// ---- {}", s.shader)))),
                "{shader}: struct {name} is bound but has no Rust counterpart in the layout table"
            );
        }
        for s in table.iter().filter(|s| s.shader == *shader) {
            let (handle, ty) = module
                .types
                .iter()
                .find(|(_, t)| t.name.as_deref() == Some(s.wgsl))
                .unwrap_or_else(|| panic!("{shader} has no struct {}", s.wgsl));
            let naga::TypeInner::Struct { members, .. } = &ty.inner else {
                panic!("{shader}: {} is not a struct", s.wgsl)
            };
            assert_eq!(
                layouter[handle].size as usize, s.size,
                "{shader}: size of {} (WGSL) vs {} (Rust)",
                s.wgsl, s.rust
            );
            let wgsl: Vec<(&str, usize, usize)> = members
                .iter()
                .map(|m| {
                    (
                        m.name.as_deref().unwrap(),
                        m.offset as usize,
                        layouter[m.ty].size as usize,
                    )
                })
                .collect();
            assert_eq!(
                wgsl, s.members,
                "{shader}: members (name, offset, size) of {} (WGSL, left) vs {} (Rust, right)",
                s.wgsl, s.rust
            );
            checked += 1;
        }
    }
    assert_eq!(checked, table.len(), "a table entry names a missing shader");
    eprintln!("{checked} shared structs match naga's layout");
}
