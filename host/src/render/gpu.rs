//! The GPU stage: a wgpu device ([`Gpu`]) and the pipelines that rasterise a [`FrameDraw`]
//! into any colour target ([`SceneRenderer`]), shared by headless rendering and the viewer.
//!
//! Backends come from the environment (`WGPU_BACKEND=vulkan|gl`, `WGPU_ADAPTER_NAME=llvmpipe`
//! …) via `InstanceDescriptor::new_without_display_handle_from_env`; on machines without a GPU
//! Mesa's lavapipe (Vulkan on the CPU) is used. Draw order: ground, ground shadows
//! (multiplicative, no depth test), capsules (depth tested), overlay (alpha blended).

use wgpu::util::DeviceExt;

use super::compose::{Capsule, FrameDraw, Globals, Shadow};
use super::overlay::Rect;
use super::RenderError;

/// Depth buffer format.
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
/// Default MSAA sample count (4× smooths the limb silhouettes and grid); 1 disables MSAA.
pub const SAMPLE_COUNT: u32 = 4;
/// Environment variable overriding the MSAA sample count (`1` or `4`).
pub const MSAA_ENV: &str = "FIGURINE_MSAA";

/// Largest frame (pixels) that gets MSAA on a CPU adapter: lavapipe's 4× MSAA costs about
/// 4× the frame time, which big frames cannot afford (and need less: their pixels are small).
pub const CPU_MSAA_MAX_PIXELS: u32 = 640 * 360;

/// Gives Mesa's window-system probing a private runtime directory when `XDG_RUNTIME_DIR` is
/// unset or not a directory (a CI runner, a container, `sudo`), so headless rendering does
/// not print "XDG_RUNTIME_DIR is invalid" on every device creation. Call it at program start,
/// before any thread is spawned: it changes the process environment.
pub fn ensure_runtime_dir() {
    let valid = std::env::var_os("XDG_RUNTIME_DIR")
        .map(std::path::PathBuf::from)
        .is_some_and(|p| p.is_dir());
    if valid {
        return;
    }
    #[cfg(unix)]
    let owner = {
        use std::os::unix::fs::MetadataExt;
        std::fs::metadata("/proc/self").map_or(0, |m| m.uid())
    };
    #[cfg(not(unix))]
    let owner = 0;
    let dir = std::env::temp_dir().join(format!("figurine-runtime-{owner}"));
    if std::fs::create_dir_all(&dir).is_ok() {
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            let _ = std::fs::set_permissions(&dir, std::fs::Permissions::from_mode(0o700));
        }
        std::env::set_var("XDG_RUNTIME_DIR", &dir);
    }
}

/// The MSAA sample count for a `width` × `height` target on `adapter`: [`MSAA_ENV`] if it is
/// `1` or `4`; else [`SAMPLE_COUNT`], except 1 on a CPU adapter (lavapipe) for frames larger
/// than [`CPU_MSAA_MAX_PIXELS`].
pub fn msaa_samples(adapter: &wgpu::Adapter, width: u32, height: u32) -> u32 {
    match std::env::var(MSAA_ENV).ok().as_deref().map(str::trim) {
        Some("1") => return 1,
        Some("4") => return 4,
        _ => {}
    }
    let cpu = adapter.get_info().device_type == wgpu::DeviceType::Cpu;
    if cpu && width.saturating_mul(height) > CPU_MSAA_MAX_PIXELS {
        1
    } else {
        SAMPLE_COUNT
    }
}
/// Limb capsule tessellation: segments around the bone, rings per hemispherical cap.
const LIMB_TESSELLATION: (u32, u32) = (16, 5);
/// Doodle capsule tessellation (thin, many): segments around, rings per cap.
const DOODLE_TESSELLATION: (u32, u32) = (6, 1);

/// A wgpu device and queue, plus what adapter they run on.
pub struct Gpu {
    /// The instance (kept for creating window surfaces).
    pub instance: wgpu::Instance,
    /// The adapter.
    pub adapter: wgpu::Adapter,
    /// The device.
    pub device: wgpu::Device,
    /// Its queue.
    pub queue: wgpu::Queue,
}

impl Gpu {
    /// Opens the default adapter without a window (headless rendering).
    pub fn headless() -> Result<Self, RenderError> {
        let instance =
            wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        Self::with_instance(instance, None)
    }

