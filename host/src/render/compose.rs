//! Composition: turns a [`Scene`] at one instant, seen by one [`Camera`], into plain draw
//! lists — limb capsules, ground shadows, grid parameters and overlay rectangles. This is the
//! last GPU-free stage; the GPU only rasterises what it gets from here.

use glam::{Mat4, Vec3};

use super::camera::{Camera, SceneMetrics};
use super::overlay::{overlay_rects, srgba, Rect};
use super::scene::{DoodlePoint, FramePose, Scene, Side};

/// At most this many doodle segments are drawn; denser doodles are thinned by arc length.
pub const MAX_DOODLE_SEGMENTS: usize = 600;
/// The doodle is drawn from this many seconds before now to as many after (a long doodle in
/// full would clutter the picture; the recent past and near future show where the toy went).
pub const DOODLE_WINDOW_S: f32 = 3.0;

/// One capsule: a limb (or a doodle segment, or a ball when both ends coincide).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Capsule {
    /// Start point (xyz, world) and radius (w).
    pub a: [f32; 4],
    /// End point (xyz, world); w unused.
    pub b: [f32; 4],
    /// Linear RGB colour; alpha 1.
    pub colour: [f32; 4],
}

/// One soft shadow on the ground: a blurred 2-D capsule between two ground points.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Shadow {
    /// Ground-plane (x, z) of both ends: `[ax, az, bx, bz]`.
    pub ends: [f32; 4],
    /// Core radius, blur width (both world units), darkness 0..1, unused.
    pub params: [f32; 4],
}

/// The per-frame constants every pipeline reads.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Globals {
    /// World → clip matrix (column-major).
    pub view_proj: [[f32; 4]; 4],
    /// Eye position (xyz), w unused.
    pub eye: [f32; 4],
    /// Ground: height, grid spacing, fade radius, line width in grid cells.
    pub ground: [f32; 4],
    /// Ground centre (x, z) and the viewport size in pixels (w, h).
    pub centre_viewport: [f32; 4],
    /// Background (horizon) colour, linear RGBA.
    pub background: [f32; 4],
    /// Direction towards the key light (xyz, unit), w unused.
    pub light: [f32; 4],
}

/// Everything to draw for one frame.
#[derive(Debug, Clone, PartialEq)]
pub struct FrameDraw {
    /// Per-frame constants.
    pub globals: Globals,
    /// Limb capsules (drawn finely tessellated).
    pub capsules: Vec<Capsule>,
    /// Doodle path segments (thin capsules, drawn coarsely tessellated).
    pub doodle: Vec<Capsule>,
    /// Ground shadows.
    pub shadows: Vec<Shadow>,
    /// Overlay rectangles (pixels).
    pub rects: Vec<Rect>,
}

/// Background colour (sRGB), a pale blue-grey that the ground fades into.
const BACKGROUND: [f32; 3] = [0.80, 0.84, 0.88];

/// sRGB colour of a bone by side and character.
fn bone_colour(side: Side, character: u16) -> [f32; 4] {
    const TINTS: [[f32; 3]; 4] = [
        [1.0, 1.0, 1.0],
        [0.75, 1.0, 0.75],
        [1.0, 0.8, 1.0],
        [1.0, 1.0, 0.7],
    ];
    let base = match side {
        Side::Centre => [0.88, 0.84, 0.78],
        Side::Left => [0.95, 0.55, 0.22],
        Side::Right => [0.22, 0.56, 0.88],
    };
    let tint = TINTS[usize::from(character) % TINTS.len()];
    srgba(base[0] * tint[0], base[1] * tint[1], base[2] * tint[2], 1.0)
}

/// A "nice" grid spacing (1, 2 or 5 × 10^k) close to `x`.
pub fn nice_spacing(x: f32) -> f32 {
    if !(x.is_finite() && x > 0.0) {
        return 1.0;
    }
    let p = 10f32.powf(x.log10().floor());
    let m = x / p;
    let n = if m < 1.5 {
        1.0
    } else if m < 3.5 {
        2.0
    } else if m < 7.5 {
        5.0
    } else {
        10.0
    };
    n * p
}

