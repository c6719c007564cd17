//! The assembler: recognised actions + doodle → one character animation (seed 000 §6).
//!
//! For each event (in time order) the action's clip variant matching the recognised effort is
//! chosen ([`super::variants`]), gets the rest of the effort the variant does not already
//! carry (retime, rescale, reshape; [`residual_effort`]), is stretched over the event's
//! `[start, end]` (output frame f shows log time
//! `t_origin + f / fps`, so timing matches the events), and is placed in the world:
//! - **in place**: at the character's spot, facing its current heading; the clip's own small
//!   steps are kept and the doodle's displacement is dropped (the seed's spatial offset);
//! - **moving, cyclic** (walk, run): whole cycles, as many as fit the path (`round(L / C)`,
//!   C = the clip's travel per cycle), within a human range of cadence ([`super::pacing::MAX_CADENCE`]);
//!   a path longer than that cadence (or [`HUMAN_ROOT_SPEED_M_S`]) covers in the time is
//!   shrunk about its start (see `pace`); the root advances along the path by the clip's own
//!   progress (stretched by `L / (m C)`), so feet do not skate; heading = path tangent;
//! - **moving, not cyclic** (jump): the root stays in place while the clip's own root does
//!   not travel (anticipation, landing, follow-through) and moves along the path, in step
//!   with the clip's own travel, during the execution (stage boundaries from phrasing can
//!   fall inside the take-off, so the clip's travel, not the label, decides).
//!
//! - **looping in place**: a looping clip (DeepMimic `"Loop": "wrap"`, or `cyclic`) that plays
//!   in place repeats as many whole times as fill the event; each repetition starts where the
//!   previous one ended (the clip's own per-cycle ground displacement and turn carried on, so
//!   the root never snaps back), and each cycle's joint mismatch between its last and first
//!   pose is spread over the cycle so the wraps do not pop (this loop closure applies to
//!   cyclic walks along the path too).
//!
//! Actions start at their event's start; an event shorter than its clip allows at
//! [`MAX_SPEEDUP`] overruns its end (a 0.3 s "turn" does not squeeze a 2.5 s pirouette 8×),
//! and so does one whose root would move faster than [`HUMAN_ROOT_SPEED_M_S`] even when the
//! fast stretches borrow time from the slow ones ([`super::effort::EffortClip::paced`]).
//! Between consecutive actions the best frames by windowed posture distance are joined by a
//! smooth blend; after the last action the final pose is held for [`AssembleOptions::hold_s`].
//! Finally feet are pinned where the source clips plant them, and where the animation itself
//! holds a foot low and slow on the ground (two-bone IK holds each planted foot where its
//! contact began, undoing slides from rescaling, path stretching and blends), every other foot
//! is lifted clear of the floor ([`super::footing`]), and ground penetration is removed with
//! two-bone IK.

use std::collections::BTreeMap;

use glam::{Quat, Vec2, Vec3};

use super::contact::{detect_contacts, find_legs, pin_feet};
use super::effort::{apply_effort, Effort, EffortClip};
use super::footing::{clear_swing_feet, fix_ground, planted, GroundFix};
use super::graph_cuts::{GraphGuide, PlacedSource};
use super::library::ActionClip;
use super::looping::{close_loop, cycle_frames, loop_closure};
use super::mirror::plays_mirrored;
use super::pacing::{
    ground_travel, pace, root_speed_max, shrink, PaceLimits, HUMAN_ROOT_ACCEL_M_S2,
    HUMAN_ROOT_SPEED_M_S, PACE_HEADROOM,
};
use super::phrasing::{detect_stages, Phrasing, Stage};
use super::trajectory::{ground, yaw_between, GroundPath, Polyline, DEFAULT_WORLD_SCALE};
use super::transition::{best_pair, blend_world, calm_root, ease_root, smoothstep, ROOT_EASE_S};
use super::variants::{choose_variant, VariantChoice};
use super::AnimError;
use crate::events::ActionRecord;
use crate::motion::{Clip, Pose};
use crate::poselog::PoseLog;

/// Fastest playback of a clip relative to its own speed (before effort retiming).
pub const MAX_SPEEDUP: f32 = 3.0;

/// Most frames an assembled animation may have (two hours at 30 fps; ≈ 360 MB of poses for a
/// 60-joint rig): events whose times span more are refused rather than exhausting memory.
pub const MAX_OUTPUT_FRAMES: usize = 216_000;

/// Frames either side of a join within which [`assemble`] looks for the sharpest change of
/// the root's velocity to ease.
pub const JOIN_EASE_REACH: usize = 2;
/// How many times [`assemble`] eases the sharpest change near each join.
pub const JOIN_EASE_PASSES: usize = 3;

