//! Real doodles: a motion-capture take turned into the pose log of a figurine played the way
//! the performer moved.
//!
//! The figurine is the character. Its position is one body landmark's (the hips by default; a
//! wrist for a jab, an ankle for a kick), and its orientation is the body's own frame, built
//! from the skeleton's landmarks every frame, so it holds for any rig ([`crate::graph::roles`]
//! finds them by name and hierarchy):
//!
//! | figurine axis | from the body |
//! |---|---|
//! | +X left | right hip → left hip |
//! | +Y up | hips → neck, made square to left |
//! | +Z front | left × up |
//!
//! A bow tilts the figurine forward, a spin turns it, a backflip turns it over. The take is
//! sampled at a tracker's rate, scaled from the file's length unit to metres (a BVH in
//! centimetres is recognised by its body height), and framed by a still lead and trail:
//! the figurine rests in the hand before and after, as a child's would.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use clap::Args;
use glam::{Mat3, Quat, Vec3};

use crate::graph::roles::{Role, RoleMap, RoleOverrides};
use crate::motion::{Clip, Skeleton, CENTIMETRE_HEIGHT};
use crate::poselog::{PoseLog, PoseSample};

/// How a take becomes a doodle.
#[derive(Debug, Clone, PartialEq)]
pub struct DoodleSpec {
    /// The body landmark whose position is the figurine's: a role name (`hips`,
    /// `right_hand`, `left_foot` …, see [`Role::name`]) or a joint name of the take.
    pub joint: String,
    /// First and last second of the take to use (None: its start, its end).
    pub span: (Option<f64>, Option<f64>),
    /// Sample rate of the log, Hz.
    pub rate: f64,
    /// Still time before and after the motion, seconds.
    pub still: f64,
    /// Metres per unit of the file (None: metres, or centimetres for a body over
    /// [`CENTIMETRE_HEIGHT`] units tall).
    pub metres_per_unit: Option<f32>,
    /// Factor applied to every position after the unit (a figurine doodle at half the
    /// performer's size: 0.5).
    pub scale: f32,
}

impl Default for DoodleSpec {
    fn default() -> Self {
        DoodleSpec {
            joint: "hips".into(),
            span: (None, None),
            rate: 120.0,
            still: 1.0,
            metres_per_unit: None,
            scale: 1.0,
        }
    }
}

/// A doodle and where its motion lies in it.
#[derive(Debug, Clone)]
pub struct Doodle {
    /// The pose log.
    pub log: PoseLog,
    /// Log time of the take's first and last sampled instant, seconds (the still lead and
    /// trail lie outside).
    pub motion: (f64, f64),
    /// Metres per unit of the file that were used.
    pub metres_per_unit: f32,
}

/// The figurine's orientation for a body whose hips are at `hips`, left and right hip joints
/// at `left` and `right` and neck at `neck`: the quaternion whose +X is the body's left, +Y
/// its up and +Z its front (see the module table). None when the landmarks are degenerate.
pub fn body_frame(hips: Vec3, left: Vec3, right: Vec3, neck: Vec3) -> Option<Quat> {
    let across = left - right;
    let up = (neck - hips).try_normalize()?;
    let front = across.cross(up).try_normalize()?;
    let left = up.cross(front);
    let q = Quat::from_mat3(&Mat3::from_cols(left, up, front)).normalize();
    q.is_finite().then_some(q)
}

/// The joint index of `name`: a role of `roles`, or a joint of `skeleton`.
fn landmark(skeleton: &Skeleton, roles: &RoleMap, name: &str) -> Result<usize> {
    if let Some(role) = Role::from_name(&name.to_ascii_lowercase()) {
        return Ok(roles.joint(role));
    }
    skeleton.find(name).with_context(|| {
        format!(
            "`{name}` is neither a body role ({}) nor a joint of the take",
            Role::ALL.map(Role::name).join(", ")
        )
    })
}

