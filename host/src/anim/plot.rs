//! Contact sheets for looking at motion: a top view of the root path (with the target path it
//! should follow) and a side view of stick figures at chosen frames. Used by
//! `figurine animate --plot` and by tests that save pictures under `target/`.

use std::path::Path;

use glam::{Vec2, Vec3};
use image::{Rgb, RgbImage};

use crate::motion::Clip;

/// Width and height of the top-view panel, pixels.
pub const PANEL: u32 = 600;
/// Side of one figure cell, pixels (cells sit in a 4 × 3 grid right of the top view).
pub const CELL: u32 = 200;
/// Figure cells per sheet.
pub const MAX_FIGURES: usize = 12;
/// Width of the world square shown in a cell, metres.
const CELL_SPAN_M: f32 = 2.4;

/// Draws the sheet: left, top view (X right, Z down) of the clip's root path (blue) over the
/// target path (red; NaN points break it); right, up to [`MAX_FIGURES`] stick figures at
/// `frames`, each seen from its side (horizontal axis = its facing, from the rig's `forward`
/// carried by the root) over the ground line, dark → light in time.
pub fn contact_sheet(clip: &Clip, frames: &[usize], target: &[Vec3], forward: Vec3) -> RgbImage {
    let mut img = RgbImage::from_pixel(PANEL + 4 * CELL, PANEL, Rgb([255, 255, 255]));
    let root = clip.root_path();
    let top: Vec<Vec2> = root
        .iter()
        .chain(target)
        .map(|p| Vec2::new(p.x, p.z))
        .collect();
    let fit = Fit::new(&top, 0);
    draw_poly(
        &mut img,
        &fit,
        target.iter().map(|p| Vec2::new(p.x, p.z)),
        Rgb([220, 40, 40]),
    );
    draw_poly(
        &mut img,
        &fit,
        root.iter().map(|p| Vec2::new(p.x, p.z)),
        Rgb([40, 60, 220]),
    );
    let chosen: Vec<usize> = frames
        .iter()
        .copied()
        .filter(|&f| f < clip.len())
        .take(MAX_FIGURES)
        .collect();
    let n = chosen.len().max(1) as f32;
    for (k, &f) in chosen.iter().enumerate() {
        let world = clip.skeleton.forward(&clip.frames[f]);
        let Some(r) = world.first() else { continue };
        // Mark the figure's root on the top view.
        let (mx, my) = fit.px(Vec2::new(r.position.x, r.position.z));
        for (dx, dy) in [(-2i32, 0i32), (2, 0), (0, -2), (0, 2), (0, 0)] {
            put(
                &mut img,
                mx as i64 + dx as i64,
                my as i64 + dy as i64,
                Rgb([0, 0, 0]),
            );
        }
        let s = (k as f32 / n * 180.0) as u8;
        let cx = PANEL + (k as u32 % 4) * CELL;
        let cy = (k as u32 / 4) * CELL;
        draw_figure(
            &mut img,
            clip,
            f,
            (cx, cy),
            Rgb([s, s / 2, 255 - s]),
            forward,
        );
        // Cell frame.
        for x in cx..cx + CELL {
            put(&mut img, x as i64, cy as i64, Rgb([220, 220, 220]));
        }
        for y in cy..cy + CELL {
            put(&mut img, cx as i64, y as i64, Rgb([220, 220, 220]));
        }
    }
    img
}

/// Draws frame `f` of `clip` as a stick figure seen from its side (horizontal axis = its
/// facing, from the rig's `forward` carried by the root) over the ground line, in the
/// [`CELL`]-sized cell whose top-left pixel is `cell`; the figure's root sits at the cell's
/// horizontal centre.
fn draw_figure(
    img: &mut RgbImage,
    clip: &Clip,
    f: usize,
    cell: (u32, u32),
    color: Rgb<u8>,
    forward: Vec3,
) {
    let Some(frame) = clip.frames.get(f) else {
        return;
    };
    let world = clip.skeleton.forward(frame);
    let Some(r) = world.first() else { return };
    let fwd = r.rotation * forward;
    let fwd = Vec2::new(fwd.x, fwd.z).normalize_or(Vec2::X);
    let base = Vec2::new(r.position.x, r.position.z);
    let (cx, cy) = cell;
    let to_px = |p: Vec3| -> (f32, f32) {
        let h = (Vec2::new(p.x, p.z) - base).dot(fwd);
        let scale = CELL as f32 / CELL_SPAN_M;
        (
            cx as f32 + CELL as f32 / 2.0 + h * scale,
            cy as f32 + CELL as f32 - 8.0 - p.y * scale,
        )
    };
    line(
        img,
        (cx as f32, to_px(Vec3::ZERO).1),
        ((cx + CELL - 1) as f32, to_px(Vec3::ZERO).1),
        Rgb([150, 150, 150]),
    );
    for (j, joint) in clip.skeleton.joints.iter().enumerate() {
        if let Some(par) = joint.parent {
            if let (Some(a), Some(b)) = (world.get(j), world.get(par)) {
                line(img, to_px(a.position), to_px(b.position), color);
            }
        }
    }
}

