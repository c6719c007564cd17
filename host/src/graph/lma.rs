//! LMA-derived features (seed 003, Table 1): 29 features → 114 measurements per window.
//!
//! All lengths are analysis metres (bodies scaled to 1.7 m, see [`super::source`]), time is
//! seconds at 30 fps, y is up, the floor is y = 0. Derivatives are central differences of the
//! role points (one-sided at clip ends). "Body frame" means the horizontal frame turned about
//! the vertical so that x runs from the right hip to the left hip.
//!
//! Per-frame features (their max / min / std / mean over a 35-frame window give φ):
//!
//! | f | feature | formula | unit |
//! |---|---------|---------|------|
//! | f1 | foot–hip distance, L and R | ‖foot − hips‖ | m |
//! | f2 | hand–shoulder distance, L and R | ‖hand − shoulder‖ | m |
//! | f3 | hands distance | ‖hand_L − hand_R‖ | m |
//! | f4 | hand–head distance, L and R | ‖hand − head‖ | m |
//! | f5 | hip–ground distance | hips.y | m |
//! | f6 | hip–ground minus feet–hip | f5 − (f1_L + f1_R)/2 | m |
//! | f7 | centroid–ground | centroid.y (mean of the 16 role points) | m |
//! | f8 | centroid–pelvis distance | ‖centroid − hips‖ | m |
//! | f9 | gait size | ‖foot_L − foot_R‖ | m |
//! | f10 | head orientation | angle between neck→head and +y | rad |
//! | f11 | deceleration peaks | local minima of d s/dt below −1 m/s², s = mean speed of pelvis, hands, feet; count per window ÷ window duration | 1/s |
//! | f12 | pelvis velocity | ‖v_hips‖ (max, std, mean) | m/s |
//! | f13 | hand velocity, L and R | ‖v_hand‖ (max, std, mean) | m/s |
//! | f14 | foot velocity, L and R | ‖v_foot‖ (max, std, mean) | m/s |
//! | f15 | pelvis acceleration | ‖a_hips‖ (max, std) | m/s² |
//! | f16 | hand acceleration, L and R | ‖a_hand‖ (max, std) | m/s² |
//! | f17 | foot acceleration, L and R | ‖a_foot‖ (max, std) | m/s² |
//! | f18 | jerk | mean ‖j‖ of pelvis, hands, feet (max, std) | m/s³ |
//! | f19 | volume, 5 joints | body-frame bounding box of head, hands, feet | m³ |
//! | f20 | volume, upper body | … chest, neck, head, shoulders, elbows, hands | m³ |
//! | f21 | volume, lower body | … hips, hip joints, knees, feet | m³ |
//! | f22 | volume, left side | … left shoulder, elbow, hand, hip, knee, foot | m³ |
//! | f23 | volume, right side | … right side likewise | m³ |
//! | f24 | torso height | ‖head − hips‖ | m |
//! | f25 | hands level | share of hand samples above the head / between head and hips / below the hips (φ105–107) | 1 |
//! | f26 | total distance | pelvis path length on the floor over the window | m |
//! | f27 | total area | convex-hull area of the pelvis floor path over the window | m² |
//! | f28 | total volume | body-frame (at the window centre) bounding box of all role points over the window | m³ |
//! | f29 | cumulative distribution | ‖pelvis_xz − mean pelvis_xz over the window‖ (max, min, std, mean) | m |
//!
//! Components: BODY φ1–44, EFFORT φ45–80, SHAPE φ81–107, SPACE φ108–114.

use glam::{Vec2, Vec3};

use super::roles::Role;
use super::{FPS, HALF, WINDOW};

/// Number of measurements per window (Table 1).
pub const MEASUREMENTS: usize = 114;

/// The four LMA components and their measurement ranges.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Component {
    /// BODY: φ1–44.
    Body,
    /// EFFORT: φ45–80.
    Effort,
    /// SHAPE: φ81–107.
    Shape,
    /// SPACE: φ108–114.
    Space,
}

impl Component {
    /// All components in order.
    pub const ALL: [Component; 4] = [
        Component::Body,
        Component::Effort,
        Component::Shape,
        Component::Space,
    ];

    /// Measurement index range (0-based: φ_k is index k − 1).
    pub fn range(self) -> std::ops::Range<usize> {
        match self {
            Component::Body => 0..44,
            Component::Effort => 44..80,
            Component::Shape => 80..107,
            Component::Space => 107..114,
        }
    }
}

/// Threshold below which a local minimum of d s/dt counts as a deceleration peak, m/s².
pub const DECEL_THRESHOLD: f32 = 1.0;

