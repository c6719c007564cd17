//! A quick-look picture of a pose log: `figurine synth plot`.
//!
//! Four panels, captioned with the tiny built-in font:
//! * top-left, **top view** (world x → right, z → up, equal aspect): the path from blue (start)
//!   to red (end, by distance travelled), with short grey ticks showing where the figurine's front points every 0.1 s;
//! * top-right, **side view** (horizontal distance along the path's main direction → right,
//!   height → up, equal aspect), same colours;
//! * middle, **speeds** over time: linear speed (black, m/s) and angular speed (orange, rad/s),
//!   each scaled to its own maximum, light grey grid lines at a round step of linear speed
//!   (1, 2 or 5 × 10^k m/s, about four lines), ticks every second, over label spans shaded by effort (sudden = warm, sustained
//!   = cool; strong = dark, light = pale);
//! * bottom, **orientation** over time relative to the first sample's heading: yaw (green,
//!   unwrapped, full height = ±2.2π), pitch of the front (blue, front-down up) and roll
//!   (magenta), both full height = ±π/2.

use std::f64::consts::{PI, TAU};
use std::path::Path;

use anyhow::{Context, Result};
use glam::{DQuat, DVec3};
use image::{Rgb, RgbImage};

use super::effort::{TimeClass, WeightClass};
use super::sequence::Label;
use crate::chart::nice_step;
use crate::poselog::PoseLog;
use crate::raster::{draw_text, text_width};

/// Picture width, pixels.
pub const WIDTH: u32 = 1200;
/// Picture height, pixels.
pub const HEIGHT: u32 = 1000;

/// Length of the heading ticks in the top view, pixels.
const HEADING_TICK_PX: f64 = 12.0;

/// Half-width of the central difference used for speeds, seconds.
const SPEED_HALF_WINDOW_S: f64 = 0.02;

#[derive(Clone, Copy)]
struct Panel {
    x0: f64,
    y0: f64,
    w: f64,
    h: f64,
}

struct Canvas {
    img: RgbImage,
}

impl Canvas {
    fn put(&mut self, x: i64, y: i64, c: Rgb<u8>) {
        if x >= 0 && y >= 0 && (x as u32) < self.img.width() && (y as u32) < self.img.height() {
            self.img.put_pixel(x as u32, y as u32, c);
        }
    }

    fn line(&mut self, a: (f64, f64), b: (f64, f64), c: Rgb<u8>) {
        if !(a.0.is_finite() && a.1.is_finite() && b.0.is_finite() && b.1.is_finite()) {
            return;
        }
        let steps = ((b.0 - a.0).abs().max((b.1 - a.1).abs()).ceil() as i64).clamp(1, 4000);
        for i in 0..=steps {
            let f = i as f64 / steps as f64;
            let x = a.0 + (b.0 - a.0) * f;
            let y = a.1 + (b.1 - a.1) * f;
            self.put(x.round() as i64, y.round() as i64, c);
        }
    }

    fn rect(&mut self, p: Panel, c: Rgb<u8>) {
        let (x1, y1) = (p.x0 + p.w, p.y0 + p.h);
        self.line((p.x0, p.y0), (x1, p.y0), c);
        self.line((x1, p.y0), (x1, y1), c);
        self.line((x1, y1), (p.x0, y1), c);
        self.line((p.x0, y1), (p.x0, p.y0), c);
    }

    fn fill_cols(&mut self, p: Panel, xa: f64, xb: f64, c: Rgb<u8>) {
        let lo = xa.max(p.x0).round() as i64;
        let hi = xb.min(p.x0 + p.w).round() as i64;
        for x in lo..=hi {
            for y in p.y0 as i64..(p.y0 + p.h) as i64 {
                self.put(x, y, c);
            }
        }
    }
}

fn ramp(f: f64) -> Rgb<u8> {
    let f = f.clamp(0.0, 1.0);
    Rgb([(40.0 + 215.0 * f) as u8, 60, (255.0 - 215.0 * f) as u8])
}

