//! Headless video: frame timing, the render loop, and the output sinks — a folder of PNGs, a
//! single PNG still, an animated GIF (global palette, fast lookup), or MP4 via `ffmpeg`.
//!
//! Encoding runs on its own thread behind a bounded queue ([`ENCODE_QUEUE`] frames) so the GPU
//! (lavapipe: the CPU) and the encoder overlap.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc::{sync_channel, Receiver, SyncSender};
use std::thread::JoinHandle;
use std::time::Instant;

use image::RgbaImage;

use super::camera::CameraPlan;
use super::compose::Composer;
use super::offscreen::OffscreenRenderer;
use super::scene::Scene;
use super::RenderError;

/// Frames waiting for the encoder at most; when full, rendering waits.
pub const ENCODE_QUEUE: usize = 4;
/// Frames sampled from the clip to train the GIF palette.
const PALETTE_SAMPLES: usize = 6;

/// What kind of output a path asks for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OutputKind {
    /// Animated GIF (`.gif`).
    Gif,
    /// H.264 video through ffmpeg (`.mp4`, `.mov`, `.mkv`).
    Video,
    /// One still image (`.png`) of the frame at a chosen time.
    Still,
    /// A folder of numbered PNG frames (an existing folder, a path ending in `/`, or a path
    /// without extension).
    PngFolder,
    /// A file extension none of the above understands.
    Unsupported,
}

impl OutputKind {
    /// Classifies an output path by its extension.
    pub fn of(path: &Path) -> Self {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        let trailing_slash = path.as_os_str().to_string_lossy().ends_with('/');
        match ext.as_deref() {
            _ if trailing_slash || path.is_dir() => OutputKind::PngFolder,
            Some("gif") => OutputKind::Gif,
            Some("mp4" | "mov" | "mkv") => OutputKind::Video,
            Some("png") => OutputKind::Still,
            None => OutputKind::PngFolder,
            Some(_) => OutputKind::Unsupported,
        }
    }
}

/// Frame size and rate of a render.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RenderOptions {
    /// Frame width, pixels.
    pub width: u32,
    /// Frame height, pixels.
    pub height: u32,
    /// Output frames per second.
    pub fps: f32,
}

/// The GIF frame delay in centiseconds for a requested rate (GIF stores whole centiseconds;
/// players treat delays under 2 cs as slow, so at least 2).
pub fn gif_delay_cs(fps: f32) -> u16 {
    if fps.is_finite() && fps > 0.0 {
        (100.0 / fps).round().clamp(2.0, 65535.0) as u16
    } else {
        4
    }
}

/// Times (seconds) of the frames of a `duration`-second clip at `fps`: 0, 1/fps, … up to the
/// last frame not after the end; always at least one frame.
pub fn frame_times(duration: f32, fps: f32) -> Vec<f32> {
    if !(fps.is_finite() && fps > 0.0 && duration.is_finite() && duration > 0.0) {
        return vec![0.0];
    }
    let n = (duration * fps + 1e-3).floor() as usize + 1;
    (0..n).map(|i| i as f32 / fps).collect()
}

/// What a finished render did.
#[derive(Debug, Clone, PartialEq)]
pub struct RenderSummary {
    /// Frames written.
    pub frames: usize,
    /// Wall time spent rendering and reading back, seconds.
    pub render_seconds: f64,
    /// Total wall time including encoding, seconds.
    pub total_seconds: f64,
    /// GPU adapter used.
    pub adapter: String,
    /// Where the output went.
    pub out: PathBuf,
}

/// Renders every frame of `scene` at `opts.fps`, calling `each(index, time, image)` in order.
/// Returns the render time in seconds.
pub fn render_frames(
    renderer: &mut OffscreenRenderer,
    scene: &Scene,
    fps: f32,
    mut each: impl FnMut(usize, f32, RgbaImage) -> Result<(), RenderError>,
) -> Result<f64, RenderError> {
    scene.validate()?;
    let plan = CameraPlan::new(scene);
    let composer = Composer::new(scene);
    let (w, h) = renderer.size();
    let aspect = w as f32 / h as f32;
    let mut spent = 0.0;
    for (i, t) in frame_times(scene.duration(), fps).into_iter().enumerate() {
        let start = Instant::now();
        let cam = plan.camera_at(t, aspect);
        let draw = composer.compose(scene, t, &cam, w, h, "");
        let img = renderer.render(&draw)?;
        spent += start.elapsed().as_secs_f64();
        each(i, t, img)?;
    }
    Ok(spent)
}