// Per-frame feature slots.
const F_COUNT: usize = 35;
const F_DECEL_PEAK: usize = 33;
const F_HANDS_HIGH: usize = 30;

#[derive(Clone, Copy)]
enum Stat {
    Max,
    Min,
    Std,
    Mean,
}

/// Layout of φ1–107 except f11: (per-frame slot, statistics), in Table 1 order.
const STAT_LAYOUT: [(usize, &[Stat]); 32] = {
    use Stat::*;
    const ALL4: &[Stat] = &[Max, Min, Std, Mean];
    const VEL: &[Stat] = &[Max, Std, Mean];
    const ACC: &[Stat] = &[Max, Std];
    [
        (0, ALL4),  // f1 L
        (1, ALL4),  // f1 R
        (2, ALL4),  // f2 L
        (3, ALL4),  // f2 R
        (4, ALL4),  // f3
        (5, ALL4),  // f4 L
        (6, ALL4),  // f4 R
        (7, ALL4),  // f5
        (8, ALL4),  // f6
        (9, ALL4),  // f7
        (10, ALL4), // f8
        (11, ALL4), // f9
        (12, ALL4), // f10
        (13, VEL),  // f12 (f11 is inserted before it)
        (14, VEL),  // f13 L
        (15, VEL),  // f13 R
        (16, VEL),  // f14 L
        (17, VEL),  // f14 R
        (18, ACC),  // f15
        (19, ACC),  // f16 L
        (20, ACC),  // f16 R
        (21, ACC),  // f17 L
        (22, ACC),  // f17 R
        (23, ACC),  // f18
        (24, ALL4), // f19
        (25, ALL4), // f20
        (26, ALL4), // f21
        (27, ALL4), // f22
        (28, ALL4), // f23
        (29, ALL4), // f24
        (30, &[]),  // f25 handled apart (three means)
        (31, &[]),
    ]
};

fn idx(r: Role) -> usize {
    r.index()
}

/// Central-difference derivative of a per-frame vector series (one-sided at the ends).
fn derivative(x: &[Vec3], dt: f32) -> Vec<Vec3> {
    let n = x.len();
    (0..n)
        .map(|k| {
            if n < 2 {
                Vec3::ZERO
            } else if k == 0 {
                (x[1] - x[0]) / dt
            } else if k == n - 1 {
                (x[n - 1] - x[n - 2]) / dt
            } else {
                (x[k + 1] - x[k - 1]) / (2.0 * dt)
            }
        })
        .collect()
}

/// Rotation about +y that takes the body's right→left hip axis to +x: returns (cos, sin).
fn body_frame(p: &[Vec3; Role::COUNT]) -> (f32, f32) {
    let lat = p[idx(Role::LeftHip)] - p[idx(Role::RightHip)];
    let v = Vec2::new(lat.x, lat.z);
    let len = v.length();
    if len > 1e-6 {
        (v.x / len, v.y / len)
    } else {
        (1.0, 0.0)
    }
}

/// A point in the body frame given by (cos, sin) of the lateral axis.
fn to_body(v: Vec3, (c, s): (f32, f32)) -> Vec3 {
    Vec3::new(c * v.x + s * v.z, v.y, -s * v.x + c * v.z)
}

fn box_volume(points: impl Iterator<Item = Vec3>) -> f32 {
    let mut lo = Vec3::splat(f32::INFINITY);
    let mut hi = Vec3::splat(f32::NEG_INFINITY);
    for p in points {
        lo = lo.min(p);
        hi = hi.max(p);
    }
    let d = (hi - lo).max(Vec3::ZERO);
    if d.is_finite() {
        d.x * d.y * d.z
    } else {
        0.0
    }
}

/// Area of the convex hull of 2-D points, m² (Andrew's monotone chain).
pub fn hull_area(points: &mut [Vec2]) -> f32 {
    if points.len() < 3 {
        return 0.0;
    }
    points.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    let cross = |o: Vec2, a: Vec2, b: Vec2| (a - o).perp_dot(b - o);
    let mut hull: Vec<Vec2> = Vec::with_capacity(points.len() * 2);
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &Vec2>> = if pass == 0 {
            Box::new(points.iter())
        } else {
            Box::new(points.iter().rev())
        };
        for &p in iter {
            while hull.len() >= start + 2
                && cross(hull[hull.len() - 2], hull[hull.len() - 1], p) <= 0.0
            {
                hull.pop();
            }
            hull.push(p);
        }
        hull.pop();
    }
    let n = hull.len();
    let twice: f32 = (0..n).map(|k| hull[k].perp_dot(hull[(k + 1) % n])).sum();
    (twice * 0.5).abs()
}