/// Most times [`assemble`] shrinks a gait's path whose root outruns a person at the cycle's
/// fastest (each by the ratio of the limit to the fastest; the bob, which the path does not
/// scale, may need a second).
pub const MAX_PATH_SHRINKS: usize = 4;

/// Share of [`HUMAN_ROOT_SPEED_M_S`] the root may reach where [`assemble`] eases a join
/// ([`ease_root`]'s `top`): more than the actions are paced to ([`PACE_HEADROOM`]), since a
/// ramp from one paced motion into another passes a little above either, but short of the
/// limit itself, since the ground pass after it raises the root by a millimetre here and there
/// (a strong jump eased to the limit landed at 4.2004 m/s).
pub const JOIN_EASE_HEADROOM: f32 = 0.99;

/// Share of the real takes' bound on a join's root acceleration
/// ([`super::envelope::ROOT_ACCEL_JOIN_M_S2`]) [`assemble`] smooths a join's root to: the
/// passes after it (re-planting the feet, the ground pass) move the root by a millimetre
/// here and there.
pub const CALM_HEADROOM: f32 = 0.8;

/// Knobs of the assembler.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AssembleOptions {
    /// Toy metres → character metres.
    pub world_scale: f32,
    /// Output frames per second.
    pub fps: f32,
    /// Seconds the final pose is held after the last action.
    pub hold_s: f32,
    /// How far (seconds) from an action boundary the transition search looks.
    pub transition_search_s: f32,
    /// Minimum blend duration, seconds.
    pub min_blend_s: f32,
    /// With a motion graph: how far (seconds) from an action boundary its transitions are
    /// looked for (graph transitions sit at 35-frame window centres, so they need more room).
    pub graph_search_s: f32,
}

impl Default for AssembleOptions {
    fn default() -> Self {
        AssembleOptions {
            world_scale: DEFAULT_WORLD_SCALE,
            fps: 30.0,
            hold_s: 0.5,
            transition_search_s: 0.25,
            min_blend_s: 0.2,
            graph_search_s: 1.0,
        }
    }
}

/// Where and when one action was placed.
#[derive(Debug, Clone)]
pub struct Placement {
    /// Action name.
    pub action: String,
    /// Output frames `start_frame..=end_frame` hold the action.
    pub start_frame: usize,
    /// Last frame of the action.
    pub end_frame: usize,
    /// The world ground path the root should follow (moving actions), metres.
    pub path: Polyline,
    /// Whether the action travels along the doodle.
    pub moving: bool,
    /// Cycles played (cyclic actions), else 1.
    pub cycles: usize,
    /// Stages on the log's clock: (stage, start s, end s).
    pub stages: Vec<(Stage, f32, f32)>,
    /// The clip variant played and why (`None` when the action has a single clip).
    pub variant: Option<VariantChoice>,
    /// The effort transferred onto the clip (§6.3–6.4): the recognised one, less what the
    /// chosen variant already carries (see [`residual_effort`]).
    pub applied_effort: Effort,
}

/// The assembled animation and what was done to make it.
#[derive(Debug, Clone)]
pub struct Assembly {
    /// The animation (metres, seconds), root in world space.
    pub clip: Clip,
    /// One placement per assembled event.
    pub placements: Vec<Placement>,
    /// Per leg, per frame: the foot is planted (the source clips' contacts at the frames'
    /// source times, and where the assembled animation holds it low and slow on the ground;
    /// [`super::footing::planted`]), and was pinned there; every other foot clears the ground.
    pub contacts: Vec<Vec<bool>>,
    /// The ground pass's report.
    pub ground: GroundFix,
    /// Transitions: (frame where the blend starts, frame where it ends).
    pub transitions: Vec<(usize, usize)>,
    /// Joins, in frame order: frames where the root's motion passes from one source to
    /// another — an action's first and last frame (before and after it, a held pose or the
    /// next action), a blend's first and last. The root's path is eased there
    /// ([`ease_root`]); `figurine check` judges its acceleration around them.
    pub joins: Vec<usize>,
    /// Per transition: the motion-graph cut it follows (`--graph`), or `None` where the
    /// windowed posture distance chose it.
    pub graph_cuts: Vec<Option<crate::graph::effort::ClipCut>>,
    /// Log-clock time (seconds) of output frame 0: the doodle's first sample, else 0 (or the
    /// first event's start if it is negative). Frame f shows log time `t_origin + f / fps`.
    pub t_origin: f64,
}

/// The arms' and legs' joints whose swing [`Assembly::limb_swing_rad`] averages.
pub const LIMB_SWING_JOINTS: [&str; 8] = [
    "right_shoulder",
    "right_elbow",
    "left_shoulder",
    "left_elbow",
    "right_hip",
    "right_knee",
    "left_hip",
    "left_knee",
];