/// Metres per file unit for `clip`: as given, or from the body's height in its first frame.
fn unit_of(clip: &Clip, roles: &RoleMap, given: Option<f32>) -> f32 {
    given.unwrap_or_else(|| {
        let p = clip.joint_positions(0);
        let y = |r: Role| p.get(roles.joint(r)).map_or(0.0, |v| v.y);
        let feet = y(Role::LeftFoot).min(y(Role::RightFoot));
        if y(Role::Head) - feet > CENTIMETRE_HEIGHT {
            0.01
        } else {
            1.0
        }
    })
}

/// Turns `clip` into a doodle as `spec` says; `name` names the take in errors.
pub fn doodle(clip: &Clip, spec: &DoodleSpec, name: &str) -> Result<Doodle> {
    if clip.is_empty() {
        bail!("{name}: the take has no frames");
    }
    if !(spec.rate.is_finite() && spec.rate > 0.0 && spec.rate <= 2000.0) {
        bail!("rate {} Hz: give 0 < rate ≤ 2000", spec.rate);
    }
    if !(spec.still.is_finite() && spec.still >= 0.0 && spec.scale.is_finite() && spec.scale > 0.0)
    {
        bail!("the still time must be ≥ 0 s and the scale > 0");
    }
    let roles = RoleMap::detect(&clip.skeleton, &RoleOverrides::new(), name)
        .with_context(|| format!("{name}: could not find the body's landmarks"))?;
    let joint = landmark(&clip.skeleton, &roles, &spec.joint)?;
    let unit = unit_of(clip, &roles, spec.metres_per_unit) * spec.scale;
    let duration = f64::from(clip.duration());
    let from = spec.span.0.unwrap_or(0.0).clamp(0.0, duration);
    let to = spec.span.1.unwrap_or(duration).clamp(from, duration);
    let period = 1.0 / spec.rate;
    let mut samples = Vec::new();
    let mut last = None;
    let mut push = |t: f64, pos: Vec3, quat: Quat| {
        samples.push(PoseSample {
            t,
            pos: (pos * unit).to_array().map(f64::from),
            quat: [quat.w, quat.x, quat.y, quat.z].map(f64::from),
        });
    };
    let steps = ((to - from) * spec.rate).floor() as usize;
    let lead = (spec.still * spec.rate).round() as usize;
    let mut first = None;
    for k in 0..=steps {
        let t = from + k as f64 * period;
        let w = clip.skeleton.forward(&clip.sample(t as f32));
        let at = |j: usize| w.get(j).map_or(Vec3::ZERO, |x| x.position);
        let frame = body_frame(
            at(roles.joint(Role::Hips)),
            at(roles.joint(Role::LeftHip)),
            at(roles.joint(Role::RightHip)),
            at(roles.joint(Role::Neck)),
        );
        // A degenerate body frame (landmarks on top of each other) keeps the last one.
        let Some(q) = frame.or(last) else { continue };
        last = Some(q);
        let pos = at(joint);
        if first.is_none() {
            first = Some((pos, q));
            for i in 0..lead {
                push(i as f64 * period, pos, q);
            }
        }
        push((lead + k) as f64 * period, pos, q);
    }
    let Some(end) = samples.last().map(|s| s.t) else {
        bail!("{name}: the body's landmarks are degenerate in every frame");
    };
    let trail = samples.last().copied();
    if let Some(s) = trail {
        for i in 1..=lead {
            samples.push(PoseSample {
                t: end + i as f64 * period,
                ..s
            });
        }
    }
    Ok(Doodle {
        log: PoseLog { samples },
        motion: (lead as f64 * period, end),
        metres_per_unit: unit / spec.scale,
    })
}