/// Per-frame features of one clip (`frames × 35` slots, see the module table).
fn frame_features(points: &[[Vec3; Role::COUNT]]) -> Vec<[f32; F_COUNT]> {
    let dt = 1.0 / FPS;
    let n = points.len();
    let track = |r: Role| -> Vec<Vec3> { points.iter().map(|p| p[idx(r)]).collect() };
    let ends = [
        Role::Hips,
        Role::LeftHand,
        Role::RightHand,
        Role::LeftFoot,
        Role::RightFoot,
    ];
    let vel: Vec<Vec<Vec3>> = ends.iter().map(|&r| derivative(&track(r), dt)).collect();
    let acc: Vec<Vec<Vec3>> = vel.iter().map(|v| derivative(v, dt)).collect();
    let jerk: Vec<Vec<Vec3>> = acc.iter().map(|a| derivative(a, dt)).collect();
    let speed_sum: Vec<Vec3> = (0..n)
        .map(|k| Vec3::splat(vel.iter().map(|v| v[k].length()).sum::<f32>() / ends.len() as f32))
        .collect();
    let dspeed = derivative(&speed_sum, dt);
    let upper = [
        Role::Chest,
        Role::Neck,
        Role::Head,
        Role::LeftShoulder,
        Role::RightShoulder,
        Role::LeftElbow,
        Role::RightElbow,
        Role::LeftHand,
        Role::RightHand,
    ];
    let lower = [
        Role::Hips,
        Role::LeftHip,
        Role::RightHip,
        Role::LeftKnee,
        Role::RightKnee,
        Role::LeftFoot,
        Role::RightFoot,
    ];
    let left = [
        Role::LeftShoulder,
        Role::LeftElbow,
        Role::LeftHand,
        Role::LeftHip,
        Role::LeftKnee,
        Role::LeftFoot,
    ];
    let right = [
        Role::RightShoulder,
        Role::RightElbow,
        Role::RightHand,
        Role::RightHip,
        Role::RightKnee,
        Role::RightFoot,
    ];
    let five = [
        Role::Head,
        Role::LeftHand,
        Role::RightHand,
        Role::LeftFoot,
        Role::RightFoot,
    ];
    (0..n)
        .map(|k| {
            let p = &points[k];
            let g = |r: Role| p[idx(r)];
            let mut f = [0.0f32; F_COUNT];
            f[0] = g(Role::LeftFoot).distance(g(Role::Hips));
            f[1] = g(Role::RightFoot).distance(g(Role::Hips));
            f[2] = g(Role::LeftHand).distance(g(Role::LeftShoulder));
            f[3] = g(Role::RightHand).distance(g(Role::RightShoulder));
            f[4] = g(Role::LeftHand).distance(g(Role::RightHand));
            f[5] = g(Role::LeftHand).distance(g(Role::Head));
            f[6] = g(Role::RightHand).distance(g(Role::Head));
            f[7] = g(Role::Hips).y;
            f[8] = f[7] - 0.5 * (f[0] + f[1]);
            let centroid = p.iter().copied().fold(Vec3::ZERO, |a, b| a + b) / Role::COUNT as f32;
            f[9] = centroid.y;
            f[10] = centroid.distance(g(Role::Hips));
            f[11] = g(Role::LeftFoot).distance(g(Role::RightFoot));
            let head_dir = (g(Role::Head) - g(Role::Neck)).normalize_or_zero();
            f[12] = head_dir.dot(Vec3::Y).clamp(-1.0, 1.0).acos();
            for (e, slot) in [(0usize, 13usize), (1, 14), (2, 15), (3, 16), (4, 17)] {
                f[slot] = vel[e][k].length();
                f[slot + 5] = acc[e][k].length();
            }
            f[23] = jerk.iter().map(|j| j[k].length()).sum::<f32>() / jerk.len() as f32;
            let frame = body_frame(p);
            let vol = |set: &[Role]| box_volume(set.iter().map(|&r| to_body(g(r), frame)));
            f[24] = vol(&five);
            f[25] = vol(&upper);
            f[26] = vol(&lower);
            f[27] = vol(&left);
            f[28] = vol(&right);
            f[29] = g(Role::Head).distance(g(Role::Hips));
            for h in [Role::LeftHand, Role::RightHand] {
                let y = g(h).y;
                let slot = if y > g(Role::Head).y {
                    F_HANDS_HIGH
                } else if y >= g(Role::Hips).y {
                    F_HANDS_HIGH + 1
                } else {
                    F_HANDS_HIGH + 2
                };
                f[slot] += 0.5;
            }
            let a = dspeed[k].x;
            let prev = if k > 0 {
                dspeed[k - 1].x
            } else {
                f32::INFINITY
            };
            let next = if k + 1 < n {
                dspeed[k + 1].x
            } else {
                f32::INFINITY
            };
            f[F_DECEL_PEAK] = if a < -DECEL_THRESHOLD && a < prev && a <= next {
                1.0
            } else {
                0.0
            };
            f
        })
        .collect()
}

