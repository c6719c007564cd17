//! A software rasteriser for test videos: a figurine — a printed tag on a card on its chest,
//! or a box with a tag on each side ([`super::body`]) — seen by a pinhole camera at 640×480
//! in grey, with the faults of a webcam — motion blur over the exposure, defocus, sensor
//! noise, light that drifts and a finger that sometimes covers part of a card. Seeded: the
//! same scene and seed give the same frames.
//!
//! Each panel of the body is a plane; a pixel is coloured by sending it back through each
//! plane's homography to the panel's coordinates (metres, u right and v down as seen from
//! outside), and the nearest panel there wins.

use glam::{DMat3, DQuat, DVec3};

use super::body::{Body, Panel};
use super::detect::{GrayFrame, Intrinsics};
use super::pose::camera_pose;
use crate::poselog::PoseSample;
use crate::synth::rng::SynthRng;

/// Grey level of the finger that occludes.
const SKIN: f64 = 160.0;

/// Webcam faults laid over the frames.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Faults {
    /// Exposure time, seconds: motion within it blurs (a webcam indoors: 5–15 ms).
    pub exposure_s: f64,
    /// Defocus blur σ, pixels.
    pub defocus_px: f64,
    /// Sensor noise σ, grey levels.
    pub noise: f64,
    /// Swing of the light level, as a fraction (0.3: from 70 % to 130 %), plus a gradient of
    /// half that across the frame.
    pub light_swing: f64,
    /// Time between a finger passing over a corner of the card for 0.3 s, seconds (0: never;
    /// 10 s covers 3 % of the frames).
    pub occlusion_every_s: f64,
}

impl Default for Faults {
    fn default() -> Self {
        Self {
            exposure_s: 0.008,
            defocus_px: 0.7,
            noise: 2.5,
            light_swing: 0.3,
            occlusion_every_s: 10.0,
        }
    }
}

/// What is in view: the figurine's body with its tags, the camera.
#[derive(Debug, Clone)]
pub struct Scene {
    /// Frame width, pixels.
    pub width: usize,
    /// Frame height, pixels.
    pub height: usize,
    /// The camera.
    pub intrinsics: Intrinsics,
    /// The figurine: its panels and the tags printed on them.
    pub body: Body,
    /// The webcam's faults.
    pub faults: Faults,
    /// Seed of the noise, light and occlusion.
    pub seed: u64,
    /// The camera's frame in the world ([`super::pose::camera_tilt`]; identity: level).
    pub camera: DQuat,
}

/// One rendered frame and what it shows.
#[derive(Debug, Clone)]
pub struct Rendered {
    /// The picture.
    pub frame: GrayFrame,
    /// Whether a finger covered part of a tag in this frame (it may be lost then): the one
    /// most turned toward the camera.
    pub occluded: bool,
}

/// A panel's homography from (u, v, 1) in metres to pixels, which side faces the camera, and
/// its depth along the optical axis as a function of (u, v).
struct PlaneView {
    panel: usize,
    inv: DMat3,
    front: bool,
    /// Depth (metres) = `depth[0] u + depth[1] v + depth[2]`.
    depth: [f64; 3],
    /// How squarely it faces the camera: the cosine between its normal and the line of
    /// sight to its centre (negative: its back).
    facing: f64,
}

impl PlaneView {
    fn new(k: &Intrinsics, panel: usize, pos: DVec3, q: DQuat) -> Option<Self> {
        let (r, t) = camera_pose(pos, q);
        if t.z <= 0.05 {
            return None;
        }
        let kmat = DMat3::from_cols(
            DVec3::new(k.fx, 0.0, 0.0),
            DVec3::new(0.0, k.fy, 0.0),
            DVec3::new(k.cx, k.cy, 1.0),
        );
        let h = kmat * DMat3::from_cols(r.x_axis, r.y_axis, t);
        if h.determinant().abs() < 1e-12 {
            return None;
        }
        // The tag's z points into the card: the printed side faces the camera when z points
        // away from it, along the line of sight.
        let facing = r.z_axis.dot(t) / t.length();
        Some(Self {
            panel,
            inv: h.inverse(),
            front: facing > 0.0,
            depth: [r.x_axis.z, r.y_axis.z, t.z],
            facing,
        })
    }

    /// Plane point under pixel (x, y); `None` where the ray misses the plane's front half-space.
    fn plane_at(&self, x: f64, y: f64) -> Option<(f64, f64)> {
        let p = self.inv * DVec3::new(x, y, 1.0);
        (p.z.abs() > 1e-12).then(|| (p.x / p.z, p.y / p.z))
    }
}