impl Assembly {
    /// How far an event's limbs swing (rad): the mean angle by which the arms' and legs' joints
    /// turn away from their pose at the event's first frame, over its frames — what effort's
    /// rescale (eq. 7) scales, and what tells a strong performance from a light one. `None`
    /// without such a placement.
    pub fn limb_swing_rad(&self, placement: usize) -> Option<f32> {
        let sk = &self.clip.skeleton;
        let joints: Vec<usize> = LIMB_SWING_JOINTS
            .iter()
            .filter_map(|n| sk.find(n))
            .collect();
        let p = self.placements.get(placement)?;
        let q0 = &self.clip.frames.get(p.start_frame)?.rotations;
        let frames = self.clip.frames.get(p.start_frame..=p.end_frame)?;
        let sum: f32 = frames
            .iter()
            .flat_map(|f| joints.iter().map(|&j| q0[j].angle_between(f.rotations[j])))
            .sum();
        Some(sum / (frames.len() * joints.len()).max(1) as f32)
    }
}

/// One placed action: its frames on the output clock.
struct Placed {
    f0: usize,
    poses: Vec<Pose>,
    /// Per frame: the action clip's time shown, seconds.
    src_times: Vec<f32>,
    /// The event's recognised effort.
    effort: Effort,
    /// The source clip file of the variant played.
    file: std::path::PathBuf,
    /// Seconds of the source file where the played clip starts (see [`ActionClip`]).
    source_start_s: Option<f32>,
    /// Per frame, per leg: the source clip's foot contact at the frame's source time.
    contacts: Vec<Vec<bool>>,
    /// Output frame time, s.
    frame_s: f32,
}

impl Placed {
    fn f1(&self) -> usize {
        self.f0 + self.poses.len().saturating_sub(1)
    }

    fn contact_at(&self, f: usize) -> Vec<bool> {
        let k = f
            .saturating_sub(self.f0)
            .min(self.contacts.len().saturating_sub(1));
        self.contacts.get(k).cloned().unwrap_or_default()
    }

    fn at(&self, f: usize) -> &Pose {
        let k = f
            .saturating_sub(self.f0)
            .min(self.poses.len().saturating_sub(1));
        &self.poses[k]
    }
}

/// Character state carried from one action to the next.
#[derive(Clone)]
struct Cursor {
    pos: Vec2,
    heading: Vec2,
}

/// Assembles an animation. `clips` must map every event's action (see
/// [`super::library::ClipLibrary::load`]); `forward` is the rig's facing in its clips.
pub fn assemble(
    events: &[ActionRecord],
    doodle: Option<&PoseLog>,
    clips: &BTreeMap<String, ActionClip>,
    forward: Vec3,
    opts: &AssembleOptions,
) -> Result<Assembly, AnimError> {
    assemble_guided(events, doodle, clips, forward, opts, None)
}