/// Equal-aspect mapping of 2-D points into a panel.
fn fit(points: &[(f64, f64)], p: Panel) -> impl Fn((f64, f64)) -> (f64, f64) {
    let (mut lx, mut hx, mut ly, mut hy) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for &(x, y) in points.iter().filter(|q| q.0.is_finite() && q.1.is_finite()) {
        lx = lx.min(x);
        hx = hx.max(x);
        ly = ly.min(y);
        hy = hy.max(y);
    }
    if lx > hx {
        (lx, hx, ly, hy) = (0.0, 1.0, 0.0, 1.0);
    }
    let span = (hx - lx).max(hy - ly).max(0.05) * 1.1;
    let s = p.w.min(p.h) / span;
    let (cx, cy) = ((lx + hx) / 2.0, (ly + hy) / 2.0);
    move |(x, y)| {
        (
            p.x0 + p.w / 2.0 + (x - cx) * s,
            p.y0 + p.h / 2.0 - (y - cy) * s,
        )
    }
}

fn label_colour(l: &Label) -> Rgb<u8> {
    let base: [f64; 3] = match l.time_class {
        TimeClass::Sudden => [255.0, 200.0, 170.0],
        TimeClass::Sustained => [170.0, 210.0, 255.0],
        TimeClass::Neutral => [210.0, 210.0, 210.0],
    };
    let k = match l.weight_class {
        WeightClass::Strong => 0.8,
        WeightClass::Light => 1.0,
        WeightClass::Neutral => 0.9,
    };
    Rgb(base.map(|v| (v * k) as u8))
}

/// Draws the four panels of `log` with optional `labels`.
pub fn plot(log: &PoseLog, labels: &[Label]) -> RgbImage {
    plot_with_handling(log, labels, &[])
}

/// Grey of a span of handling that plays no action.
const HANDLED_GREY: Rgb<u8> = Rgb([225, 225, 225]);

