//! `figurine check`: would a person believe this motion? A plausibility report on any BVH or
//! DeepMimic clip, computed from its joints' world positions, in the measures
//! motion-synthesis work judges generated motion by (PhysDiff, Yuan et al. 2023: penetration,
//! floating, skating), plus knees and elbows bent backwards, torso tilt and root pops.
//!
//! | measure | how | unit |
//! |---|---|---|
//! | penetration | depth of a foot's lowest point below the ground: mean over frames, max | mm |
//! | airborne | longest stretch with no foot within [`NEAR_GROUND_M`] of the ground | s |
//! | skating | horizontal speed of a foot's lowest point while it is within [`CONTACT_M`] of the ground: median, share above [`SKATE_M_S`] | cm/s, % |
//! | torso tilt | angle of hips → neck from vertical: 95th percentile, max; an assembled animation's, per action, against the real takes of its kind ([`super::tilt_reference`]) | ° |
//! | knee bent backwards | the thigh–shin bend about the hips' right axis (a knee folds the shin back, about their left): max | ° |
//! | elbow bent backwards | in the upper arm's frame, the bend about the opposite of the axis the elbow folds about when well bent over the clip: max | ° |
//! | root speed, acceleration | the hips' speed and acceleration (finite differences): 95th percentile, max | m/s, m/s² |
//! | pops at joins | an assembled animation's root acceleration within [`JOIN_WINDOW_S`] of a join (where one action, or a held pose, hands over to the next; [`check_assembly`]): max | m/s² |
//!
//! Lengths are read in metres; a file whose body is over [`crate::motion::CENTIMETRE_HEIGHT`]
//! units tall is read in centimetres. The ground is the plane y = 0 (the project's
//! animations stand on it), or estimated as a low percentile of the feet's height
//! ([`Ground::Auto`]) for takes recorded elsewhere. Landmarks come from
//! [`crate::graph::roles`], so any rig with named hips, neck, legs and arms is read.

use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::Args;
use glam::{Quat, Vec3};
use serde::Serialize;

use super::tilt_reference::{TiltJudgement, TiltReference};
use super::torso_tilt::{tilt_deg, TiltFigures};
use crate::graph::roles::{Role, RoleMap, RoleOverrides};
use crate::motion::CENTIMETRE_HEIGHT;
use crate::motion::{Clip, Skeleton};

/// Height of a foot's lowest point under which it is in ground contact, m.
pub const CONTACT_M: f32 = 0.025;
/// Height under which a foot is near the ground (not airborne), m.
pub const NEAR_GROUND_M: f32 = 0.10;
/// Contact-foot speed above which a frame skates, m/s.
pub const SKATE_M_S: f32 = 0.10;
/// Percentile of the feet's lowest height taken as the ground by [`Ground::Auto`].
pub const AUTO_GROUND_PERCENTILE: f32 = 0.05;

/// Seconds either side of a join within which [`check_assembly`] judges the root's
/// acceleration: two frames at 30 fps, where a pop (a jump of the root's velocity from one
/// frame to the next) shows; the actions' own motion further off is their own.
pub const JOIN_WINDOW_S: f32 = 0.07;

pub use super::envelope;

/// Where the ground is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Ground {
    /// The plane y = this, metres.
    At(f32),
    /// A low percentile ([`AUTO_GROUND_PERCENTILE`]) of the feet's lowest height.
    Auto,
}

