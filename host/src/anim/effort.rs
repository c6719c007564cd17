//! Effort transfer (seed 000 §6.3–6.4): retiming, rescaling, reshaping a neutral clip so it
//! shows the recognised Laban Time (Lt) and Weight (Lw).
//!
//! - **Time** (§6.4.1): preparation and anticipation are rescaled (eq. 7) by
//!   `c = 1 / (3|Lt| + 1)`; the stage clock is retimed with eq. 6's stage functions
//!   `f_i(t) = f_{i-1}(end_{i-1}) + a_i · t^b_i` (t in seconds from the stage start):
//!   sudden (Lt ≥ 0) anticipation `t^(1 − 0.5 Lt)`, execution `t^(1 − 0.4 Lt) / (2 Lt + 1)`;
//!   sustained anticipation `(0.5 Lt + 1) t`, execution `(1 − 2 Lt) t^(1 − 0.4 Lt)`; other
//!   stages keep their timing. Sudden executions get shorter and start with an acceleration,
//!   sustained ones longer and decelerating.
//! - **Weight** (§6.4.2): arc-length reparametrisation `L_i = V_i^k Δt + L_{i−1}`, traversed
//!   uniformly in output time, with V the mean joint speed normalised by its clip mean and
//!   floored at [`SPEED_FLOOR`]. Read literally, the seed's `k = α Lw` (α = [`ALPHA`]) would
//!   make strong motions *more* uniform (uniform arc length is uniform speed at k = 1) and
//!   light ones diverge near V = 0, the opposite of its stated aim; we implement the aim: the
//!   output speed goes as `V^(1 − k)` with `k = −α Lw` for strong (speed variations amplified)
//!   and `k = min(α |Lw|, 1)` for light (flattened, "between 0 and 1": at full lightness the
//!   speed is uniform). Then eq. 7 over every stage with `c = Lw + 1` (strong) or `1 / (1 − Lw)`
//!   (light); then reshaping: every spine bone (the chain from the root to the head, found
//!   automatically) is rotated by `δθ = 0.1 · Lw` rad about the body's lateral axis, strong
//!   sinking forward, light rising; each frame's torso tilt is then held within
//!   [`super::torso_tilt::HOLD_DEG`] of its source frame's
//!   ([`super::torso_tilt::hold_torso_tilt`]).
//!
//! Eq. 7 is applied with each stage's reference chained to the previous stage's rescaled end,
//! so the rescaled motion stays continuous at stage boundaries. Every joint is rescaled only
//! as far as it stays within the range the library's actors moved it in
//! ([`super::joint_limits::JointRanges`]; a strong run's hips swing wider, but never into a
//! split), the hinges (knees, elbows) are then held within the range they bend in
//! ([`super::joint_limits`]), and the frames in which the source stood are put back on the
//! ground ([`super::contact::keep_source_contacts`]): a strong jump flies higher, a strong
//! punch does not hover. The root's orientation (the body's facing and balance) is left
//! alone; its height is rescaled, and for cyclic clips its ground travel follows the feet's
//! rescaled sweep ([`stride_ratio`]) so that a cycle covers the distance its legs step.
//! Cyclic clips (gaits) keep their clock within the cycle; their Time shows in the cadence
//! (see [`apply_effort`]). Feet that slide because of rescaling are pinned afterwards by the
//! assembler's contact pass, and [`EffortClip::paced`] keeps a retimed clip's root within
//! the speed a person moves at.

use glam::{Quat, Vec3};

use super::contact::{find_legs, keep_feet_above_floor, keep_source_contacts};
use super::joint_limits::{find_hinges, limit_hinges, JointRanges};
use super::phrasing::{Phrasing, Stage};
use super::torso_tilt::{hold_torso_tilt, HOLD_DEG};
use crate::motion::{Clip, Pose, Skeleton};

/// Exponent of the weight arc-length reparametrisation (seed: α = 1.5).
pub const ALPHA: f32 = 1.5;
/// Reshaping angle per spine bone at |Lw| = 1, radians (seed: δθ = 0.1 · Lw).
pub const RESHAPE_RAD: f32 = 0.1;
/// Floor of the normalised joint speed in the arc-length reparametrisation.
pub const SPEED_FLOOR: f32 = 0.1;
/// Bisection steps finding how far a joint may be rescaled within its range (1/256 of the
/// factor's span).
const RANGE_BISECTIONS: usize = 8;
/// Sub-samples per source frame when tabulating time maps.
const SUBSTEPS: usize = 4;

