//! Cameras: a perspective [`Camera`], the automatic follow camera of headless renders
//! ([`CameraPlan`]) and the user-driven [`OrbitCamera`] of the window viewer.
//!
//! The follow camera derives everything from the scene's own extent, never from assumed units:
//! a clip in centimetres, metres or inches is framed alike. It looks at the figure's front from
//! a three-quarter view (or from the side of the overall travel direction for locomotion),
//! follows the figure with symmetric (lag-free) smoothing, and zooms to keep the figure and
//! its nearby motion inside the frame.

use glam::{Mat4, Vec2, Vec3};

use super::scene::{pose_bounds, Scene};

/// Vertical field of view of every camera, radians (40°).
pub const VFOV: f32 = 40.0 * std::f32::consts::PI / 180.0;
/// How far above the horizon the follow camera looks down, radians (14°).
pub const ELEVATION: f32 = 14.0 * std::f32::consts::PI / 180.0;
/// Smoothing of the followed target, seconds (Gaussian sigma).
const TARGET_SIGMA_S: f32 = 0.4;
/// Half-width of the window whose motion the framing keeps visible, seconds.
const FRAME_WINDOW_S: f32 = 0.6;
/// Smoothing of the framing radius (zoom), seconds (Gaussian sigma).
const RADIUS_SIGMA_S: f32 = 0.5;
/// Extra room around the framed sphere (1.0 = tight).
const MARGIN: f32 = 1.12;

/// A perspective camera in world space (metres, +Y up).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    /// Eye position.
    pub eye: Vec3,
    /// Point looked at.
    pub target: Vec3,
    /// Vertical field of view, radians.
    pub vfov: f32,
    /// Near clip distance, metres.
    pub near: f32,
    /// Far clip distance, metres.
    pub far: f32,
}

impl Camera {
    /// World → clip-space matrix for a viewport of `aspect` = width / height (depth 0..1).
    pub fn view_proj(&self, aspect: f32) -> Mat4 {
        let aspect = if aspect.is_finite() && aspect > 0.0 {
            aspect
        } else {
            1.0
        };
        let up = if (self.eye - self.target).normalize_or_zero().y.abs() > 0.999 {
            Vec3::Z
        } else {
            Vec3::Y
        };
        Mat4::perspective_rh(self.vfov, aspect, self.near, self.far)
            * Mat4::look_at_rh(self.eye, self.target, up)
    }
}

/// Distance at which a sphere of `radius` fills the smaller field of view.
fn fit_distance(radius: f32, vfov: f32, aspect: f32) -> f32 {
    let half_v = vfov * 0.5;
    let half_h = (half_v.tan() * aspect.max(0.05)).atan();
    radius / half_v.min(half_h).sin()
}

/// Near/far planes for a camera at `distance` from a framed sphere of `radius`.
fn clip_planes(distance: f32, radius: f32) -> (f32, f32) {
    let near = (distance - 4.0 * radius).max(distance * 0.02).max(1e-4);
    (near, distance + 40.0 * radius)
}

/// Size and ground level of a scene, derived from its geometry.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SceneMetrics {
    /// Typical figure size: median over frames of the pose's bounding-box diagonal (scene
    /// units, metres by convention). Never zero.
    pub size: f32,
    /// Height of the ground plane: the lowest bone endpoint of the whole clip.
    pub ground: f32,
}

impl SceneMetrics {
    /// Measures a scene; a scene without geometry gets size 1 and ground 0.
    pub fn of(scene: &Scene) -> Self {
        let mut diags: Vec<f32> = Vec::with_capacity(scene.frames.len());
        let mut ground = f32::INFINITY;
        for f in &scene.frames {
            if let Some((lo, hi)) = pose_bounds(f) {
                diags.push((hi - lo).length());
                ground = ground.min(lo.y);
            }
        }
        diags.sort_by(f32::total_cmp);
        let size = diags.get(diags.len() / 2).copied().unwrap_or(1.0);
        let size = if size.is_finite() && size > 1e-6 {
            size
        } else {
            1.0
        };
        let ground = if ground.is_finite() { ground } else { 0.0 };
        SceneMetrics { size, ground }
    }