/// The plausibility figures of one clip (see the module table).
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Plausibility {
    /// The clip's name.
    pub name: String,
    /// Its duration, s.
    pub seconds: f32,
    /// The ground used, m.
    pub ground_m: f32,
    /// Mean over frames of the deepest foot penetration, mm.
    pub penetration_mean_mm: f32,
    /// Deepest foot penetration, mm.
    pub penetration_max_mm: f32,
    /// Longest stretch with no foot near the ground, s.
    pub airborne_max_s: f32,
    /// Median horizontal speed of a foot in contact, cm/s.
    pub skate_median_cm_s: f32,
    /// Share of contact frames whose foot moves faster than [`SKATE_M_S`], %.
    pub skate_share_pct: f32,
    /// 95th percentile of the torso's tilt from vertical, °.
    pub tilt_p95_deg: f32,
    /// Largest torso tilt, °.
    pub tilt_max_deg: f32,
    /// Largest backward bend of a knee, °.
    pub knee_backwards_max_deg: f32,
    /// Largest backward bend of an elbow, °.
    pub elbow_backwards_max_deg: f32,
    /// 95th percentile of the root's speed, m/s.
    pub root_speed_p95: f32,
    /// Largest root speed, m/s.
    pub root_speed_max: f32,
    /// 95th percentile of the root's acceleration, m/s².
    pub root_accel_p95: f32,
    /// Largest root acceleration, m/s².
    pub root_accel_max: f32,
    /// Largest root acceleration within [`JOIN_WINDOW_S`] of a join, m/s² (assembled
    /// animations, [`check_assembly`]; `None` for a file, whose joins are not known).
    pub root_accel_joins_max: Option<f32>,
    /// An assembled animation's torso tilt per placement, against the range of real takes of
    /// its action's kind ([`super::tilt_reference`]; empty for a file, whose actions are not
    /// known).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub tilt_by_action: Vec<TiltJudgement>,
}

impl Plausibility {
    /// The measures in which the clip leaves the real-mocap [`envelope`] (empty: within).
    pub fn beyond(&self) -> Vec<&'static str> {
        use envelope as e;
        [
            (self.penetration_max_mm > e::PENETRATION_MM, "penetration"),
            (self.airborne_max_s > e::AIRBORNE_S, "hovering"),
            (self.skate_median_cm_s > e::SKATE_CM_S, "skating"),
            (
                self.knee_backwards_max_deg > e::BENT_BACKWARDS_DEG,
                "knee backwards",
            ),
            (
                self.elbow_backwards_max_deg > e::BENT_BACKWARDS_DEG,
                "elbow backwards",
            ),
            (self.root_speed_max > e::ROOT_SPEED_M_S, "root speed"),
            (
                self.root_accel_joins_max
                    .is_some_and(|a| a > e::ROOT_ACCEL_JOIN_M_S2),
                "pops at joins",
            ),
            (self.tilt_by_action.iter().any(|t| !t.holds()), "torso tilt"),
        ]
        .into_iter()
        .filter_map(|(out, what)| out.then_some(what))
        .collect()
    }
}

/// A leg's landmarks: hip, knee, ankle, and the foot's points (the ankle and below).
struct Leg {
    hip: usize,
    knee: usize,
    ankle: usize,
    foot: Vec<usize>,
}

fn descendants(sk: &Skeleton, j: usize) -> Vec<usize> {
    let mut out = vec![j];
    let mut k = 0;
    while let Some(&n) = out.get(k) {
        out.extend(sk.children(n));
        k += 1;
    }
    out
}

/// The `q`-quantile of `xs` (0 for none).
fn quantile(xs: &[f32], q: f32) -> f32 {
    let mut v: Vec<f32> = xs.iter().copied().filter(|x| x.is_finite()).collect();
    if v.is_empty() {
        return 0.0;
    }
    v.sort_by(f32::total_cmp);
    let i = ((v.len() - 1) as f32 * q).round() as usize;
    v[i.min(v.len() - 1)]
}

fn max_of(xs: impl IntoIterator<Item = f32>) -> f32 {
    xs.into_iter().filter(|x| x.is_finite()).fold(0.0, f32::max)
}

/// The angle (°) by which a limb whose proximal segment points along `u` and distal one along
/// `d` is bent the wrong way: a knee flexes about the body's left axis `left` (the shin folds
/// back, `u × d` points left), so a bend about the right axis is backwards. Lateral bending
/// counts for nothing. 0 for a limb bent the right way or straight.
fn bent_backwards(u: Vec3, d: Vec3, left: Vec3) -> f32 {
    let (Some(u), Some(d), Some(left)) =
        (u.try_normalize(), d.try_normalize(), left.try_normalize())
    else {
        return 0.0;
    };
    let sagittal = u.cross(d).dot(left);
    (-sagittal).atan2(u.dot(d)).to_degrees().max(0.0)
}

/// Least bend (rad) of a frame whose bending axis tells which way an elbow folds.
const FOLDED_RAD: f32 = 0.35;

