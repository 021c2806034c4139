//! egui in the player's window: winit events in (`egui-winit`), the panel drawn over the
//! presented frame (`egui-wgpu`), one render pass that loads what the blit drew.

use crate::gpu::Gpu;
use std::sync::Arc;
use winit::window::Window;

/// egui's input state and renderer for one window.
pub struct Layer {
    pub ctx: egui::Context,
    state: egui_winit::State,
    renderer: egui_wgpu::Renderer,
    /// Events to add to the next frame's input (scripted input, [`super::script`]).
    pub injected: Vec<egui::Event>,
}

impl Layer {
    pub fn new(gpu: &Gpu, window: &Arc<Window>, format: wgpu::TextureFormat) -> Layer {
        let ctx = egui::Context::default();
        let state = egui_winit::State::new(
            ctx.clone(),
            egui::ViewportId::ROOT,
            window.as_ref(),
            Some(window.scale_factor() as f32),
            None,
            Some(gpu.device.limits().max_texture_dimension_2d as usize),
        );
        let renderer = egui_wgpu::Renderer::new(&gpu.device, format, Default::default());
        Layer {
            ctx,
            state,
            renderer,
            injected: Vec::new(),
        }
    }

    /// Give egui a window event; true when egui used it (the window then ignores it).
    pub fn on_event(&mut self, window: &Window, event: &winit::event::WindowEvent) -> bool {
        self.state.on_window_event(window, event).consumed
    }

    /// Run `ui` for this frame and draw its output over `view` (the window's surface texture,
    /// already holding the frame).
    pub fn draw(
        &mut self,
        gpu: &Gpu,
        window: &Window,
        view: &wgpu::TextureView,
        size: [u32; 2],
        ui: impl FnMut(&mut egui::Ui),
    ) {
        let mut input = self.state.take_egui_input(window);
        input.events.append(&mut self.injected);
        let out = self.ctx.run_ui(input, ui);
        self.state
            .handle_platform_output(window, out.platform_output);
        let jobs = self.ctx.tessellate(out.shapes, out.pixels_per_point);
        for (id, deltas) in &out.textures_delta.set {
            for delta in deltas {
                self.renderer
                    .update_texture(&gpu.device, &gpu.queue, *id, delta);
            }
        }
        let screen = egui_wgpu::ScreenDescriptor {
            size_in_pixels: size,
            pixels_per_point: out.pixels_per_point,
        };
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        let extra = self
            .renderer
            .update_buffers(&gpu.device, &gpu.queue, &mut enc, &jobs, &screen);
        {
            let pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("panel"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view,
                    resolve_target: None,
                    depth_slice: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Load,
                        store: wgpu::StoreOp::Store,
                    },
                })],
                ..Default::default()
            });
            self.renderer
                .render(&mut pass.forget_lifetime(), &jobs, &screen);
        }
        gpu.queue
            .submit(extra.into_iter().chain(std::iter::once(enc.finish())));
        for id in &out.textures_delta.free {
            self.renderer.free_texture(id);
        }
    }
}