    /// Default limb radius when a bone has none: a fixed fraction of the figure size.
    pub fn default_radius(&self) -> f32 {
        self.size * 0.028
    }
}

/// Gaussian smoothing of a sequence with `sigma` samples (clamped at the ends).
fn smooth<T>(xs: &[T], sigma: f32) -> Vec<T>
where
    T: Copy + std::ops::Mul<f32, Output = T> + std::ops::Add<Output = T>,
{
    if xs.len() < 2 || sigma < 0.5 {
        return xs.to_vec();
    }
    let half = (3.0 * sigma).ceil() as isize;
    let weights: Vec<f32> = (-half..=half)
        .map(|k| (-(k * k) as f32 / (2.0 * sigma * sigma)).exp())
        .collect();
    let total: f32 = weights.iter().sum();
    let last = xs.len() as isize - 1;
    (0..xs.len() as isize)
        .map(|i| {
            let mut acc = xs[i as usize] * 0.0;
            for (k, w) in (-half..=half).zip(&weights) {
                let j = (i + k).clamp(0, last) as usize;
                acc = acc + xs[j] * (w / total);
            }
            acc
        })
        .collect()
}

/// Horizontal unit vector rotated by `angle` radians about +Y.
fn rotate_y(v: Vec3, angle: f32) -> Vec3 {
    let (s, c) = angle.sin_cos();
    Vec3::new(c * v.x + s * v.z, 0.0, -s * v.x + c * v.z)
}

/// The follow camera of a whole scene, planned in advance (offline, so smoothing has no lag).
#[derive(Debug, Clone)]
pub struct CameraPlan {
    fps: f32,
    targets: Vec<Vec3>,
    radii: Vec<f32>,
    /// Unit vector from the target towards the eye.
    direction: Vec3,
    metrics: SceneMetrics,
}

impl CameraPlan {
    /// Plans the camera for `scene`: where to look, from which side, how far, at each frame.
    pub fn new(scene: &Scene) -> Self {
        let metrics = SceneMetrics::of(scene);
        let fps = if scene.fps.is_finite() && scene.fps > 0.0 {
            scene.fps
        } else {
            30.0
        };
        // Per-frame centre and half-diagonal; frames without geometry repeat the previous one.
        let mut centres = Vec::with_capacity(scene.frames.len());
        let mut halves = Vec::with_capacity(scene.frames.len());
        let mut prev = (
            Vec3::new(0.0, metrics.ground + metrics.size * 0.4, 0.0),
            metrics.size * 0.5,
        );
        for f in &scene.frames {
            if let Some((lo, hi)) = pose_bounds(f) {
                prev = ((lo + hi) * 0.5, (hi - lo).length() * 0.5);
            }
            centres.push(prev.0);
            halves.push(prev.1);
        }
        if centres.is_empty() {
            centres.push(prev.0);
            halves.push(metrics.size * 0.5);
        }
        let targets = smooth(&centres, TARGET_SIGMA_S * fps);
        let win = (FRAME_WINDOW_S * fps).ceil() as usize;
        // Radius each frame needs around its own (smoothed) target, then the largest need
        // nearby so the zoom widens before a big move instead of after it.
        let own: Vec<f32> = (0..targets.len())
            .map(|i| halves[i] + (centres[i] - targets[i]).length())
            .collect();
        let need: Vec<f32> = (0..own.len())
            .map(|i| {
                let lo = i.saturating_sub(win);
                let hi = (i + win).min(own.len() - 1);
                own[lo..=hi]
                    .iter()
                    .fold(metrics.size * 0.5, |a, &b| a.max(b))
            })
            .collect();
        let radii = smooth(&need, RADIUS_SIGMA_S * fps);
        let direction = Self::choose_direction(scene, &targets, &metrics);
        CameraPlan {
            fps,
            targets,
            radii,
            direction,
            metrics,
        }
    }