/// The 114 measurements of every window of a clip, flat (`windows × MEASUREMENTS`).
///
/// Window `w` is centred on frame `w + HALF`; a clip of `n ≥ WINDOW` frames has
/// `n − WINDOW + 1` windows, a shorter clip none.
pub fn clip_measurements(points: &[[Vec3; Role::COUNT]]) -> Vec<f32> {
    let n = points.len();
    if n < WINDOW {
        return Vec::new();
    }
    let feats = frame_features(points);
    let windows = n - WINDOW + 1;
    let mut out = vec![0.0f32; windows * MEASUREMENTS];
    let mut hull = Vec::with_capacity(WINDOW);
    for (w, phi) in out.chunks_exact_mut(MEASUREMENTS).enumerate() {
        let win = &feats[w..w + WINDOW];
        let pts = &points[w..w + WINDOW];
        let mut k = 0;
        let mut push = |v: f32, k: &mut usize| {
            phi[*k] = if v.is_finite() { v } else { 0.0 };
            *k += 1;
        };
        for (i, (slot, stats)) in STAT_LAYOUT.iter().enumerate() {
            if i == 13 {
                // f11, φ53: deceleration peaks per second.
                let peaks: f32 = win.iter().map(|f| f[F_DECEL_PEAK]).sum();
                push(peaks / (WINDOW as f32 / FPS), &mut k);
            }
            if *slot == F_HANDS_HIGH {
                for s in 0..3 {
                    push(
                        win.iter().map(|f| f[F_HANDS_HIGH + s]).sum::<f32>() / WINDOW as f32,
                        &mut k,
                    );
                }
            }
            if stats.is_empty() {
                continue;
            }
            let vals = win.iter().map(|f| f[*slot]);
            let (mx, mn, sd, mean) = stats4(vals);
            for s in stats.iter() {
                push(
                    match s {
                        Stat::Max => mx,
                        Stat::Min => mn,
                        Stat::Std => sd,
                        Stat::Mean => mean,
                    },
                    &mut k,
                );
            }
        }
        // SPACE.
        let hips: Vec<Vec2> = pts
            .iter()
            .map(|p| {
                let h = p[idx(Role::Hips)];
                Vec2::new(h.x, h.z)
            })
            .collect();
        let dist: f32 = hips.windows(2).map(|s| s[0].distance(s[1])).sum();
        push(dist, &mut k);
        hull.clear();
        hull.extend_from_slice(&hips);
        push(hull_area(&mut hull), &mut k);
        let frame = body_frame(&pts[HALF]);
        push(
            box_volume(
                pts.iter()
                    .flat_map(|p| p.iter().map(move |&v| to_body(v, frame))),
            ),
            &mut k,
        );
        let mean = hips.iter().copied().fold(Vec2::ZERO, |a, b| a + b) / WINDOW as f32;
        let (mx, mn, sd, mu) = stats4(hips.iter().map(|h| h.distance(mean)));
        for v in [mx, mn, sd, mu] {
            push(v, &mut k);
        }
        debug_assert_eq!(k, MEASUREMENTS);
    }
    out
}