/// Laban efforts of one action, each in [-1, 1].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Effort {
    /// Time Lt: > 0 sudden, < 0 sustained.
    pub time: f32,
    /// Weight Lw: > 0 strong, < 0 light.
    pub weight: f32,
}

impl Effort {
    /// Clamps both values into [-1, 1]; non-finite values become 0 (neutral).
    pub fn sanitized(self) -> Effort {
        let f = |x: f32| {
            if x.is_finite() {
                x.clamp(-1.0, 1.0)
            } else {
                0.0
            }
        };
        Effort {
            time: f(self.time),
            weight: f(self.weight),
        }
    }
}

/// A clip with efforts applied: modified poses on the source clock plus a time map from the
/// normalised output clock w ∈ [0, 1] to source time.
#[derive(Debug, Clone)]
pub struct EffortClip {
    /// Poses after rescaling and reshaping (same frames and frame time as the source).
    pub clip: Clip,
    /// The stages of the source clip.
    pub phrasing: Phrasing,
    /// Monotone table of (w, source seconds), w from 0 to 1.
    pub(super) table: Vec<(f32, f32)>,
    /// Seconds the table's timing lasts at the effort's own pace (eq. 6's stage clock: the
    /// source's length for a neutral Time, shorter for sudden, longer for sustained), before
    /// an event's length stretches or squeezes it.
    pub(super) natural_s: f32,
}

impl EffortClip {
    /// Source time (seconds) shown at normalised output time `w` ∈ [0, 1].
    pub fn source_time(&self, w: f32) -> f32 {
        lookup(&self.table, w.clamp(0.0, 1.0), false)
    }

    /// Normalised output time at which source time `s` (seconds) is shown.
    pub fn output_w(&self, s: f32) -> f32 {
        lookup(&self.table, s, true)
    }

    /// Pose at normalised output time `w`.
    pub fn pose(&self, w: f32) -> Pose {
        self.clip.sample(self.source_time(w))
    }

    /// Output interval (w0, w1) of a stage, if present.
    pub fn stage_w(&self, stage: Stage) -> Option<(f32, f32)> {
        let s = self.phrasing.span(stage)?;
        let dt = self.clip.frame_time;
        Some((
            self.output_w(s.start as f32 * dt),
            self.output_w(s.end as f32 * dt),
        ))
    }
}

/// Interpolates a monotone table; `inverse` looks up by the second column.
fn lookup(table: &[(f32, f32)], x: f32, inverse: bool) -> f32 {
    let key = |e: &(f32, f32)| if inverse { e.1 } else { e.0 };
    let val = |e: &(f32, f32)| if inverse { e.0 } else { e.1 };
    let (Some(first), Some(last)) = (table.first(), table.last()) else {
        return 0.0;
    };
    if !x.is_finite() || x <= key(first) {
        return val(first);
    }
    if x >= key(last) {
        return val(last);
    }
    let i = table
        .partition_point(|e| key(e) <= x)
        .clamp(1, table.len() - 1);
    let (a, b) = (&table[i - 1], &table[i]);
    let span = key(b) - key(a);
    let u = if span > 0.0 { (x - key(a)) / span } else { 0.0 };
    val(a) + (val(b) - val(a)) * u
}

