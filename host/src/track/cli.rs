//! `figurine track …`: the command-line face of the tracker.
//!
//! * `figurine track --video FILE | --camera /dev/videoN [--tag-size 0.04] [--tag-id 0]
//!   [--family tag36h11] [--fov DEG | --calibration CAL.json] --out LOG.csv|-` — a pose log,
//!   one sample per frame where the tag was seen (`--out -`: to stdout, a line per frame as it
//!   comes, for `figurine live`'s stdin);
//! * `track print-tag` — a tag to print; `track render` — a test video of a pose log;
//!   `track bench` — the tracker against the truth on rendered doodles.

use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use clap::{Args, Subcommand};
use glam::DVec3;
use image::{Rgb, RgbImage};

use super::detect::{tag_pattern, Detection, Detector, DetectorSettings, Family, Intrinsics};
use super::eval::{place, render_video, scene, Setup};
use super::pose::{camera_pose, intrinsics_from_fov, project, Calibration, DEFAULT_FOV_DEG};
use super::print::print_tags;
use super::render::Faults;
use super::rig::{BoxSize, Rig, DEFAULT_BOX_M};
use super::tracker::{Tracker, DEFAULT_EXPOSURE_S};
use super::video::{FrameReader, Source};
use super::TrackError;
use crate::poselog::{PoseLog, PoseSample, HEADER};

/// Arguments of `figurine track`.
#[derive(Args, Debug)]
#[command(args_conflicts_with_subcommands = true, subcommand_negates_reqs = true)]
pub struct TrackArgs {
    #[command(subcommand)]
    command: Option<TrackCommand>,
    #[command(flatten)]
    run: RunArgs,
}

/// Tracking a video or a camera.
#[derive(Args, Debug)]
pub struct RunArgs {
    /// Video file to track (anything ffmpeg reads).
    #[arg(long, conflicts_with = "camera", required_unless_present = "camera")]
    pub video: Option<PathBuf>,
    /// Live V4L2 camera, e.g. /dev/video0 (runs until the camera stops or Ctrl-C).
    #[arg(long)]
    pub camera: Option<PathBuf>,
    /// Edge of the tag's black square, metres (what `print-tag --size` printed).
    #[arg(long, default_value_t = 0.04)]
    pub tag_size: f64,
    /// The tag's id within its family.
    #[arg(long, default_value_t = 0)]
    pub tag_id: u32,
    /// Tag family.
    #[arg(long, value_enum, default_value = "tag36h11")]
    pub family: Family,
    /// The camera's horizontal field of view, degrees, when there is no calibration
    /// (default 60; a wrong guess scales every distance, see the README).
    #[arg(long, conflicts_with = "calibration")]
    pub fov: Option<f64>,
    /// Camera intrinsics from `figurine track calibrate`.
    #[arg(long)]
    pub calibration: Option<PathBuf>,
    /// Output pose log (CSV); `-` writes to stdout, flushed per sample (pipe it into
    /// `figurine live`).
    #[arg(long, required_unless_present_any = ["overlay", "level"])]
    pub out: Option<PathBuf>,
    /// Also write the first frame where the tag was found, with its corners and the
    /// figurine's axes drawn (PNG).
    #[arg(long)]
    pub overlay: Option<PathBuf>,
    /// Camera frame size WIDTHxHEIGHT.
    #[arg(long, default_value = "640x480")]
    pub size: String,
    /// Camera frames per second.
    #[arg(long, default_value_t = 30.0)]
    pub fps: f64,
    /// Detector threads for a whole frame's search (a region near the tag uses one).
    #[arg(long, default_value_t = 2)]
    pub threads: u32,
    /// Write the orientation as measured, without the adaptive smoothing that keeps a still
    /// figurine from jittering by a degree or two.
    #[arg(long)]
    pub raw: bool,
    /// The camera's exposure time, milliseconds, from which a fast tag's motion blur is
    /// predicted and undone when the plain search misses it (0: never).
    #[arg(long, default_value_t = DEFAULT_EXPOSURE_S * 1000.0)]
    pub exposure_ms: f64,
    /// How far the camera looks down, degrees (0: level): the log's world keeps +Y up all the
    /// same. A laptop's webcam looking at a toy on the desk looks down 20–40°; `--level`
    /// measures it from the toy standing upright in view.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub camera_tilt: f64,
    /// Measure how far the camera looks down, from a video of the figurine standing upright
    /// and still in view for a second or two (from a camera: its first few seconds, then
    /// stop), and print it for `--camera-tilt` ([`super::level`]).
    #[arg(long, conflicts_with = "camera_tilt")]
    pub level: bool,
    /// Track a rig of tags around the figurine instead of one on its chest: `box` (tags
    /// `--tag-id` … `--tag-id`+3 on the front, left, back and right sides of a box, see
    /// `--box-width`, `--box-depth`) or a rig file (JSON: each tag's id, centre, normal and up
    /// in the figurine frame).
    #[arg(long)]
    pub rig: Option<String>,
    /// The box's size with `--rig box`.
    #[command(flatten)]
    pub box_size: BoxArgs,
}