/// The largest backward bend (°) of an elbow whose upper arm and forearm point along `arm[f]`
/// in each frame, both in the upper arm's own frame: the way the elbow folds is the axis it
/// turns about when it is well bent, on the whole over the clip (people fold their elbows the
/// right way far more than they overextend them), and a bend about the opposite axis is
/// backwards. 0 for an arm never well bent.
fn elbow_backwards(arm: &[(Vec3, Vec3)]) -> f32 {
    let axis: Vec3 = arm
        .iter()
        .filter_map(|&(u, d)| {
            let (u, d) = (u.try_normalize()?, d.try_normalize()?);
            (u.dot(d) < FOLDED_RAD.cos()).then(|| u.cross(d).try_normalize())?
        })
        .sum();
    let Some(axis) = axis.try_normalize() else {
        return 0.0;
    };
    max_of(arm.iter().map(|&(u, d)| bent_backwards(u, d, axis)))
}

/// Measures an assembled animation ([`check_clip`] in metres on the ground y = 0), its
/// root's acceleration around its joins ([`Plausibility::root_accel_joins_max`]) and each
/// action's torso tilt against the real takes of its kind in `tilt`
/// ([`Plausibility::tilt_by_action`]).
pub fn check_assembly(
    asm: &super::assemble::Assembly,
    name: &str,
    tilt: &TiltReference,
) -> Result<Plausibility> {
    let mut r = check_clip(&asm.clip, Ground::At(0.0), name)?;
    r.root_accel_joins_max = Some(accel_near(&asm.clip, &asm.joins, JOIN_WINDOW_S));
    r.tilt_by_action = tilt.judge(asm)?;
    Ok(r)
}

/// The largest acceleration (m/s², lengths in metres) of `clip`'s root within `window`
/// seconds of any of the frames `joins` (0 without joins).
pub fn accel_near(clip: &Clip, joins: &[usize], window: f32) -> f32 {
    let dt = clip.frame_time.max(1e-6);
    let w = (window / dt).round() as usize;
    let root = clip.root_path();
    max_of(joins.iter().flat_map(|&k| {
        let root = &root;
        (k.saturating_sub(w).max(1)..=(k + w).min(root.len().saturating_sub(2)))
            .map(move |f| (root[f + 1] - 2.0 * root[f] + root[f - 1]).length() / (dt * dt))
    }))
}