/// `figurine doodle`: a motion-capture take as a figurine pose log.
#[derive(Debug, Args)]
pub struct DoodleArgs {
    /// The take: a BVH file, or a DeepMimic clip (`humanoid3d_*.txt`, read on the humanoid
    /// URDF fetched by `cargo xtask setup`).
    #[arg(long = "from", value_name = "TAKE")]
    pub from: PathBuf,
    /// The body landmark the figurine follows: a role (hips, chest, neck, head, left_hand,
    /// right_hand, left_foot, right_foot …) or a joint name of the take.
    #[arg(long, default_value = "hips")]
    pub joint: String,
    /// First second of the take to use.
    #[arg(long)]
    pub start: Option<f64>,
    /// Last second of the take to use.
    #[arg(long)]
    pub end: Option<f64>,
    /// Sample rate of the log, Hz.
    #[arg(long, default_value_t = 120.0)]
    pub rate: f64,
    /// Still time before and after the motion, seconds.
    #[arg(long, default_value_t = 1.0)]
    pub still: f64,
    /// Metres per unit of the file (default: metres, or centimetres for a body over 3 units
    /// tall).
    #[arg(long)]
    pub unit: Option<f32>,
    /// Factor on every position (0.5: a doodle at half the performer's size).
    #[arg(long, default_value_t = 1.0)]
    pub scale: f32,
    /// Label the motion as this action: a `# label ACTION START..END` line, as `figurine
    /// synth` writes.
    #[arg(long)]
    pub label: Option<String>,
    /// Output pose log (CSV).
    #[arg(long)]
    pub out: PathBuf,
}

/// Runs `figurine doodle`.
pub fn run(a: &DoodleArgs) -> Result<()> {
    let clip = crate::motion::read_take(&a.from, None)?;
    let spec = DoodleSpec {
        joint: a.joint.clone(),
        span: (a.start, a.end),
        rate: a.rate,
        still: a.still,
        metres_per_unit: a.unit,
        scale: a.scale,
    };
    let d = doodle(&clip, &spec, &a.from.to_string_lossy())?;
    write_doodle(&d, a.label.as_deref(), &a.out)?;
    eprintln!(
        "{}: {} samples at {} Hz, motion {:.2}–{:.2} s, {} m per unit",
        a.out.display(),
        d.log.samples.len(),
        a.rate,
        d.motion.0,
        d.motion.1,
        d.metres_per_unit
    );
    Ok(())
}