/// [`assemble`], taking transitions from a motion graph where it has them (see
/// [`super::graph_cuts`]).
pub fn assemble_guided(
    events: &[ActionRecord],
    doodle: Option<&PoseLog>,
    clips: &BTreeMap<String, ActionClip>,
    forward: Vec3,
    opts: &AssembleOptions,
    guide: Option<&GraphGuide>,
) -> Result<Assembly, AnimError> {
    if events.is_empty() {
        return Err(AnimError::Data(
            "no actions to animate (the event list is empty)".into(),
        ));
    }
    if !(opts.fps.is_finite()
        && opts.fps >= 1.0
        && opts.world_scale.is_finite()
        && opts.world_scale > 0.0)
    {
        return Err(AnimError::Data(format!(
            "bad options: fps {} and world scale {} must be positive",
            opts.fps, opts.world_scale
        )));
    }
    let mut missing: Vec<String> = events
        .iter()
        .filter(|e| !clips.contains_key(&e.action))
        .map(|e| e.action.clone())
        .collect();
    if !missing.is_empty() {
        missing.sort();
        missing.dedup();
        return Err(AnimError::MissingClips {
            library: "the loaded clips".into(),
            missing,
            available: clips.keys().cloned().collect(),
        });
    }
    let mut evs: Vec<ActionRecord> = events
        .iter()
        .filter(|e| e.start.is_finite() && e.end.is_finite())
        .cloned()
        .collect();
    evs.sort_by(|a, b| a.start.total_cmp(&b.start));
    let path = doodle.map(|d| GroundPath::from_log(d, opts.world_scale));
    // Output time 0 is the doodle's first sample (or the log clock's 0 without a doodle).
    let first_event = evs.first().map(|e| e.start).unwrap_or(0.0);
    let t_shift = match path.as_ref().and_then(|p| p.t.first()) {
        Some(&t0) => (t0 as f64).min(first_event),
        None => first_event.min(0.0),
    };
    let fps = opts.fps;
    let last_end = evs.iter().map(|e| e.end).fold(t_shift, f64::max);
    let span_frames = (last_end - t_shift) * f64::from(fps);
    if span_frames.is_nan() || span_frames > MAX_OUTPUT_FRAMES as f64 {
        return Err(AnimError::Data(format!(
            "the actions span {:.6e} s (from {t_shift} s to {last_end} s of the log clock): \
             {span_frames:.3e} frames at {fps} fps, more than the {MAX_OUTPUT_FRAMES} an \
             animation may have",
            last_end - t_shift
        )));
    }
    let frame_of = |t: f64| ((t - t_shift) as f32 * fps).round().max(0.0) as usize;

    let skeleton = clips
        .values()
        .next()
        .map(|c| c.clip.skeleton.clone())
        .unwrap_or_default();
    let mut phrasings: BTreeMap<String, Phrasing> = BTreeMap::new();
    let mut source_contacts: BTreeMap<String, Vec<Vec<bool>>> = BTreeMap::new();
    let legs = clips
        .values()
        .next()
        .map(|c| find_legs(&c.clip))
        .unwrap_or_default();
    let mut cursor = Cursor {
        pos: Vec2::ZERO,
        heading: initial_heading(doodle),
    };
    let mut placed: Vec<Placed> = Vec::new();
    let mut placements: Vec<Placement> = Vec::new();
    let mut last_f1 = 0usize;
    for ev in &evs {
        let Some(primary) = clips.get(&ev.action) else {
            continue;
        };
        let effort = Effort {
            time: ev.time as f32,
            weight: ev.weight as f32,
        };
        let (ac, variant) = choose_variant(
            primary,
            crate::graph::effort::Effort {
                time: effort.time,
                weight: effort.weight,
            },
            guide,
        );
        // A clip stepping to one side steps towards the side the doodle moves.
        let ac = match (&path, ac.mirrored.as_deref()) {
            (Some(p), Some(m))
                if ac.moving
                    && plays_mirrored(
                        &ac.clip,
                        Some(&m.clip),
                        &p.chunk(ev.start as f32, ev.end as f32),
                        cursor.heading,
                        forward,
                    ) =>
            {
                m
            }
            _ => ac,
        };
        // Caches are per variant.
        let key = format!("{}\u{0}{}", ev.action, ac.variant);
        let mut f0 = frame_of(ev.start);
        if !placed.is_empty() && f0 < last_f1 {
            f0 = last_f1; // overlapping events: the later one starts when the earlier ends
        }
        let phrasing = phrasings
            .entry(key.clone())
            .or_insert_with(|| {
                if ac.cyclic {
                    Phrasing::whole(&ac.clip)
                } else {
                    detect_stages(&ac.clip)
                }
            })
            .clone();
        let applied = residual_effort(effort, variant.as_ref());
        let ec = apply_effort(
            &ac.clip,
            &phrasing,
            applied,
            forward,
            ac.cyclic,
            ac.ranges.as_deref(),
        );
        let doodled = match &path {
            _ if !ac.moving => Polyline::new(Vec::new()),
            Some(p) => p.chunk(ev.start as f32, ev.end as f32),
            None => natural_path(ac, (ev.end - ev.start) as f32),
        };
        let (chunk, cycles) = pace(ac, &ec, &doodled, (ev.end - ev.start) as f32);
        // Never faster than MAX_SPEEDUP × the clip (all its cycles): a too-short event overruns
        // into the pause after it (the next action waits if it must).
        let min_len = (cycles as f32 * ac.clip.duration() / MAX_SPEEDUP * fps).ceil() as usize;
        let mut f1 = frame_of(ev.end).max(f0 + min_len.max(2));
        // Nor does any stretch of it move the root faster than a person: the time map gives
        // such stretches the time they need (see `EffortClip::paced`), per cycle. A gait whose
        // path is longer than its cycles' travel moves its root that much faster.
        let stretch = if ac.moving && ac.cyclic {
            let per_cycle = ground_travel(&ec.clip);
            (chunk.length() / (cycles.max(1) as f32 * per_cycle).max(1e-3)).max(1.0)
        } else {
            1.0
        };
        let top_speed = HUMAN_ROOT_SPEED_M_S * PACE_HEADROOM;
        let (ec, cycle_s) = ec.paced(
            (f1 - f0) as f32 / fps / cycles.max(1) as f32,
            &PaceLimits {
                speed_m_s: top_speed / stretch,
                accel_m_s2: HUMAN_ROOT_ACCEL_M_S2,
                frame_s: 1.0 / fps,
            },
        );
        f1 = f1.max(f0 + (cycle_s * cycles.max(1) as f32 * fps).ceil() as usize);
        // Nor faster than a person moves: an action whose root would outrun
        // HUMAN_ROOT_SPEED_M_S (a short event squeezing a long clip, a sudden retime
        // compressing a lunge) takes the time it needs, its timing slowed evenly — but never
        // beyond the clip's own pace (or the event's length, if longer): what is still too
        // fast then is no matter of timing.
        let slowest = f1.max(f0 + (cycles as f32 * ac.clip.duration() * fps).ceil() as usize);
        let start = cursor.clone();
        let mut placed_action;
        let mut chunk = chunk;
        let mut shrinks = 0;
        loop {
            if f1 > MAX_OUTPUT_FRAMES {
                return Err(AnimError::Data(format!(
                    "action {} at {} s would end at frame {f1}, past the {MAX_OUTPUT_FRAMES} \
                     frames an animation may have",
                    ev.action, ev.start
                )));
            }
            cursor = start.clone();
            placed_action = place_action(ac, &ec, &chunk, &mut cursor, forward, f1 - f0, cycles);
            let fastest = root_speed_max(&placed_action.0, 1.0 / fps);
            if fastest <= top_speed {
                break;
            }
            // A gait's root follows its path: where its bob and surge on top of the path's
            // pace outrun a person (a strong run's amplified bob drops the root 6 cm in a
            // frame as it lands), the path is shrunk about its start rather than the gait
            // slowed past its event (the same cycles, shorter strides).
            if ac.moving && ac.cyclic && shrinks < MAX_PATH_SHRINKS && chunk.length() > 0.05 {
                chunk = shrink(&chunk, chunk.length() * top_speed / fastest);
                shrinks += 1;
                continue;
            }
            if f1 >= slowest {
                break;
            }
            let n = (f1 - f0) as f32;
            let need = (n * fastest / top_speed).ceil().max(n + 1.0) as usize;
            f1 = (f0 + need).min(slowest);
        }
        let duration = (f1 - f0) as f32 / fps;
        let (poses, world_path, cycles, src_times) = placed_action;
        let src_contacts = source_contacts
            .entry(key)
            .or_insert_with(|| detect_contacts(&ac.clip, &legs))
            .clone();
        let contacts = src_times
            .iter()
            .map(|&t| {
                let k = (t / ac.clip.frame_time.max(1e-6)).round().max(0.0) as usize;
                src_contacts
                    .iter()
                    .map(|leg| leg.get(k).copied().unwrap_or(false))
                    .collect()
            })
            .collect();
        let stages = ec
            .phrasing
            .spans
            .iter()
            .filter_map(|s| {
                let (a, b) = ec.stage_w(s.stage)?;
                let t0 = f0 as f32 / fps + t_shift as f32;
                Some((s.stage, t0 + a * duration, t0 + b * duration))
            })
            .collect();
        placements.push(Placement {
            action: ev.action.clone(),
            start_frame: f0,
            end_frame: f1,
            path: world_path,
            moving: ac.moving,
            cycles,
            stages,
            variant,
            applied_effort: applied,
        });
        placed.push(Placed {
            f0,
            poses,
            contacts,
            src_times,
            effort,
            file: ac.file.clone(),
            source_start_s: ac.source_start_s,
            frame_s: 1.0 / fps,
        });
        last_f1 = f1;
    }

    // Timeline with transitions.
    let total = last_f1 + (opts.hold_s.max(0.0) * fps).round() as usize;
    let search = ((opts.transition_search_s * fps).round() as usize).max(1);
    let min_blend = ((opts.min_blend_s * fps).round() as usize).max(2);
    let graph_search = ((opts.graph_search_s.max(0.0) * fps).round() as usize).max(search);
    let mut cuts: Vec<(usize, usize)> = Vec::new(); // (i, j) per boundary
    let mut graph_cuts = Vec::new();
    for w in placed.windows(2) {
        let (a, b) = (&w[0], &w[1]);
        let graph_cut = guide.and_then(|g| {
            let pa = PlacedSource {
                file: &a.file,
                source_start_s: a.source_start_s,
                f0: a.f0,
                src_times: &a.src_times,
            };
            let pb = PlacedSource {
                file: &b.file,
                source_start_s: b.source_start_s,
                f0: b.f0,
                src_times: &b.src_times,
            };
            let want = crate::graph::effort::Effort {
                time: b.effort.time,
                weight: b.effort.weight,
            };
            g.cut(
                &pa,
                a.f1().saturating_sub(graph_search).max(a.f0)..=a.f1(),
                &pb,
                b.f0..=(b.f0 + graph_search).min(b.f1()),
                Some(want),
            )
        });
        graph_cuts.push(graph_cut.map(|(_, _, c)| c));
        if let Some((i, j, _)) = graph_cut {
            cuts.push(widen(i, j, min_blend, a.f0, b.f1()));
            continue;
        }
        let ra = a.f1().saturating_sub(search).max(a.f0)..=a.f1();
        let rb = b.f0..=(b.f0 + search).min(b.f1());
        let pa: Vec<Vec<Vec3>> = (0..=a.f1())
            .map(|f| {
                if f < a.f0 {
                    Vec::new()
                } else {
                    skeleton.positions(a.at(f))
                }
            })
            .collect();
        let pb: Vec<Vec<Vec3>> = (0..=b.f1())
            .map(|f| {
                if f < b.f0 {
                    Vec::new()
                } else {
                    skeleton.positions(b.at(f))
                }
            })
            .collect();
        // A blend starts and ends where the root moves no more sharply than real takes
        // mostly do (a turn's hop, a strong jump's squat would show at the blend's edge), if
        // the search finds such frames.
        let (ca, cb) = (calm_frames(a, ra.clone()), calm_frames(b, rb.clone()));
        let ra: Vec<usize> = if ca.is_empty() { ra.collect() } else { ca };
        let rb: Vec<usize> = if cb.is_empty() { rb.collect() } else { cb };
        let (i, j) = match best_pair(&pa, ra, &pb, rb) {
            Some((i, j, _)) => (i, j),
            None => (a.f1(), b.f0),
        };
        cuts.push(widen(i, j, min_blend, a.f0, b.f1()));
    }
    let mut frames = Vec::with_capacity(total + 1);
    let mut contact_frames: Vec<Vec<bool>> = Vec::with_capacity(total + 1);
    for f in 0..=total {
        // Which placed action owns frame f, or which transition covers it.
        let mut pose = placed[0].at(f).clone();
        let mut contact = placed[0].contact_at(f);
        for (k, p) in placed.iter().enumerate() {
            let start_cut = if k == 0 { 0 } else { cuts[k - 1].1 };
            let end_cut = cuts.get(k).map(|c| c.0).unwrap_or(usize::MAX);
            if f >= start_cut && f <= end_cut {
                pose = p.at(f).clone();
                contact = p.contact_at(f);
                break;
            }
            if let (Some(&(i, j)), Some(next)) = (cuts.get(k), placed.get(k + 1)) {
                if f > i && f < j {
                    let u = smoothstep((f - i) as f32 / (j - i) as f32);
                    pose = blend_world(p.at(f), next.at(f), u);
                    // A blended foot is planted only if both sides plant it.
                    contact = p
                        .contact_at(f)
                        .iter()
                        .zip(next.contact_at(f))
                        .map(|(a, b)| *a && b)
                        .collect();
                    break;
                }
            }
        }
        frames.push(pose);
        contact_frames.push(contact);
    }
    // The root's path is C1 across every join: where a held pose meets a moving clip, or a
    // blend hands over from one action's root to the next, its velocity changes over
    // ROOT_EASE_S rather than in one frame.
    let mut joins: Vec<usize> = placed
        .iter()
        .flat_map(|p| [p.f0, p.f1()])
        .chain(cuts.iter().flat_map(|&(i, j)| [i, j]))
        .filter(|&f| f <= total)
        .collect();
    joins.sort_unstable();
    joins.dedup();
    let ease = ((ROOT_EASE_S * fps).round() as usize).max(1);
    // Nor does the easing make the root outrun a person: it may use most of the headroom the
    // actions were paced with (PACE_HEADROOM), not all (the ground pass comes after).
    let top = HUMAN_ROOT_SPEED_M_S * JOIN_EASE_HEADROOM / fps;
    for &k in &joins {
        // The step may land a frame or two off the join (a clip whose root stops just before
        // its last frame): the sharpest nearby is eased, a few times over.
        for _ in 0..JOIN_EASE_PASSES {
            let root = |f: usize| frames[f].translations[0];
            let sharpest = (k.saturating_sub(JOIN_EASE_REACH).max(1)
                ..=(k + JOIN_EASE_REACH).min(frames.len().saturating_sub(2)))
                .max_by(|&a, &b| {
                    let acc = |f: usize| (root(f + 1) - 2.0 * root(f) + root(f - 1)).length();
                    acc(a).total_cmp(&acc(b))
                });
            if let Some(m) = sharpest {
                ease_root(&mut frames, m, ease, top);
            }
        }
    }
    // Nor is the root's path sharper about a join than real takes move theirs: where the
    // action is cut mid-hop, it settles there.
    let most = super::envelope::ROOT_ACCEL_JOIN_M_S2 * CALM_HEADROOM / (fps * fps);
    for &k in &joins {
        calm_root(&mut frames, k, JOIN_EASE_REACH, most);
    }
    let mut clip = Clip {
        name: "figurine".into(),
        skeleton,
        frame_time: 1.0 / fps,
        frames,
    };
    // Per leg, per frame.
    let contacts: Vec<Vec<bool>> = (0..legs.len())
        .map(|l| {
            contact_frames
                .iter()
                .map(|c| c.get(l).copied().unwrap_or(false))
                .collect()
        })
        .collect();
    // The feet the animation itself sets down stand too; every other foot clears the floor
    // (a light effort's shrunken swing would scuff it).
    let contacts = planted(&clip, &legs, &contacts);
    pin_feet(&mut clip, &legs, &contacts);
    clear_swing_feet(&mut clip, &legs, &contacts);
    let ground = fix_ground(&mut clip, &legs);
    Ok(Assembly {
        clip,
        placements,
        contacts,
        ground,
        transitions: cuts,
        joins,
        graph_cuts,
        t_origin: t_shift,
    })
}