/// Measures `clip` (its lengths in the file's unit; `name` names it in errors).
pub fn check_clip(clip: &Clip, ground: Ground, name: &str) -> Result<Plausibility> {
    if clip.len() < 3 {
        anyhow::bail!("{name}: too short to judge ({} frames)", clip.len());
    }
    let sk = &clip.skeleton;
    let roles = RoleMap::detect(sk, &RoleOverrides::new(), name)
        .with_context(|| format!("{name}: could not find the body's landmarks"))?;
    let world: Vec<Vec<(Vec3, Quat)>> = clip
        .frames
        .iter()
        .map(|p| {
            sk.forward(p)
                .into_iter()
                .map(|w| (w.position, w.rotation))
                .collect()
        })
        .collect();
    let pos = |f: usize, j: usize| world[f].get(j).map_or(Vec3::ZERO, |w| w.0);
    let j = |r: Role| roles.joint(r);
    // Metres per unit, from the body's height in the first frame.
    let height = pos(0, j(Role::Head)).y
        - pos(0, j(Role::LeftFoot))
            .y
            .min(pos(0, j(Role::RightFoot)).y);
    let unit = if height > CENTIMETRE_HEIGHT {
        0.01
    } else {
        1.0
    };
    let p = |f: usize, j: usize| pos(f, j) * unit;
    let legs: Vec<Leg> = [
        (Role::LeftHip, Role::LeftKnee, Role::LeftFoot),
        (Role::RightHip, Role::RightKnee, Role::RightFoot),
    ]
    .into_iter()
    .map(|(h, k, a)| {
        let foot = descendants(sk, j(a));
        Leg {
            hip: j(h),
            knee: j(k),
            ankle: j(a),
            foot,
        }
    })
    .collect();
    let n = clip.len();
    let dt = clip.frame_time;
    // Each foot's lowest point per frame: (height, joint).
    let lowest = |f: usize, leg: &Leg| {
        leg.foot
            .iter()
            .map(|&i| (p(f, i).y, i))
            .min_by(|a, b| a.0.total_cmp(&b.0))
            .unwrap_or((p(f, leg.ankle).y, leg.ankle))
    };
    let ground_m = match ground {
        Ground::At(y) => y,
        Ground::Auto => {
            let lows: Vec<f32> = (0..n)
                .flat_map(|f| legs.iter().map(move |l| (f, l)))
                .map(|(f, l)| lowest(f, l).0)
                .collect();
            quantile(&lows, AUTO_GROUND_PERCENTILE)
        }
    };
    let mut penetration = Vec::with_capacity(n);
    let mut airborne_run = 0usize;
    let mut airborne_max = 0usize;
    let mut contact_speeds = Vec::new();
    for f in 0..n {
        let lows: Vec<(f32, usize)> = legs.iter().map(|l| lowest(f, l)).collect();
        let deepest = lows.iter().map(|l| l.0).fold(f32::INFINITY, f32::min);
        penetration.push((ground_m - deepest).max(0.0) * 1000.0);
        if deepest - ground_m > NEAR_GROUND_M {
            airborne_run += 1;
            airborne_max = airborne_max.max(airborne_run);
        } else {
            airborne_run = 0;
        }
        if f + 1 < n {
            for &(h, i) in &lows {
                if h - ground_m <= CONTACT_M {
                    let d = p(f + 1, i) - p(f, i);
                    contact_speeds.push(Vec3::new(d.x, 0.0, d.z).length() / dt);
                }
            }
        }
    }
    let skating = contact_speeds.iter().filter(|&&s| s > SKATE_M_S).count();
    let tilt: Vec<f32> = (0..n)
        .map(|f| tilt_deg(p(f, j(Role::Hips)), p(f, j(Role::Neck))))
        .collect();
    let tilt_figures = TiltFigures::of(&tilt);
    let knee_back = max_of((0..n).flat_map(|f| {
        let left = p(f, j(Role::LeftHip)) - p(f, j(Role::RightHip));
        legs.iter()
            .map(|l| {
                let (hip, knee, ankle) = (p(f, l.hip), p(f, l.knee), p(f, l.ankle));
                bent_backwards(knee - hip, ankle - knee, left)
            })
            .collect::<Vec<_>>()
    }));
    let elbow_back = [
        (Role::LeftShoulder, Role::LeftElbow, Role::LeftHand),
        (Role::RightShoulder, Role::RightElbow, Role::RightHand),
    ]
    .into_iter()
    .map(|(s, e, h)| {
        // In the upper arm's own frame, where an elbow's hinge axis stays put.
        let arm: Vec<(Vec3, Vec3)> = world
            .iter()
            .map(|w| {
                let at = |r: Role| w.get(j(r)).copied().unwrap_or((Vec3::ZERO, Quat::IDENTITY));
                let local = at(s).1.inverse();
                (local * (at(e).0 - at(s).0), local * (at(h).0 - at(e).0))
            })
            .collect();
        elbow_backwards(&arm)
    })
    .fold(0.0, f32::max);
    let root: Vec<Vec3> = (0..n).map(|f| p(f, j(Role::Hips))).collect();
    let speed: Vec<f32> = root
        .windows(2)
        .map(|w| (w[1] - w[0]).length() / dt)
        .collect();
    let accel: Vec<f32> = root
        .windows(3)
        .map(|w| (w[2] - 2.0 * w[1] + w[0]).length() / (dt * dt))
        .collect();
    Ok(Plausibility {
        name: name.to_string(),
        seconds: clip.duration(),
        ground_m,
        penetration_mean_mm: penetration.iter().sum::<f32>() / n as f32,
        penetration_max_mm: max_of(penetration.iter().copied()),
        airborne_max_s: airborne_max as f32 * dt,
        skate_median_cm_s: quantile(&contact_speeds, 0.5) * 100.0,
        skate_share_pct: if contact_speeds.is_empty() {
            0.0
        } else {
            100.0 * skating as f32 / contact_speeds.len() as f32
        },
        tilt_p95_deg: tilt_figures.p95,
        tilt_max_deg: tilt_figures.max,
        knee_backwards_max_deg: knee_back,
        elbow_backwards_max_deg: elbow_back,
        root_speed_p95: quantile(&speed, 0.95),
        root_speed_max: max_of(speed.iter().copied()),
        root_accel_p95: quantile(&accel, 0.95),
        root_accel_max: max_of(accel.iter().copied()),
        root_accel_joins_max: None,
        tilt_by_action: Vec::new(),
    })
}

