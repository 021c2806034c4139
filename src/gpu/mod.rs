//! wgpu device, shader loading and readback. Every WGSL kernel in `shaders/` has a Rust twin in
//! the library that tests compare it with (on Mesa's lavapipe in CI).
//!
//! Shaders share types through `shaders/common.wgsl`, which is prepended to every kernel's source
//! (WGSL has no includes); [`shader_source`] does the concatenation for the device and the naga
//! validation test alike.

pub mod atmosphere;
pub mod blit;
pub mod compressed_gather;
pub mod compute;
pub mod exposure;
pub mod freeform_caster;
pub mod freeform_shader;
pub mod mesh_materials;
pub mod mesh_renderer;
pub mod radiosity_runtime;
pub mod readback;
pub mod render_target;
pub mod terrain_air;
mod terrain_buffers;
mod terrain_pipelines;
pub mod terrain_renderer;
pub mod themes;
pub mod timing;

use crate::error::{Error, Result};
use serde::Serialize;

/// A GPU device with its queue and what the adapter offers.
pub struct Gpu {
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub adapter: wgpu::Adapter,
    pub info: AdapterReport,
}

/// What relume reports about the adapter it uses.
#[derive(Clone, Debug, Serialize)]
pub struct AdapterReport {
    pub name: String,
    pub backend: String,
    pub device_type: String,
    pub driver: String,
    /// Hardware BC1..BC7 texture sampling is available.
    pub bc_textures: bool,
    /// GPU timestamp queries are available (per-pass GPU times in frames.json).
    pub timestamps: bool,
    pub max_texture_dimension_2d: u32,
    pub max_storage_buffer_binding_size: u64,
}

/// Which graphics API to use.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, serde::Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum BackendChoice {
    Vulkan,
    Gl,
    Metal,
    Dx12,
}

impl BackendChoice {
    fn backends(self) -> wgpu::Backends {
        match self {
            BackendChoice::Vulkan => wgpu::Backends::VULKAN,
            BackendChoice::Gl => wgpu::Backends::GL,
            BackendChoice::Metal => wgpu::Backends::METAL,
            BackendChoice::Dx12 => wgpu::Backends::DX12,
        }
    }
}

/// The fix to suggest when no adapter exists.
pub const NO_ADAPTER_HINT: &str =
    "no GPU adapter found. On Debian/Ubuntu install the software Vulkan driver: \
     `sudo apt-get install mesa-vulkan-drivers libvulkan1` (or `make deps`); \
     or try `--backend gl` with `libegl1 libegl-mesa0 libgl1-mesa-dri`";

/// The instance every window and headless device is made from: `backend`, else `WGPU_BACKEND`
/// from the environment, else Vulkan then GL.
pub fn instance_descriptor(backend: Option<BackendChoice>) -> wgpu::InstanceDescriptor {
    let mut desc = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
    match backend {
        Some(b) => desc.backends = b.backends(),
        None if std::env::var_os("WGPU_BACKEND").is_none() => {
            desc.backends = wgpu::Backends::VULKAN | wgpu::Backends::GL
        }
        None => {}
    }
    desc
}

impl Gpu {
    /// Open a device. `backend` None means `WGPU_BACKEND` from the environment, else Vulkan
    /// then GL. Requests BC textures and timestamp queries when the adapter has them.
    pub fn new(backend: Option<BackendChoice>) -> Result<Gpu> {
        let desc = instance_descriptor(backend);
        let instance = wgpu::Instance::new(desc);
        Self::from_instance(&instance, None)
    }