/// Applies Time and Weight efforts to a clip with the given phrasing; `forward` is the rig's
/// facing in its own frame (the clip library's `forward`), which defines the spine's bending axis;
/// `ranges` (the library's joint ranges, if known) bound every joint after rescaling.
///
/// `cyclic` clips (gait cycles) are treated as locomotion: their root's ground travel follows
/// the rescaled stride — scaled by how much wider or narrower the feet now sweep relative to
/// the hips ([`stride_ratio`]), so a cycle covers the distance its legs step — and their clock
/// is left uniform within the cycle. A gait's timing within a step is set by the body's
/// mechanics (a foot lands when it lands); eq. 6's warp inside every cycle would make the
/// body lurch from 1 to 8 m/s each step. Their Time shows in the cadence instead: the
/// assembler fits whole cycles into the doodle's own duration, short for sudden doodles and
/// long for sustained ones.
pub fn apply_effort(
    clip: &Clip,
    phrasing: &Phrasing,
    effort: Effort,
    forward: Vec3,
    cyclic: bool,
    ranges: Option<&JointRanges>,
) -> EffortClip {
    let e = effort.sanitized();
    let mut out = clip.clone();
    let n = clip.len();
    let dt = clip.frame_time.max(1e-6);
    // Rescale (eq. 7): per-stage factor from Time (prep/anticipation) and Weight (all).
    let c_w = if e.weight >= 0.0 {
        e.weight + 1.0
    } else {
        1.0 / (1.0 - e.weight)
    };
    let c_t = 1.0 / (3.0 * e.time.abs() + 1.0);
    let factors: Vec<(usize, usize, f32)> = phrasing
        .spans
        .iter()
        .map(|s| {
            let time_part = match s.stage {
                Stage::Preparation | Stage::Anticipation => c_t,
                _ => 1.0,
            };
            (s.start, s.end, time_part * c_w)
        })
        .collect();
    // An amplified swing stays a human one: every joint within the range the library's actors
    // moved it in, and no knee or elbow bent backwards.
    rescale_stages(clip, &mut out, &factors, ranges);
    limit_hinges(&find_hinges(clip), &mut out);
    if cyclic {
        let ratio = stride_ratio(clip, &out);
        scale_travel(clip, &mut out, ratio);
    }
    // A rescaled height flies higher where the source flew, but stands where it stood.
    keep_source_contacts(clip, &mut out);
    keep_feet_above_floor(clip, &mut out);
    reshape(&mut out, e.weight, forward);
    // Bent further or straighter, the torso stays within the tilt real takes of one kind
    // vary by at different vigour (a light bow still bows).
    hold_torso_tilt(clip, &mut out, HOLD_DEG);

    // Time maps: weight arc length G (source → arc clock), then eq. 6 stages F.
    let speeds = joint_speeds(clip);
    let mean = speeds.iter().sum::<f32>() / speeds.len().max(1) as f32;
    // Output time spent per source second ∝ V^k: k < 0 makes fast parts faster and slow parts
    // slower (strong); 0 < k ≤ 1 evens the speed out (light), k = 1 being uniform speed.
    let k = if cyclic {
        0.0
    } else if e.weight >= 0.0 {
        -ALPHA * e.weight
    } else {
        (ALPHA * -e.weight).min(1.0)
    };
    // Cycles keep their own clock (see above): no stage warp either.
    let lt = if cyclic { 0.0 } else { e.time };
    let mut arc = vec![0.0f32; n];
    for i in 1..n {
        let v = if mean > 1e-9 {
            (speeds[i] / mean).max(SPEED_FLOOR)
        } else {
            1.0
        };
        arc[i] = arc[i - 1] + v.powf(k) * dt;
    }
    let total_src = (n.saturating_sub(1)) as f32 * dt;
    let total_arc = arc.last().copied().unwrap_or(0.0).max(1e-9);
    // G(src) in seconds of the arc clock (rescaled to the source duration).
    let g_at = |f: f32| -> f32 {
        let i = (f.floor() as usize).min(n.saturating_sub(1));
        let j = (i + 1).min(n.saturating_sub(1));
        let u = f - i as f32;
        (arc[i] + (arc[j] - arc[i]) * u) / total_arc * total_src
    };
    let bounds: Vec<(Stage, f32, f32)> = phrasing
        .spans
        .iter()
        .map(|s| (s.stage, g_at(s.start as f32), g_at(s.end as f32)))
        .collect();
    let stage_f = |g: f32| -> f32 {
        let mut acc = 0.0;
        for &(stage, a, b) in &bounds {
            let local = (g.min(b) - a).max(0.0);
            let (ak, bk) = stage_params(stage, lt);
            acc += ak * local.powf(bk);
            if g <= b {
                break;
            }
        }
        acc
    };
    let steps = (n.saturating_sub(1)) * SUBSTEPS;
    let mut table = Vec::with_capacity(steps + 1);
    for k in 0..=steps {
        let f = k as f32 / SUBSTEPS as f32;
        table.push((stage_f(g_at(f)), f * dt));
    }
    let end = table.last().map(|e| e.0).unwrap_or(1.0).max(1e-9);
    for e in &mut table {
        e.0 /= end;
    }
    // Guard monotonicity against float ties.
    for i in 1..table.len() {
        if table[i].0 < table[i - 1].0 {
            table[i].0 = table[i - 1].0;
        }
    }
    EffortClip {
        clip: out,
        phrasing: phrasing.clone(),
        table,
        natural_s: end,
    }
}