/// The size of a box rig.
#[derive(Args, Debug, Clone, Copy)]
pub struct BoxArgs {
    /// The box rig's width (across, the figurine's X: its front and back faces), metres.
    #[arg(long, default_value_t = DEFAULT_BOX_M)]
    pub box_width: f64,
    /// The box rig's depth (front to back, its Z: its left and right faces), metres.
    #[arg(long, default_value_t = DEFAULT_BOX_M)]
    pub box_depth: f64,
    /// A fifth tag (`--tag-id`+4) on the box's top, its printed top toward the figurine's
    /// back: the top's height above the side tags' centres, metres (a bow turns every side
    /// tag toward the floor; the top faces the camera then).
    #[arg(long)]
    pub box_top: Option<f64>,
}

impl BoxArgs {
    /// The box these arguments describe.
    pub fn size(&self) -> BoxSize {
        BoxSize {
            width: self.box_width,
            depth: self.box_depth,
            top: self.box_top,
        }
    }
}

/// The rig `--rig` names (`None`: one tag `id` on the chest), checked against the family.
pub fn rig_from_args(
    rig: Option<&str>,
    family: Family,
    id: u32,
    tag_size: f64,
    size: BoxArgs,
) -> Result<Rig, TrackError> {
    match rig {
        None => {
            tag_pattern(family, id)?;
            Ok(Rig::single(id, tag_size))
        }
        Some("box") => Rig::checked_box(family, id, tag_size, size.size()),
        Some(path) => Rig::read(Path::new(path), family, tag_size),
    }
}

#[derive(Subcommand, Debug)]
enum TrackCommand {
    /// Write a tag to print at its true size (PNG with its pixel density, or PDF).
    PrintTag {
        /// Tag id.
        #[arg(long, default_value_t = 0)]
        id: u32,
        /// Edge of the black square, metres.
        #[arg(long, default_value_t = 0.04)]
        size: f64,
        /// Tag family.
        #[arg(long, value_enum, default_value = "tag36h11")]
        family: Family,
        /// Output file: .png or .pdf.
        #[arg(long)]
        out: PathBuf,
        /// PNG pixels per cell (the file's density keeps the printed size whatever this is).
        #[arg(long, default_value_t = 40)]
        px_per_cell: u32,
        /// Print every tag of a rig (`box`, or a rig file), each captioned with its face,
        /// ids from `--id` on.
        #[arg(long)]
        rig: Option<String>,
        #[command(flatten)]
        box_size: BoxArgs,
    },
    /// Measure the camera's focal length from a video of the tag turned through different
    /// tilts (10+ frames tilted 15° or more), and write CAL.json for `--calibration`.
    Calibrate {
        /// The video (record it with the webcam at the size you will track at).
        #[arg(long)]
        video: PathBuf,
        /// The tag's id.
        #[arg(long, default_value_t = 0)]
        tag_id: u32,
        /// Tag family.
        #[arg(long, value_enum, default_value = "tag36h11")]
        family: Family,
        /// Output calibration (JSON).
        #[arg(long)]
        out: PathBuf,
    },
    /// Render a test video: the tag on a figurine moving along a pose log, seen by a webcam.
    Render(RenderArgs),
    /// The tracker against the truth on rendered doodles: errors by distance and speed,
    /// frames lost, latency, the recognizer's actions from both logs, the tracked noise.
    Bench(super::bench::BenchArgs),
}

