//! Mesh scenes at runtime: punctual lights with shadow maps, emitters, and (when the bake has a
//! radiosity transfer) indirect light gathered on the GPU.

use super::Sun;
use super::{PlayerOptions, TransportChoice};
use crate::baked::{self, Manifest};
use crate::error::Result;
use crate::gpu::compressed_gather::DecodePath;
use crate::gpu::mesh_renderer::MeshRenderer;
use crate::gpu::radiosity_runtime::{RadiosityRuntime, TransportSource};
use crate::gpu::timing::PassTimer;
use crate::gpu::Gpu;
use crate::radiosity::mesh::display::display_mesh_of;
use crate::radiosity::PatchSet;
use crate::render::camera::Camera;
use crate::render::lights::GpuLight;
use crate::render::mesh_reference::FrameSettings;
use crate::scene::{Light, Scene};
use std::path::Path;

/// A loaded mesh bake.
pub struct MeshPlayer {
    pub scene: Scene,
    pub renderer: MeshRenderer,
    /// Lights of the scene file and `--light`, each with whether it is on (the window's panel
    /// edits them).
    pub lights: Vec<(Light, bool)>,
    /// The sun, when set.
    pub sun: Option<GpuLight>,
    /// The baked light transfer, when the bake has one.
    pub radiosity: Option<(PatchSet, RadiosityRuntime)>,
    /// The source file's cameras (glTF camera nodes).
    pub views: Vec<crate::scene::Viewpoint>,
}

/// Shadow-map resolution.
pub const SHADOW_SIZE: u32 = 2048;

impl MeshPlayer {
    /// Load a scene bake.
    pub fn load(
        gpu: &Gpu,
        dir: &Path,
        manifest: &Manifest,
        opts: &PlayerOptions,
        width: u32,
        height: u32,
    ) -> Result<Self> {
        let scene = baked::scene::read(dir)?;
        let views = if manifest.file(baked::scene::VIEWS_FILE).is_some() {
            baked::scene::read_views(dir)?
        } else {
            Vec::new()
        };
        let has_transport = manifest.file(baked::encoded::TRANSFER_FILE).is_some()
            || manifest.file(baked::transport::FILE).is_some();
        // With baked light, draw the display mesh: triangles split to 1.5 voxels so that the
        // per-vertex indirect light can follow the patches (radiosity::mesh::display).
        let (scene, set) = if has_transport {
            let mut set = baked::patches::read(dir)?;
            if set.corners.len() != 3 * scene.triangles.len() {
                return Err(super::mixed_bakes(
                    dir,
                    baked::patches::FILE,
                    format!("covers {} mesh corners", set.corners.len()),
                    format!("{} has {}", baked::scene::FILE, 3 * scene.triangles.len()),
                ));
            }
            let (display, corners) = display_mesh_of(&scene, &set);
            set.corners = corners;
            (display, Some(set))
        } else {
            (scene, None)
        };
        let renderer = MeshRenderer::new(gpu, &scene, width, height, SHADOW_SIZE)?;
        let lights = scene.lights.iter().map(|l| (l.clone(), true)).collect();
        let radiosity = match set {
            Some(set) => Some(load_radiosity(gpu, dir, manifest, opts, &renderer, set)?),
            None => None,
        };
        let mut p = MeshPlayer {
            scene,
            renderer,
            lights,
            sun: None,
            radiosity,
            views,
        };
        p.upload_lights(gpu)?;
        Ok(p)
    }

    /// The first view: the source file's first camera when it has one, else
    /// [`crate::render::first_view`] (the framing from the front when it sees into the scene,
    /// else a viewpoint inside it).
    pub fn default_camera(&self) -> Camera {
        match self.views.first() {
            Some(v) => {
                let (lo, hi) = self.scene.bounds();
                let radius = (hi - lo).length().max(1e-6);
                let eye = glam::Vec3::from(v.eye);
                Camera {
                    eye,
                    target: v.target.into(),
                    up: v.up.into(),
                    fov_y_deg: v.fov_y_deg,
                    near: (radius * 1e-3).max(1e-6),
                    far: (eye - (lo + hi) * 0.5).length() + 2.0 * radius,
                }
            }
            None => crate::render::first_view::first_view(&self.scene).0,
        }
    }