    /// Opens an adapter on `instance`, compatible with `surface` when given.
    pub fn with_instance(
        instance: wgpu::Instance,
        surface: Option<&wgpu::Surface<'_>>,
    ) -> Result<Self, RenderError> {
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            force_fallback_adapter: false,
            compatible_surface: surface,
            ..Default::default()
        }))
        .map_err(|e| RenderError::NoAdapter(e.to_string()))?;
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("figurine"),
            required_features: wgpu::Features::empty(),
            required_limits: wgpu::Limits::downlevel_defaults().using_resolution(adapter.limits()),
            ..Default::default()
        }))
        .map_err(|e| RenderError::NoDevice(e.to_string()))?;
        Ok(Gpu {
            instance,
            adapter,
            device,
            queue,
        })
    }

    /// Adapter name and backend, e.g. `llvmpipe (LLVM 15.0.6, 256 bits) on Vulkan`.
    pub fn describe(&self) -> String {
        let info = self.adapter.get_info();
        format!("{} on {:?}", info.name, info.backend)
    }
}

/// A growable GPU buffer of instances.
struct InstanceBuffer {
    buffer: wgpu::Buffer,
    capacity: u64,
    label: &'static str,
}

impl InstanceBuffer {
    fn new(device: &wgpu::Device, label: &'static str, capacity: u64) -> Self {
        let buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: capacity.max(64),
            usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        InstanceBuffer {
            buffer,
            capacity: capacity.max(64),
            label,
        }
    }

    fn upload(&mut self, device: &wgpu::Device, queue: &wgpu::Queue, bytes: &[u8]) {
        if bytes.is_empty() {
            return;
        }
        if bytes.len() as u64 > self.capacity {
            *self = Self::new(device, self.label, (bytes.len() as u64).next_power_of_two());
        }
        queue.write_buffer(&self.buffer, 0, bytes);
    }
}

/// Pipelines and buffers that draw a [`FrameDraw`].
pub struct SceneRenderer {
    capsule_pipeline: wgpu::RenderPipeline,
    ground_pipeline: wgpu::RenderPipeline,
    shadow_pipeline: wgpu::RenderPipeline,
    rect_pipeline: wgpu::RenderPipeline,
    globals: wgpu::Buffer,
    bind_group: wgpu::BindGroup,
    capsule_mesh: wgpu::Buffer,
    capsule_indices: wgpu::Buffer,
    /// Index range and base vertex of the limb mesh, then of the doodle mesh.
    meshes: [(std::ops::Range<u32>, i32); 2],
    instances: Vec<Capsule>,
    capsules: InstanceBuffer,
    shadows: InstanceBuffer,
    rects: InstanceBuffer,
}

/// Vertices (local direction xyz, cap flag) and indices of the unit capsule: two hemispheres
/// whose equators are joined by the cylinder; the vertex shader places and scales it.
fn capsule_mesh((seg, rings): (u32, u32)) -> (Vec<[f32; 4]>, Vec<u16>) {
    let mut verts = Vec::new();
    let total_rings = 2 * rings + 2;
    for k in 0..total_rings {
        let (lat, flag) = if k <= rings {
            (-90.0 + 90.0 * k as f32 / rings as f32, 0.0)
        } else {
            (90.0 * (k - rings - 1) as f32 / rings as f32, 1.0)
        };
        let lat = f32::to_radians(lat);
        for j in 0..=seg {
            let lon = std::f32::consts::TAU * j as f32 / seg as f32;
            verts.push([
                lat.cos() * lon.cos(),
                lat.sin(),
                lat.cos() * lon.sin(),
                flag,
            ]);
        }
    }
    let row = seg + 1;
    let mut idx = Vec::new();
    for k in 0..total_rings - 1 {
        for j in 0..seg {
            let p = |kk: u32, jj: u32| (kk * row + jj) as u16;
            // Counter-clockwise seen from outside.
            idx.extend([p(k, j), p(k + 1, j), p(k, j + 1)]);
            idx.extend([p(k + 1, j), p(k + 1, j + 1), p(k, j + 1)]);
        }
    }
    (verts, idx)
}