/// Builds [`FrameDraw`]s for one scene; holds what does not change from frame to frame.
#[derive(Debug, Clone)]
pub struct Composer {
    metrics: SceneMetrics,
    doodle: Vec<DoodlePoint>,
}

impl Composer {
    /// Prepares composition of `scene` (measures it, thins the doodle).
    pub fn new(scene: &Scene) -> Self {
        Composer {
            metrics: SceneMetrics::of(scene),
            doodle: thin_doodle(&scene.doodle, MAX_DOODLE_SEGMENTS),
        }
    }

    /// A composer with given metrics and no doodle (live poses, where there is no clip to
    /// measure in advance).
    pub fn with_metrics(metrics: SceneMetrics) -> Self {
        Composer {
            metrics,
            doodle: Vec::new(),
        }
    }

    /// The scene's measured size and ground.
    pub fn metrics(&self) -> SceneMetrics {
        self.metrics
    }

    /// Draw lists for `scene` at time `t` (seconds) seen by `camera` in a `width` × `height`
    /// frame, with `status` text in the corner.
    pub fn compose(
        &self,
        scene: &Scene,
        t: f32,
        camera: &Camera,
        width: u32,
        height: u32,
        status: &str,
    ) -> FrameDraw {
        let pose = scene.pose_at(t);
        self.compose_pose(scene, &pose, t, camera, width, height, status)
    }

    /// Like [`Composer::compose`] but with an explicit pose (e.g. pushed live).
    #[allow(clippy::too_many_arguments)]
    pub fn compose_pose(
        &self,
        scene: &Scene,
        pose: &FramePose,
        t: f32,
        camera: &Camera,
        width: u32,
        height: u32,
        status: &str,
    ) -> FrameDraw {
        let m = self.metrics;
        let default_r = m.default_radius();
        let mut capsules = Vec::with_capacity(pose.segments.len() + self.doodle.len() + 1);
        let mut shadows = Vec::with_capacity(pose.segments.len() + self.doodle.len() + 1);
        let mut lowest = f32::INFINITY;
        let (mut sum, mut count) = (Vec3::ZERO, 0.0f32);
        for s in pose.segments.iter().filter(|s| s.is_finite()) {
            let r = s.radius.unwrap_or(default_r).clamp(0.0, m.size);
            capsules.push(Capsule {
                a: s.start.extend(r).to_array(),
                b: s.end.extend(0.0).to_array(),
                colour: bone_colour(s.side, s.character),
            });
            let h = (s.start.y.min(s.end.y) - r - m.ground).max(0.0);
            lowest = lowest.min(h);
            sum += s.start + s.end;
            count += 2.0;
            let fade = (1.0 - h / (0.7 * m.size)).clamp(0.0, 1.0);
            if fade > 0.0 {
                shadows.push(Shadow {
                    ends: [s.start.x, s.start.z, s.end.x, s.end.z],
                    params: [r * 0.9, r * 0.8 + h * 0.35, 0.42 * fade * fade, 0.0],
                });
            }
        }
        // A broad soft blob under the whole body: ambient occlusion that fades when airborne.
        if count > 0.0 {
            let c = sum / count;
            let fade = (1.0 - lowest / (0.8 * m.size)).clamp(0.0, 1.0);
            shadows.push(Shadow {
                ends: [c.x, c.z, c.x, c.z],
                params: [0.08 * m.size, 0.22 * m.size, 0.3 * fade, 0.0],
            });
        }
        let mut doodle = Vec::with_capacity(self.doodle.len());
        self.push_doodle(t, &mut doodle, &mut capsules, &mut shadows);
        let aspect = width.max(1) as f32 / height.max(1) as f32;
        let dist = (camera.eye - camera.target).length();
        let bg = srgba(BACKGROUND[0], BACKGROUND[1], BACKGROUND[2], 1.0);
        let globals = Globals {
            view_proj: camera.view_proj(aspect).to_cols_array_2d(),
            eye: camera.eye.extend(1.0).to_array(),
            ground: [
                m.ground,
                nice_spacing(m.size / 3.5),
                (m.size * 6.0).max(dist * 2.5),
                0.02,
            ],
            centre_viewport: [
                camera.target.x,
                camera.target.z,
                width.max(1) as f32,
                height.max(1) as f32,
            ],
            background: bg,
            light: key_light(camera).extend(0.0).to_array(),
        };
        FrameDraw {
            globals,
            capsules,
            doodle,
            shadows,
            rects: overlay_rects(scene, t, width, height, status),
        }
    }