/// Renders the still at time `t` seconds.
pub fn render_still(
    renderer: &mut OffscreenRenderer,
    scene: &Scene,
    t: f32,
) -> Result<RgbaImage, RenderError> {
    scene.validate()?;
    let plan = CameraPlan::new(scene);
    let composer = Composer::new(scene);
    let (w, h) = renderer.size();
    let cam = plan.camera_at(t, w as f32 / h as f32);
    renderer.render(&composer.compose(scene, t, &cam, w, h, ""))
}

/// Renders `scene` to `out` (kind chosen by [`OutputKind::of`]); a `.png` gets the still at
/// `still_at` seconds (default: the middle). Reports progress on stderr when `progress`.
pub fn render_to_path(
    scene: &Scene,
    opts: RenderOptions,
    out: &Path,
    still_at: Option<f32>,
    progress: bool,
) -> Result<RenderSummary, RenderError> {
    scene.validate()?;
    let started = Instant::now();
    let kind = OutputKind::of(out);
    if kind == OutputKind::Unsupported {
        return Err(RenderError::Encode {
            path: out.to_path_buf(),
            reason: "unsupported output: use .gif, .mp4 (.mov, .mkv), .png (one still) or a \
                     folder path ending in / (PNG frames)"
                .into(),
        });
    }
    if kind == OutputKind::Video && !ffmpeg_available() {
        return Err(RenderError::NoFfmpeg);
    }
    let mut renderer = OffscreenRenderer::new(opts.width, opts.height)?;
    let adapter = renderer.gpu().describe();
    if kind == OutputKind::Still {
        let t = still_at.unwrap_or(scene.duration() * 0.5);
        let r0 = Instant::now();
        let img = render_still(&mut renderer, scene, t)?;
        let render_seconds = r0.elapsed().as_secs_f64();
        create_parent(out)?;
        img.save(out).map_err(|e| RenderError::Encode {
            path: out.to_path_buf(),
            reason: e.to_string(),
        })?;
        return Ok(RenderSummary {
            frames: 1,
            render_seconds,
            total_seconds: started.elapsed().as_secs_f64(),
            adapter,
            out: out.to_path_buf(),
        });
    }
    let fps = if kind == OutputKind::Gif {
        100.0 / f32::from(gif_delay_cs(opts.fps))
    } else {
        opts.fps
    };
    let total = frame_times(scene.duration(), fps).len();
    let sink: Box<dyn FrameSink> = match kind {
        OutputKind::Gif => {
            let palette = train_palette(&mut renderer, scene)?;
            Box::new(GifSink::create(
                out,
                opts.width,
                opts.height,
                gif_delay_cs(opts.fps),
                palette,
            )?)
        }
        OutputKind::Video => Box::new(FfmpegSink::spawn(out, opts.width, opts.height, fps)?),
        OutputKind::PngFolder | OutputKind::Still | OutputKind::Unsupported => {
            Box::new(PngFolderSink::create(out)?)
        }
    };
    let encoder = EncoderThread::start(sink);
    let mut frames = 0;
    let render_seconds = render_frames(&mut renderer, scene, fps, |i, _, img| {
        frames = i + 1;
        if progress && (i % 10 == 0 || i + 1 == total) {
            eprint!("\rrendering frame {}/{total}", i + 1);
        }
        encoder.push(img)
    });
    if progress {
        eprintln!();
    }
    // Always join the encoder, even when rendering failed, so no thread or ffmpeg is leaked.
    let finished = encoder.finish();
    let render_seconds = render_seconds?;
    finished?;
    Ok(RenderSummary {
        frames,
        render_seconds,
        total_seconds: started.elapsed().as_secs_f64(),
        adapter,
        out: out.to_path_buf(),
    })
}

fn create_parent(path: &Path) -> Result<(), RenderError> {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => {
            std::fs::create_dir_all(p).map_err(|source| RenderError::Io {
                path: p.to_path_buf(),
                source,
            })
        }
        _ => Ok(()),
    }
}

/// A consumer of rendered frames.
pub trait FrameSink: Send {
    /// Takes the next frame.
    fn push(&mut self, img: RgbaImage) -> Result<(), RenderError>;
    /// Completes the output (flushes files, waits for ffmpeg).
    fn finish(self: Box<Self>) -> Result<(), RenderError>;
}