impl Scene {
    /// A world pose's position and orientation in the camera's frame.
    pub fn in_camera(&self, pose: &PoseSample) -> (DVec3, DQuat) {
        let to_camera = self.camera.inverse();
        let q = DQuat::from_xyzw(pose.quat[1], pose.quat[2], pose.quat[3], pose.quat[0]);
        (
            to_camera * DVec3::from_array(pose.pos),
            (to_camera * q).normalize(),
        )
    }

    /// The views of the body's panels at the pose (the backs of a closed box's faces left
    /// out).
    fn views(&self, pose: &PoseSample) -> Vec<PlaneView> {
        let (pos, q) = self.in_camera(pose);
        self.body
            .panels
            .iter()
            .enumerate()
            .filter_map(|(i, panel)| {
                let (p, pq) = self.body.panel_pose(panel, pos, q);
                PlaneView::new(&self.intrinsics, i, p, pq)
            })
            .filter(|v| v.front || self.body.panels[v.panel].two_sided)
            .collect()
    }

    /// Grey level at pixel (x, y) of the nearest panel there, `None` where no panel is.
    fn sample(&self, views: &[PlaneView], x: f64, y: f64) -> Option<f64> {
        let mut best: Option<(f64, f64)> = None;
        for v in views {
            let Some((u, vv)) = v.plane_at(x, y) else {
                continue;
            };
            let Some(g) = self.body.shade(&self.body.panels[v.panel], u, vv, v.front) else {
                continue;
            };
            let z = v.depth[0] * u + v.depth[1] * vv + v.depth[2];
            if best.is_none_or(|(bz, _)| z < bz) {
                best = Some((z, g));
            }
        }
        best.map(|(_, g)| g)
    }

    /// Whether pixel (x, y) lies on or near (within `margin` metres of) a tag's card, where
    /// edges need fine sampling.
    fn near_card(&self, views: &[PlaneView], x: f64, y: f64, margin: f64) -> bool {
        views.iter().any(|v| {
            let panel = &self.body.panels[v.panel];
            panel.tag.is_some()
                && v.plane_at(x, y).is_some_and(|(u, vv)| {
                    u.abs().max(vv.abs()) <= self.body.half_card(panel) + margin
                })
        })
    }

    /// A still background with some texture (a room: edges and soft blobs), seeded.
    pub fn background(&self) -> Vec<f64> {
        let mut rng = SynthRng::from_u64(self.seed ^ 0xb6);
        let waves: Vec<(f64, f64, f64, f64)> = (0..6)
            .map(|_| {
                (
                    rng.uniform(0.005, 0.05),
                    rng.uniform(0.005, 0.05),
                    rng.uniform(0.0, 6.3),
                    rng.uniform(8.0, 25.0),
                )
            })
            .collect();
        let edge = rng.uniform(0.3, 0.7) * self.width as f64;
        let mut bg = Vec::with_capacity(self.width * self.height);
        for y in 0..self.height {
            for x in 0..self.width {
                let (xf, yf) = (x as f64, y as f64);
                let mut v = if xf < edge { 140.0 } else { 95.0 };
                for &(a, b, p, amp) in &waves {
                    v += amp * (a * xf + b * yf + p).sin();
                }
                bg.push(v);
            }
        }
        bg
    }