    fn push_doodle(
        &self,
        t: f32,
        segments: &mut Vec<Capsule>,
        capsules: &mut Vec<Capsule>,
        shadows: &mut Vec<Shadow>,
    ) {
        let m = self.metrics;
        let r = m.size * 0.008;
        let past = srgba(0.85, 0.15, 0.55, 1.0);
        let future = srgba(0.85, 0.7, 0.8, 1.0);
        for w in self.doodle.windows(2) {
            let (p, q) = (w[0], w[1]);
            if q.t < t - DOODLE_WINDOW_S || p.t > t + DOODLE_WINDOW_S {
                continue;
            }
            segments.push(Capsule {
                a: p.pos.extend(r).to_array(),
                b: q.pos.extend(0.0).to_array(),
                colour: if q.t <= t { past } else { future },
            });
            shadows.push(Shadow {
                ends: [p.pos.x, p.pos.z, q.pos.x, q.pos.z],
                params: [r * 0.5, r, 0.2, 0.0],
            });
        }
        // A ball where the toy is now.
        if let Some(now) = doodle_position(&self.doodle, t) {
            capsules.push(Capsule {
                a: now.extend(r * 3.0).to_array(),
                b: now.extend(0.0).to_array(),
                colour: past,
            });
        }
    }
}

/// The key light: above, a little to the camera's right and in front of the figure, so the
/// side the camera sees is always lit whatever the viewing direction.
fn key_light(camera: &Camera) -> Vec3 {
    let to_eye = (camera.eye - camera.target).normalize_or(Vec3::Z);
    let flat = Vec3::new(to_eye.x, 0.0, to_eye.z).normalize_or(Vec3::Z);
    let right = (-flat).cross(Vec3::Y);
    (flat * 0.55 + right * 0.6 + Vec3::Y).normalize()
}

/// The doodle position at time `t` (linear between samples), if the doodle covers `t`.
fn doodle_position(doodle: &[DoodlePoint], t: f32) -> Option<Vec3> {
    let first = doodle.first()?;
    let last = doodle.last()?;
    if t < first.t || t > last.t {
        return None;
    }
    let k = doodle.partition_point(|p| p.t <= t);
    if k == 0 || k >= doodle.len() {
        return Some(last.pos);
    }
    let (p, q) = (doodle[k - 1], doodle[k]);
    let w = if q.t > p.t {
        (t - p.t) / (q.t - p.t)
    } else {
        0.0
    };
    Some(p.pos.lerp(q.pos, w))
}

/// Drops non-finite samples and thins the path to at most `max_segments` segments, keeping
/// points at least (length / max_segments) apart along the path, and the last point.
pub fn thin_doodle(doodle: &[DoodlePoint], max_segments: usize) -> Vec<DoodlePoint> {
    let pts: Vec<DoodlePoint> = doodle
        .iter()
        .copied()
        .filter(|p| p.t.is_finite() && p.pos.is_finite())
        .collect();
    if pts.len() <= max_segments + 1 || max_segments == 0 {
        return pts;
    }
    let length: f32 = pts.windows(2).map(|w| (w[1].pos - w[0].pos).length()).sum();
    let step = length / max_segments as f32;
    let mut out = vec![pts[0]];
    let mut acc = 0.0;
    for w in pts.windows(2) {
        acc += (w[1].pos - w[0].pos).length();
        if acc >= step {
            out.push(w[1]);
            acc = 0.0;
        }
    }
    if let (Some(l), Some(o)) = (pts.last(), out.last()) {
        if l != o {
            out.push(*l);
        }
    }
    // Still too many (a path with long pauses): keep every k-th point.
    if out.len() > max_segments + 1 {
        let k = out.len().div_ceil(max_segments + 1);
        let last = out[out.len() - 1];
        out = out.into_iter().step_by(k).collect();
        if out.last() != Some(&last) {
            out.push(last);
        }
    }
    out
}