/// Runs a [`FrameSink`] on its own thread behind a bounded queue.
pub struct EncoderThread {
    tx: Option<SyncSender<RgbaImage>>,
    handle: JoinHandle<Result<(), RenderError>>,
}

impl EncoderThread {
    /// Starts the thread.
    pub fn start(mut sink: Box<dyn FrameSink>) -> Self {
        let (tx, rx): (SyncSender<RgbaImage>, Receiver<RgbaImage>) = sync_channel(ENCODE_QUEUE);
        let handle = std::thread::spawn(move || {
            let mut result = Ok(());
            for img in rx {
                if result.is_ok() {
                    result = sink.push(img);
                }
            }
            let done = sink.finish();
            result.and(done)
        });
        EncoderThread {
            tx: Some(tx),
            handle,
        }
    }

    /// Queues a frame (waits while the queue is full). An encoder that already failed reports
    /// its error at [`EncoderThread::finish`].
    pub fn push(&self, img: RgbaImage) -> Result<(), RenderError> {
        match &self.tx {
            Some(tx) => tx
                .send(img)
                .map_err(|_| RenderError::Gpu("encoder thread stopped".into())),
            None => Ok(()),
        }
    }

    /// Closes the queue, waits for the encoder, and returns its result.
    pub fn finish(mut self) -> Result<(), RenderError> {
        self.tx = None;
        self.handle
            .join()
            .unwrap_or_else(|_| Err(RenderError::Gpu("encoder thread panicked".into())))
    }
}

/// Writes `frame_00000.png`, `frame_00001.png`, … into a folder.
pub struct PngFolderSink {
    dir: PathBuf,
    next: usize,
}

impl PngFolderSink {
    /// Creates the folder (and parents) if needed.
    pub fn create(dir: &Path) -> Result<Self, RenderError> {
        std::fs::create_dir_all(dir).map_err(|source| RenderError::Io {
            path: dir.to_path_buf(),
            source,
        })?;
        Ok(PngFolderSink {
            dir: dir.to_path_buf(),
            next: 0,
        })
    }
}

impl FrameSink for PngFolderSink {
    fn push(&mut self, img: RgbaImage) -> Result<(), RenderError> {
        let path = self.dir.join(format!("frame_{:05}.png", self.next));
        img.save(&path).map_err(|e| RenderError::Encode {
            path,
            reason: e.to_string(),
        })?;
        self.next += 1;
        Ok(())
    }

    fn finish(self: Box<Self>) -> Result<(), RenderError> {
        Ok(())
    }
}

/// The GIF palette index that marks a pixel unchanged from the previous frame.
pub const TRANSPARENT: u8 = 255;

/// A 255-colour palette with a fast lookup from 5-bit-per-channel RGB.
pub struct Palette {
    /// RGB triples.
    pub colours: Vec<u8>,
    lut: Vec<u8>,
}

impl Palette {
    /// Trains a palette on sample RGBA pixels (NeuQuant, 255 colours) and builds the lookup
    /// table; index [`TRANSPARENT`] is left free for "unchanged since the previous frame".
    pub fn train(rgba: &[u8]) -> Self {
        let nq = color_quant::NeuQuant::new(10, 255, rgba);
        let mut colours = nq.color_map_rgb();
        colours.resize(256 * 3, 0);
        let mut lut = vec![0u8; 32 * 32 * 32];
        for (i, slot) in lut.iter_mut().enumerate() {
            let c = |shift: usize| (((i >> shift) & 31) * 255 / 31) as u8;
            *slot = nq.index_of(&[c(10), c(5), c(0), 255]) as u8;
        }
        Palette { colours, lut }
    }

    /// Palette indices of an RGBA image (nearest palette colour of each pixel's 5-bit RGB).
    /// No dithering: the scene's flat colours and soft gradients quantise cleanly, and
    /// undithered frames compress better.
    pub fn map(&self, img: &RgbaImage) -> Vec<u8> {
        img.as_raw()
            .chunks_exact(4)
            .map(|px| {
                let q = |v: u8| usize::from(v >> 3);
                self.lut[(q(px[0]) << 10) | (q(px[1]) << 5) | q(px[2])]
            })
            .collect()
    }
}