/// `figurine check`.
#[derive(Debug, Args)]
pub struct CheckArgs {
    /// Clips to judge: BVH files, or DeepMimic clips (`humanoid3d_*.txt`).
    #[arg(required_unless_present_any = ["defaults", "reference"])]
    pub clips: Vec<PathBuf>,
    /// Judge every default action in the four effort corners and neutral, assembled along a
    /// generated doodle (as `figurine animate` would), against the real-mocap envelope.
    #[arg(long)]
    pub defaults: bool,
    /// Judge the real motion capture `cargo xtask setup` fetched (the reference; ground
    /// estimated).
    #[arg(long)]
    pub reference: bool,
    /// Seed of the doodles `--defaults` generates.
    #[arg(long, default_value_t = 5)]
    pub seed: u64,
    /// With `--defaults`: also draw one sheet per action into this folder (`ACTION.png`), a
    /// row of stick figures per effort (sudden-strong, sudden-light, sustained-strong,
    /// sustained-light, neutral), to see what each effort does to it.
    #[arg(long, requires = "defaults")]
    pub sheets: Option<PathBuf>,
    /// The ground: a height in metres, or `auto` (a low percentile of the feet's height).
    #[arg(long, default_value = "0")]
    pub ground: String,
    /// Print one JSON object per clip instead of a table.
    #[arg(long)]
    pub json: bool,
}

/// Every default action in the four effort corners and neutral, each assembled along a
/// doodle generated at `seed` from its label (as `figurine animate --labels` does), judged.
pub fn check_defaults(seed: u64) -> Result<Vec<Plausibility>> {
    let tilt = default_tilt_reference()?;
    check_animations(&super::defaults::default_animations(seed)?.0, &tilt)
}

/// The torso-tilt reference of the default library's actions ([`TiltReference::of_library`]).
pub fn default_tilt_reference() -> Result<TiltReference> {
    TiltReference::of_library(&super::library::ClipLibrary::default_library()?)
}

/// Judges assembled default animations, each labelled "ACTION EFFORT".
fn check_animations(
    anims: &[super::defaults::DefaultAnimation],
    tilt: &TiltReference,
) -> Result<Vec<Plausibility>> {
    anims
        .iter()
        .map(|a| check_assembly(&a.assembly, &format!("{} {}", a.action, a.effort), tilt))
        .collect()
}

/// The real takes of the data folder (BVH files, DeepMimic clips), judged with the ground
/// estimated.
pub fn check_reference() -> Result<Vec<Plausibility>> {
    let dir = crate::data::data_dir();
    let mut files: Vec<PathBuf> = ["bvh", "deepmimic"]
        .iter()
        .filter_map(|sub| std::fs::read_dir(dir.join(sub)).ok())
        .flatten()
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            let name = p
                .file_name()
                .map(|n| n.to_string_lossy().to_string())
                .unwrap_or_default();
            name.ends_with(".bvh") || (name.starts_with("humanoid3d_") && name.ends_with(".txt"))
        })
        .collect();
    files.sort();
    if files.is_empty() {
        anyhow::bail!(
            "no motion capture under {}: run `cargo xtask setup` to fetch it",
            dir.display()
        );
    }
    files.iter().map(|p| check_path(p, Ground::Auto)).collect()
}

/// Loads and judges one clip file.
pub fn check_path(path: &std::path::Path, ground: Ground) -> Result<Plausibility> {
    let (clip, _) = super::cli::load_named_clip(&path.to_string_lossy(), None, None)?;
    let name = path.file_name().map_or_else(
        || path.display().to_string(),
        |n| n.to_string_lossy().into(),
    );
    check_clip(&clip, ground, &name)
}