    /// Set or clear the sun (a white directional light of 3 W/m² irradiance... scaled by the
    /// scene's size-independent units: irradiance is per square metre of scene unit).
    pub fn set_sun(&mut self, gpu: &Gpu, sun: Option<Sun>) -> Result<()> {
        self.sun = sun.map(|s| GpuLight::from_light(&crate::render::lights::sun_light(&s), 1.0, 0));
        self.upload_lights(gpu)
    }

    /// Add punctual lights to the scene's own (on).
    pub fn add_lights(&mut self, gpu: &Gpu, lights: &[Light]) -> Result<()> {
        self.lights.extend(lights.iter().map(|l| (l.clone(), true)));
        self.upload_lights(gpu)
    }

    /// Replace the punctual lights (each with whether it is on); the indirect light follows.
    pub fn set_lights(&mut self, gpu: &Gpu, lights: &[(Light, bool)]) -> Result<()> {
        self.lights = lights.to_vec();
        self.upload_lights(gpu)
    }

    fn upload_lights(&mut self, gpu: &Gpu) -> Result<()> {
        let mut all: Vec<GpuLight> = self
            .lights
            .iter()
            .filter(|(_, on)| *on)
            .map(|(l, _)| GpuLight::from_light(l, 1.0, 0))
            .collect();
        all.extend(self.sun);
        self.renderer.set_lights(gpu, &all)
    }

    /// Record and submit one frame.
    pub fn render(
        &mut self,
        gpu: &Gpu,
        camera: &Camera,
        s: &FrameSettings,
        timer: &mut PassTimer,
    ) -> Result<()> {
        timer.reset();
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        if s.direct && s.shadows {
            self.renderer.record_shadows(&mut enc, timer);
        }
        if let Some((set, rt)) = &self.radiosity {
            rt.record(
                gpu,
                &mut enc,
                &self.renderer,
                s,
                set.samples_per_patch,
                timer,
            );
        }
        self.renderer.record_shade(gpu, &mut enc, camera, s, timer);
        timer.resolve(&mut enc);
        gpu.queue.submit([enc.finish()]);
        gpu.wait();
        Ok(())
    }
}

/// The bake's light transfer on the GPU for the patches `set` (its corners those of the
/// renderer's mesh): the compressed transport when the bake has one (unless `opts` asks for the
/// dense reference), else the dense `transport.npy`.
fn load_radiosity(
    gpu: &Gpu,
    dir: &Path,
    manifest: &Manifest,
    opts: &PlayerOptions,
    renderer: &MeshRenderer,
    set: PatchSet,
) -> Result<(PatchSet, RadiosityRuntime)> {
    let has_encoded = manifest.file(baked::encoded::TRANSFER_FILE).is_some();
    let has_dense = manifest.file(baked::transport::FILE).is_some();
    let patches = set.patches.len();
    let same_patches = |file: &str, n: usize| {
        if n == patches {
            Ok(())
        } else {
            Err(super::mixed_bakes(
                dir,
                file,
                format!("holds a transport of {n} patches"),
                format!("{} has {patches}", baked::patches::FILE),
            ))
        }
    };
    let use_dense = match opts.transport {
        TransportChoice::Dense => true,
        TransportChoice::Compressed => false,
        TransportChoice::Auto => !has_encoded,
    };
    let rt = if use_dense {
        if !has_dense {
            return Err(crate::error::Error::input(
                dir,
                "this bake has no transport.npy (it was encoded only); drop --transport dense",
            ));
        }
        let matrix = baked::transport::read(dir)?;
        same_patches(baked::transport::FILE, matrix.n)?;
        RadiosityRuntime::new(gpu, &set, TransportSource::Dense(&matrix), renderer)?
    } else {
        if !has_encoded {
            return Err(crate::error::Error::input(
                dir,
                "this bake has no encoded transport (run the `encode` stage)",
            ));
        }
        let encoded = baked::encoded::read(dir)?;
        same_patches(baked::encoded::SIDECAR_FILE, encoded.dense.n)?;
        let path = opts
            .decode
            .unwrap_or_else(|| DecodePath::best(gpu, encoded.dense.encoding));
        RadiosityRuntime::new(
            gpu,
            &set,
            TransportSource::Compressed(&encoded, path),
            renderer,
        )?
    };
    Ok((set, rt))
}
