//! The window viewer (winit + wgpu): plays a clip with an orbit camera, or shows poses pushed
//! live (puppetry) and measures event-to-first-frame time.
//!
//! Controls: left-drag orbit, right-drag pan, wheel zoom, Space play/pause, ←/→ one frame
//! (Shift: one second), ↑/↓ speed ×2/÷2, Home restart, F follow on/off, L loop on/off,
//! R reset camera, click or drag on the timeline bar to seek, Esc/Q quit.
//!
//! winit needs the main thread: call [`run_viewer`] from `main` and push live poses from other
//! threads through a [`LiveFeed`] clone.

use std::sync::Arc;
use std::time::Instant;

use glam::Vec3;
use winit::application::ApplicationHandler;
use winit::dpi::PhysicalSize;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{Key, NamedKey};
use winit::window::{Window, WindowId};

use super::camera::{CameraPlan, SceneMetrics};
use super::compose::Composer;
use super::gpu::{msaa_samples, Attachments, Gpu, SceneRenderer};
use super::live::{LatencyStats, LiveFeed};
use super::overlay::OverlayLayout;
use super::playback::{DragButton, ViewerInput, ViewerKey, ViewerState};
use super::scene::{pose_bounds, FramePose, Scene, TimelineSpan};
use super::RenderError;

/// Seconds of recent history the live timeline bar shows.
pub const LIVE_WINDOW_S: f32 = 20.0;
/// Time constant of the live follow camera, seconds.
const LIVE_FOLLOW_TAU_S: f32 = 0.3;

/// What the viewer shows.
pub enum ViewerSource {
    /// A finished animation, played back.
    Clip(Scene),
    /// Poses pushed at run time.
    Live(LiveFeed),
}

/// How to open the viewer window.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ViewerOptions {
    /// Initial window size, pixels.
    pub size: (u32, u32),
    /// Close by itself after this long (smoke tests, timed demos); `None` = until closed.
    pub quit_after: Option<std::time::Duration>,
}

impl Default for ViewerOptions {
    fn default() -> Self {
        ViewerOptions {
            size: (1280, 720),
            quit_after: None,
        }
    }
}

/// What a viewer session did, returned when its window closes.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ViewerReport {
    /// Frames presented.
    pub frames: u64,
    /// Event-to-first-frame latency (live mode only).
    pub latency: Option<LatencyStats>,
}

/// Maps a key press to a viewer key (`shift` held or not).
pub fn map_key(key: &Key, shift: bool) -> Option<ViewerKey> {
    match key {
        Key::Named(NamedKey::Space) => Some(ViewerKey::PlayPause),
        Key::Named(NamedKey::ArrowLeft) => Some(ViewerKey::Back { big: shift }),
        Key::Named(NamedKey::ArrowRight) => Some(ViewerKey::Forward { big: shift }),
        Key::Named(NamedKey::ArrowUp) => Some(ViewerKey::Faster),
        Key::Named(NamedKey::ArrowDown) => Some(ViewerKey::Slower),
        Key::Named(NamedKey::Home) => Some(ViewerKey::Restart),
        Key::Named(NamedKey::Escape) => Some(ViewerKey::Quit),
        Key::Character(c) => match c.to_ascii_lowercase().as_str() {
            "f" => Some(ViewerKey::ToggleFollow),
            "l" => Some(ViewerKey::ToggleLoop),
            "r" => Some(ViewerKey::ResetCamera),
            "q" => Some(ViewerKey::Quit),
            "+" | "=" => Some(ViewerKey::Faster),
            "-" => Some(ViewerKey::Slower),
            _ => None,
        },
        _ => None,
    }
}

/// The timeline fraction (0..1) under pixel (`x`, `y`), if it is on the bar (with a little
/// slack above it so the playhead is easy to grab).
pub fn timeline_fraction(x: f32, y: f32, width: u32, height: u32) -> Option<f32> {
    let [x0, y0, x1, y1] = OverlayLayout::new(width, height).bar;
    let slack = (y1 - y0) * 0.5;
    (x >= x0 - 2.0 && x <= x1 + 2.0 && y >= y0 - slack && y <= y1 + 2.0)
        .then(|| ((x - x0) / (x1 - x0)).clamp(0.0, 1.0))
}