/// Arguments of `figurine track render`.
#[derive(Args, Debug)]
pub struct RenderArgs {
    /// The figurine's path (a pose log, e.g. from `figurine synth gesture`).
    #[arg(long)]
    log: PathBuf,
    /// Output video (MP4).
    #[arg(long)]
    out: PathBuf,
    /// Also write the true poses at the video's frame times (the video's clock).
    #[arg(long)]
    truth: Option<PathBuf>,
    /// Distance from the camera to the path's first pose, metres (the path is moved to start
    /// straight ahead, facing the camera).
    #[arg(long, default_value_t = 0.7)]
    distance: f64,
    /// Horizontal field of view, degrees.
    #[arg(long, default_value_t = DEFAULT_FOV_DEG)]
    fov: f64,
    /// Frames per second.
    #[arg(long, default_value_t = 30.0)]
    fps: f64,
    /// Edge of the tag's black square, metres.
    #[arg(long, default_value_t = 0.04)]
    tag_size: f64,
    /// Tag id.
    #[arg(long, default_value_t = 0)]
    tag_id: u32,
    /// Seed of noise, light and occlusion.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// No blur, noise, light changes or occlusion.
    #[arg(long)]
    clean: bool,
    /// Draw a box rig around the figurine (`box`: tags `--tag-id` … +3 on its front, left,
    /// back and right) instead of one tag on its chest.
    #[arg(long, value_parser = ["box"])]
    rig: Option<String>,
    #[command(flatten)]
    box_size: BoxArgs,
    /// How far the camera looks down at the path's first pose, degrees (0: level).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    camera_tilt: f64,
    /// Take the log as it is, already in the camera's world frame (origin at the camera, +Y
    /// up, +Z toward the camera: a tracked log), instead of moving it in front of the camera.
    #[arg(long, conflicts_with = "distance")]
    as_is: bool,
}

/// `figurine track …`.
pub fn run(args: &TrackArgs) -> Result<()> {
    match &args.command {
        Some(TrackCommand::PrintTag {
            id,
            size,
            family,
            out,
            px_per_cell,
            rig,
            box_size,
        }) => {
            let rig = rig
                .as_deref()
                .map(|r| rig_from_args(Some(r), *family, *id, *size, *box_size))
                .transpose()?;
            Ok(print_tags(
                *family,
                *id,
                *size,
                out,
                *px_per_cell,
                rig.as_ref(),
            )?)
        }
        Some(TrackCommand::Calibrate {
            video,
            tag_id,
            family,
            out,
        }) => calibrate(video, *family, *tag_id, out),
        Some(TrackCommand::Render(r)) => render(r),
        Some(TrackCommand::Bench(b)) => super::bench::run(b),
        None => track(&args.run),
    }
}

fn calibrate(video: &Path, family: Family, id: u32, out: &Path) -> Result<()> {
    let (views, width, height) = super::calibrate::corners_from_video(video, family, id)?;
    let cal = super::calibrate::calibrate(&views, width, height)?;
    let text = serde_json::to_string_pretty(&cal)?;
    std::fs::write(out, text + "\n").map_err(|source| TrackError::Write {
        path: out.to_path_buf(),
        source,
    })?;
    let fov = 2.0 * (width as f64 / 2.0 / cal.fx).atan().to_degrees();
    eprintln!(
        "{}: f = {:.1} px at {width}×{height} (horizontal field of view {fov:.1}°), \
         corners fit to {:.2} px RMS over {} views",
        out.display(),
        cal.fx,
        cal.rms_px.unwrap_or(f64::NAN),
        views.len()
    );
    Ok(())
}