/// The effort to transfer onto a chosen variant: the recognised effort less the variant's own
/// (both in [−1, 1], the difference clamped). A variant's effort is measured relative to its
/// siblings, so a sudden-strong kick played by the spinning kick, which is sudden and strong
/// already, is not retimed and amplified a second time; a single clip (no choice) gets the
/// whole recognised effort, as in seed 000 §6.
pub fn residual_effort(recognised: Effort, variant: Option<&VariantChoice>) -> Effort {
    let e = recognised.sanitized();
    match variant {
        Some(v) => Effort {
            time: e.time - v.variant_effort.time,
            weight: e.weight - v.variant_effort.weight,
        }
        .sanitized(),
        None => e,
    }
}

/// The frames of `range` at which `p`'s placed root accelerates within
/// [`super::envelope::ROOT_ACCEL_JOIN_M_S2`] for [`JOIN_EASE_REACH`] frames either side (as
/// `figurine check` judges a join).
fn calm_frames(p: &Placed, range: std::ops::RangeInclusive<usize>) -> Vec<usize> {
    let dt = p.frame_s;
    let accel = |f: usize| {
        let r = |k: usize| p.at(k).translations[0];
        (r(f + 1) - 2.0 * r(f) + r(f.saturating_sub(1))).length() / (dt * dt)
    };
    range
        .filter(|&f| {
            (f.saturating_sub(JOIN_EASE_REACH)..=f + JOIN_EASE_REACH)
                .all(|k| accel(k) <= super::envelope::ROOT_ACCEL_JOIN_M_S2)
        })
        .collect()
}

