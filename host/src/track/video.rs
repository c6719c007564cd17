//! Frames in and out through Debian's `ffmpeg`: a video file or a V4L2 camera decoded to raw
//! grey frames on a pipe (`-f rawvideo -pix_fmt gray`), and grey frames encoded to H.264 MP4.
//!
//! Why a pipe, not a decoding crate: ffmpeg is already a project dependency (`render` writes
//! MP4 with it), it reads every container and codec a phone or webcam produces, and its V4L2
//! input opens a camera with the same code path; the Rust ffmpeg bindings need the `-dev`
//! headers and libclang to build, for no gain here. A frame's time is its index over the
//! stream's frame rate for a file, and its arrival on the pipe for a camera.

use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStdin, ChildStdout, Command, Stdio};
use std::time::Instant;

use super::detect::GrayFrame;
use super::TrackError;

/// What ffprobe says about a video file's first video stream.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VideoInfo {
    /// Frame width, pixels.
    pub width: usize,
    /// Frame height, pixels.
    pub height: usize,
    /// Frames per second.
    pub fps: f64,
}

fn tool_missing(tool: &str, e: std::io::Error) -> TrackError {
    TrackError::Tool {
        tool: tool.to_string(),
        reason: format!("{e} (install Debian's ffmpeg: `cargo xtask setup`)"),
    }
}

/// Reads a file's frame size and rate with ffprobe.
pub fn probe(path: &Path) -> Result<VideoInfo, TrackError> {
    let unreadable = |reason: String| TrackError::Unreadable {
        path: path.to_path_buf(),
        reason,
    };
    if !path.is_file() {
        return Err(unreadable("no such file".into()));
    }
    let out = Command::new("ffprobe")
        .args(["-v", "error", "-select_streams", "v:0", "-show_entries"])
        .arg("stream=width,height,avg_frame_rate,r_frame_rate")
        .args(["-of", "default=noprint_wrappers=1"])
        .arg(path)
        .output()
        .map_err(|e| tool_missing("ffprobe", e))?;
    let text = String::from_utf8_lossy(&out.stdout);
    let field = |name: &str| {
        text.lines()
            .find_map(|l| l.strip_prefix(name)?.strip_prefix('='))
            .map(str::trim)
    };
    let err = String::from_utf8_lossy(&out.stderr);
    let (Some(w), Some(h)) = (field("width"), field("height")) else {
        let why = err.lines().last().unwrap_or("no video stream").trim();
        return Err(unreadable(format!("not a video ffmpeg can read: {why}")));
    };
    let (width, height) = match (w.parse::<usize>(), h.parse::<usize>()) {
        (Ok(w), Ok(h)) if w > 0 && h > 0 => (w, h),
        _ => return Err(unreadable(format!("frame size `{w}×{h}`"))),
    };
    let rate = |s: &str| -> Option<f64> {
        let (n, d) = s.split_once('/').unwrap_or((s, "1"));
        let v = n.parse::<f64>().ok()? / d.parse::<f64>().ok()?;
        (v.is_finite() && v > 0.0).then_some(v)
    };
    let fps = field("avg_frame_rate")
        .and_then(rate)
        .or_else(|| field("r_frame_rate").and_then(rate))
        .ok_or_else(|| unreadable("no frame rate".into()))?;
    Ok(VideoInfo { width, height, fps })
}

/// Where frames come from.
#[derive(Debug, Clone, PartialEq)]
pub enum Source {
    /// A video file, timed by frame index.
    File(PathBuf),
    /// A V4L2 camera (`/dev/videoN`) at a requested size and rate, timed by arrival.
    Camera {
        /// The device node.
        device: PathBuf,
        /// Requested frame width, pixels.
        width: usize,
        /// Requested frame height, pixels.
        height: usize,
        /// Requested frames per second.
        fps: f64,
    },
}

/// A running ffmpeg decoder yielding grey frames with their times.
pub struct FrameReader {
    child: Child,
    stdout: ChildStdout,
    source: Source,
    width: usize,
    height: usize,
    fps: f64,
    index: u64,
    started: Instant,
    stderr_path: PathBuf,
}