/// (max, min, population std, mean) of a sequence.
fn stats4(vals: impl Iterator<Item = f32> + Clone) -> (f32, f32, f32, f32) {
    let mut mx = f32::NEG_INFINITY;
    let mut mn = f32::INFINITY;
    let mut sum = 0.0f64;
    let mut sq = 0.0f64;
    let mut n = 0usize;
    for v in vals {
        mx = mx.max(v);
        mn = mn.min(v);
        sum += v as f64;
        sq += (v as f64) * (v as f64);
        n += 1;
    }
    if n == 0 {
        return (0.0, 0.0, 0.0, 0.0);
    }
    let mean = sum / n as f64;
    let var = (sq / n as f64 - mean * mean).max(0.0);
    (mx, mn, var.sqrt() as f32, mean as f32)
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A standing body whose hips move along x at `speed` m/s, hands swinging with `amp` m.
    pub(crate) fn synthetic(frames: usize, speed: f32, amp: f32) -> Vec<[Vec3; Role::COUNT]> {
        (0..frames)
            .map(|k| {
                let t = k as f32 / FPS;
                let x = speed * t;
                let sw = amp * (t * 6.0).sin();
                let mut p = [Vec3::ZERO; Role::COUNT];
                let mut set = |r: Role, v: Vec3| p[r.index()] = v + Vec3::new(x, 0.0, 0.0);
                set(Role::Hips, Vec3::new(0.0, 1.0, 0.0));
                set(Role::Chest, Vec3::new(0.0, 1.3, 0.0));
                set(Role::Neck, Vec3::new(0.0, 1.5, 0.0));
                set(Role::Head, Vec3::new(0.0, 1.65, 0.0));
                set(Role::LeftShoulder, Vec3::new(0.0, 1.45, 0.2));
                set(Role::RightShoulder, Vec3::new(0.0, 1.45, -0.2));
                set(Role::LeftElbow, Vec3::new(0.0, 1.2, 0.25));
                set(Role::RightElbow, Vec3::new(0.0, 1.2, -0.25));
                set(Role::LeftHand, Vec3::new(sw, 0.95, 0.25));
                set(Role::RightHand, Vec3::new(-sw, 0.95, -0.25));
                set(Role::LeftHip, Vec3::new(0.0, 0.95, 0.1));
                set(Role::RightHip, Vec3::new(0.0, 0.95, -0.1));
                set(Role::LeftKnee, Vec3::new(0.0, 0.5, 0.1));
                set(Role::RightKnee, Vec3::new(0.0, 0.5, -0.1));
                set(Role::LeftFoot, Vec3::new(0.0, 0.05, 0.1));
                set(Role::RightFoot, Vec3::new(0.0, 0.05, -0.1));
                p
            })
            .collect()
    }

    #[test]
    fn window_count_and_known_values() {
        let pts = synthetic(50, 1.0, 0.0);
        let m = clip_measurements(&pts);
        assert_eq!(m.len(), (50 - WINDOW + 1) * MEASUREMENTS);
        let phi = &m[..MEASUREMENTS];
        // φ1..4: left foot-hip distance is constant.
        let d = Vec3::new(0.0, 0.95, 0.1).length();
        for v in &phi[0..2] {
            assert!((v - d).abs() < 1e-4, "{v} vs {d}");
        }
        assert!(phi[2].abs() < 1e-4, "std {}", phi[2]);
        // φ29: hip height 1 m.
        assert!((phi[28] - 1.0).abs() < 1e-5);
        // φ54 pelvis speed max ≈ 1 m/s, φ56 mean ≈ 1 m/s.
        assert!((phi[53] - 1.0).abs() < 1e-3, "{}", phi[53]);
        assert!((phi[55] - 1.0).abs() < 1e-3);
        // φ108 distance travelled over 34 frame steps at 1 m/s.
        assert!((phi[107] - 34.0 / 30.0).abs() < 1e-3, "{}", phi[107]);
        // Straight path: no hull area; hands just below the hips → low level.
        assert!(phi[108].abs() < 1e-4);
        assert!((phi[106] - 1.0).abs() < 1e-6 && phi[104].abs() < 1e-6 && phi[105].abs() < 1e-6);
        assert!(m.iter().all(|v| v.is_finite()));
    }

    #[test]
    fn effort_measurements_grow_with_speed() {
        let slow = clip_measurements(&synthetic(40, 0.0, 0.1));
        let fast = clip_measurements(&synthetic(40, 0.0, 0.5));
        // Left-hand velocity max φ57 and acceleration max φ71.
        assert!(fast[56] > 3.0 * slow[56], "{} vs {}", fast[56], slow[56]);
        assert!(fast[70] > 3.0 * slow[70]);
    }

    #[test]
    fn short_clip_has_no_windows() {
        assert!(clip_measurements(&synthetic(WINDOW - 1, 1.0, 0.1)).is_empty());
        assert_eq!(
            clip_measurements(&synthetic(WINDOW, 1.0, 0.1)).len(),
            MEASUREMENTS
        );
    }

    #[test]
    fn hull_area_of_square() {
        let mut p = vec![
            Vec2::new(0.0, 0.0),
            Vec2::new(1.0, 0.0),
            Vec2::new(0.5, 0.5),
            Vec2::new(1.0, 1.0),
            Vec2::new(0.0, 1.0),
        ];
        assert!((hull_area(&mut p) - 1.0).abs() < 1e-6);
    }
}