/// Follow target for live poses: exponential smoothing towards the pose centre, with a
/// running estimate of figure size and ground.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LiveTracker {
    target: Option<Vec3>,
    /// Running scene metrics (largest size seen, lowest ground seen).
    pub metrics: Option<SceneMetrics>,
}

impl LiveTracker {
    /// A tracker that has seen nothing.
    pub fn new() -> Self {
        LiveTracker {
            target: None,
            metrics: None,
        }
    }

    /// Feeds the current pose after `dt` seconds; returns the smoothed target.
    pub fn update(&mut self, pose: &FramePose, dt: f32) -> Vec3 {
        if let Some((lo, hi)) = pose_bounds(pose) {
            let centre = (lo + hi) * 0.5;
            let size = (hi - lo).length().max(1e-3);
            let m = self
                .metrics
                .get_or_insert(SceneMetrics { size, ground: lo.y });
            m.size = m.size.max(size);
            m.ground = m.ground.min(lo.y);
            let k = if dt.is_finite() && dt > 0.0 {
                1.0 - (-dt / LIVE_FOLLOW_TAU_S).exp()
            } else {
                0.0
            };
            let t = self.target.get_or_insert(centre);
            *t += (centre - *t) * k;
        }
        self.target.unwrap_or(Vec3::ZERO)
    }
}

impl Default for LiveTracker {
    fn default() -> Self {
        Self::new()
    }
}

/// Window, surface and GPU objects, created once the event loop runs.
struct WindowGfx {
    window: Arc<Window>,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    gpu: Gpu,
    renderer: SceneRenderer,
    attachments: Attachments,
    samples: u32,
}

struct App {
    source: ViewerSource,
    size: (u32, u32),
    deadline: Option<Instant>,
    gfx: Option<WindowGfx>,
    state: ViewerState,
    plan: Option<CameraPlan>,
    composer: Composer,
    tracker: LiveTracker,
    last_tick: Instant,
    cursor: (f32, f32),
    dragging: Option<DragButton>,
    seeking: bool,
    shift: bool,
    report: ViewerReport,
    error: Option<RenderError>,
}

impl App {
    fn new(source: ViewerSource, opts: ViewerOptions) -> Self {
        let size = opts.size;
        let aspect = size.0.max(1) as f32 / size.1.max(1) as f32;
        let (state, plan, composer) = match &source {
            ViewerSource::Clip(scene) => {
                let plan = CameraPlan::new(scene);
                let state = ViewerState::new(
                    scene.duration(),
                    scene.fps,
                    plan.direction(),
                    plan.radius_at(0.0),
                    aspect,
                );
                (state, Some(plan), Composer::new(scene))
            }
            ViewerSource::Live(_) => {
                let dir = Vec3::new(0.5, 0.25, 1.0).normalize();
                let mut state = ViewerState::new(0.0, 60.0, dir, 1.0, aspect);
                state.playback.playing = true;
                (state, None, Composer::new(&Scene::default()))
            }
        };
        App {
            source,
            size,
            deadline: opts.quit_after.map(|d| Instant::now() + d),
            gfx: None,
            state,
            plan,
            composer,
            tracker: LiveTracker::new(),
            last_tick: Instant::now(),
            cursor: (0.0, 0.0),
            dragging: None,
            seeking: false,
            shift: false,
            report: ViewerReport::default(),
            error: None,
        }
    }