fn render(a: &RenderArgs) -> Result<()> {
    if !(a.distance > 0.1 && a.fov > 1.0 && a.fov < 170.0 && a.fps > 0.0 && a.tag_size > 0.0) {
        return Err(TrackError::BadArgument(
            "--distance > 0.1 m, 1 < --fov < 170, --fps and --tag-size positive".into(),
        )
        .into());
    }
    check_tilt(a.camera_tilt)?;
    let log = PoseLog::read_path(&a.log)?;
    let setup = Setup {
        fov_deg: a.fov,
        fps: a.fps,
        tag_size: a.tag_size,
        distance: a.distance,
        faults: if a.clean {
            Faults {
                exposure_s: 0.0,
                defocus_px: 0.0,
                noise: 0.0,
                light_swing: 0.0,
                occlusion_every_s: 0.0,
            }
        } else {
            Faults::default()
        },
        seed: a.seed,
        rig_box: a.rig.as_ref().map(|_| a.box_size.size()),
        camera_tilt_deg: a.camera_tilt,
        ..Setup::default()
    };
    let placed = if a.as_is {
        log
    } else {
        place(&log, setup.distance, setup.camera())
    };
    let sc = scene(&setup, Family::Tag36h11, a.tag_id)?;
    let frames = render_video(&setup, &sc, &placed, &a.out)?;
    if let Some(path) = &a.truth {
        super::eval::truth_log(&frames).write_path(path)?;
    }
    let placed_at = if a.as_is {
        String::new()
    } else {
        format!(", starting {:.2} m ahead", a.distance)
    };
    eprintln!(
        "{}: {} frames at {} fps, tag {} mm{placed_at}",
        a.out.display(),
        frames.len(),
        a.fps,
        a.tag_size * 1000.0,
    );
    Ok(())
}

fn parse_size(s: &str) -> Result<(usize, usize), TrackError> {
    let bad = || TrackError::BadArgument(format!("--size `{s}`: expected WIDTHxHEIGHT"));
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(bad)?;
    match (w.trim().parse(), h.trim().parse()) {
        (Ok(w), Ok(h)) if w > 0 && h > 0 && w <= 8192 && h <= 8192 => Ok((w, h)),
        _ => Err(bad()),
    }
}

/// The intrinsics for a `width`×`height` source from the arguments.
fn intrinsics(args: &RunArgs, width: usize, height: usize) -> Result<Intrinsics, TrackError> {
    if let Some(path) = &args.calibration {
        let cal = Calibration::read(path)?;
        return cal
            .intrinsics_for(width, height)
            .map_err(|reason| TrackError::BadCalibration {
                path: path.clone(),
                reason,
            });
    }
    let fov = args.fov.unwrap_or(DEFAULT_FOV_DEG);
    if !(fov > 1.0 && fov < 170.0) {
        return Err(TrackError::BadArgument(format!(
            "--fov {fov}: a horizontal field of view in degrees, 1..170"
        )));
    }
    Ok(intrinsics_from_fov(width, height, fov))
}

/// A camera tilt given on the command line: degrees, between looking straight down and up.
fn check_tilt(deg: f64) -> Result<(), TrackError> {
    if deg.abs() < 90.0 {
        Ok(())
    } else {
        Err(TrackError::BadArgument(format!(
            "--camera-tilt {deg}: how far the camera looks down, degrees (-90 to 90)"
        )))
    }
}