impl std::fmt::Debug for FrameReader {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("FrameReader")
            .field("source", &self.source)
            .field("index", &self.index)
            .finish()
    }
}

impl FrameReader {
    /// Starts decoding `source`.
    pub fn open(source: Source) -> Result<Self, TrackError> {
        let (width, height, fps, input): (usize, usize, f64, Vec<String>) = match &source {
            Source::File(path) => {
                let info = probe(path)?;
                let input = vec!["-i".into(), path.display().to_string()];
                (info.width, info.height, info.fps, input)
            }
            Source::Camera {
                device,
                width,
                height,
                fps,
            } => {
                check_camera(device)?;
                let input = vec![
                    "-f".into(),
                    "v4l2".into(),
                    "-framerate".into(),
                    format!("{fps}"),
                    "-video_size".into(),
                    format!("{width}x{height}"),
                    "-i".into(),
                    device.display().to_string(),
                ];
                (*width, *height, *fps, input)
            }
        };
        // ffmpeg's complaints go to a file so a full pipe can never stall it, and are read
        // back to explain an early end.
        let stderr_path = std::env::temp_dir().join(format!(
            "figurine-track-ffmpeg-{}-{}.log",
            std::process::id(),
            NEXT_LOG.fetch_add(1, std::sync::atomic::Ordering::Relaxed)
        ));
        let stderr = std::fs::File::create(&stderr_path).map_err(|e| TrackError::Tool {
            tool: "ffmpeg".into(),
            reason: format!("cannot create {}: {e}", stderr_path.display()),
        })?;
        let mut child = Command::new("ffmpeg")
            .args(["-hide_banner", "-loglevel", "error", "-nostdin"])
            .args(&input)
            // A camera may not offer the size asked for: scale to it, so frames are what the
            // reader expects whatever the driver chose.
            .args(["-vf", &format!("scale={width}:{height}")])
            .args(["-f", "rawvideo", "-pix_fmt", "gray", "-"])
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(stderr)
            .spawn()
            .map_err(|e| tool_missing("ffmpeg", e))?;
        let Some(stdout) = child.stdout.take() else {
            let _ = child.kill();
            return Err(TrackError::Tool {
                tool: "ffmpeg".into(),
                reason: "no output pipe".into(),
            });
        };
        Ok(Self {
            child,
            stdout,
            source,
            width,
            height,
            fps,
            index: 0,
            started: Instant::now(),
            stderr_path,
        })
    }

    /// Frame width, pixels.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Frame height, pixels.
    pub fn height(&self) -> usize {
        self.height
    }

    /// Frames per second (the file's, or the rate asked of the camera).
    pub fn fps(&self) -> f64 {
        self.fps
    }

    /// The next frame and its time (seconds from the first frame for a file, from opening for
    /// a camera); `None` at the end of the stream. A stream that ends before its first frame
    /// is an error carrying ffmpeg's reason.
    pub fn next_frame(&mut self) -> Result<Option<(f64, GrayFrame)>, TrackError> {
        let mut pixels = vec![0u8; self.width * self.height];
        let mut filled = 0;
        while filled < pixels.len() {
            match self.stdout.read(&mut pixels[filled..]) {
                Ok(0) => break,
                Ok(n) => filled += n,
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                Err(e) => return Err(self.failure(e.to_string())),
            }
        }
        if filled < pixels.len() {
            let status = self.child.wait().ok();
            if self.index == 0 || status.is_some_and(|s| !s.success()) {
                return Err(self.failure(String::new()));
            }
            return Ok(None);
        }
        let t = match self.source {
            Source::File(_) => self.index as f64 / self.fps,
            Source::Camera { .. } => self.started.elapsed().as_secs_f64(),
        };
        self.index += 1;
        Ok(Some((
            t,
            GrayFrame {
                width: self.width,
                height: self.height,
                pixels,
            },
        )))
    }