impl SceneRenderer {
    /// Builds the pipelines for colour targets of `format` with `samples` MSAA samples (1 or
    /// 4) and a [`DEPTH_FORMAT`] depth buffer.
    pub fn new(device: &wgpu::Device, format: wgpu::TextureFormat, samples: u32) -> Self {
        let shader = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("figurine shader"),
            source: wgpu::ShaderSource::Wgsl(include_str!("shader.wgsl").into()),
        });
        let globals = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("globals"),
            size: std::mem::size_of::<Globals>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("globals layout"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            }],
        });
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("globals"),
            layout: &layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: globals.as_entire_binding(),
            }],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("figurine layout"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let make = |label: &str,
                    vs: &str,
                    fs: &str,
                    buffers: &[Option<wgpu::VertexBufferLayout<'_>>],
                    cull: Option<wgpu::Face>,
                    depth: (bool, wgpu::CompareFunction),
                    blend: Option<wgpu::BlendState>| {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(label),
                layout: Some(&pipeline_layout),
                vertex: wgpu::VertexState {
                    module: &shader,
                    entry_point: Some(vs),
                    compilation_options: Default::default(),
                    buffers,
                },
                primitive: wgpu::PrimitiveState {
                    topology: wgpu::PrimitiveTopology::TriangleList,
                    front_face: wgpu::FrontFace::Ccw,
                    cull_mode: cull,
                    ..Default::default()
                },
                depth_stencil: Some(wgpu::DepthStencilState {
                    format: DEPTH_FORMAT,
                    depth_write_enabled: Some(depth.0),
                    depth_compare: Some(depth.1),
                    stencil: Default::default(),
                    bias: Default::default(),
                }),
                multisample: wgpu::MultisampleState {
                    count: samples,
                    ..Default::default()
                },
                fragment: Some(wgpu::FragmentState {
                    module: &shader,
                    entry_point: Some(fs),
                    compilation_options: Default::default(),
                    targets: &[Some(wgpu::ColorTargetState {
                        format,
                        blend,
                        write_mask: wgpu::ColorWrites::ALL,
                    })],
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        let capsule_layouts = [
            Some(wgpu::VertexBufferLayout {
                array_stride: 16,
                step_mode: wgpu::VertexStepMode::Vertex,
                attributes: &wgpu::vertex_attr_array![0 => Float32x4],
            }),
            Some(wgpu::VertexBufferLayout {
                array_stride: std::mem::size_of::<Capsule>() as u64,
                step_mode: wgpu::VertexStepMode::Instance,
                attributes: &wgpu::vertex_attr_array![1 => Float32x4, 2 => Float32x4, 3 => Float32x4],
            }),
        ];
        let shadow_layouts = [Some(wgpu::VertexBufferLayout {
            array_stride: std::mem::size_of::<Shadow>() as u64,
            step_mode: wgpu::VertexStepMode::Instance,
            attributes: &wgpu::vertex_attr_array![0 => Float32x4, 1 => Float32x4],
        })];
        let rect_layouts = [Some(wgpu::VertexBufferLayout {
            array_stride: std::mem::size_of::<Rect>() as u64,
            step_mode: wgpu::VertexStepMode::Instance,
            attributes: &wgpu::vertex_attr_array![0 => Float32x4, 1 => Float32x4],
        })];
        let multiply = wgpu::BlendState {
            color: wgpu::BlendComponent {
                src_factor: wgpu::BlendFactor::Zero,
                dst_factor: wgpu::BlendFactor::Src,
                operation: wgpu::BlendOperation::Add,
            },
            alpha: wgpu::BlendComponent::OVER,
        };
        use wgpu::CompareFunction::{Always, Less};
        let capsule_pipeline = make(
            "capsules",
            "vs_capsule",
            "fs_capsule",
            &capsule_layouts,
            Some(wgpu::Face::Back),
            (true, Less),
            None,
        );
        let ground_pipeline = make(
            "ground",
            "vs_ground",
            "fs_ground",
            &[],
            None,
            (true, Less),
            None,
        );
        let shadow_pipeline = make(
            "shadows",
            "vs_shadow",
            "fs_shadow",
            &shadow_layouts,
            None,
            (false, Always),
            Some(multiply),
        );
        let rect_pipeline = make(
            "overlay",
            "vs_rect",
            "fs_rect",
            &rect_layouts,
            None,
            (false, Always),
            Some(wgpu::BlendState::ALPHA_BLENDING),
        );
        let (mut verts, mut idx) = capsule_mesh(LIMB_TESSELLATION);
        let limb = (0..idx.len() as u32, 0);
        let (dv, di) = capsule_mesh(DOODLE_TESSELLATION);
        let doodle = (
            idx.len() as u32..(idx.len() + di.len()) as u32,
            verts.len() as i32,
        );
        verts.extend(dv);
        idx.extend(di);
        let capsule_mesh = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("capsule mesh"),
            contents: bytemuck::cast_slice(&verts),
            usage: wgpu::BufferUsages::VERTEX,
        });
        let capsule_indices = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("capsule indices"),
            contents: bytemuck::cast_slice(&idx),
            usage: wgpu::BufferUsages::INDEX,
        });
        SceneRenderer {
            capsule_pipeline,
            ground_pipeline,
            shadow_pipeline,
            rect_pipeline,
            globals,
            bind_group,
            capsule_mesh,
            capsule_indices,
            meshes: [limb, doodle],
            instances: Vec::new(),
            capsules: InstanceBuffer::new(device, "capsule instances", 64 * 48),
            shadows: InstanceBuffer::new(device, "shadow instances", 64 * 32),
            rects: InstanceBuffer::new(device, "overlay rects", 512 * 32),
        }
    }

    /// Records the drawing of `frame` into `encoder`: clears and renders into the multisampled
    /// `attachments`, resolving into `resolve` (same size, the pipelines' colour format).
    pub fn draw(
        &mut self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        attachments: &Attachments,
        resolve: &wgpu::TextureView,
        frame: &FrameDraw,
    ) {
        let (device, queue) = (&gpu.device, &gpu.queue);
        // Without MSAA, draw straight into the target.
        let (view, resolve_target) = match &attachments.msaa {
            Some(msaa) => (msaa, Some(resolve)),
            None => (resolve, None),
        };
        let depth = &attachments.depth;
        queue.write_buffer(&self.globals, 0, bytemuck::bytes_of(&frame.globals));
        self.instances.clear();
        self.instances.extend_from_slice(&frame.capsules);
        self.instances.extend_from_slice(&frame.doodle);
        self.capsules
            .upload(device, queue, bytemuck::cast_slice(&self.instances));
        self.shadows
            .upload(device, queue, bytemuck::cast_slice(&frame.shadows));
        self.rects
            .upload(device, queue, bytemuck::cast_slice(&frame.rects));
        let [r, g, b, _] = frame.globals.background;
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("scene"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view,
                depth_slice: None,
                resolve_target,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color {
                        r: f64::from(r),
                        g: f64::from(g),
                        b: f64::from(b),
                        a: 1.0,
                    }),
                    store: if resolve_target.is_some() {
                        wgpu::StoreOp::Discard
                    } else {
                        wgpu::StoreOp::Store
                    },
                },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: depth,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(1.0),
                    store: wgpu::StoreOp::Discard,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_bind_group(0, &self.bind_group, &[]);
        pass.set_pipeline(&self.ground_pipeline);
        pass.draw(0..6, 0..1);
        if !frame.shadows.is_empty() {
            pass.set_pipeline(&self.shadow_pipeline);
            pass.set_vertex_buffer(0, self.shadows.buffer.slice(..));
            pass.draw(0..6, 0..frame.shadows.len() as u32);
        }
        if !self.instances.is_empty() {
            pass.set_pipeline(&self.capsule_pipeline);
            pass.set_vertex_buffer(0, self.capsule_mesh.slice(..));
            pass.set_vertex_buffer(1, self.capsules.buffer.slice(..));
            pass.set_index_buffer(self.capsule_indices.slice(..), wgpu::IndexFormat::Uint16);
            let limbs = frame.capsules.len() as u32;
            let all = self.instances.len() as u32;
            let [(limb_idx, limb_base), (doodle_idx, doodle_base)] = self.meshes.clone();
            if limbs > 0 {
                pass.draw_indexed(limb_idx, limb_base, 0..limbs);
            }
            if all > limbs {
                pass.draw_indexed(doodle_idx, doodle_base, limbs..all);
            }
        }
        if !frame.rects.is_empty() {
            pass.set_pipeline(&self.rect_pipeline);
            pass.set_vertex_buffer(0, self.rects.buffer.slice(..));
            pass.draw(0..6, 0..frame.rects.len() as u32);
        }
    }
}