/// `figurine track --video|--camera …`.
pub fn track(args: &RunArgs) -> Result<()> {
    if !(args.tag_size.is_finite() && args.tag_size > 0.0 && args.tag_size < 1.0) {
        return Err(TrackError::BadArgument(format!(
            "--tag-size {}: the black square's edge in metres, e.g. 0.04",
            args.tag_size
        ))
        .into());
    }
    let rig = rig_from_args(
        args.rig.as_deref(),
        args.family,
        args.tag_id,
        args.tag_size,
        args.box_size,
    )?;
    let ids = rig
        .faces
        .iter()
        .map(|f| f.id.to_string())
        .collect::<Vec<_>>()
        .join(", ");
    let source = match (&args.video, &args.camera) {
        (Some(v), _) => Source::File(v.clone()),
        (None, Some(c)) => {
            let (width, height) = parse_size(&args.size)?;
            Source::Camera {
                device: c.clone(),
                width,
                height,
                fps: args.fps,
            }
        }
        (None, None) => {
            return Err(TrackError::BadArgument("give --video FILE or --camera DEV".into()).into())
        }
    };
    // Checked before any frame is read, so a bad file is reported as such at once.
    if !(args.exposure_ms >= 0.0 && args.exposure_ms < 1000.0) {
        return Err(TrackError::BadArgument(format!(
            "--exposure-ms {}: the camera's exposure in milliseconds (0 to 1000)",
            args.exposure_ms
        ))
        .into());
    }
    if let Some(path) = &args.calibration {
        Calibration::read(path)?;
    }
    check_tilt(args.camera_tilt)?;
    let name = match &source {
        Source::File(p) => p.display().to_string(),
        Source::Camera { device, .. } => device.display().to_string(),
    };
    let mut reader = FrameReader::open(source.clone())?;
    let k = intrinsics(args, reader.width(), reader.height())?;
    let settings = DetectorSettings {
        threads: args.threads,
        ..DetectorSettings::default()
    };
    let detector = Detector::new(args.family, settings)?;
    if rig.faces.len() > 1 {
        eprintln!("{name}: following a rig of {} tags:", rig.faces.len());
        for line in rig.describe() {
            eprintln!("  {line}");
        }
    }
    let tag_size = rig.tag_size;
    let mut tracker = Tracker::with_rig(detector, rig, k)
        .with_smoothing(!args.raw)
        .with_exposure(args.exposure_ms / 1000.0)
        .with_camera_tilt(args.camera_tilt);
    let mut sink = Sink::open(args.out.as_deref())?;
    let mut overlay_done = args.overlay.is_none();
    let mut frames = 0u64;
    let mut samples = 0u64;
    let mut latency = Vec::new();
    let live = matches!(source, Source::Camera { .. });
    let mut kept = Vec::new();
    while let Some((t, frame)) = reader.next_frame()? {
        // A live camera runs until stopped: the level is measured over its first seconds.
        if args.level
            && live
            && kept
                .first()
                .is_some_and(|f: &PoseSample| t - f.t > super::level::LIVE_S)
        {
            break;
        }
        let start = std::time::Instant::now();
        let result = tracker.frame(t, &frame);
        latency.push(start.elapsed().as_secs_f64());
        frames += 1;
        if let Some(s) = &result.sample {
            sink.push(s)?;
            samples += 1;
            if args.level {
                kept.push(*s);
            }
        }
        if !overlay_done {
            if let (Some(path), false) = (&args.overlay, result.detections.is_empty()) {
                overlay(
                    &frame,
                    &result.detections,
                    result.pose.as_ref(),
                    tag_size,
                    &k,
                    path,
                )?;
                overlay_done = true;
            }
        }
        if live && frames.is_multiple_of(150) && samples == 0 {
            eprintln!(
                "{name}: no {} tag {ids} seen yet ({frames} frames)",
                args.family.name(),
            );
        }
    }
    sink.finish()?;
    if samples == 0 {
        return Err(TrackError::NoTag {
            source_name: name,
            family: args.family.name(),
            ids,
            frames,
        }
        .into());
    }
    let median_ms = super::eval::quantile(&mut latency, 0.5) * 1000.0;
    eprintln!(
        "{name}: {samples} samples from {frames} frames ({:.1} % lost), {median_ms:.1} ms per frame",
        100.0 * (frames - samples) as f64 / frames.max(1) as f64
    );
    if args.level {
        let level = super::level::measure(&kept)?;
        println!(
            "the camera looks down {:.1}° (rolled {:.1}°; from {} still samples, up axes \
             within {:.1}° RMS): track with --camera-tilt {:.1}",
            level.tilt_deg,
            (level.roll_deg * 10.0).round() / 10.0 + 0.0,
            level.still,
            level.spread_deg,
            level.tilt_deg
        );
        if level.roll_deg.abs() > 3.0 {
            eprintln!(
                "{name}: the camera is rolled {:.1}°, which --camera-tilt does not undo: \
                 turn it level sideways",
                level.roll_deg
            );
        }
    }
    Ok(())
}