    /// The error for a stream that failed, in ffmpeg's words where it gave any.
    fn failure(&mut self, fallback: String) -> TrackError {
        let _ = self.child.kill();
        let _ = self.child.wait();
        let said = std::fs::read_to_string(&self.stderr_path).unwrap_or_default();
        let said = said
            .lines()
            .rev()
            .find(|l| !l.trim().is_empty())
            .unwrap_or("");
        let reason = if said.is_empty() {
            if fallback.is_empty() {
                "ffmpeg produced no frame".to_string()
            } else {
                fallback
            }
        } else {
            said.trim().to_string()
        };
        match &self.source {
            Source::File(path) => TrackError::Unreadable {
                path: path.clone(),
                reason,
            },
            Source::Camera { device, .. } => camera_error(device, &reason),
        }
    }
}

impl Drop for FrameReader {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
        let _ = std::fs::remove_file(&self.stderr_path);
    }
}

static NEXT_LOG: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);

/// Fails early, with a plain reason, for a camera that is not there or not a device.
fn check_camera(device: &Path) -> Result<(), TrackError> {
    use std::os::unix::fs::FileTypeExt;
    let meta = std::fs::metadata(device).map_err(|e| TrackError::Camera {
        device: device.to_path_buf(),
        reason: if e.kind() == std::io::ErrorKind::NotFound {
            "no such camera (is it plugged in? `ls /dev/video*` lists the cameras)".into()
        } else {
            e.to_string()
        },
    })?;
    // Video4Linux devices are character devices of major number 81.
    use std::os::unix::fs::MetadataExt;
    let rdev = meta.rdev();
    let major = ((rdev >> 8) & 0xfff) | ((rdev >> 32) & !0xfff);
    if !meta.file_type().is_char_device() || major != 81 {
        return Err(TrackError::Camera {
            device: device.to_path_buf(),
            reason: "not a video device (expected /dev/videoN)".into(),
        });
    }
    Ok(())
}

/// Turns ffmpeg's complaint about a camera into a reason a person can act on.
fn camera_error(device: &Path, said: &str) -> TrackError {
    let lower = said.to_ascii_lowercase();
    let reason = if lower.contains("busy") {
        format!("the camera is busy: another program is using it ({said})")
    } else if lower.contains("permission") {
        format!("no permission: add yourself to the `video` group ({said})")
    } else {
        said.to_string()
    };
    TrackError::Camera {
        device: device.to_path_buf(),
        reason,
    }
}

/// An ffmpeg H.264 encoder fed grey frames (for rendered test videos).
pub struct Mp4Writer {
    child: Option<Child>,
    stdin: Option<ChildStdin>,
    path: PathBuf,
    frame_len: usize,
}

impl Mp4Writer {
    /// Starts encoding `width`×`height` grey frames at `fps` into `path` (H.264 at CRF 12: a
    /// webcam's stream keeps its sensor noise, which CRF 18 would smooth away in still
    /// frames and so flatter the tracker's jitter at rest).
    pub fn create(path: &Path, width: usize, height: usize, fps: f64) -> Result<Self, TrackError> {
        let mut child = Command::new("ffmpeg")
            .args(["-hide_banner", "-loglevel", "error", "-y"])
            .args(["-f", "rawvideo", "-pix_fmt", "gray"])
            .args(["-s", &format!("{width}x{height}"), "-r", &format!("{fps}")])
            .args(["-i", "-", "-c:v", "libx264", "-preset", "veryfast"])
            .args(["-crf", "12", "-pix_fmt", "yuv420p"])
            .arg(path)
            .stdin(Stdio::piped())
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .map_err(|e| tool_missing("ffmpeg", e))?;
        let stdin = child.stdin.take();
        Ok(Self {
            child: Some(child),
            stdin,
            path: path.to_path_buf(),
            frame_len: width * height,
        })
    }