    fn init(&mut self, event_loop: &ActiveEventLoop) -> Result<(), RenderError> {
        let attrs = Window::default_attributes()
            .with_title("figurine view")
            .with_inner_size(PhysicalSize::new(self.size.0, self.size.1));
        let window = Arc::new(
            event_loop
                .create_window(attrs)
                .map_err(|e| RenderError::Window(e.to_string()))?,
        );
        let instance =
            wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        let surface = instance
            .create_surface(window.clone())
            .map_err(|e| RenderError::Window(e.to_string()))?;
        let gpu = Gpu::with_instance(instance, Some(&surface))?;
        let inner = window.inner_size();
        let (w, h) = (inner.width.max(1), inner.height.max(1));
        let mut config = surface
            .get_default_config(&gpu.adapter, w, h)
            .ok_or_else(|| RenderError::Window("surface not supported by the adapter".into()))?;
        let caps = surface.get_capabilities(&gpu.adapter);
        if let Some(f) = caps.formats.iter().copied().find(|f| f.is_srgb()) {
            config.format = f;
        }
        surface.configure(&gpu.device, &config);
        // The window can be resized: decide once for its largest likely size.
        let samples = msaa_samples(&gpu.adapter, w, h);
        let renderer = SceneRenderer::new(&gpu.device, config.format, samples);
        let attachments = Attachments::new(&gpu.device, w, h, config.format, samples);
        eprintln!("figurine view: {}", gpu.describe());
        self.gfx = Some(WindowGfx {
            window,
            surface,
            config,
            gpu,
            renderer,
            attachments,
            samples,
        });
        Ok(())
    }

    fn resize(&mut self, w: u32, h: u32) {
        if let Some(g) = &mut self.gfx {
            if w == 0 || h == 0 {
                return;
            }
            g.config.width = w;
            g.config.height = h;
            g.surface.configure(&g.gpu.device, &g.config);
            g.attachments = Attachments::new(&g.gpu.device, w, h, g.config.format, g.samples);
        }
    }