    /// Picks the viewing side: three-quarter front of the figure's initial facing, or for
    /// locomotion the side of the travel direction that shows the figure's front.
    fn choose_direction(scene: &Scene, targets: &[Vec3], m: &SceneMetrics) -> Vec3 {
        let facing = initial_facing(scene);
        let travel = match (targets.first(), targets.last()) {
            (Some(a), Some(b)) => Vec3::new(b.x - a.x, 0.0, b.z - a.z),
            _ => Vec3::ZERO,
        };
        let horizontal = if travel.length() > 0.6 * m.size {
            let mut side = Vec3::new(-travel.z, 0.0, travel.x).normalize();
            if side.dot(facing) < 0.0 {
                side = -side;
            }
            // Turn a little towards the front so the face and chest show.
            let toward = if rotate_y(side, 0.1).dot(facing) > side.dot(facing) {
                1.0
            } else {
                -1.0
            };
            rotate_y(side, toward * 25f32.to_radians())
        } else {
            rotate_y(facing, 30f32.to_radians())
        };
        let (s, c) = ELEVATION.sin_cos();
        (horizontal * c + Vec3::Y * s).normalize()
    }

    /// Typical figure size and ground level of the planned scene.
    pub fn metrics(&self) -> SceneMetrics {
        self.metrics
    }

    /// Unit vector from the look-at point towards the eye.
    pub fn direction(&self) -> Vec3 {
        self.direction
    }

    fn index(&self, t: f32) -> (usize, usize, f32) {
        let last = self.targets.len().saturating_sub(1);
        let f = if t.is_finite() {
            (t * self.fps).clamp(0.0, last as f32)
        } else {
            0.0
        };
        let i = (f.floor() as usize).min(last);
        (i, (i + 1).min(last), f - i as f32)
    }

    /// Smoothed look-at point at time `t` seconds.
    pub fn target_at(&self, t: f32) -> Vec3 {
        let (i, j, w) = self.index(t);
        self.targets[i].lerp(self.targets[j], w)
    }

    /// Radius (scene units) of the sphere the camera keeps in view at time `t`.
    pub fn radius_at(&self, t: f32) -> f32 {
        let (i, j, w) = self.index(t);
        self.radii[i] + (self.radii[j] - self.radii[i]) * w
    }

    /// The follow camera at time `t` seconds for a viewport of `aspect` = width / height.
    pub fn camera_at(&self, t: f32, aspect: f32) -> Camera {
        let target = self.target_at(t);
        let radius = self.radius_at(t) * MARGIN;
        let distance = fit_distance(radius, VFOV, aspect);
        let (near, far) = clip_planes(distance, radius);
        Camera {
            eye: target + self.direction * distance,
            target,
            vfov: VFOV,
            near,
            far,
        }
    }
}

/// The figure's initial facing (mean over the first second), horizontal and unit length.
/// Without facing data, the horizontal axis along which the figure is thinnest (a standing
/// person is wide across the shoulders and thin front to back).
fn initial_facing(scene: &Scene) -> Vec3 {
    let n = ((scene.fps.max(1.0)) as usize).clamp(1, scene.frames.len().max(1));
    let sum: Vec3 = scene
        .frames
        .iter()
        .take(n)
        .filter_map(|f| f.facing)
        .filter(|v| v.is_finite())
        .map(|v| Vec3::new(v.x, 0.0, v.z).normalize_or_zero())
        .sum();
    if sum.length() > 1e-3 {
        return sum.normalize();
    }
    // Covariance of horizontal joint offsets about each frame's centre.
    let (mut sxx, mut sxz, mut szz) = (0.0f32, 0.0f32, 0.0f32);
    for f in scene.frames.iter().take(n) {
        let Some((lo, hi)) = pose_bounds(f) else {
            continue;
        };
        let c = (lo + hi) * 0.5;
        for s in f.segments.iter().filter(|s| s.is_finite()) {
            for p in [s.start, s.end] {
                let d = Vec2::new(p.x - c.x, p.z - c.z);
                sxx += d.x * d.x;
                sxz += d.x * d.y;
                szz += d.y * d.y;
            }
        }
    }
    // Eigenvector of the smaller eigenvalue of [[sxx, sxz], [sxz, szz]].
    let tr = sxx + szz;
    let det = sxx * szz - sxz * sxz;
    let small = tr * 0.5 - ((tr * 0.5).powi(2) - det).max(0.0).sqrt();
    let v = if sxz.abs() > 1e-9 {
        Vec3::new(sxz, 0.0, small - sxx)
    } else if sxx <= szz {
        Vec3::X
    } else {
        Vec3::Z
    };
    let v = v.normalize_or_zero();
    if v == Vec3::ZERO {
        Vec3::Z
    } else if v.z < 0.0 || (v.z == 0.0 && v.x < 0.0) {
        -v
    } else {
        v
    }
}