    /// Open a device on `instance`, compatible with `surface` when given.
    pub fn from_instance(
        instance: &wgpu::Instance,
        surface: Option<&wgpu::Surface<'_>>,
    ) -> Result<Gpu> {
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            force_fallback_adapter: false,
            compatible_surface: surface,
            ..Default::default()
        }))
        .map_err(|e| Error::Gpu(format!("{NO_ADAPTER_HINT} ({e})")))?;
        let offered = adapter.features();
        let wanted = wgpu::Features::TEXTURE_COMPRESSION_BC | wgpu::Features::TIMESTAMP_QUERY;
        let required_features = offered & wanted;
        let alimits = adapter.limits();
        let required_limits = wgpu::Limits {
            max_storage_buffer_binding_size: alimits.max_storage_buffer_binding_size,
            max_buffer_size: alimits.max_buffer_size,
            max_texture_dimension_2d: alimits.max_texture_dimension_2d,
            max_compute_workgroup_storage_size: alimits.max_compute_workgroup_storage_size,
            max_storage_buffers_per_shader_stage: alimits
                .max_storage_buffers_per_shader_stage
                .min(16),
            ..wgpu::Limits::downlevel_defaults().using_resolution(alimits.clone())
        };
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("relume"),
            required_features,
            required_limits,
            ..Default::default()
        }))
        .map_err(|e| Error::Gpu(format!("the adapter refused a device: {e}")))?;
        let ai = adapter.get_info();
        let limits = device.limits();
        let info = AdapterReport {
            name: ai.name.clone(),
            backend: format!("{:?}", ai.backend),
            device_type: format!("{:?}", ai.device_type),
            driver: format!("{} {}", ai.driver, ai.driver_info),
            bc_textures: required_features.contains(wgpu::Features::TEXTURE_COMPRESSION_BC),
            timestamps: required_features.contains(wgpu::Features::TIMESTAMP_QUERY),
            max_texture_dimension_2d: limits.max_texture_dimension_2d,
            max_storage_buffer_binding_size: limits.max_storage_buffer_binding_size,
        };
        Ok(Gpu {
            device,
            queue,
            adapter,
            info,
        })
    }

    /// Compile a kernel from `shaders/` (with `common.wgsl` prepended), turning validation
    /// errors into [`Error::Internal`] instead of a panic.
    pub fn shader(&self, name: &str) -> Result<wgpu::ShaderModule> {
        let source = shader_source(name)?;
        let scope = self.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let module = self
            .device
            .create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some(name),
                source: wgpu::ShaderSource::Wgsl(source.into()),
            });
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(Error::Internal(format!("shader {name}: {e}")));
        }
        Ok(module)
    }

    /// Wait for all submitted work.
    pub fn wait(&self) {
        let _ = self.device.poll(wgpu::PollType::wait_indefinitely());
    }
}

/// The WGSL files of `shaders/`, by file name, embedded at compile time.
/// Embed `shaders/NAME` for each name.
macro_rules! shaders {
    ($($name:literal),* $(,)?) => { &[$(($name, include_str!(concat!("../../shaders/", $name)))),*] };
}

pub const SHADERS: &[(&str, &str)] = shaders![
    "atmosphere.wgsl",
    "atmosphere_common.wgsl",
    "atmosphere_kernel.wgsl",
    "atmosphere_lookup.wgsl",
    "blit.wgsl",
    "common.wgsl",
    "corner_interpolate.wgsl",
    "direct_light.wgsl",
    "exposure_histogram.wgsl",
    "freeform.wgsl",
    "freeform_affine.wgsl",
    "freeform_shade.wgsl",
    "freeform_texture.wgsl",
    "gather_compressed.wgsl",
    "gather_dense.wgsl",
    "lighting.wgsl",
    "material.wgsl",
    "mesh_shade.wgsl",
    "shadow_depth.wgsl",
    "shadow_masked.wgsl",
    "terrain_mask.wgsl",
    "terrain_render.wgsl",
    "terrain_shadow.wgsl",
    "theme.wgsl",
    "theme_kernel.wgsl",
    "tonemap_test.wgsl",
];

fn raw_source(name: &str) -> Result<(&'static str, &'static str)> {
    SHADERS
        .iter()
        .find(|(n, _)| *n == name)
        .copied()
        .ok_or_else(|| Error::Internal(format!("no shader named {name}")))
}

/// Full source of a kernel: `common.wgsl`, then every file named by a `//! include NAME` line
/// (in order, each once; an included file's own includes come before it, depth first), then
/// the kernel itself.
pub fn shader_source(name: &str) -> Result<String> {
    let (_, common) = raw_source("common.wgsl")?;
    if name == "common.wgsl" {
        return Ok(common.to_string());
    }
    let (kernel, body) = raw_source(name)?;
    let mut out = String::from(common);
    let mut included = vec!["common.wgsl", kernel];
    include_all(body, &mut included, &mut out)?;
    out.push_str(&format!("\n// ---- {name}\n{body}"));
    Ok(out)
}

/// Append the files `body` includes (and theirs, first) that are not in `included` yet.
fn include_all(body: &str, included: &mut Vec<&'static str>, out: &mut String) -> Result<()> {
    for line in body.lines() {
        if let Some(inc) = line.trim().strip_prefix("//! include ") {
            let (inc_name, inc_body) = raw_source(inc.trim())?;
            if !included.contains(&inc_name) {
                included.push(inc_name);
                include_all(inc_body, included, out)?;
                out.push_str(&format!("\n// ---- {inc_name}\n{inc_body}"));
            }
        }
    }
    Ok(())
}