    fn redraw(&mut self) -> Result<(), RenderError> {
        let now = Instant::now();
        let dt = now.duration_since(self.last_tick).as_secs_f32();
        self.last_tick = now;
        self.state.playback.advance(dt);
        let Some(g) = &mut self.gfx else {
            return Ok(());
        };
        let (w, h) = (g.config.width, g.config.height);
        // What to draw: pose, overlay scene, followed point, radius.
        let (pose, overlay_scene, t, followed, radius, seq, status) = match &self.source {
            ViewerSource::Clip(scene) => {
                let t = self.state.playback.time;
                let plan = self.plan.as_ref();
                let followed = plan.map_or(Vec3::ZERO, |p| p.target_at(t));
                let radius = plan.map_or(1.0, |p| p.radius_at(t));
                let status = self.state.playback.status();
                (scene.pose_at(t), None, t, followed, radius, None, status)
            }
            ViewerSource::Live(feed) => {
                let Some(snap) = feed.snapshot() else {
                    return Ok(());
                };
                let followed = self.tracker.update(&snap.pose, dt);
                if let Some(m) = self.tracker.metrics {
                    self.composer = Composer::with_metrics(m);
                }
                let radius = self.tracker.metrics.map_or(1.0, |m| m.size * 0.5);
                let shift = (snap.now - LIVE_WINDOW_S).max(0.0);
                let timeline: Vec<TimelineSpan> = snap
                    .timeline
                    .iter()
                    .filter(|s| s.end >= shift)
                    .map(|s| TimelineSpan {
                        start: s.start - shift,
                        end: s.end - shift,
                        ..s.clone()
                    })
                    .collect();
                let scene = Scene {
                    title: "live".into(),
                    fps: 60.0,
                    frames: vec![FramePose::default(); 2],
                    doodle: Vec::new(),
                    timeline,
                };
                let st = feed.latency_stats();
                let status = format!(
                    "event->frame {:.0} ms (p95 {:.0}, n={})",
                    st.median.as_secs_f64() * 1e3,
                    st.p95.as_secs_f64() * 1e3,
                    st.count
                );
                let t = snap.now - shift;
                (
                    snap.pose,
                    Some(scene),
                    t,
                    followed,
                    radius,
                    Some(snap.seq),
                    status,
                )
            }
        };
        let camera = self.state.camera(followed, radius);
        let scene_for_overlay = match (&overlay_scene, &self.source) {
            (Some(s), _) => s,
            (None, ViewerSource::Clip(s)) => s,
            (None, ViewerSource::Live(_)) => return Ok(()),
        };
        let draw = self
            .composer
            .compose_pose(scene_for_overlay, &pose, t, &camera, w, h, &status);
        let frame = match g.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(f)
            | wgpu::CurrentSurfaceTexture::Suboptimal(f) => f,
            wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
                g.surface.configure(&g.gpu.device, &g.config);
                return Ok(());
            }
            _ => return Ok(()),
        };
        let view = frame.texture.create_view(&Default::default());
        let mut encoder = g
            .gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("view"),
            });
        g.renderer
            .draw(&g.gpu, &mut encoder, &g.attachments, &view, &draw);
        g.gpu.queue.submit([encoder.finish()]);
        g.window.pre_present_notify();
        g.gpu.queue.present(frame);
        self.report.frames += 1;
        if let (Some(seq), ViewerSource::Live(feed)) = (seq, &self.source) {
            feed.frame_presented(seq, Instant::now());
        }
        Ok(())
    }

    fn input(&mut self, input: ViewerInput) {
        self.state.handle(input);
    }
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.gfx.is_none() {
            if let Err(e) = self.init(event_loop) {
                self.error = Some(e);
                event_loop.exit();
            }
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        let (w, h) = self
            .gfx
            .as_ref()
            .map_or(self.size, |g| (g.config.width, g.config.height));
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(size) => self.resize(size.width, size.height),
            WindowEvent::ModifiersChanged(m) => self.shift = m.state().shift_key(),
            WindowEvent::KeyboardInput { event, .. } if event.state == ElementState::Pressed => {
                if let Some(k) = map_key(&event.logical_key, self.shift) {
                    self.input(ViewerInput::Key(k));
                }
            }
            WindowEvent::MouseInput { state, button, .. } => {
                let pressed = state == ElementState::Pressed;
                match button {
                    MouseButton::Left if pressed => {
                        if let Some(f) = timeline_fraction(self.cursor.0, self.cursor.1, w, h) {
                            self.seeking = true;
                            self.input(ViewerInput::SeekFraction(f));
                        } else {
                            self.dragging = Some(DragButton::Left);
                        }
                    }
                    MouseButton::Right if pressed => self.dragging = Some(DragButton::Right),
                    _ if !pressed => {
                        self.dragging = None;
                        self.seeking = false;
                    }
                    _ => {}
                }
            }
            WindowEvent::CursorMoved { position, .. } => {
                let (x, y) = (position.x as f32, position.y as f32);
                let (dx, dy) = (x - self.cursor.0, y - self.cursor.1);
                self.cursor = (x, y);
                if self.seeking {
                    let [x0, _, x1, _] = OverlayLayout::new(w, h).bar;
                    self.input(ViewerInput::SeekFraction((x - x0) / (x1 - x0)));
                } else if let Some(button) = self.dragging {
                    self.input(ViewerInput::Drag { button, dx, dy });
                }
            }
            WindowEvent::MouseWheel { delta, .. } => {
                let lines = match delta {
                    MouseScrollDelta::LineDelta(_, y) => y,
                    MouseScrollDelta::PixelDelta(p) => p.y as f32 / 40.0,
                };
                self.input(ViewerInput::Scroll(lines));
            }
            WindowEvent::RedrawRequested => {
                if let Err(e) = self.redraw() {
                    self.error = Some(e);
                    event_loop.exit();
                }
            }
            _ => {}
        }
        if self.state.quit || self.deadline.is_some_and(|d| Instant::now() >= d) {
            event_loop.exit();
        }
    }

    fn about_to_wait(&mut self, _event_loop: &ActiveEventLoop) {
        if let Some(g) = &self.gfx {
            g.window.request_redraw();
        }
    }
}