/// (a, b) of eq. 6 for one stage.
fn stage_params(stage: Stage, lt: f32) -> (f32, f32) {
    match stage {
        Stage::Anticipation if lt >= 0.0 => (1.0, 1.0 - 0.5 * lt),
        Stage::Anticipation => (0.5 * lt + 1.0, 1.0),
        Stage::Execution if lt >= 0.0 => (1.0 / (2.0 * lt + 1.0), 1.0 - 0.4 * lt),
        Stage::Execution => (1.0 - 2.0 * lt, 1.0 - 0.4 * lt),
        _ => (1.0, 1.0),
    }
}

/// Mean joint speed per frame, relative to the root's ground point (length units / s).
pub fn joint_speeds(clip: &Clip) -> Vec<f32> {
    let pos: Vec<Vec<Vec3>> = clip
        .all_positions()
        .into_iter()
        .map(|p| {
            let r = p.first().copied().unwrap_or(Vec3::ZERO);
            let base = Vec3::new(r.x, 0.0, r.z);
            p.into_iter().map(|v| v - base).collect()
        })
        .collect();
    let n = pos.len();
    let dt = clip.frame_time.max(1e-6);
    (0..n)
        .map(|i| {
            let (a, b) = (i.saturating_sub(1), (i + 1).min(n.saturating_sub(1)));
            if a == b {
                return 0.0;
            }
            let s: f32 = pos[a]
                .iter()
                .zip(&pos[b])
                .map(|(p, q)| (*q - *p).length())
                .sum();
            s / pos[i].len().max(1) as f32 / ((b - a) as f32 * dt)
        })
        .collect()
}

/// Largest joint rotation (radians) away from the stage-start pose that rescaling may
/// produce: amplifying a large swing past this would wrap round and flip the limb.
pub const MAX_RESCALED_ANGLE: f32 = 2.6;

/// `q^c` for a unit quaternion along the shorter arc (any real c), the result's angle capped
/// at [`MAX_RESCALED_ANGLE`] when amplifying.
fn quat_pow(q: Quat, c: f32) -> Quat {
    let q = if q.w < 0.0 { -q } else { q };
    let (axis, angle) = q.normalize().to_axis_angle();
    if angle.abs() < 1e-7 || !axis.is_finite() {
        return Quat::IDENTITY;
    }
    let scaled = angle * c;
    let scaled = if c > 1.0 {
        scaled.clamp(
            -MAX_RESCALED_ANGLE.max(angle.abs()),
            MAX_RESCALED_ANGLE.max(angle.abs()),
        )
    } else {
        scaled
    };
    Quat::from_axis_angle(axis, scaled)
}