/// Draws the four panels of `log` with `labels`, and `handled` spans (handling that plays no
/// action, [`super::Handling`]) shaded grey and captioned as no action.
pub fn plot_with_handling(log: &PoseLog, labels: &[Label], handled: &[Label]) -> RgbImage {
    let mut c = Canvas {
        img: RgbImage::from_pixel(WIDTH, HEIGHT, Rgb([255, 255, 255])),
    };
    let s = &log.samples;
    let n = s.len();
    let pos: Vec<DVec3> = s.iter().map(|p| DVec3::from_array(p.pos)).collect();
    let quat: Vec<DQuat> = s
        .iter()
        .map(|p| {
            let q = DQuat::from_xyzw(p.quat[1], p.quat[2], p.quat[3], p.quat[0]);
            if q.length_squared() > 0.0 && q.is_finite() {
                q.normalize()
            } else {
                DQuat::IDENTITY
            }
        })
        .collect();
    let grey = Rgb([150, 150, 150]);
    let top = Panel {
        x0: 20.0,
        y0: 20.0,
        w: 570.0,
        h: 440.0,
    };
    let side = Panel {
        x0: 610.0,
        y0: 20.0,
        w: 570.0,
        h: 440.0,
    };
    let speed = Panel {
        x0: 20.0,
        y0: 480.0,
        w: 1160.0,
        h: 250.0,
    };
    let orient = Panel {
        x0: 20.0,
        y0: 750.0,
        w: 1160.0,
        h: 230.0,
    };
    let (t_lo, t_hi) = match (s.first(), s.last()) {
        (Some(a), Some(b)) if b.t > a.t => (a.t, b.t),
        _ => (0.0, 1.0),
    };
    let tx = |p: Panel, t: f64| p.x0 + (t - t_lo) / (t_hi - t_lo) * p.w;
    let shaded = labels
        .iter()
        .map(|l| (l, label_colour(l)))
        .chain(handled.iter().map(|h| (h, HANDLED_GREY)));
    for (l, col) in shaded {
        c.fill_cols(speed, tx(speed, l.start), tx(speed, l.end), col);
        c.fill_cols(orient, tx(orient, l.start), tx(orient, l.end), col);
    }
    for p in [top, side, speed, orient] {
        c.rect(p, grey);
    }
    let ink = Rgb([60, 60, 60]);
    for l in labels {
        let x = tx(speed, l.start) + 3.0;
        let effort = format!(
            "{}-{}",
            short_time(l.time_class),
            short_weight(l.weight_class)
        );
        draw_text(&mut c.img, x as i64, speed.y0 as i64 + 4, &l.action, 2, ink);
        draw_text(&mut c.img, x as i64, speed.y0 as i64 + 22, &effort, 1, ink);
    }
    for h in handled {
        let x = tx(speed, h.start) + 3.0;
        draw_text(&mut c.img, x as i64, speed.y0 as i64 + 4, &h.action, 2, ink);
        draw_text(
            &mut c.img,
            x as i64,
            speed.y0 as i64 + 22,
            "NO ACTION",
            1,
            ink,
        );
    }
    let mut captions: Vec<(Panel, String, bool)> = vec![
        (top, "TOP VIEW X-Z, BLUE TO RED".into(), false),
        (side, "SIDE VIEW, HEIGHT".into(), false),
        (
            orient,
            "YAW GREEN +-2.2PI, PITCH BLUE, ROLL MAGENTA +-PI/2".into(),
            false,
        ),
        (orient, format!("{t_lo:.2} S .. {t_hi:.2} S"), true),
    ];
    if n < 2 {
        draw_captions(&mut c, &captions);
        return c.img;
    }
    // Colour by distance travelled, so the direction of motion shows even after long pauses.
    let mut arc = vec![0.0; n];
    for i in 1..n {
        arc[i] = arc[i - 1] + (pos[i] - pos[i - 1]).length();
    }
    let total = arc[n - 1].max(1e-12);
    let frac = |i: usize| arc[i] / total;

    // Top view with heading ticks.
    let xz: Vec<(f64, f64)> = pos.iter().map(|p| (p.x, p.z)).collect();
    let map = fit(&xz, top);
    // Heading ticks are a fixed number of pixels long, whatever the zoom.
    let metres_per_pixel = {
        let (a, b) = (map((0.0, 0.0)), map((1.0, 0.0)));
        1.0 / (b.0 - a.0).abs().max(1e-9)
    };
    let tick_len = HEADING_TICK_PX * metres_per_pixel;
    let mut next_tick = t_lo;
    for i in 1..n {
        c.line(map(xz[i - 1]), map(xz[i]), ramp(frac(i)));
        if s[i].t >= next_tick {
            next_tick = s[i].t + 0.1;
            let f = quat[i] * DVec3::Z;
            let h = DVec3::new(f.x, 0.0, f.z).normalize_or_zero() * tick_len;
            c.line(map(xz[i]), map((xz[i].0 + h.x, xz[i].1 + h.z)), grey);
        }
    }

    // Side view along the main horizontal direction (first sample to the farthest one).
    let far = pos
        .iter()
        .map(|p| DVec3::new(p.x - pos[0].x, 0.0, p.z - pos[0].z))
        .fold(
            DVec3::ZERO,
            |a, d| if d.length() > a.length() { d } else { a },
        );
    let dir = if far.length() > 0.02 {
        far.normalize()
    } else {
        DVec3::X
    };
    let sy: Vec<(f64, f64)> = pos.iter().map(|p| ((*p - pos[0]).dot(dir), p.y)).collect();
    let map = fit(&sy, side);
    for i in 1..n {
        c.line(map(sy[i - 1]), map(sy[i]), ramp(frac(i)));
    }

    // Speeds by central differences over ±SPEED_HALF_WINDOW_S.
    let mut lin = vec![0.0; n];
    let mut ang = vec![0.0; n];
    let (mut j, mut k) = (0usize, 0usize);
    for i in 0..n {
        while j + 1 < i && s[j + 1].t <= s[i].t - SPEED_HALF_WINDOW_S {
            j += 1;
        }
        k = k.max(i);
        while k + 1 < n && s[k].t < s[i].t + SPEED_HALF_WINDOW_S {
            k += 1;
        }
        let dt = s[k].t - s[j].t;
        if dt > 0.0 {
            lin[i] = (pos[k] - pos[j]).length() / dt;
            ang[i] = quat[k].angle_between(quat[j]) / dt;
        }
    }
    let lmax = lin.iter().cloned().fold(1e-9, f64::max);
    let amax = ang.iter().cloned().fold(1e-9, f64::max);
    let vy = |v: f64, m: f64| speed.y0 + speed.h - v / m * speed.h * 0.95;
    // Grid: light lines at a round step of linear speed, ticks every second of log time.
    let step = nice_step(lmax / 4.0);
    captions.push((
        speed,
        format!(
            "SPEED BLACK, PEAK {lmax:.2} M/S, GRID {step} M/S; ANGULAR ORANGE, PEAK {amax:.1} RAD/S"
        ),
        false,
    ));
    let mut g = step;
    while g < lmax {
        let y = vy(g, lmax);
        c.line((speed.x0, y), (speed.x0 + speed.w, y), Rgb([225, 225, 225]));
        g += step;
    }
    let mut sec = t_lo.ceil();
    while sec <= t_hi {
        for p in [speed, orient] {
            let x = tx(p, sec);
            c.line((x, p.y0 + p.h - 8.0), (x, p.y0 + p.h), grey);
        }
        sec += 1.0;
    }
    for i in 1..n {
        let (xa, xb) = (tx(speed, s[i - 1].t), tx(speed, s[i].t));
        c.line(
            (xa, vy(ang[i - 1], amax)),
            (xb, vy(ang[i], amax)),
            Rgb([240, 140, 0]),
        );
        c.line(
            (xa, vy(lin[i - 1], lmax)),
            (xb, vy(lin[i], lmax)),
            Rgb([0, 0, 0]),
        );
    }

    // Orientation angles.
    let mid = orient.y0 + orient.h / 2.0;
    c.line((orient.x0, mid), (orient.x0 + orient.w, mid), grey);
    let oy = |a: f64, range: f64| mid - (a / range).clamp(-1.0, 1.0) * orient.h / 2.0;
    let ranges = [2.2 * PI, PI / 2.0, PI / 2.0];
    let y0 = quat.first().map_or(0.0, |q| {
        let f = *q * DVec3::Z;
        f.x.atan2(f.z)
    });
    let mut prev: Option<(f64, [f64; 3])> = None;
    let mut prev_raw = y0;
    let mut yaw_unwrapped = 0.0;
    let cols = [Rgb([0, 160, 0]), Rgb([0, 60, 220]), Rgb([200, 0, 200])];
    for i in 0..n {
        let f = quat[i] * DVec3::Z;
        let up = quat[i] * DVec3::Y;
        let yaw = f.x.atan2(f.z);
        let pitch = (-f.y).clamp(-1.0, 1.0).asin();
        let left_h = DVec3::new(f.z, 0.0, -f.x).normalize_or_zero();
        let roll = (-up.dot(left_h)).clamp(-1.0, 1.0).asin();
        let d = (yaw - prev_raw + PI).rem_euclid(TAU) - PI;
        yaw_unwrapped += d;
        prev_raw = yaw;
        let cur = [yaw_unwrapped, pitch, roll];
        let x = tx(orient, s[i].t);
        if let Some((px, pa)) = prev {
            for a in 0..3 {
                c.line(
                    (px, oy(pa[a], ranges[a])),
                    (x, oy(cur[a], ranges[a])),
                    cols[a],
                );
            }
        }
        prev = Some((x, cur));
    }
    draw_captions(&mut c, &captions);
    c.img
}

