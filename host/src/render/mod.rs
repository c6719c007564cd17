//! Rendering: animation produces poses, rendering only consumes them.
//!
//! Data flow, one file per stage:
//! - [`scene`]: the GPU-agnostic input — per frame a list of bone segments (world metres, +Y
//!   up), the doodle path, the timeline of recognised actions with efforts, fps.
//! - [`from_clip`]: the thin glue from a motion [`crate::motion::Clip`] (e.g. an imported
//!   BVH) to a scene, plus doodle/event loading.
//! - [`camera`]: follow camera framed from the scene's own extent (any units), orbit camera.
//! - [`overlay`]: the colour-coded timeline bar and text, as pixel rectangles.
//! - [`compose`]: scene + time + camera → draw lists (capsules, shadows, grid, overlay).
//! - [`gpu`]: wgpu pipelines that rasterise draw lists (lavapipe when there is no GPU).
//! - [`offscreen`]: headless targets and readback to images.
//! - [`video`]: frame timing and the output sinks: PNG folder, GIF, MP4 (ffmpeg).
//! - [`cli`]: the `figurine render` and `figurine view` subcommands.
//! - [`playback`], [`live`], [`viewer`]: the window viewer's state machine, the live pose
//!   feed for puppetry, and the winit window itself.
//! - [`procedural`]: a procedural walking stick figure for tests, benchmarks and demos.
//!
//! The stages that need the GPU or a window (`gpu`, `offscreen`, `video`, `cli`, `playback`,
//! `viewer`) are the crate's default `render` feature; the scene, camera, overlay, compose and
//! puppet stages build without it.
//!
//! Usage:
//! ```text
//! figurine render ANIM.bvh [--doodle LOG.csv] [--events E.jsonl|LABELS.json] \
//!     --out OUT.gif|OUT.mp4|OUT.png|DIR/ [--size WxH] [--fps N] [--at T] [--from S --to S]
//! figurine view ANIM.bvh [--doodle LOG.csv] [--events E.jsonl] [--size WxH]
//! ```
//! `ANIM` may be `procedural` (the built-in walking figure). MSAA is 4× except on a CPU
//! adapter for frames above 640×360 (`FIGURINE_MSAA=1|4` overrides). The golden image of
//! `tests/render_gpu.rs` is regenerated with
//! `FIGURINE_BLESS=1 cargo test -p figurine-host --test render_gpu golden` (then look at it).

pub mod camera;
#[cfg(feature = "render")]
pub mod cli;
pub mod compose;
pub mod from_clip;
#[cfg(feature = "render")]
pub mod gpu;
pub mod live;
#[cfg(feature = "render")]
pub mod offscreen;
pub mod overlay;
#[cfg(feature = "render")]
pub mod playback;
pub mod procedural;
pub mod puppet;
pub mod scene;
#[cfg(feature = "render")]
pub mod video;
#[cfg(feature = "render")]
pub mod viewer;

use std::path::PathBuf;

/// Everything that can go wrong while rendering.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// No GPU adapter (not even lavapipe) is available.
    #[error(
        "no GPU adapter found ({0}); on a machine without a GPU install Mesa's lavapipe: \
         `apt-get install mesa-vulkan-drivers libvulkan1`"
    )]
    NoAdapter(String),
    /// The adapter refused to open a device.
    #[error("could not open the GPU device: {0}")]
    NoDevice(String),
    /// A GPU operation failed.
    #[error("GPU error: {0}")]
    Gpu(String),
    /// The requested frame size is unusable.
    #[error("invalid frame size {width}x{height} (each side must be 1..={max} pixels)")]
    BadSize {
        /// Requested width, pixels.
        width: u32,
        /// Requested height, pixels.
        height: u32,
        /// Largest side allowed.
        max: u32,
    },
    /// The scene cannot be rendered.
    #[error("cannot render: {0}")]
    Scene(#[from] scene::SceneError),
    /// Writing output failed.
    #[error("{path}: {source}")]
    Io {
        /// The file or folder.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// Encoding an image or video failed.
    #[error("{path}: encoding failed: {reason}")]
    Encode {
        /// The output.
        path: PathBuf,
        /// What went wrong.
        reason: String,
    },
    /// MP4 output needs ffmpeg, which was not found.
    #[error(
        "MP4 output needs `ffmpeg` on PATH (install it: `apt-get install ffmpeg`), or write \
         a .gif or a folder of PNGs instead"
    )]
    NoFfmpeg,
    /// The window viewer failed.
    #[error("viewer: {0}")]
    Window(String),
}
