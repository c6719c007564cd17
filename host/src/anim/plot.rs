//! Contact sheets for looking at motion: a top view of the root path (with the target path it
//! should follow) and a side view of stick figures at chosen frames. Used by
//! `figurine animate --plot` and by tests that save pictures under `target/`.

use std::path::Path;

use glam::{Vec2, Vec3};
use image::{Rgb, RgbImage};

use crate::motion::Clip;

/// Width and height of one panel, pixels.
pub const PANEL: u32 = 600;

/// Draws the sheet: left, top view (X right, Z down) of the clip's root path (blue), the
/// target path (red) and the feet's lowest points; right, side view (X right, Y up) of stick
/// figures at `frames` (dark → light in time) over the ground line.
pub fn contact_sheet(clip: &Clip, frames: &[usize], target: &[Vec3]) -> RgbImage {
    let mut img = RgbImage::from_pixel(PANEL * 2, PANEL, Rgb([255, 255, 255]));
    let root = clip.root_path();
    // Top view.
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
    // Side view.
    let poses: Vec<(usize, Vec<Vec3>)> = frames
        .iter()
        .filter(|&&f| f < clip.len())
        .map(|&f| (f, clip.joint_positions(f)))
        .collect();
    let mut pts: Vec<Vec2> = poses
        .iter()
        .flat_map(|(_, p)| p.iter().map(|v| Vec2::new(v.x, v.y)))
        .collect();
    pts.push(Vec2::ZERO);
    let fit = Fit::new(&pts, PANEL);
    let (gx0, gx1) = pts
        .iter()
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), p| {
            (a.min(p.x), b.max(p.x))
        });
    draw_poly(
        &mut img,
        &fit,
        [Vec2::new(gx0, 0.0), Vec2::new(gx1, 0.0)].into_iter(),
        Rgb([120, 120, 120]),
    );
    let n = poses.len().max(1) as f32;
    for (i, (_, p)) in poses.iter().enumerate() {
        let s = (i as f32 / n * 180.0) as u8;
        let color = Rgb([s, s / 2, 255 - s]);
        for (j, joint) in clip.skeleton.joints.iter().enumerate() {
            if let (Some(par), Some(a)) = (joint.parent, p.get(j)) {
                if let Some(b) = p.get(par) {
                    draw_poly(
                        &mut img,
                        &fit,
                        [Vec2::new(a.x, a.y), Vec2::new(b.x, b.y)].into_iter(),
                        color,
                    );
                }
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
    path: &Path,
) -> anyhow::Result<()> {
    contact_sheet(clip, frames, target)
        .save(path)
        .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))
}

/// Maps world 2-D points into one panel, equal scale on both axes, Y up for side views.
struct Fit {
    lo: Vec2,
    scale: f32,
    x0: u32,
    flip_y: bool,
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
            flip_y: x0 > 0,
        }
    }

    fn px(&self, p: Vec2) -> (f32, f32) {
        let q = (p - self.lo) * self.scale;
        let y = if self.flip_y { PANEL as f32 - q.y } else { q.y };
        (self.x0 as f32 + q.x, y)
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
            let (px, py) = (x as i64 + dx, y as i64 + dy);
            if px >= 0 && py >= 0 && (px as u32) < img.width() && (py as u32) < img.height() {
                img.put_pixel(px as u32, py as u32, color);
            }
        }
    }
}