/// A camera the user steers: orbit around a target, zoom, pan.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OrbitCamera {
    /// Look-at point (world).
    pub target: Vec3,
    /// Eye distance from the target (world units).
    pub distance: f32,
    /// Angle about +Y, radians (0 = eye on +Z of the target).
    pub azimuth: f32,
    /// Angle above the horizon, radians, kept within ±85°.
    pub elevation: f32,
}

impl OrbitCamera {
    /// Largest elevation magnitude, radians (85°): avoids the degenerate straight-down view.
    pub const MAX_ELEVATION: f32 = 85.0 * std::f32::consts::PI / 180.0;

    /// An orbit camera looking at `target` from `direction` (unit, target → eye) at `distance`.
    pub fn from_direction(target: Vec3, direction: Vec3, distance: f32) -> Self {
        let d = direction.normalize_or(Vec3::Z);
        OrbitCamera {
            target,
            distance: distance.max(1e-3),
            azimuth: d.x.atan2(d.z),
            elevation: d.y.clamp(-1.0, 1.0).asin(),
        }
    }

    /// Unit vector from the target to the eye.
    pub fn direction(&self) -> Vec3 {
        let (se, ce) = self.elevation.sin_cos();
        let (sa, ca) = self.azimuth.sin_cos();
        Vec3::new(ce * sa, se, ce * ca)
    }

    /// Rotates by `d_azimuth` and `d_elevation` radians (elevation clamped).
    pub fn orbit(&mut self, d_azimuth: f32, d_elevation: f32) {
        if d_azimuth.is_finite() {
            self.azimuth = (self.azimuth + d_azimuth).rem_euclid(std::f32::consts::TAU);
        }
        if d_elevation.is_finite() {
            self.elevation =
                (self.elevation + d_elevation).clamp(-Self::MAX_ELEVATION, Self::MAX_ELEVATION);
        }
    }

    /// Multiplies the distance by `factor` (> 1 zooms out), within [1e-3, 1e6].
    pub fn zoom(&mut self, factor: f32) {
        if factor.is_finite() && factor > 0.0 {
            self.distance = (self.distance * factor).clamp(1e-3, 1e6);
        }
    }

    /// Moves the target across the view plane by (`dx`, `dy`) fractions of the distance.
    pub fn pan(&mut self, dx: f32, dy: f32) {
        let forward = -self.direction();
        let right = forward.cross(Vec3::Y).normalize_or(Vec3::X);
        let up = right.cross(forward);
        self.target += (right * dx + up * dy) * self.distance;
    }

    /// The camera; `radius` (scene units) sets the clip planes.
    pub fn camera(&self, radius: f32) -> Camera {
        let (near, far) = clip_planes(self.distance, radius.max(self.distance * 0.05));
        Camera {
            eye: self.target + self.direction() * self.distance,
            target: self.target,
            vfov: VFOV,
            near,
            far,
        }
    }
}