/// Writes a doodle's log, with a label line over its motion when `label` is given.
pub fn write_doodle(d: &Doodle, label: Option<&str>, out: &Path) -> Result<()> {
    let mut text = Vec::new();
    if let Some(action) = label {
        text.extend(format!("# label {action} {:.6}..{:.6}\n", d.motion.0, d.motion.1).bytes());
    }
    d.log.write(&mut text)?;
    std::fs::write(out, text).with_context(|| format!("writing {}", out.display()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::motion::{Joint, Pose};

    /// A stick figure facing +X (its left towards −Z), `height` units tall: hips (root),
    /// left and right hip, knees, feet, chest, neck, head; it walks `speed` units/s along +X
    /// for `seconds` at 30 fps, turning `yaw` rad about +Y over the take.
    fn walker(height: f32, speed: f32, seconds: f32, yaw: f32) -> Clip {
        let h = height;
        let j = |name: &str, parent: Option<usize>, o: [f32; 3]| {
            Joint::bare(name, parent, Vec3::from(o) * h)
        };
        let skeleton = Skeleton {
            joints: vec![
                j("Hips", None, [0.0, 0.5, 0.0]),
                j("LeftUpLeg", Some(0), [0.0, 0.0, -0.1]),
                j("LeftLeg", Some(1), [0.0, -0.25, 0.0]),
                j("LeftFoot", Some(2), [0.0, -0.25, 0.0]),
                j("RightUpLeg", Some(0), [0.0, 0.0, 0.1]),
                j("RightLeg", Some(4), [0.0, -0.25, 0.0]),
                j("RightFoot", Some(5), [0.0, -0.25, 0.0]),
                j("Spine", Some(0), [0.0, 0.15, 0.0]),
                j("Neck", Some(7), [0.0, 0.2, 0.0]),
                j("Head", Some(8), [0.0, 0.15, 0.0]),
                j("LeftArm", Some(7), [0.0, 0.15, -0.15]),
                j("LeftForeArm", Some(10), [0.0, -0.15, 0.0]),
                j("LeftHand", Some(11), [0.0, -0.15, 0.0]),
                j("RightArm", Some(7), [0.0, 0.15, 0.15]),
                j("RightForeArm", Some(13), [0.0, -0.15, 0.0]),
                j("RightHand", Some(14), [0.0, -0.15, 0.0]),
            ],
        };
        let frames = (0..=(seconds * 30.0) as usize)
            .map(|f| {
                let t = f as f32 / 30.0;
                let mut p = Pose::rest(&skeleton);
                p.translations[0] = Vec3::new(speed * t, 0.5 * h, 0.0);
                p.rotations[0] = Quat::from_rotation_y(yaw * t / seconds);
                p
            })
            .collect();
        Clip {
            name: "walker".into(),
            skeleton,
            frame_time: 1.0 / 30.0,
            frames,
        }
    }

    #[test]
    fn the_figurine_follows_the_hips_and_faces_where_the_body_faces() {
        let clip = walker(1.7, 1.2, 2.0, 0.0);
        let d = doodle(&clip, &DoodleSpec::default(), "walker").unwrap();
        let s = &d.log.samples;
        // 1 s still, 2 s of motion at 120 Hz, 1 s still.
        assert_eq!(s.len(), 120 + 241 + 120);
        assert!((d.motion.0 - 1.0).abs() < 1e-9 && (d.motion.1 - 3.0).abs() < 1e-6);
        assert_eq!(s[0].pos, s[119].pos, "the lead is still");
        let end = s[360];
        assert!((end.pos[0] - 2.4).abs() < 1e-4, "{:?}", end.pos);
        assert!((end.pos[1] - 0.85).abs() < 1e-4, "{:?}", end.pos);
        // Facing +X: the figurine's front (+Z) points along world +X, its left (+X) along −Z.
        let q = Quat::from_xyzw(
            end.quat[1] as f32,
            end.quat[2] as f32,
            end.quat[3] as f32,
            end.quat[0] as f32,
        );
        assert!((q * Vec3::Z - Vec3::X).length() < 1e-5, "{q:?}");
        assert!((q * Vec3::X + Vec3::Z).length() < 1e-5, "{q:?}");
    }

    #[test]
    fn a_take_in_centimetres_is_read_in_metres_and_a_turn_turns_the_figurine() {
        let clip = walker(170.0, 120.0, 1.0, core::f32::consts::FRAC_PI_2);
        let spec = DoodleSpec {
            joint: "right_hand".into(),
            still: 0.0,
            rate: 60.0,
            ..DoodleSpec::default()
        };
        let d = doodle(&clip, &spec, "walker").unwrap();
        assert_eq!(d.metres_per_unit, 0.01);
        let s = &d.log.samples;
        let first = s[0];
        // The right hand: 0.5 + 0.15 + 0.15 − 0.3 of 1.7 m up, 0.15 of it towards +Z (the
        // body's right).
        assert!((first.pos[1] - 0.5 * 1.7).abs() < 1e-4, "{:?}", first.pos);
        assert!((first.pos[2] - 0.255).abs() < 1e-4, "{:?}", first.pos);
        // A quarter turn to the left about +Y: the front ends along −Z.
        let last = s[s.len() - 1];
        let q = Quat::from_xyzw(
            last.quat[1] as f32,
            last.quat[2] as f32,
            last.quat[3] as f32,
            last.quat[0] as f32,
        );
        assert!((q * Vec3::Z + Vec3::Z).length() < 1e-4, "{q:?}");
    }

    #[test]
    fn bad_requests_are_clear_errors() {
        let clip = walker(1.7, 1.0, 1.0, 0.0);
        let bad = |spec: DoodleSpec| doodle(&clip, &spec, "walker").unwrap_err().to_string();
        let e = bad(DoodleSpec {
            joint: "tail".into(),
            ..DoodleSpec::default()
        });
        assert!(e.contains("`tail` is neither a body role"), "{e}");
        let e = bad(DoodleSpec {
            rate: 0.0,
            ..DoodleSpec::default()
        });
        assert!(e.contains("rate"), "{e}");
        let empty = Clip {
            frames: Vec::new(),
            ..clip.clone()
        };
        let e = doodle(&empty, &DoodleSpec::default(), "empty").unwrap_err();
        assert!(e.to_string().contains("no frames"), "{e}");
    }
}