/// Eq. 7 per stage, references chained so the result is continuous.
/// Each joint's rotation is rescaled by `c` unless that leaves its range (`ranges`); then by
/// the factor between 1 and `c` nearest `c` that keeps it within (bisection on the factor, so
/// the joint stops where the amplified swing meets the edge of its range rather than being
/// clamped after the fact, which for a swing amplified past half a turn would flip it to the
/// opposite side).
fn rescale_stages(
    src: &Clip,
    out: &mut Clip,
    factors: &[(usize, usize, f32)],
    ranges: Option<&JointRanges>,
) {
    let joints = src.skeleton.len();
    let Some(first) = src.frames.first() else {
        return;
    };
    let mut ref_out = first.clone();
    for &(s, e, c) in factors {
        let Some(ref_src) = src.frames.get(s).cloned() else {
            continue;
        };
        for f in s..=e.min(src.len().saturating_sub(1)) {
            let (Some(p), Some(o)) = (src.frames.get(f), out.frames.get_mut(f)) else {
                continue;
            };
            for j in 0..joints {
                if j == 0 {
                    // The root's orientation is the body's facing and balance: rescaling it
                    // would over- or under-turn the character and tip it over. Its height is
                    // rescaled like any translation; its ground travel is the legs' doing
                    // (see `scale_travel`).
                    let ts = ref_src.translations[0];
                    let tt = p.translations[0];
                    o.translations[0].y = ref_out.translations[0].y + (tt.y - ts.y) * c;
                    continue;
                }
                let qs = ref_src.rotations[j];
                let qt = p.rotations[j];
                // eq. 7: q(t) = scale(q(s) q(t)^-1, c)^-1 q(s), with q(s) → rescaled reference.
                let at = |c: f32| {
                    (quat_pow(qs * qt.inverse(), c).inverse() * ref_out.rotations[j]).normalize()
                };
                let mut q = at(c);
                // The factor nearest c that keeps the joint within its range, from the
                // source's own motion (1) if that is within, else from the stage's rescaled
                // reference (0): where an earlier stage's factor moved the reference, even the
                // source's own motion from it may leave the range (a crouch's rise amplified
                // from a squat that sudden anticipation made shallower swings the leg back
                // past standing, up behind the body).
                let within = ranges.filter(|r| !r.contains(j, q)).and_then(|r| {
                    [1.0, 0.0]
                        .into_iter()
                        .find(|&k| r.contains(j, at(k)))
                        .map(|k| (r, k))
                });
                if let Some((r, from)) = within {
                    let (mut inside, mut outside) = (from, c);
                    for _ in 0..RANGE_BISECTIONS {
                        let mid = 0.5 * (inside + outside);
                        if r.contains(j, at(mid)) {
                            inside = mid;
                        } else {
                            outside = mid;
                        }
                    }
                    q = at(inside);
                }
                o.rotations[j] = q;
                let ts = ref_src.translations[j];
                let tt = p.translations[j];
                let scaled = ref_out.translations[j] + (tt - ts) * c;
                if src.skeleton.joints[j].has_position() {
                    o.translations[j] = scaled;
                }
            }
        }
        if let Some(end) = out.frames.get(e.min(src.len().saturating_sub(1))) {
            ref_out = end.clone();
        }
    }
}

/// How much wider (> 1) or narrower the feet of `out` sweep than those of `src` (the same
/// frames before rescaling): per leg, the extent of the ankle's position relative to the
/// hips along the clip's direction of travel, summed over the legs. 1 when the source's feet
/// do not sweep (or it has no legs, or does not travel).
pub fn stride_ratio(src: &Clip, out: &Clip) -> f32 {
    let legs = find_legs(src);
    let root = src.root_path();
    let (Some(&r0), Some(&rl)) = (root.first(), root.last()) else {
        return 1.0;
    };
    let Some(dir) = Vec3::new(rl.x - r0.x, 0.0, rl.z - r0.z).try_normalize() else {
        return 1.0;
    };
    let sweep = |c: &Clip| -> f32 {
        let pos = c.all_positions();
        legs.iter()
            .map(|l| {
                let along = pos.iter().filter_map(|p| {
                    Some((*p.get(l.ankle)? - *p.first()?).dot(dir)).filter(|v| v.is_finite())
                });
                let (lo, hi) = along.fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), v| {
                    (a.min(v), b.max(v))
                });
                if hi >= lo {
                    hi - lo
                } else {
                    0.0
                }
            })
            .sum()
    };
    let before = sweep(src);
    if before < 1e-3 {
        return 1.0;
    }
    sweep(out) / before
}

/// Scales the root's ground travel (from the first frame) of `out` by `ratio`, from that of
/// `src` (the same frames before rescaling).
fn scale_travel(src: &Clip, out: &mut Clip, ratio: f32) {
    let Some(r0) = src.frames.first().map(|p| p.translations[0]) else {
        return;
    };
    for (p, o) in src.frames.iter().zip(&mut out.frames) {
        let t = p.translations[0];
        o.translations[0].x = r0.x + (t.x - r0.x) * ratio;
        o.translations[0].z = r0.z + (t.z - r0.z) * ratio;
    }
}

/// The spine: joints on the chain from the root to the head (the leaf highest in frame 0),
/// excluding the root itself and the end site.
pub fn spine_chain(clip: &Clip) -> Vec<usize> {
    let sk = &clip.skeleton;
    let Some(head) = head_leaf(clip) else {
        return Vec::new();
    };
    sk.chain_to(head)
        .into_iter()
        .filter(|&j| sk.joints[j].parent.is_some() && !sk.joints[j].end_site)
        .collect()
}