/// Distance at which the follow camera frames a sphere of `radius`; used by the viewer to
/// start its orbit camera where the follow camera would be.
pub fn framing_distance(radius: f32, aspect: f32) -> f32 {
    fit_distance(radius * MARGIN, VFOV, aspect)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::scene::{BoneSegment, FramePose};

    fn standing(offset: Vec3, scale: f32, facing: Option<Vec3>) -> FramePose {
        // Shoulders along X, so the figure faces +Z or -Z.
        let p = |x: f32, y: f32, z: f32| offset + Vec3::new(x, y, z) * scale;
        FramePose {
            segments: vec![
                BoneSegment::new(p(0.0, 0.9, 0.0), p(0.0, 1.5, 0.0)),
                BoneSegment::new(p(-0.2, 1.45, 0.0), p(0.2, 1.45, 0.0)),
                BoneSegment::new(p(-0.1, 0.9, 0.0), p(-0.1, 0.0, 0.05)),
                BoneSegment::new(p(0.1, 0.9, 0.0), p(0.1, 0.0, 0.05)),
                BoneSegment::new(p(0.0, 1.5, 0.0), p(0.0, 1.75, 0.0)),
            ],
            facing,
        }
    }

    fn scene(frames: Vec<FramePose>) -> Scene {
        Scene {
            fps: 30.0,
            frames,
            ..Scene::default()
        }
    }

    /// Projects a world point to normalised device coordinates.
    fn ndc(cam: &Camera, aspect: f32, p: Vec3) -> Vec3 {
        let c = cam.view_proj(aspect) * p.extend(1.0);
        c.truncate() / c.w
    }

    #[test]
    fn framing_is_unit_independent() {
        for scale in [0.01f32, 1.0, 39.37, 100.0] {
            let s = scene(vec![standing(Vec3::ZERO, scale, Some(Vec3::Z)); 10]);
            let plan = CameraPlan::new(&s);
            let cam = plan.camera_at(0.1, 16.0 / 9.0);
            for seg in &s.frames[0].segments {
                for p in [seg.start, seg.end] {
                    let q = ndc(&cam, 16.0 / 9.0, p);
                    assert!(q.x.abs() < 0.95 && q.y.abs() < 0.95, "scale {scale}: {q}");
                    assert!(q.z > 0.0 && q.z < 1.0);
                }
            }
            // The figure fills a decent part of the frame.
            let head = ndc(&cam, 16.0 / 9.0, Vec3::new(0.0, 1.75, 0.0) * scale);
            let foot = ndc(&cam, 16.0 / 9.0, Vec3::new(0.1, 0.0, 0.05) * scale);
            assert!(head.y - foot.y > 0.9, "figure too small at scale {scale}");
        }
    }

    #[test]
    fn camera_sees_the_front() {
        let s = scene(vec![standing(Vec3::ZERO, 1.0, Some(-Vec3::Z)); 5]);
        let plan = CameraPlan::new(&s);
        assert!(plan.direction().dot(-Vec3::Z) > 0.7);
        assert!(plan.direction().y > 0.0);
    }

    #[test]
    fn facing_fallback_uses_thin_axis() {
        let s = scene(vec![standing(Vec3::ZERO, 1.0, None); 5]);
        let d = CameraPlan::new(&s).direction();
        // Thin axis is Z: the camera looks mostly along it.
        assert!(d.z.abs() > d.x.abs(), "{d}");
    }

    #[test]
    fn follows_a_walk_from_the_side() {
        let frames = (0..90)
            .map(|i| standing(Vec3::new(0.0, 0.0, i as f32 * 0.05), 1.0, Some(Vec3::Z)))
            .collect();
        let s = scene(frames);
        let plan = CameraPlan::new(&s);
        let d = plan.direction();
        // Mostly sideways (X), somewhat frontal (+Z).
        assert!(d.x.abs() > 0.6 && d.z > 0.2, "{d}");
        for i in [0usize, 45, 89] {
            let t = i as f32 / 30.0;
            let cam = plan.camera_at(t, 1.5);
            let pelvis = Vec3::new(0.0, 0.9, i as f32 * 0.05);
            let q = ndc(&cam, 1.5, pelvis);
            assert!(q.x.abs() < 0.5 && q.y.abs() < 0.6, "frame {i}: {q}");
        }
    }

    #[test]
    fn orbit_camera_round_trips_direction() {
        let dir = Vec3::new(1.0, 0.5, -2.0).normalize();
        let mut o = OrbitCamera::from_direction(Vec3::ONE, dir, 5.0);
        assert!((o.direction() - dir).length() < 1e-5);
        assert!((o.camera(1.0).eye - (Vec3::ONE + dir * 5.0)).length() < 1e-4);
        o.orbit(0.0, 10.0);
        assert!((o.elevation - OrbitCamera::MAX_ELEVATION).abs() < 1e-6);
        o.zoom(2.0);
        assert!((o.distance - 10.0).abs() < 1e-4);
        o.zoom(f32::NAN);
        assert!((o.distance - 10.0).abs() < 1e-4);
    }

    #[test]
    fn smoothing_keeps_constants() {
        let xs = vec![Vec3::ONE; 20];
        for v in smooth(&xs, 4.0) {
            assert!((v - Vec3::ONE).length() < 1e-5);
        }
    }
}