/// Multisampled colour (when MSAA is on) and depth attachments of one size and format.
pub struct Attachments {
    /// Multisampled colour; `None` without MSAA (drawing goes straight to the target).
    pub msaa: Option<wgpu::TextureView>,
    /// Depth, with the same sample count.
    pub depth: wgpu::TextureView,
    /// Size in pixels.
    pub size: (u32, u32),
}

impl Attachments {
    /// Creates attachments of `width` × `height` pixels for colour `format` with `samples`
    /// samples per pixel.
    pub fn new(
        device: &wgpu::Device,
        width: u32,
        height: u32,
        format: wgpu::TextureFormat,
        samples: u32,
    ) -> Self {
        let make = |label: &str, format: wgpu::TextureFormat| {
            device
                .create_texture(&wgpu::TextureDescriptor {
                    label: Some(label),
                    size: wgpu::Extent3d {
                        width: width.max(1),
                        height: height.max(1),
                        depth_or_array_layers: 1,
                    },
                    mip_level_count: 1,
                    sample_count: samples,
                    dimension: wgpu::TextureDimension::D2,
                    format,
                    usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
                    view_formats: &[],
                })
                .create_view(&Default::default())
        };
        Attachments {
            msaa: (samples > 1).then(|| make("msaa colour", format)),
            depth: make("depth", DEPTH_FORMAT),
            size: (width, height),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn capsule_mesh_is_closed_and_indexed_in_range() {
        let (v, i) = capsule_mesh(LIMB_TESSELLATION);
        assert!(i.iter().all(|&k| (k as usize) < v.len()));
        assert_eq!(i.len() % 3, 0);
        // Every direction is unit length; both caps are present.
        assert!(v
            .iter()
            .all(|d| ((d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt() - 1.0).abs() < 1e-5));
        assert!(v.iter().any(|d| d[3] == 0.0) && v.iter().any(|d| d[3] == 1.0));
    }
}