/// Renders a few frames spread over the clip and trains the GIF palette on them.
fn train_palette(renderer: &mut OffscreenRenderer, scene: &Scene) -> Result<Palette, RenderError> {
    let d = scene.duration();
    let mut pixels = Vec::new();
    for k in 0..PALETTE_SAMPLES {
        let t = d * k as f32 / (PALETTE_SAMPLES - 1) as f32;
        pixels.extend_from_slice(render_still(renderer, scene, t)?.as_raw());
    }
    Ok(Palette::train(&pixels))
}

/// Animated GIF with one global palette, looping forever.
pub struct GifSink {
    encoder: gif::Encoder<std::io::BufWriter<std::fs::File>>,
    palette: Palette,
    delay: u16,
    path: PathBuf,
    size: (u16, u16),
    /// Palette indices of the previous frame, to code unchanged pixels as transparent.
    previous: Option<Vec<u8>>,
}

impl GifSink {
    /// Creates the file; frames must be `width` × `height` (each at most 65535).
    pub fn create(
        path: &Path,
        width: u32,
        height: u32,
        delay_cs: u16,
        palette: Palette,
    ) -> Result<Self, RenderError> {
        let enc_err = |reason: String| RenderError::Encode {
            path: path.to_path_buf(),
            reason,
        };
        let (w, h) = (
            u16::try_from(width).map_err(|e| enc_err(e.to_string()))?,
            u16::try_from(height).map_err(|e| enc_err(e.to_string()))?,
        );
        create_parent(path)?;
        let file = std::fs::File::create(path).map_err(|source| RenderError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        let mut encoder = gif::Encoder::new(std::io::BufWriter::new(file), w, h, &palette.colours)
            .map_err(|e| enc_err(e.to_string()))?;
        encoder
            .set_repeat(gif::Repeat::Infinite)
            .map_err(|e| enc_err(e.to_string()))?;
        Ok(GifSink {
            encoder,
            palette,
            delay: delay_cs,
            path: path.to_path_buf(),
            size: (w, h),
            previous: None,
        })
    }
}

impl FrameSink for GifSink {
    fn push(&mut self, img: RgbaImage) -> Result<(), RenderError> {
        let indices = self.palette.map(&img);
        // Unchanged pixels become transparent over the kept previous frame: the static sky
        // and overlay then cost almost nothing after LZW.
        let (coded, transparent) = match &self.previous {
            Some(prev) if prev.len() == indices.len() => (
                indices
                    .iter()
                    .zip(prev)
                    .map(|(&i, &p)| if i == p { TRANSPARENT } else { i })
                    .collect(),
                Some(TRANSPARENT),
            ),
            _ => (indices.clone(), None),
        };
        self.previous = Some(indices);
        let mut frame =
            gif::Frame::from_indexed_pixels(self.size.0, self.size.1, coded, transparent);
        frame.dispose = gif::DisposalMethod::Keep;
        frame.delay = self.delay;
        self.encoder
            .write_frame(&frame)
            .map_err(|e| RenderError::Encode {
                path: self.path.clone(),
                reason: e.to_string(),
            })
    }

    fn finish(self: Box<Self>) -> Result<(), RenderError> {
        let path = self.path.clone();
        let mut w = self.encoder.into_inner().map_err(|e| RenderError::Encode {
            path: path.clone(),
            reason: e.to_string(),
        })?;
        w.flush().map_err(|source| RenderError::Io { path, source })
    }
}

/// True when an `ffmpeg` executable runs.
pub fn ffmpeg_available() -> bool {
    Command::new("ffmpeg")
        .arg("-version")
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
}

/// H.264 video: raw RGBA frames piped into `ffmpeg`.
pub struct FfmpegSink {
    child: Child,
    path: PathBuf,
}

impl FfmpegSink {
    /// Starts ffmpeg writing `path` from `width` × `height` frames at `fps`.
    pub fn spawn(path: &Path, width: u32, height: u32, fps: f32) -> Result<Self, RenderError> {
        if !ffmpeg_available() {
            return Err(RenderError::NoFfmpeg);
        }
        create_parent(path)?;
        let child = Command::new("ffmpeg")
            .args([
                "-y",
                "-loglevel",
                "error",
                "-f",
                "rawvideo",
                "-pix_fmt",
                "rgba",
            ])
            .args(["-s", &format!("{width}x{height}")])
            .args(["-framerate", &format!("{fps}")])
            .args(["-i", "-"])
            .args(["-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2"])
            .args(["-c:v", "libx264", "-preset", "veryfast", "-crf", "20"])
            .args(["-pix_fmt", "yuv420p", "-movflags", "+faststart"])
            .arg(path)
            .stdin(Stdio::piped())
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .map_err(|source| RenderError::Io {
                path: PathBuf::from("ffmpeg"),
                source,
            })?;
        Ok(FfmpegSink {
            child,
            path: path.to_path_buf(),
        })
    }
}

impl FrameSink for FfmpegSink {
    fn push(&mut self, img: RgbaImage) -> Result<(), RenderError> {
        let stdin = self
            .child
            .stdin
            .as_mut()
            .ok_or_else(|| RenderError::Encode {
                path: self.path.clone(),
                reason: "ffmpeg stdin closed".into(),
            })?;
        stdin
            .write_all(img.as_raw())
            .map_err(|e| RenderError::Encode {
                path: self.path.clone(),
                reason: format!("ffmpeg stopped reading: {e}"),
            })
    }