/// Projects a world point to pixel coordinates (origin top-left), or `None` behind the eye.
pub fn project_to_pixels(view_proj: Mat4, p: Vec3, width: u32, height: u32) -> Option<(f32, f32)> {
    let c = view_proj * p.extend(1.0);
    if c.w <= 1e-6 {
        return None;
    }
    let n = c.truncate() / c.w;
    Some((
        (n.x * 0.5 + 0.5) * width as f32,
        (0.5 - n.y * 0.5) * height as f32,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::camera::CameraPlan;
    use crate::render::scene::BoneSegment;

    #[test]
    fn nice_spacing_rounds() {
        assert_eq!(nice_spacing(0.45), 0.5);
        assert_eq!(nice_spacing(18.0), 20.0);
        assert!((nice_spacing(0.013) - 0.01).abs() < 1e-6);
        assert_eq!(nice_spacing(f32::NAN), 1.0);
    }

    #[test]
    fn thinning_bounds_segments_and_keeps_ends() {
        let pts: Vec<DoodlePoint> = (0..5000)
            .map(|i| DoodlePoint {
                t: i as f32 * 0.001,
                pos: Vec3::new((i as f32 * 0.01).sin(), 0.5, i as f32 * 0.001),
            })
            .collect();
        let thin = thin_doodle(&pts, 100);
        assert!(thin.len() <= 101 && thin.len() > 50, "{}", thin.len());
        assert_eq!(thin.first(), pts.first());
        assert_eq!(thin.last(), pts.last());
        let mut bad = pts.clone();
        bad[3].pos = Vec3::NAN;
        assert!(thin_doodle(&bad[..10], 100).len() == 9);
    }

    #[test]
    fn compose_skips_non_finite_bones_and_shadows_touching_feet() {
        let seg = |a: Vec3, b: Vec3| BoneSegment::new(a, b);
        let scene = Scene {
            fps: 30.0,
            frames: vec![FramePose {
                segments: vec![
                    seg(Vec3::new(0.0, 0.0, 0.0), Vec3::new(0.0, 1.0, 0.0)),
                    seg(Vec3::new(0.0, 1.0, 0.0), Vec3::new(0.0, 1.7, 0.0)),
                    seg(Vec3::NAN, Vec3::ZERO),
                ],
                facing: None,
            }],
            ..Scene::default()
        };
        let composer = Composer::new(&scene);
        let cam = CameraPlan::new(&scene).camera_at(0.0, 1.0);
        let draw = composer.compose(&scene, 0.0, &cam, 64, 64, "");
        assert_eq!(draw.capsules.len(), 2);
        // The leg touching the ground casts the darkest bone shadow.
        assert!(draw.shadows[0].params[2] > draw.shadows[1].params[2]);
        let (px, py) = project_to_pixels(
            Mat4::from_cols_array_2d(&draw.globals.view_proj),
            Vec3::new(0.0, 0.85, 0.0),
            64,
            64,
        )
        .expect("in front");
        assert!(
            (px - 32.0).abs() < 8.0 && (py - 32.0).abs() < 12.0,
            "{px} {py}"
        );
    }

    #[test]
    fn doodle_position_interpolates() {
        let d = [
            DoodlePoint {
                t: 0.0,
                pos: Vec3::ZERO,
            },
            DoodlePoint {
                t: 1.0,
                pos: Vec3::X,
            },
        ];
        assert_eq!(doodle_position(&d, 0.5), Some(Vec3::X * 0.5));
        assert_eq!(doodle_position(&d, 2.0), None);
    }
}