    /// Renders the frame at `t` (seconds of the log's clock; `index` numbers the frame for the
    /// noise) with the figurine's pose over the exposure given by `pose_at`.
    pub fn render(
        &self,
        background: &[f64],
        index: u64,
        t: f64,
        pose_at: impl Fn(f64) -> Option<PoseSample>,
    ) -> Rendered {
        let (w, h) = (self.width, self.height);
        let mut img: Vec<f64> = background.to_vec();
        img.resize(w * h, 128.0);
        // Motion blur: the exposure is averaged over a few instants.
        const SUB: usize = 4;
        let views: Vec<Vec<PlaneView>> = (0..SUB)
            .map(|i| {
                let dt = self.faults.exposure_s * ((i as f64 + 0.5) / SUB as f64 - 0.5);
                pose_at(t + dt).map_or_else(Vec::new, |p| self.views(&p))
            })
            .collect();
        let bbox = self.bbox(&views, t, &pose_at);
        if let Some(bbox) = bbox {
            let (x0, y0, x1, y1) = bbox;
            // 16 samples per pixel, 4 in each sub-exposure on grids shifted by a quarter
            // pixel: coarser sampling quantises an edge's place within its pixel enough to
            // bias the detected corners by a tenth of a pixel (1.5 % of depth at 1 m).
            let offsets: Vec<[(f64, f64); 4]> = (0..views.len())
                .map(|i| {
                    let (ox, oy) = ((i % 2) as f64 * 0.25, ((i / 2) % 2) as f64 * 0.25);
                    [0.125, 0.625]
                        .iter()
                        .flat_map(|&sy| [0.125, 0.625].map(|sx| (sx + ox, sy + oy)))
                        .collect::<Vec<_>>()
                        .try_into()
                        .unwrap_or([(0.5, 0.5); 4])
                })
                .collect();
            // Only the cards need the fine sampling: away from them (by `margin` in the plane,
            // tens of pixels) one sample per sub-exposure draws the body and the room.
            let margin = 0.01;
            let mid = &views[views.len() / 2];
            for y in y0..y1 {
                for x in x0..x1 {
                    let coarse = !self.near_card(mid, x as f64 + 0.5, y as f64 + 0.5, margin);
                    let mut sum = 0.0;
                    let mut n = 0.0;
                    for (view, offs) in views.iter().zip(&offsets) {
                        let offs: &[(f64, f64)] = if coarse { &offs[..1] } else { offs };
                        for &(sx, sy) in offs {
                            let (px, py) = (x as f64 + sx, y as f64 + sy);
                            let g = self.sample(view, px, py).unwrap_or(background[y * w + x]);
                            sum += g;
                            n += 1.0;
                        }
                    }
                    img[y * w + x] = sum / n;
                }
            }
        }
        let occluded = self.occlude(&mut img, t, &views);
        self.light(&mut img, t);
        if self.faults.defocus_px > 0.0 {
            // Only around the figurine: the room is smooth already, and blurring all of it
            // would be most of a frame's time.
            if let Some((x0, y0, x1, y1)) = bbox {
                let pad = 8;
                let (x0, y0) = (x0.saturating_sub(pad), y0.saturating_sub(pad));
                let (x1, y1) = ((x1 + pad).min(w), (y1 + pad).min(h));
                let (bw, bh) = (x1 - x0, y1 - y0);
                let mut part: Vec<f64> = (y0..y1)
                    .flat_map(|y| img[y * w + x0..y * w + x1].iter().copied())
                    .collect();
                gaussian_blur(&mut part, bw, bh, self.faults.defocus_px);
                for (row, y) in (y0..y1).enumerate() {
                    img[y * w + x0..y * w + x1].copy_from_slice(&part[row * bw..(row + 1) * bw]);
                }
            }
        }
        let mut rng = SynthRng::from_u64(self.seed.wrapping_mul(0x9e37) ^ index);
        let sigma = self.faults.noise;
        let pixels = img
            .iter()
            .map(|&v| {
                // Irwin–Hall: four 16-bit uniforms from one draw make a near-normal variate
                // (σ 1) without a logarithm per pixel.
                let n = if sigma > 0.0 {
                    let r = rng.next_u64();
                    let sum: f64 = (0..4).map(|k| ((r >> (16 * k)) & 0xffff) as f64).sum();
                    sigma * (sum / 65535.0 - 2.0) * 3f64.sqrt()
                } else {
                    0.0
                };
                (v + n).round().clamp(0.0, 255.0) as u8
            })
            .collect();
        Rendered {
            frame: GrayFrame {
                width: w,
                height: h,
                pixels,
            },
            occluded,
        }
    }

    /// Pixel box (x0, y0, x1, y1) holding the body in every sub-exposure view.
    fn bbox(
        &self,
        views: &[Vec<PlaneView>],
        t: f64,
        pose_at: &impl Fn(f64) -> Option<PoseSample>,
    ) -> Option<(usize, usize, usize, usize)> {
        let (mut x0, mut y0, mut x1, mut y1) = (f64::MAX, f64::MAX, f64::MIN, f64::MIN);
        let mut any = false;
        for i in 0..views.len() {
            let dt = self.faults.exposure_s * ((i as f64 + 0.5) / views.len() as f64 - 0.5);
            let Some(p) = pose_at(t + dt) else { continue };
            let (pos, q) = self.in_camera(&p);
            for panel in &self.body.panels {
                let (pp, pq) = self.body.panel_pose(panel, pos, q);
                let (r, c) = camera_pose(pp, pq);
                for (u, v) in panel_corners(panel) {
                    let q = r * DVec3::new(u, v, 0.0) + c;
                    let Some([px, py]) = super::pose::project(&self.intrinsics, q) else {
                        return Some((0, 0, self.width, self.height));
                    };
                    x0 = x0.min(px);
                    y0 = y0.min(py);
                    x1 = x1.max(px);
                    y1 = y1.max(py);
                    any = true;
                }
            }
        }
        if !any {
            return None;
        }
        let clip = |v: f64, hi: usize| v.clamp(0.0, hi as f64) as usize;
        let b = (
            clip(x0.floor() - 2.0, self.width),
            clip(y0.floor() - 2.0, self.height),
            clip(x1.ceil() + 2.0, self.width),
            clip(y1.ceil() + 2.0, self.height),
        );
        (b.0 < b.2 && b.1 < b.3).then_some(b)
    }