/// Stretches a cut (i, j) to at least `min_blend` frames, half before and half after, staying
/// within the outgoing action's first frame `a0` and the incoming action's last frame `b1`.
fn widen(mut i: usize, mut j: usize, min_blend: usize, a0: usize, b1: usize) -> (usize, usize) {
    if j < i + min_blend {
        let need = i + min_blend - j;
        let back = (need / 2).min(i.saturating_sub(a0));
        i -= back;
        j = (j + need - back).min(b1);
    }
    (i, j)
}

/// The toy's facing (object +Z) at the first sample, projected to the ground; +X otherwise.
fn initial_heading(doodle: Option<&PoseLog>) -> Vec2 {
    doodle
        .and_then(|d| {
            d.samples
                .iter()
                .find(|s| s.quat.iter().all(|v| v.is_finite()))
        })
        .map(|s| {
            let [w, x, y, z] = s.quat.map(|v| v as f32);
            let q = Quat::from_xyzw(x, y, z, w);
            let f = if q.length() > 1e-6 {
                q.normalize() * Vec3::Z
            } else {
                Vec3::X
            };
            ground(f)
        })
        .filter(|g| g.length() > 0.2)
        .map(|g| g.normalize())
        .unwrap_or(Vec2::X)
}

/// Without a doodle, moving actions travel as far as their clip does, straight ahead.
fn natural_path(ac: &ActionClip, duration: f32) -> Polyline {
    let travel = ground_travel(&ac.clip);
    let len = if ac.cyclic {
        let cycles = (duration / ac.clip.duration().max(1e-3)).round().max(1.0);
        travel * cycles
    } else {
        travel
    };
    Polyline::new(vec![Vec2::ZERO, Vec2::new(len, 0.0)])
}