/// Writes each caption at the bottom (left, or right when flagged) of its panel, on white.
fn draw_captions(c: &mut Canvas, captions: &[(Panel, String, bool)]) {
    for (p, text, right) in captions {
        let w = f64::from(text_width(text, 2));
        let x = if *right {
            p.x0 + p.w - w - 4.0
        } else {
            p.x0 + 4.0
        };
        let y = p.y0 + p.h - 19.0;
        for py in y as i64..(y + 17.0) as i64 {
            for px in (x - 2.0) as i64..(x + w + 1.0) as i64 {
                c.put(px, py, Rgb([255, 255, 255]));
            }
        }
        draw_text(
            &mut c.img,
            x as i64,
            y as i64 + 2,
            text,
            2,
            Rgb([60, 60, 60]),
        );
    }
}

/// Tiles small copies of several plots into one picture, `cols` per row, in order, each with
/// its caption written on top.
pub fn gallery(pictures: &[(RgbImage, String)], cols: u32) -> RgbImage {
    let cols = cols.max(1);
    let (cw, ch) = (WIDTH / 3, HEIGHT / 3);
    let rows = (pictures.len() as u32).div_ceil(cols).max(1);
    let mut out = RgbImage::from_pixel(cols * cw, rows * ch, Rgb([255, 255, 255]));
    for (i, (pic, caption)) in pictures.iter().enumerate() {
        let small =
            image::imageops::resize(pic, cw - 6, ch - 6, image::imageops::FilterType::Triangle);
        let (x, y) = ((i as u32 % cols) * cw + 3, (i as u32 / cols) * ch + 3);
        image::imageops::replace(&mut out, &small, i64::from(x), i64::from(y));
        draw_text(
            &mut out,
            i64::from(x) + 6,
            i64::from(y) + 6,
            caption,
            2,
            Rgb([0, 0, 0]),
        );
    }
    out
}

