//! The `figurine render` and `figurine view` subcommands.

use std::path::PathBuf;

use clap::Args;

use super::from_clip::{load_scene, slice_scene};
use super::procedural::{walking_scene, FigureParams};
use super::scene::Scene;
use super::video::{render_to_path, RenderOptions};

/// Parses `WxH` (e.g. `640x360`).
pub fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("size `{s}` must look like 640x360"))?;
    let w: u32 = w
        .trim()
        .parse()
        .map_err(|_| format!("bad width in `{s}`"))?;
    let h: u32 = h
        .trim()
        .parse()
        .map_err(|_| format!("bad height in `{s}`"))?;
    if w == 0 || h == 0 {
        return Err(format!("size `{s}` must be at least 1x1"));
    }
    Ok((w, h))
}

/// Input shared by `render` and `view`.
#[derive(Args, Debug, Clone)]
pub struct SceneArgs {
    /// Animation to show: a BVH file (any unit, Y- or Z-up), or `procedural` for the built-in
    /// walking figure.
    pub anim: PathBuf,
    /// Pose log (CSV) whose path is drawn as the doodle; its first sample is time 0.
    #[arg(long)]
    pub doodle: Option<PathBuf>,
    /// Recognised actions for the timeline bar: JSON lines of `figurine simulate`, or the
    /// labels (JSON array) of `figurine synth`.
    #[arg(long)]
    pub events: Option<PathBuf>,
    /// Toy metres → character metres for drawing the doodle (as `animate --world-scale`).
    #[arg(long, default_value_t = super::from_clip::DEFAULT_DOODLE_SCALE)]
    pub doodle_scale: f32,
    /// Start of the part to show, seconds.
    #[arg(long)]
    pub from: Option<f32>,
    /// End of the part to show, seconds.
    #[arg(long)]
    pub to: Option<f32>,
}

impl SceneArgs {
    /// Loads the scene these arguments describe.
    pub fn load(&self) -> anyhow::Result<Scene> {
        let scene = if self.anim.as_os_str() == "procedural" {
            let mut s = walking_scene(8.0, 30.0, &FigureParams::default());
            if self.doodle.is_some() || self.events.is_some() {
                s.doodle.clear();
                s.timeline.clear();
            }
            if let Some(p) = &self.doodle {
                let log = crate::poselog::PoseLog::read_path(p)?;
                let t0 = log.samples.first().map_or(0.0, |x| x.t);
                s.doodle = super::from_clip::doodle_from_log(&log, t0);
                super::from_clip::place_doodle(&mut s.doodle, self.doodle_scale, (0.0, 0.0), 0.0);
            }
            if let Some(p) = &self.events {
                let ev = super::from_clip::read_actions(p)?;
                s.timeline = super::from_clip::timeline_from_events(&ev, 0.0);
            }
            s
        } else {
            load_scene(
                &self.anim,
                self.doodle.as_deref(),
                self.events.as_deref(),
                self.doodle_scale,
            )?
        };
        let scene = if self.from.is_some() || self.to.is_some() {
            slice_scene(
                &scene,
                self.from.unwrap_or(0.0),
                self.to.unwrap_or(f32::INFINITY),
            )
        } else {
            scene
        };
        scene.validate()?;
        Ok(scene)
    }
}

/// `figurine render`: headless render to a GIF, an MP4 (needs ffmpeg), a PNG still, or a
/// folder of PNG frames.
#[derive(Args, Debug, Clone)]
pub struct RenderArgs {
    /// What to render.
    #[command(flatten)]
    pub scene: SceneArgs,
    /// Output: `OUT.gif`, `OUT.mp4` (ffmpeg), `OUT.png` (one still), or `DIR/` (PNG frames).
    #[arg(long)]
    pub out: PathBuf,
    /// Frame size in pixels, `WxH`.
    #[arg(long, default_value = "640x360", value_parser = parse_size)]
    pub size: (u32, u32),
    /// Output frames per second (GIF rounds the frame delay to whole centiseconds).
    #[arg(long, default_value_t = 30.0)]
    pub fps: f32,
    /// For a `.png` still: the time to show, seconds (default: the middle).
    #[arg(long)]
    pub at: Option<f32>,
}

/// Runs `figurine render`.
pub fn run_render(args: &RenderArgs) -> anyhow::Result<()> {
    if !(args.fps.is_finite() && args.fps > 0.0 && args.fps <= 1000.0) {
        anyhow::bail!("--fps must be in (0, 1000], got {}", args.fps);
    }
    let scene = args.scene.load()?;
    let opts = RenderOptions {
        width: args.size.0,
        height: args.size.1,
        fps: args.fps,
    };
    let summary = render_to_path(&scene, opts, &args.out, args.at, true)?;
    eprintln!(
        "wrote {} ({} frame{}, {}x{}) in {:.1} s (rendering {:.1} s) on {}",
        summary.out.display(),
        summary.frames,
        if summary.frames == 1 { "" } else { "s" },
        opts.width,
        opts.height,
        summary.total_seconds,
        summary.render_seconds,
        summary.adapter
    );
    Ok(())
}

/// `figurine view`: a window with orbit camera and playback controls.
#[derive(Args, Debug, Clone)]
pub struct ViewArgs {
    /// What to show.
    #[command(flatten)]
    pub scene: SceneArgs,
    /// Initial window size in pixels, `WxH`.
    #[arg(long, default_value = "1280x720", value_parser = parse_size)]
    pub size: (u32, u32),
    /// Close the window by itself after this many seconds (smoke tests, timed demos).
    #[arg(long)]
    pub quit_after: Option<f32>,
}

/// Runs `figurine view` (blocks until the window closes).
pub fn run_view(args: &ViewArgs) -> anyhow::Result<()> {
    let scene = args.scene.load()?;
    let quit_after = match args.quit_after {
        Some(s) if s.is_finite() && s >= 0.0 => Some(std::time::Duration::from_secs_f32(s)),
        Some(s) => anyhow::bail!("--quit-after must be a non-negative number of seconds, got {s}"),
        None => None,
    };
    let opts = super::viewer::ViewerOptions {
        size: args.size,
        quit_after,
    };
    let report = super::viewer::run_viewer(super::viewer::ViewerSource::Clip(scene), opts)?;
    eprintln!("figurine view: {} frames presented", report.frames);
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse() {
        assert_eq!(parse_size("640x360"), Ok((640, 360)));
        assert_eq!(parse_size("16X9"), Ok((16, 9)));
        assert!(parse_size("0x9").is_err());
        assert!(parse_size("640").is_err());
        assert!(parse_size("ax9").is_err());
    }
}