/// Runs `figurine check`.
pub fn run(a: &CheckArgs) -> Result<()> {
    let ground = match a.ground.as_str() {
        "auto" => Ground::Auto,
        y => Ground::At(
            y.parse::<f32>()
                .ok()
                .filter(|y| y.is_finite())
                .with_context(|| format!("--ground {y}: a height in metres, or auto"))?,
        ),
    };
    let mut rows = Vec::new();
    if a.reference {
        rows.extend(check_reference()?);
    }
    let mut tilt_reference = None;
    if a.defaults {
        let (anims, forward) = super::defaults::default_animations(a.seed)?;
        let tilt = default_tilt_reference()?;
        rows.extend(check_animations(&anims, &tilt)?);
        tilt_reference = Some(tilt);
        if let Some(dir) = &a.sheets {
            let written = super::defaults::write_effort_sheets(&anims, forward, dir)?;
            eprintln!("{} effort sheets in {}", written.len(), dir.display());
        }
    }
    for path in &a.clips {
        rows.push(check_path(path, ground)?);
    }
    if a.json {
        for r in &rows {
            println!("{}", serde_json::to_string(r)?);
        }
        return Ok(());
    }
    print_table(&rows);
    if let Some(tilt) = &tilt_reference {
        print_tilt_reference(tilt);
    }
    let within = rows.iter().filter(|r| r.beyond().is_empty()).count();
    println!(
        "within the real-mocap envelope (penetration ≤ {} mm, airborne ≤ {} s, contact-foot \
         speed ≤ {} cm/s, knees and elbows backwards ≤ {}°, root ≤ {} m/s, ≤ {} m/s² at joins, \
         an assembled action's torso tilt within its kind's range): {within} of {}",
        envelope::PENETRATION_MM,
        envelope::AIRBORNE_S,
        envelope::SKATE_CM_S,
        envelope::BENT_BACKWARDS_DEG,
        envelope::ROOT_SPEED_M_S,
        envelope::ROOT_ACCEL_JOIN_M_S2,
        rows.len()
    );
    let mut counts: std::collections::BTreeMap<&str, usize> = Default::default();
    for r in &rows {
        for b in r.beyond() {
            *counts.entry(b).or_default() += 1;
        }
    }
    if !counts.is_empty() {
        let list: Vec<String> = counts.iter().map(|(k, n)| format!("{k} {n}")).collect();
        println!("beyond it: {}", list.join(", "));
    }
    Ok(())
}

/// The tilt column of a row: for one action, its tilt p95/max over its own frames, the
/// ranges of its kind and whether it holds; for several, how many hold; `-` for a file.
fn tilt_column(judged: &[TiltJudgement]) -> String {
    match judged {
        [] => "-".into(),
        [one] => match one.bounds {
            None => "no take of its kind".into(),
            Some(b) => format!(
                "{:.0}/{:.0} in {:.0}-{:.0}/{:.0}-{:.0} {}",
                one.figures.p95,
                one.figures.max,
                b.p95.0,
                b.p95.1,
                b.max.0,
                b.max.1,
                if one.holds() { "ok" } else { "OUT" }
            ),
        },
        many => {
            let ok = many.iter().filter(|t| t.holds()).count();
            format!("{ok} of {} actions below their kind's top", many.len())
        }
    }
}

/// Prints the real takes of each kind of action, their tilt, and the range an assembled
/// animation of that kind is held to.
pub fn print_tilt_reference(tilt: &TiltReference) {
    println!(
        "torso tilt of the real takes of each kind (p95/max °), ranges widened by {:.1}° (the \
         widest spread among one performer's takes of one kind at different vigour, measured \
         {:.2}°):",
        tilt.margin_deg,
        super::tilt_reference::vigour_spread(&tilt.kinds)
    );
    for (action, takes) in &tilt.kinds {
        let list: Vec<String> = takes
            .iter()
            .map(|t| format!("{} {:.0}/{:.0}", t.source, t.figures.p95, t.figures.max))
            .collect();
        let range = tilt.bounds(action).map_or_else(String::new, |b| {
            format!(
                " → p95 {:.0}-{:.0}, max {:.0}-{:.0}",
                b.p95.0, b.p95.1, b.max.0, b.max.1
            )
        });
        println!("  {action:<9} {}{range}", list.join(", "));
    }
}