    /// Lays a finger over a corner of a card during occlusion episodes — the card most
    /// turned toward the camera —; whether it covers a tag's pattern.
    fn occlude(&self, img: &mut [f64], t: f64, views: &[Vec<PlaneView>]) -> bool {
        let every = self.faults.occlusion_every_s;
        if every <= 0.0 {
            return false;
        }
        // Episodes of 0.3 s start at seeded times, one per `every` seconds on average.
        let slot = (t / every).floor();
        let mut rng = SynthRng::from_u64(self.seed ^ 0x0cc1 ^ (slot as i64 as u64));
        let start = slot * every + rng.uniform(0.0, (every - 0.3).max(0.0));
        let corner = rng.index(4);
        if t < start || t > start + 0.3 {
            return false;
        }
        let Some(view) = views[views.len() / 2]
            .iter()
            .filter(|v| self.body.panels[v.panel].tag.is_some())
            .max_by(|a, b| a.facing.total_cmp(&b.facing))
        else {
            return false;
        };
        let panel = &self.body.panels[view.panel];
        let (cell, border) = (
            self.body.cell(panel),
            panel.tag.as_ref().map_or(0, |t| t.border_width),
        );
        // The finger's tip sits a cell inside the pattern's corner; its width one fifth of
        // the tag, reaching outward off the card.
        let Ok(fwd) = view_forward(view) else {
            return false;
        };
        let half = cell * border as f64 / 2.0 - cell;
        let (su, sv) = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)][corner];
        let tip = fwd * DVec3::new(su * half, sv * half, 1.0);
        let out = fwd * DVec3::new(su * half * 3.0, sv * half * 3.0, 1.0);
        let (tip, out) = (tip.truncate() / tip.z, out.truncate() / out.z);
        let radius = ((out - tip).length() / 6.0).max(2.0);
        let (w, h) = (self.width, self.height);
        let x0 = (tip.x.min(out.x) - radius).max(0.0) as usize;
        let x1 = ((tip.x.max(out.x) + radius).max(0.0) as usize).min(w);
        let y0 = (tip.y.min(out.y) - radius).max(0.0) as usize;
        let y1 = ((tip.y.max(out.y) + radius).max(0.0) as usize).min(h);
        let seg = out - tip;
        let len2 = seg.length_squared().max(1e-9);
        for y in y0..y1 {
            for x in x0..x1 {
                let p = glam::DVec2::new(x as f64 + 0.5, y as f64 + 0.5);
                let s = ((p - tip).dot(seg) / len2).clamp(0.0, 1.0);
                if (p - (tip + seg * s)).length() < radius {
                    img[y * w + x] = SKIN;
                }
            }
        }
        true
    }

    /// Scales the picture by a light level drifting over time and across the frame.
    fn light(&self, img: &mut [f64], t: f64) {
        let swing = self.faults.light_swing;
        if swing <= 0.0 {
            return;
        }
        let phase = (self.seed % 1000) as f64 * 0.01;
        let level = 1.0 + swing * (std::f64::consts::TAU * t / 3.7 + phase).sin();
        let w = self.width as f64;
        for (i, v) in img.iter_mut().enumerate() {
            let x = (i % self.width) as f64 / w - 0.5;
            *v *= level * (1.0 + 0.5 * swing * x);
        }
    }
}

/// A panel's four corners in its plane coordinates (u, v), metres.
fn panel_corners(panel: &Panel) -> [(f64, f64); 4] {
    let (w, top, bottom) = (panel.half_width, panel.top, panel.bottom);
    [(-w, -top), (w, -top), (w, bottom), (-w, bottom)]
}

/// The plane's homography to pixels (the inverse of the stored one).
fn view_forward(view: &PlaneView) -> Result<DMat3, ()> {
    let h = view.inv.inverse();
    if h.is_finite() {
        Ok(h)
    } else {
        Err(())
    }
}