/// The head: among the leaves that are above the root on average over the clip, the one with
/// the shortest chain from the root (arms branch off the spine and are longer chains; raised
/// hands are therefore not mistaken for the head); ties go to the higher leaf.
pub fn head_leaf(clip: &Clip) -> Option<usize> {
    let sk: &Skeleton = &clip.skeleton;
    let n = sk.len();
    if n == 0 || clip.is_empty() {
        return None;
    }
    let step = (clip.len() / 30).max(1);
    let mut height = vec![0.0f32; n];
    for f in (0..clip.len()).step_by(step) {
        let p = clip.joint_positions(f);
        for j in 0..n {
            height[j] += p[j].y - p[0].y;
        }
    }
    (0..n)
        .filter(|&j| sk.children(j).is_empty() && height[j] > 0.0)
        .min_by(|&a, &b| {
            sk.depth(a)
                .cmp(&sk.depth(b))
                .then(height[b].total_cmp(&height[a]))
        })
}

/// Bends the spine about the body's lateral axis by `RESHAPE_RAD · Lw` per bone
/// (strong: forward and down; light: up and back).
fn reshape(clip: &mut Clip, lw: f32, forward: Vec3) {
    let spine = spine_chain(clip);
    let Some(head) = head_leaf(clip) else { return };
    if spine.is_empty() || lw == 0.0 || clip.is_empty() {
        return;
    }
    let w0 = clip.skeleton.forward(&clip.frames[0]);
    let root_rot0 = w0[0].rotation;
    let up = (w0[head].position - w0[0].position).normalize_or_zero();
    // Forward: the rig's facing, carried by the root in frame 0, made horizontal.
    let f = root_rot0 * forward;
    let fwd = (f - up * f.dot(up)).normalize_or_zero();
    let mut lateral = up.cross(fwd).normalize_or_zero();
    if lateral == Vec3::ZERO {
        return;
    }
    // Positive rotation must move the head forward.
    let probe = Quat::from_axis_angle(lateral, 0.1) * up;
    if probe.dot(fwd) < 0.0 {
        lateral = -lateral;
    }
    let lateral_in_root = root_rot0.inverse() * lateral;
    let delta = RESHAPE_RAD * lw;
    for f in 0..clip.len() {
        let world = clip.skeleton.forward(&clip.frames[f]);
        let axis = (world[0].rotation * lateral_in_root).normalize_or_zero();
        for &j in &spine {
            let wj = world[j].rotation;
            let local_axis = (wj.inverse() * axis).normalize_or_zero();
            if local_axis == Vec3::ZERO {
                continue;
            }
            let r = &mut clip.frames[f].rotations[j];
            *r = (*r * Quat::from_axis_angle(local_axis, delta)).normalize();
        }
    }
}

/// Forward tilt of the spine: angle (radians) between the root→head vector and +Y.
pub fn spine_tilt(clip: &Clip, frame: usize) -> f32 {
    let Some(head) = head_leaf(clip) else {
        return 0.0;
    };
    let p = clip.joint_positions(frame);
    let v = (p[head] - p[0]).normalize_or_zero();
    v.dot(Vec3::Y).clamp(-1.0, 1.0).acos()
}