/// Prints the figures of `rows` as a table, one clip a line.
pub fn print_table(rows: &[Plausibility]) {
    println!(
        "{:<28} {:>6} {:>13} {:>8} {:>13} {:>11} {:>7} {:>7} {:>11} {:>13} {:>10}  action's tilt \
         in its kind's p95/max range",
        "clip",
        "s",
        "penetr. mm",
        "air s",
        "skate cm/s %",
        "tilt p95/max",
        "knee°",
        "elbow°",
        "root m/s",
        "root m/s²",
        "joins m/s²",
    );
    // (The measures beyond the envelope follow each row.)
    for r in rows {
        println!(
            "{:<28} {:>6.1} {:>6.1} {:>6.1} {:>8.2} {:>6.1} {:>6.0} {:>5.0} {:>5.0} {:>7.0} {:>7.0} {:>5.1} {:>5.1} {:>6.0} {:>6.0} {:>10}  {}",
            r.name.chars().take(28).collect::<String>(),
            r.seconds,
            r.penetration_mean_mm,
            r.penetration_max_mm,
            r.airborne_max_s,
            r.skate_median_cm_s,
            r.skate_share_pct,
            r.tilt_p95_deg,
            r.tilt_max_deg,
            r.knee_backwards_max_deg,
            r.elbow_backwards_max_deg,
            r.root_speed_p95,
            r.root_speed_max,
            r.root_accel_p95,
            r.root_accel_max,
            r.root_accel_joins_max
                .map_or_else(|| "-".to_string(), |a| format!("{a:.0}")),
            tilt_column(&r.tilt_by_action),
        );
        let beyond = r.beyond();
        if !beyond.is_empty() {
            println!("{:<28} beyond: {}", "", beyond.join(", "));
        }
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::motion::{Joint, Pose};

    /// Index of [`figure`]'s spine joint.
    pub(crate) const SPINE: usize = 9;

    /// A stick figure facing +Z (left towards +X), 1.7 m tall, standing with its soles on the
    /// ground: `pose(f, &mut Pose)` animates frame `f` of `frames` at 30 fps.
    pub(crate) fn figure(frames: usize, pose: impl Fn(usize, &mut Pose)) -> Clip {
        let j = |name: &str, parent: Option<usize>, o: [f32; 3]| {
            Joint::bare(name, parent, Vec3::from(o))
        };
        let skeleton = Skeleton {
            joints: vec![
                j("Hips", None, [0.0, 0.9, 0.0]),
                j("LeftUpLeg", Some(0), [0.1, 0.0, 0.0]),
                j("LeftLeg", Some(1), [0.0, -0.42, 0.0]),
                j("LeftFoot", Some(2), [0.0, -0.42, 0.0]),
                j("LeftToe", Some(3), [0.0, -0.06, 0.15]),
                j("RightUpLeg", Some(0), [-0.1, 0.0, 0.0]),
                j("RightLeg", Some(5), [0.0, -0.42, 0.0]),
                j("RightFoot", Some(6), [0.0, -0.42, 0.0]),
                j("RightToe", Some(7), [0.0, -0.06, 0.15]),
                j("Spine", Some(0), [0.0, 0.2, 0.0]),
                j("Neck", Some(9), [0.0, 0.35, 0.0]),
                j("Head", Some(10), [0.0, 0.2, 0.0]),
                j("LeftArm", Some(9), [0.18, 0.3, 0.0]),
                j("LeftForeArm", Some(12), [0.0, -0.28, 0.0]),
                j("LeftHand", Some(13), [0.0, -0.25, 0.0]),
                j("RightArm", Some(9), [-0.18, 0.3, 0.0]),
                j("RightForeArm", Some(15), [0.0, -0.28, 0.0]),
                j("RightHand", Some(16), [0.0, -0.25, 0.0]),
            ],
        };
        let frames = (0..frames)
            .map(|f| {
                let mut p = Pose::rest(&skeleton);
                pose(f, &mut p);
                p
            })
            .collect();
        Clip {
            name: "figure".into(),
            skeleton,
            frame_time: 1.0 / 30.0,
            frames,
        }
    }

    fn check(clip: &Clip) -> Plausibility {
        check_clip(clip, Ground::At(0.0), "figure").unwrap()
    }

    #[test]
    fn standing_still_is_plausible_in_every_measure() {
        let r = check(&figure(30, |_, _| {}));
        assert_eq!(r.penetration_max_mm, 0.0);
        assert_eq!(r.airborne_max_s, 0.0);
        assert_eq!(r.skate_median_cm_s, 0.0);
        assert_eq!(r.tilt_max_deg, 0.0);
        assert_eq!(r.knee_backwards_max_deg, 0.0);
        assert_eq!(r.root_speed_max, 0.0);
    }

    #[test]
    fn a_knee_bent_backwards_is_measured_and_one_bent_forwards_is_not() {
        // The left shin rotated about the left axis (+X): a positive angle swings the foot
        // forward of the knee, which only a knee bent backwards does.
        let bent = |deg: f32| {
            check(&figure(3, move |_, p| {
                p.rotations[2] = Quat::from_rotation_x(-deg.to_radians());
            }))
            .knee_backwards_max_deg
        };
        assert!((bent(30.0) - 30.0).abs() < 0.1, "{}", bent(30.0));
        assert_eq!(bent(-60.0), 0.0, "a knee flexed the right way");
    }

    #[test]
    fn hovering_sinking_skating_and_leaning_are_measured() {
        // Lifted 0.5 m for the second of two seconds.
        let r = check(&figure(60, |f, p| {
            if f >= 30 {
                p.translations[0].y += 0.5;
            }
        }));
        assert!((r.airborne_max_s - 30.0 / 30.0).abs() < 0.05, "{r:?}");
        // 3 cm into the ground.
        let r = check(&figure(10, |_, p| p.translations[0].y -= 0.03));
        assert!((r.penetration_max_mm - 30.0).abs() < 0.5, "{r:?}");
        assert!((r.penetration_mean_mm - 30.0).abs() < 0.5, "{r:?}");
        // Gliding at 0.6 m/s with both feet on the ground.
        let r = check(&figure(30, |f, p| p.translations[0].z += 0.02 * f as f32));
        assert!((r.skate_median_cm_s - 60.0).abs() < 0.5, "{r:?}");
        assert_eq!(r.skate_share_pct, 100.0);
        assert!((r.root_speed_max - 0.6).abs() < 1e-3, "{r:?}");
        // The whole body pitched forward 45° about the hips.
        let r = check(&figure(5, |_, p| {
            p.rotations[0] = Quat::from_rotation_x(0.25 * std::f32::consts::PI)
        }));
        assert!((r.tilt_max_deg - 45.0).abs() < 0.1, "{r:?}");
    }

    #[test]
    fn a_pop_is_measured_at_its_join_only() {
        // Standing for half a second, then gliding at 0.6 m/s: 18 m/s² at frame 15.
        let clip = figure(30, |f, p| {
            p.translations[0].z += 0.02 * (f as f32 - 15.0).max(0.0);
        });
        let pop = accel_near(&clip, &[15], JOIN_WINDOW_S);
        assert!((pop - 18.0).abs() < 0.01, "{pop}");
        // A join elsewhere does not see it, nor does a file without joins.
        assert_eq!(accel_near(&clip, &[2], 0.1), 0.0);
        let r = check(&clip);
        assert_eq!(r.root_accel_joins_max, None);
        assert!(r.beyond().is_empty(), "{r:?}");
        let judged = Plausibility {
            root_accel_joins_max: Some(envelope::ROOT_ACCEL_JOIN_M_S2 + 1.0),
            ..r
        };
        assert_eq!(judged.beyond(), vec!["pops at joins"]);
    }

    #[test]
    fn a_take_in_centimetres_reads_alike() {
        let metres = figure(30, |f, p| p.translations[0].z += 0.02 * f as f32);
        let mut cm = metres.clone();
        cm.scale_lengths(100.0);
        let (a, b) = (check(&metres), check(&cm));
        assert!((a.skate_median_cm_s - b.skate_median_cm_s).abs() < 0.01);
        assert!(check_clip(&figure(2, |_, _| {}), Ground::Auto, "short").is_err());
    }

    #[test]
    fn an_elbow_folded_against_its_usual_way_is_measured() {
        // The forearm folds about +Z (towards +X) by 30–90° in most frames, and 25° the
        // other way in one.
        let fold = |deg: f32| {
            let r = deg.to_radians();
            (Vec3::NEG_Y, Vec3::new(r.sin(), -r.cos(), 0.0))
        };
        let mut arm: Vec<(Vec3, Vec3)> = [30.0, 60.0, 90.0, 45.0].map(fold).to_vec();
        assert_eq!(elbow_backwards(&arm), 0.0);
        arm.push(fold(-25.0));
        assert!(
            (elbow_backwards(&arm) - 25.0).abs() < 0.01,
            "{}",
            elbow_backwards(&arm)
        );
        // An arm never well bent tells nothing.
        assert_eq!(elbow_backwards(&[fold(5.0), fold(-10.0)]), 0.0);
    }
}