/// Where samples go: a file or stdout, a line per sample as it is made and flushed, so a
/// camera session ended with Ctrl-C keeps every sample and `live` reading the pipe gets each
/// pose at once.
struct Sink {
    out: Option<(String, Box<dyn Write>)>,
}

impl Sink {
    fn open(out: Option<&Path>) -> Result<Self> {
        let (name, mut w): (String, Box<dyn Write>) = match out {
            None => return Ok(Sink { out: None }),
            Some(p) if p == Path::new("-") => ("stdout".into(), Box::new(std::io::stdout())),
            Some(p) => {
                // Fails now, not after the whole video, when the file cannot be made.
                let f = std::fs::File::create(p).map_err(|source| TrackError::Write {
                    path: p.to_path_buf(),
                    source,
                })?;
                (
                    p.display().to_string(),
                    Box::new(std::io::BufWriter::new(f)),
                )
            }
        };
        writeln!(w, "{}", HEADER.join(",")).with_context(|| format!("writing {name}"))?;
        w.flush().with_context(|| format!("writing {name}"))?;
        Ok(Sink {
            out: Some((name, w)),
        })
    }

    fn push(&mut self, s: &PoseSample) -> Result<()> {
        let Some((name, w)) = &mut self.out else {
            return Ok(());
        };
        let mut one = Vec::new();
        PoseLog { samples: vec![*s] }.write(&mut one)?;
        // `write` puts a header first: keep only the sample's line.
        let line = one.splitn(2, |&b| b == b'\n').nth(1).unwrap_or(&[]);
        w.write_all(line)
            .with_context(|| format!("writing {name}"))?;
        w.flush().with_context(|| format!("writing {name}"))
    }

    fn finish(self) -> Result<()> {
        if let Some((name, mut w)) = self.out {
            w.flush().with_context(|| format!("writing {name}"))?;
        }
        Ok(())
    }
}

/// Writes `frame` with the detected corners of every tag (red, the first one larger) and the
/// figurine's axes from its origin (+X left red, +Y up green, +Z front blue, 1.5 tag edges
/// long).
pub fn overlay(
    frame: &super::detect::GrayFrame,
    found: &[Detection],
    pose: Option<&super::detect::CameraPose>,
    tag_size: f64,
    k: &Intrinsics,
    path: &Path,
) -> Result<()> {
    use crate::raster::{fill_rect, line};
    let mut img = RgbImage::from_fn(frame.width as u32, frame.height as u32, |x, y| {
        let v = frame.pixels[y as usize * frame.width + x as usize];
        Rgb([v, v, v])
    });
    let pt = |p: [f64; 2]| (p[0].round() as i64, p[1].round() as i64);
    let red = Rgb([255, 40, 40]);
    for d in found {
        for i in 0..4 {
            line(
                &mut img,
                pt(d.corners[i]),
                pt(d.corners[(i + 1) % 4]),
                Rgb([255, 200, 0]),
            );
            let (x, y) = pt(d.corners[i]);
            let r = if i == 0 { 3 } else { 1 };
            fill_rect(&mut img, x - r, y - r, 2 * r + 1, 2 * r + 1, red);
        }
    }
    if let Some(pose) = pose {
        let (p, q) = super::pose::figurine_pose(pose);
        let (r, t) = camera_pose(p, q);
        let origin = project(k, t);
        let axes = [
            (DVec3::X, red),
            (DVec3::Y, Rgb([40, 220, 40])),
            (DVec3::Z, Rgb([60, 120, 255])),
        ];
        for (axis, colour) in axes {
            // A figurine axis in the camera frame: through the figurine→tag flip.
            let tip = t + r * (super::pose::FLIP_YZ * axis) * tag_size * 1.5;
            if let (Some(a), Some(b)) = (origin, project(k, tip)) {
                let ((ax, ay), (bx, by)) = (pt(a), pt(b));
                for (dx, dy) in [(0, 0), (1, 0), (0, 1)] {
                    line(&mut img, (ax + dx, ay + dy), (bx + dx, by + dy), colour);
                }
            }
        }
    }
    img.save(path)
        .with_context(|| format!("writing {}", path.display()))
}