/// Opens a window showing `source` and runs until it is closed (or `opts.quit_after`). Must
/// be called on the main thread. Live mode prints event-to-first-frame statistics on exit.
pub fn run_viewer(source: ViewerSource, opts: ViewerOptions) -> Result<ViewerReport, RenderError> {
    if let ViewerSource::Clip(scene) = &source {
        scene.validate()?;
    }
    let event_loop = EventLoop::new().map_err(|e| {
        RenderError::Window(format!(
            "{e} (the viewer needs a display: X11 or Wayland; use `figurine render` headless)"
        ))
    })?;
    event_loop.set_control_flow(ControlFlow::Poll);
    let mut app = App::new(source, opts);
    event_loop
        .run_app(&mut app)
        .map_err(|e| RenderError::Window(e.to_string()))?;
    if let Some(e) = app.error.take() {
        return Err(e);
    }
    if let ViewerSource::Live(feed) = &app.source {
        let st = feed.latency_stats();
        app.report.latency = Some(st);
        eprintln!(
            "event to first frame: median {:.1} ms, p95 {:.1} ms, max {:.1} ms over {} events",
            st.median.as_secs_f64() * 1e3,
            st.p95.as_secs_f64() * 1e3,
            st.max.as_secs_f64() * 1e3,
            st.count
        );
    }
    Ok(app.report)
}

/// Convenience for puppetry: shows the poses pushed into `feed` (see [`LiveFeed`]).
pub fn run_live_viewer(feed: LiveFeed, opts: ViewerOptions) -> Result<ViewerReport, RenderError> {
    run_viewer(ViewerSource::Live(feed), opts)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::procedural::{walking_pose, walking_scene, FigureParams};

    #[test]
    fn keys_map_to_viewer_keys() {
        assert_eq!(
            map_key(&Key::Named(NamedKey::Space), false),
            Some(ViewerKey::PlayPause)
        );
        assert_eq!(
            map_key(&Key::Named(NamedKey::ArrowLeft), true),
            Some(ViewerKey::Back { big: true })
        );
        assert_eq!(
            map_key(&Key::Character("F".into()), false),
            Some(ViewerKey::ToggleFollow)
        );
        assert_eq!(map_key(&Key::Character("z".into()), false), None);
    }

    #[test]
    fn timeline_hit_test() {
        let [x0, y0, x1, y1] = OverlayLayout::new(640, 360).bar;
        let mid = timeline_fraction((x0 + x1) * 0.5, (y0 + y1) * 0.5, 640, 360);
        assert!(mid.is_some_and(|f| (f - 0.5).abs() < 0.01));
        assert_eq!(timeline_fraction(320.0, 10.0, 640, 360), None);
    }

    #[test]
    fn app_constructs_without_a_window() {
        let scene = walking_scene(2.0, 30.0, &FigureParams::default());
        let opts = ViewerOptions {
            size: (640, 360),
            quit_after: None,
        };
        let app = App::new(ViewerSource::Clip(scene), opts);
        assert!(app.gfx.is_none());
        assert!((app.state.playback.duration - 2.0).abs() < 1e-4);
        let live = App::new(ViewerSource::Live(LiveFeed::new()), opts);
        assert!(live.plan.is_none());
    }

    #[test]
    fn live_tracker_converges_on_the_figure() {
        let mut tr = LiveTracker::new();
        let p = FigureParams {
            offset: Vec3::new(10.0, 0.0, 0.0),
            travel: 0.0,
            ..FigureParams::default()
        };
        let pose = walking_pose(0.0, &p);
        let mut t = Vec3::ZERO;
        for _ in 0..100 {
            t = tr.update(&pose, 0.05);
        }
        assert!((t.x - 10.0).abs() < 0.2, "{t}");
        let m = tr.metrics.expect("metrics");
        assert!(m.size > 1.0 && m.ground < 0.2);
    }
}