    /// Appends one frame (`width * height` grey levels).
    pub fn push(&mut self, frame: &GrayFrame) -> Result<(), TrackError> {
        let broken = |reason: String| TrackError::Tool {
            tool: "ffmpeg".into(),
            reason,
        };
        if frame.pixels.len() != self.frame_len {
            return Err(broken(format!(
                "frame of {} pixels, expected {}",
                frame.pixels.len(),
                self.frame_len
            )));
        }
        let stdin = self
            .stdin
            .as_mut()
            .ok_or_else(|| broken("encoder already finished".into()))?;
        stdin
            .write_all(&frame.pixels)
            .map_err(|e| broken(format!("writing {}: {e}", self.path.display())))
    }

    /// Finishes the file.
    pub fn finish(mut self) -> Result<(), TrackError> {
        drop(self.stdin.take());
        let Some(child) = self.child.take() else {
            return Ok(());
        };
        let out = child
            .wait_with_output()
            .map_err(|e| tool_missing("ffmpeg", e))?;
        if !out.status.success() {
            return Err(TrackError::Tool {
                tool: "ffmpeg".into(),
                reason: format!(
                    "encoding {}: {}",
                    self.path.display(),
                    String::from_utf8_lossy(&out.stderr).trim()
                ),
            });
        }
        Ok(())
    }
}

impl Drop for Mp4Writer {
    fn drop(&mut self) {
        drop(self.stdin.take());
        if let Some(mut child) = self.child.take() {
            let _ = child.wait();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_missing_camera_says_so() {
        let err = FrameReader::open(Source::Camera {
            device: "/dev/video-figurine-none".into(),
            width: 640,
            height: 480,
            fps: 30.0,
        })
        .unwrap_err()
        .to_string();
        assert!(err.contains("no such camera"), "{err}");
        let err = FrameReader::open(Source::Camera {
            device: "/dev/null".into(),
            width: 640,
            height: 480,
            fps: 30.0,
        })
        .unwrap_err()
        .to_string();
        assert!(err.contains("not a video device"), "{err}");
    }

    #[test]
    fn busy_and_permission_complaints_are_explained() {
        let e = camera_error(Path::new("/dev/video0"), "Device or resource busy").to_string();
        assert!(e.contains("busy: another program"), "{e}");
        let e = camera_error(Path::new("/dev/video0"), "Permission denied").to_string();
        assert!(e.contains("video` group"), "{e}");
    }

    #[test]
    fn a_file_that_is_not_a_video_is_unreadable() {
        let dir = std::env::temp_dir().join(format!("figurine-video-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let junk = dir.join("junk.mp4");
        std::fs::write(&junk, b"this is not a video").unwrap();
        let err = FrameReader::open(Source::File(junk))
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("junk.mp4") && err.contains("not a video"),
            "{err}"
        );
        let err = probe(&dir.join("missing.mp4")).unwrap_err().to_string();
        assert!(err.contains("no such file"), "{err}");
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn encoded_frames_decode_to_the_same_picture() {
        let dir = std::env::temp_dir().join(format!("figurine-video-rt-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("ramp.mp4");
        let (w, h) = (64, 48);
        let mut enc = Mp4Writer::create(&path, w, h, 30.0).unwrap();
        for i in 0..5u8 {
            let pixels = (0..w * h).map(|p| ((p % w) * 4) as u8 ^ i).collect();
            enc.push(&GrayFrame {
                width: w,
                height: h,
                pixels,
            })
            .unwrap();
        }
        enc.finish().unwrap();
        let mut r = FrameReader::open(Source::File(path)).unwrap();
        assert_eq!((r.width(), r.height()), (w, h));
        let mut n = 0;
        while let Some((t, f)) = r.next_frame().unwrap() {
            assert!((t - n as f64 / 30.0).abs() < 1e-9);
            // A horizontal ramp survives H.264 within a few levels.
            let x = 40;
            assert!((f.pixels[10 * w + x] as i32 - (x * 4) as i32).abs() < 12);
            n += 1;
        }
        assert_eq!(n, 5);
        let _ = std::fs::remove_dir_all(&dir);
    }
}