    fn finish(mut self: Box<Self>) -> Result<(), RenderError> {
        drop(self.child.stdin.take());
        let out = std::mem::replace(&mut self.child, dummy_child()?)
            .wait_with_output()
            .map_err(|source| RenderError::Io {
                path: self.path.clone(),
                source,
            })?;
        if out.status.success() {
            Ok(())
        } else {
            Err(RenderError::Encode {
                path: self.path.clone(),
                reason: format!(
                    "ffmpeg failed ({}): {}",
                    out.status,
                    String::from_utf8_lossy(&out.stderr).trim()
                ),
            })
        }
    }
}

/// A finished placeholder process so the real child can be moved out of the sink.
fn dummy_child() -> Result<Child, RenderError> {
    Command::new("true")
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .map_err(|source| RenderError::Io {
            path: PathBuf::from("true"),
            source,
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn output_kinds() {
        assert_eq!(OutputKind::of(Path::new("a.gif")), OutputKind::Gif);
        assert_eq!(OutputKind::of(Path::new("a.GIF")), OutputKind::Gif);
        assert_eq!(OutputKind::of(Path::new("a.mp4")), OutputKind::Video);
        assert_eq!(OutputKind::of(Path::new("a.png")), OutputKind::Still);
        assert_eq!(OutputKind::of(Path::new("frames/")), OutputKind::PngFolder);
        assert_eq!(OutputKind::of(Path::new("frames")), OutputKind::PngFolder);
        assert_eq!(OutputKind::of(Path::new("a.webm")), OutputKind::Unsupported);
        assert_eq!(OutputKind::of(Path::new("a.webm/")), OutputKind::PngFolder);
    }

    #[test]
    fn frame_times_cover_the_clip() {
        let t = frame_times(1.0, 30.0);
        assert_eq!(t.len(), 31);
        assert_eq!(t[30], 1.0);
        assert_eq!(frame_times(0.0, 30.0), vec![0.0]);
        assert_eq!(frame_times(f32::NAN, 30.0), vec![0.0]);
        assert_eq!(frame_times(2.0, 0.0), vec![0.0]);
    }

    #[test]
    fn gif_delays() {
        assert_eq!(gif_delay_cs(25.0), 4);
        assert_eq!(gif_delay_cs(30.0), 3);
        assert_eq!(gif_delay_cs(1000.0), 2);
        assert_eq!(gif_delay_cs(-1.0), 4);
    }

    #[test]
    fn palette_maps_its_training_colours_closely() {
        let mut img = RgbaImage::new(256, 64);
        for (x, y, p) in img.enumerate_pixels_mut() {
            *p = image::Rgba([x as u8, (y * 4) as u8, 255 - x as u8, 255]);
        }
        let pal = Palette::train(img.as_raw());
        let idx = pal.map(&img);
        let mut total = 0u64;
        for (k, px) in img.pixels().enumerate() {
            let i = usize::from(idx[k]) * 3;
            for c in 0..3 {
                total +=
                    u64::from((i32::from(pal.colours[i + c]) - i32::from(px[c])).unsigned_abs());
            }
        }
        let mean = total as f64 / (img.width() * img.height() * 3) as f64;
        assert!(mean < 10.0, "mean palette error {mean}");
    }
}