/// Signed forward lean of the spine (radians): the angle of the vector from the first spine
/// joint to the head, from +Y towards the body's facing (`forward`, the rig's facing
/// direction carried by the root); positive leans forward.
pub fn spine_lean(clip: &Clip, frame: usize, forward: Vec3) -> f32 {
    let Some(head) = head_leaf(clip) else {
        return 0.0;
    };
    let base = spine_chain(clip).first().copied().unwrap_or(0);
    let w = match clip.frames.get(frame) {
        Some(p) => clip.skeleton.forward(p),
        None => return 0.0,
    };
    let v = w[head].position - w[base].position;
    let f = w[0].rotation * forward;
    let f = Vec3::new(f.x, 0.0, f.z).normalize_or_zero();
    v.dot(f).atan2(v.y)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::anim::library::ClipLibrary;
    use crate::anim::phrasing::detect_stages;

    fn punch() -> Option<Clip> {
        crate::data::data_file("deepmimic", "humanoid.urdf")?;
        let lib = ClipLibrary::default_library().ok()?;
        Some(lib.load(["punch"]).ok()?.remove("punch")?.clip)
    }

    #[test]
    fn neutral_effort_is_identity() {
        let Some(c) = punch() else {
            eprintln!("skipping: deepmimic data missing — run `cargo xtask setup`");
            return;
        };
        let ph = detect_stages(&c);
        let e = apply_effort(&c, &ph, Effort::default(), Vec3::X, false, None);
        for (a, b) in e.clip.frames.iter().zip(&c.frames) {
            for (qa, qb) in a.rotations.iter().zip(&b.rotations) {
                assert!(qa.dot(*qb).abs() > 1.0 - 1e-6);
            }
            for (ta, tb) in a.translations.iter().zip(&b.translations) {
                assert!((*ta - *tb).length() < 1e-5);
            }
        }
        for w in [0.0, 0.3, 0.77, 1.0] {
            assert!((e.source_time(w) - w * c.duration()).abs() < 1e-3);
        }
    }

    #[test]
    fn sudden_shortens_and_sustained_lengthens_execution() {
        let Some(c) = punch() else {
            eprintln!("skipping: deepmimic data missing — run `cargo xtask setup`");
            return;
        };
        let ph = detect_stages(&c);
        let frac = |lt: f32| {
            let e = apply_effort(
                &c,
                &ph,
                Effort {
                    time: lt,
                    weight: 0.0,
                },
                Vec3::X,
                false,
                None,
            );
            let (a, b) = e.stage_w(Stage::Execution).unwrap();
            b - a
        };
        let (sudden, neutral, sustained) = (frac(1.0), frac(0.0), frac(-1.0));
        assert!(
            sudden < neutral && neutral < sustained,
            "{sudden} {neutral} {sustained}"
        );
    }

    #[test]
    fn strong_bends_the_spine_more_and_moves_more() {
        let Some(c) = punch() else {
            eprintln!("skipping: deepmimic data missing — run `cargo xtask setup`");
            return;
        };
        let ph = detect_stages(&c);
        let light = apply_effort(
            &c,
            &ph,
            Effort {
                time: 0.0,
                weight: -1.0,
            },
            Vec3::X,
            false,
            None,
        );
        let strong = apply_effort(
            &c,
            &ph,
            Effort {
                time: 0.0,
                weight: 1.0,
            },
            Vec3::X,
            false,
            None,
        );
        let mid = c.len() / 2;
        assert!(spine_tilt(&strong.clip, mid) > spine_tilt(&light.clip, mid));
        let amp = |k: &Clip| joint_speeds(k).iter().sum::<f32>();
        assert!(amp(&strong.clip) > amp(&c) && amp(&c) > amp(&light.clip));
    }

    #[test]
    fn a_return_amplified_from_a_moved_reference_stays_within_the_joints_range() {
        use crate::anim::phrasing::StageSpan;
        use crate::motion::Joint;
        // A joint bends 1.5 rad (anticipation) and straightens again (execution).
        let skeleton = Skeleton {
            joints: vec![
                Joint::bare("root", None, Vec3::ZERO),
                Joint::bare("knee", Some(0), Vec3::new(0.0, -0.4, 0.0)),
            ],
        };
        let frames: Vec<Pose> = (0..=40)
            .map(|f| {
                let mut p = Pose::rest(&skeleton);
                let bend = 1.5 * (1.0 - (f as f32 - 20.0).abs() / 20.0);
                p.rotations[1] = Quat::from_rotation_x(bend);
                p.translations[0] = Vec3::new(0.0, 0.9, 0.0);
                p
            })
            .collect();
        let clip = Clip {
            name: "bend".into(),
            skeleton,
            frame_time: 1.0 / 30.0,
            frames,
        };
        let phrasing = Phrasing {
            spans: vec![
                StageSpan {
                    stage: Stage::Anticipation,
                    start: 0,
                    end: 20,
                },
                StageSpan {
                    stage: Stage::Execution,
                    start: 20,
                    end: 40,
                },
            ],
            speed: vec![1.0; 41],
        };
        let ranges = JointRanges::learn([&clip]);
        // Sudden and strong: the bend is rescaled by ½ (so it ends shallower), its return by
        // 2 from there: −3 rad from a 0.75 rad bend, past straight and round behind.
        let ec = apply_effort(
            &clip,
            &phrasing,
            Effort {
                time: 1.0,
                weight: 1.0,
            },
            Vec3::Z,
            false,
            Some(&ranges),
        );
        for (f, p) in ec.clip.frames.iter().enumerate() {
            assert!(
                ranges.contains(1, p.rotations[1]),
                "frame {f}: {:?}",
                p.rotations[1]
            );
        }
    }
}