/// In-place separable Gaussian blur of σ pixels (edges clamped).
pub fn gaussian_blur(img: &mut [f64], w: usize, h: usize, sigma: f64) {
    let r = (2.5 * sigma).ceil().max(1.0) as isize;
    let kernel: Vec<f64> = (-r..=r)
        .map(|i| (-(i * i) as f64 / (2.0 * sigma * sigma)).exp())
        .collect();
    let total: f64 = kernel.iter().sum();
    let kernel: Vec<f64> = kernel.iter().map(|k| k / total).collect();
    let mut tmp = vec![0.0; img.len()];
    // Rows, then columns: one pass along `len` samples `step` apart, for `lines` lines
    // starting `across` apart.
    let pass =
        |src: &[f64], dst: &mut [f64], len: usize, step: usize, lines: usize, across: usize| {
            for line in 0..lines {
                for i in 0..len {
                    let mut s = 0.0;
                    for (j, k) in kernel.iter().enumerate() {
                        let ii = (i as isize + j as isize - r).clamp(0, len as isize - 1) as usize;
                        s += k * src[line * across + ii * step];
                    }
                    dst[line * across + i * step] = s;
                }
            }
        };
    pass(img, &mut tmp, w, 1, h, w);
    pass(&tmp, img, h, w, w, 1);
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::track::detect::{tag_pattern, Detector, DetectorSettings, Family};
    use crate::track::pose::{angle_between_deg, figurine_pose, intrinsics_from_fov};
    use glam::DQuat;

    /// The tests' scene: 640×480 at 60°, a 4 cm tag36h11 #0, `faults`, noise seed `seed`.
    pub(crate) fn test_scene(faults: Faults, seed: u64) -> Scene {
        Scene {
            width: 640,
            height: 480,
            intrinsics: intrinsics_from_fov(640, 480, 60.0),
            body: Body::chest(tag_pattern(Family::Tag36h11, 0).unwrap(), 0.04),
            faults,
            seed,
            camera: DQuat::IDENTITY,
        }
    }

    fn scene(faults: Faults) -> Scene {
        test_scene(faults, 3)
    }

    #[test]
    fn a_rendered_still_tag_is_found_where_it_was_put() {
        let s = scene(Faults {
            occlusion_every_s: 0.0,
            ..Faults::default()
        });
        let q = DQuat::from_euler(glam::EulerRot::YXZ, 0.5, -0.3, 0.2);
        let pose = PoseSample {
            t: 0.0,
            pos: [0.05, -0.03, -0.6],
            quat: [q.w, q.x, q.y, q.z],
        };
        let bg = s.background();
        let r = s.render(&bg, 0, 0.0, |_| Some(pose));
        let mut d = Detector::new(Family::Tag36h11, DetectorSettings::default()).unwrap();
        let found = d.detect(&r.frame);
        assert_eq!(found.len(), 1, "one tag");
        let solved = crate::track::pnp::solve_pose(&found[0].corners, 0.04, &s.intrinsics, None);
        let (p, q2) = figurine_pose(&solved.unwrap());
        let err_mm = (p - DVec3::from_array(pose.pos)).length() * 1000.0;
        assert!(err_mm < 10.0, "position off by {err_mm} mm");
        let err_deg = angle_between_deg(q, q2);
        assert!(err_deg < 3.0, "orientation off by {err_deg}°");
    }

    #[test]
    fn the_back_of_the_figurine_shows_no_tag() {
        let s = scene(Faults::default());
        let q = DQuat::from_rotation_y(std::f64::consts::PI);
        let pose = PoseSample {
            t: 0.0,
            pos: [0.0, 0.0, -0.5],
            quat: [q.w, q.x, q.y, q.z],
        };
        let r = s.render(&s.background(), 0, 0.0, |_| Some(pose));
        let mut d = Detector::new(Family::Tag36h11, DetectorSettings::default()).unwrap();
        assert!(d.detect(&r.frame).is_empty());
    }

    #[test]
    fn rendering_is_seeded() {
        let s = scene(Faults::default());
        let pose = PoseSample {
            t: 0.0,
            pos: [0.0, 0.0, -0.7],
            quat: [1.0, 0.0, 0.0, 0.0],
        };
        let bg = s.background();
        let a = s.render(&bg, 5, 0.2, |_| Some(pose));
        let b = s.render(&bg, 5, 0.2, |_| Some(pose));
        assert_eq!(a.frame, b.frame);
        let c = s.render(&bg, 6, 0.2, |_| Some(pose));
        assert_ne!(a.frame, c.frame, "noise differs frame to frame");
    }
}