/// Places one action on `n + 1` output frames, playing `cycles` cycles; returns the poses (root in world), the world
/// path it followed, the number of cycles and each frame's source time (s). Updates the cursor.
fn place_action(
    ac: &ActionClip,
    ec: &EffortClip,
    chunk: &Polyline,
    cursor: &mut Cursor,
    forward: Vec3,
    n: usize,
    cycles: usize,
) -> (Vec<Pose>, Polyline, usize, Vec<f32>) {
    let clip = &ec.clip;
    let src_root = clip.root_path();
    let r0 = src_root.first().copied().unwrap_or(Vec3::ZERO);
    let rl = src_root.last().copied().unwrap_or(r0);
    let q0 = clip
        .frames
        .first()
        .map(|p| p.rotations[0])
        .unwrap_or(Quat::IDENTITY);
    let ql = clip.frames.last().map(|p| p.rotations[0]).unwrap_or(q0);
    let facing0 = ground(q0 * forward).normalize_or(Vec2::X);
    let net = ground(rl - r0);
    let clip_dir = if ac.moving && net.length() > 0.05 {
        net.normalize()
    } else {
        facing0
    };
    let along = |v: Vec3| ground(v).dot(clip_dir);
    let across = |v: Vec3| {
        let g = ground(v);
        g - clip_dir * g.dot(clip_dir)
    };
    let moving = ac.moving && chunk.length() > 0.05;
    // Orient the path: it starts at the character's position.
    let world_path = Polyline::new(chunk.pts.iter().map(|p| cursor.pos + *p).collect());
    let start_heading = if moving {
        chunk.tangent_at(0.0, 0.3).unwrap_or(cursor.heading)
    } else {
        cursor.heading
    };
    let r_start = yaw_between(clip_dir, start_heading);
    let base = cursor.pos;
    let cycle_len = along(rl - r0);
    let stretch = if cycles > 0 && cycle_len > 0.05 {
        chunk.length() / (cycles as f32 * cycle_len)
    } else {
        1.0
    };
    // Yaw drift of one cycle, removed so cycles join without a turn.
    let drift = if ac.cyclic {
        let a = ground(q0 * forward).normalize_or(Vec2::X);
        let b = ground(ql * forward).normalize_or(Vec2::X);
        super::trajectory::yaw(b) - super::trajectory::yaw(a)
    } else {
        0.0
    };
    let loop_frames = cycle_frames(clip, forward, ac.anchor, cycles);
    let closure = if cycles > 1 {
        loop_closure(clip)
    } else {
        Vec::new()
    };
    let exec = ec.stage_w(Stage::Execution).unwrap_or((0.0, 1.0));
    let mut sigma_max = 0.0f32;
    let mut poses = Vec::with_capacity(n + 1);
    let mut src_times = Vec::with_capacity(n + 1);
    for k in 0..=n {
        let u = k as f32 / n.max(1) as f32;
        let (w, cycle) = if cycles > 1 {
            let uc = u * cycles as f32;
            let c = (uc.floor() as usize).min(cycles - 1);
            (uc - c as f32, c)
        } else {
            (u, 0)
        };
        let src_t = ec.source_time(w);
        src_times.push(src_t);
        let mut pose = ec.clip.sample(src_t);
        close_loop(&mut pose, &closure, src_t / clip.duration().max(1e-6));
        let r = pose.translations[0];
        let q = pose.rotations[0];
        let (root_xz, rot) = if !moving {
            let drift = if ac.anchor {
                ground(rl - r0) * (src_t / clip.duration().max(1e-6))
            } else {
                Vec2::ZERO
            };
            let (off, turn) = loop_frames
                .get(cycle)
                .copied()
                .unwrap_or((Vec2::ZERO, Quat::IDENTITY));
            (
                base + rot2(r_start, off + rot2(turn, ground(r - r0) - drift)),
                r_start * turn,
            )
        } else if ac.cyclic {
            let s = (cycle as f32 * cycle_len + along(r - r0)) * stretch;
            let tangent = chunk.tangent_at(s, 0.3).unwrap_or(start_heading);
            let rt = yaw_between(clip_dir, tangent) * Quat::from_rotation_y(-drift * w);
            (
                cursor.pos + chunk.point_at(s) + rot2(rt, across(r - r0)),
                rt,
            )
        } else {
            // Not cyclic: the root stays put while the clip's own root does not travel
            // (anticipation, landing) and follows the path in step with the clip's travel
            // during the execution; never backwards.
            let total = along(rl - r0);
            let sigma = if total.abs() > 0.05 {
                (along(r - r0) / total).clamp(0.0, 1.0)
            } else {
                ((w - exec.0) / (exec.1 - exec.0).max(1e-6)).clamp(0.0, 1.0)
            };
            sigma_max = sigma_max.max(sigma);
            let s = sigma_max * chunk.length();
            let tangent = chunk.tangent_at(s, 0.3).unwrap_or(start_heading);
            (
                cursor.pos + chunk.point_at(s),
                yaw_between(clip_dir, tangent),
            )
        };
        pose.translations[0] = Vec3::new(root_xz.x, r.y, root_xz.y);
        pose.rotations[0] = (rot * q).normalize();
        poses.push(pose);
    }
    if let Some(last) = poses.last() {
        let t = last.translations[0];
        cursor.pos = Vec2::new(t.x, t.z);
        let f = ground(last.rotations[0] * forward);
        if f.length() > 0.2 {
            cursor.heading = f.normalize();
        }
    }
    (poses, world_path, cycles, src_times)
}

/// Rotates a ground vector by a yaw quaternion.
fn rot2(q: Quat, v: Vec2) -> Vec2 {
    ground(q * Vec3::new(v.x, 0.0, v.y))
}