fn short_time(t: TimeClass) -> &'static str {
    match t {
        TimeClass::Sudden => "SUDDEN",
        TimeClass::Sustained => "SUSTAINED",
        TimeClass::Neutral => "NEUTRAL",
    }
}

fn short_weight(w: WeightClass) -> &'static str {
    match w {
        WeightClass::Strong => "STRONG",
        WeightClass::Light => "LIGHT",
        WeightClass::Neutral => "NEUTRAL",
    }
}

/// The handled spans a generated log records in its `# handled KIND START..END` lines (see
/// [`super::Doodle::write_csv`]); other lines, and malformed ones, are skipped.
pub fn handled_spans(text: &str) -> Vec<Label> {
    text.lines()
        .filter_map(|l| l.strip_prefix("# handled "))
        .filter_map(|rest| {
            let (kind, span) = rest.trim().split_once(' ')?;
            let (a, b) = span.split_once("..")?;
            let (start, end) = (a.trim().parse().ok()?, b.trim().parse().ok()?);
            Some(Label {
                action: kind.to_string(),
                start,
                end,
                time_class: TimeClass::Neutral,
                weight_class: WeightClass::Neutral,
            })
        })
        .collect()
}

/// Reads a pose log (and labels JSON), plots it with the handling it records, and writes the
/// PNG.
pub fn plot_files(log: &Path, labels: Option<&Path>, out: &Path) -> Result<()> {
    // Read once: the samples and the `# handled` lines come from the same bytes.
    let bytes = std::fs::read(log).with_context(|| format!("reading {}", log.display()))?;
    let pl = PoseLog::read(bytes.as_slice(), log)?;
    let handled = handled_spans(&String::from_utf8_lossy(&bytes));
    let labels: Vec<Label> = match labels {
        Some(p) => {
            let text =
                std::fs::read_to_string(p).with_context(|| format!("reading {}", p.display()))?;
            serde_json::from_str(&text).with_context(|| format!("parsing {}", p.display()))?
        }
        None => Vec::new(),
    };
    plot_with_handling(&pl, &labels, &handled)
        .save(out)
        .with_context(|| format!("writing {}", out.display()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synth::{sequence, Knobs};

    #[test]
    fn handled_spans_come_back_from_a_written_log_and_are_shaded() {
        let knobs = Knobs {
            handling: 1.0,
            ..Knobs::default()
        };
        let d = sequence(5, &knobs, 2, None);
        let path = std::env::temp_dir().join(format!("figurine-plot-{}.csv", std::process::id()));
        d.write_csv(&path).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        std::fs::remove_file(&path).ok();
        let spans = handled_spans(&text);
        assert_eq!(spans.len(), 1);
        assert_eq!(spans[0].action, d.handled[0].action);
        assert!((spans[0].start - d.handled[0].start).abs() < 1e-6);
        assert!((spans[0].end - d.handled[0].end).abs() < 1e-6);
        // Malformed lines are skipped.
        assert!(handled_spans("# handled lift\n# handled lift a..b\n").is_empty());
        // The span is shaded grey in the speed panel, where nothing else is.
        let bare = plot(&d.log, &d.labels);
        let shaded = plot_with_handling(&d.log, &d.labels, &spans);
        let greys = |img: &RgbImage| img.pixels().filter(|p| **p == HANDLED_GREY).count();
        assert!(greys(&shaded) > greys(&bare) + 1000);
    }
}