/// Draws one row per `(clip, frames)` pair: `per_row` stick figures (as in
/// [`contact_sheet`]) at frames evenly spaced over the range, dark → light in time, each in
/// its own [`CELL`]. Rows set side by side let a reader compare versions of one motion (the
/// effort sheets of `figurine check --defaults --sheets`).
pub fn effort_sheet(
    rows: &[(&Clip, std::ops::RangeInclusive<usize>)],
    per_row: usize,
    forward: Vec3,
) -> RgbImage {
    let per_row = per_row.max(1);
    let mut img = RgbImage::from_pixel(
        per_row as u32 * CELL,
        rows.len().max(1) as u32 * CELL,
        Rgb([255, 255, 255]),
    );
    for (i, (clip, span)) in rows.iter().enumerate() {
        let (a, b) = (
            *span.start(),
            (*span.end()).min(clip.len().saturating_sub(1)),
        );
        for k in 0..per_row {
            let u = if per_row > 1 {
                k as f32 / (per_row - 1) as f32
            } else {
                0.0
            };
            let f = a + (u * b.saturating_sub(a) as f32).round() as usize;
            let s = (u * 180.0) as u8;
            let cell = (k as u32 * CELL, i as u32 * CELL);
            draw_figure(&mut img, clip, f, cell, Rgb([s, s / 2, 255 - s]), forward);
            for x in cell.0..cell.0 + CELL {
                put(&mut img, x as i64, cell.1 as i64, Rgb([220, 220, 220]));
            }
            for y in cell.1..cell.1 + CELL {
                put(&mut img, cell.0 as i64, y as i64, Rgb([220, 220, 220]));
            }
        }
    }
    img
}

/// Saves a contact sheet as PNG.
pub fn save_contact_sheet(
    clip: &Clip,
    frames: &[usize],
    target: &[Vec3],
    forward: Vec3,
    path: &Path,
) -> anyhow::Result<()> {
    contact_sheet(clip, frames, target, forward)
        .save(path)
        .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))
}

/// Maps world ground points into the top-view panel, equal scale on both axes.
struct Fit {
    lo: Vec2,
    scale: f32,
    x0: u32,
}

impl Fit {
    fn new(pts: &[Vec2], x0: u32) -> Fit {
        let finite = pts.iter().filter(|p| p.is_finite());
        let (lo, hi) = finite.fold(
            (Vec2::splat(f32::INFINITY), Vec2::splat(f32::NEG_INFINITY)),
            |(a, b), p| (a.min(*p), b.max(*p)),
        );
        let (lo, hi) = if lo.x <= hi.x {
            (lo, hi)
        } else {
            (Vec2::ZERO, Vec2::ONE)
        };
        let span = (hi - lo).max_element().max(1e-3);
        let pad = 0.05 * span;
        Fit {
            lo: lo - Vec2::splat(pad),
            scale: (PANEL as f32) / (span + 2.0 * pad),
            x0,
        }
    }

    fn px(&self, p: Vec2) -> (f32, f32) {
        let q = (p - self.lo) * self.scale;
        (self.x0 as f32 + q.x, q.y)
    }
}

fn draw_poly(img: &mut RgbImage, fit: &Fit, pts: impl Iterator<Item = Vec2>, color: Rgb<u8>) {
    let mut prev: Option<(f32, f32)> = None;
    for p in pts {
        if !p.is_finite() {
            prev = None;
            continue;
        }
        let q = fit.px(p);
        if let Some(a) = prev {
            line(img, a, q, color);
        }
        prev = Some(q);
    }
}

fn line(img: &mut RgbImage, a: (f32, f32), b: (f32, f32), color: Rgb<u8>) {
    let steps = ((b.0 - a.0).abs().max((b.1 - a.1).abs()).ceil() as usize).clamp(1, 4000);
    for i in 0..=steps {
        let t = i as f32 / steps as f32;
        let x = a.0 + (b.0 - a.0) * t;
        let y = a.1 + (b.1 - a.1) * t;
        for (dx, dy) in [(0, 0), (1, 0), (0, 1)] {
            put(img, x as i64 + dx, y as i64 + dy, color);
        }
    }
}

fn put(img: &mut RgbImage, x: i64, y: i64, color: Rgb<u8>) {
    if x >= 0 && y >= 0 && (x as u32) < img.width() && (y as u32) < img.height() {
        img.put_pixel(x as u32, y as u32, color);
    }
}
