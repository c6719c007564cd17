//! Headless rendering: draws frames into an offscreen texture and reads them back as RGBA
//! images (8-bit sRGB), for PNG/GIF/MP4 export and tests.

use image::RgbaImage;

use super::compose::FrameDraw;
use super::gpu::{msaa_samples, Attachments, Gpu, SceneRenderer};
use super::RenderError;

/// Colour format of offscreen frames (sRGB-encoded 8-bit RGBA, what PNG/GIF expect).
pub const OFFSCREEN_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;
/// Largest accepted frame side, pixels.
pub const MAX_SIDE: u32 = 8192;

/// Renders [`FrameDraw`]s of one size to images, without a window.
pub struct OffscreenRenderer {
    gpu: Gpu,
    renderer: SceneRenderer,
    attachments: Attachments,
    resolve: wgpu::Texture,
    resolve_view: wgpu::TextureView,
    readback: wgpu::Buffer,
    padded_row: u32,
    width: u32,
    height: u32,
}

impl OffscreenRenderer {
    /// Opens the GPU (lavapipe when there is no other) and allocates `width` × `height` targets.
    pub fn new(width: u32, height: u32) -> Result<Self, RenderError> {
        Self::with_gpu(Gpu::headless()?, width, height)
    }

    /// Like [`OffscreenRenderer::new`] on an already opened GPU.
    pub fn with_gpu(gpu: Gpu, width: u32, height: u32) -> Result<Self, RenderError> {
        let limit = gpu.device.limits().max_texture_dimension_2d.min(MAX_SIDE);
        if width == 0 || height == 0 || width > limit || height > limit {
            return Err(RenderError::BadSize {
                width,
                height,
                max: limit,
            });
        }
        let samples = msaa_samples(&gpu.adapter, width, height);
        let renderer = SceneRenderer::new(&gpu.device, OFFSCREEN_FORMAT, samples);
        let attachments = Attachments::new(&gpu.device, width, height, OFFSCREEN_FORMAT, samples);
        let resolve = gpu.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("resolved frame"),
            size: wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: OFFSCREEN_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let resolve_view = resolve.create_view(&Default::default());
        let align = wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
        let padded_row = (width * 4).div_ceil(align) * align;
        let readback = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("readback"),
            size: u64::from(padded_row) * u64::from(height),
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Ok(OffscreenRenderer {
            gpu,
            renderer,
            attachments,
            resolve,
            resolve_view,
            readback,
            padded_row,
            width,
            height,
        })
    }

    /// Frame size in pixels.
    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// The GPU in use.
    pub fn gpu(&self) -> &Gpu {
        &self.gpu
    }

    /// Renders one frame and reads it back.
    pub fn render(&mut self, frame: &FrameDraw) -> Result<RgbaImage, RenderError> {
        let device = &self.gpu.device;
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("offscreen frame"),
        });
        self.renderer.draw(
            &self.gpu,
            &mut encoder,
            &self.attachments,
            &self.resolve_view,
            frame,
        );
        encoder.copy_texture_to_buffer(
            wgpu::TexelCopyTextureInfo {
                texture: &self.resolve,
                mip_level: 0,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            wgpu::TexelCopyBufferInfo {
                buffer: &self.readback,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(self.padded_row),
                    rows_per_image: Some(self.height),
                },
            },
            wgpu::Extent3d {
                width: self.width,
                height: self.height,
                depth_or_array_layers: 1,
            },
        );
        self.gpu.queue.submit([encoder.finish()]);
        let (tx, rx) = std::sync::mpsc::channel();
        self.readback.map_async(wgpu::MapMode::Read, .., move |r| {
            let _ = tx.send(r);
        });
        device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| RenderError::Gpu(e.to_string()))?;
        rx.recv()
            .map_err(|e| RenderError::Gpu(e.to_string()))?
            .map_err(|e| RenderError::Gpu(e.to_string()))?;
        let mut pixels = Vec::with_capacity((self.width * self.height * 4) as usize);
        {
            let view = self
                .readback
                .get_mapped_range(..)
                .map_err(|e| RenderError::Gpu(e.to_string()))?;
            let row = (self.width * 4) as usize;
            for chunk in view.chunks(self.padded_row as usize) {
                pixels.extend_from_slice(&chunk[..row]);
            }
        }
        self.readback.unmap();
        RgbaImage::from_raw(self.width, self.height, pixels)
            .ok_or_else(|| RenderError::Gpu("readback size mismatch".into()))
    }
}
