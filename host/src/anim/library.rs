//! The clip library: which motion clip plays each recognised action, and how.
//!
//! A JSON file maps action names to clips:
//! ```json
//! { "version": 1,
//!   "skeleton": { "format": "deepmimic-urdf", "file": "deepmimic/humanoid.urdf" },
//!   "forward": [1, 0, 0],
//!   "actions": {
//!     "walk":  { "file": "deepmimic/humanoid3d_walk.txt", "moving": true, "cyclic": true },
//!     "bow":   { "file": "deepmimic/humanoid3d_getup_facedown.txt", "moving": false,
//!                "cyclic": false, "frames": [150, 182], "pingpong": true, "note": "…" } } }
//! ```
//! `moving` actions follow the doodle's path, others play in place (§6.2); `cyclic` actions
//! repeat whole cycles along the path. `frames` picks an inclusive frame range, `pingpong`
//! plays it backwards then forwards, `anchor` keeps an in-place clip that travels on its spot,
//! `scale` turns a BVH clip's unit into metres (default
//! 0.01 for `.bvh`, 1 for DeepMimic). `forward` is the direction the rig faces, in its root
//! joint's frame. `"retarget": {"tpose": F}` plays a BVH take of another rig on the library's
//! skeleton ([`super::retarget`]; frame F of the file is the performer's T-pose), and
//! `"both_sides": true` loads a clip that steps to one side with its mirror image
//! ([`super::mirror`]), playing whichever steps towards the side the doodle moves.
//!
//! **Variants.** An action may instead list several clips, e.g. a plain kick and a spinning
//! kick: `"kick": [ {"name": "kick", "file": …}, {"name": "spinkick", "file": …} ]`. Each
//! element is a clip object as above plus an optional `name` (default: the file's stem, with
//! its frame range). The assembler plays the variant whose Effort-component LMA features best
//! match the action's recognised Laban Time and Weight (see [`super::variants`]); the first
//! variant is the action's primary clip (the one shown by `figurine clip`, and the tie winner).
//! A list must hold 1 to [`MAX_VARIANTS`] clips with distinct names that agree on `moving`;
//! anything else is an error naming the file and line. A single clip object is a list of one,
//! so older libraries read unchanged.
//!
//! **Loops.** `loop` says whether the clip may be repeated seamlessly when an action lasts
//! longer than it (the root carried forward by the clip's own per-cycle displacement and
//! turn). Default: DeepMimic's `"Loop": "wrap"` for a whole DeepMimic file (no `frames`, no
//! `pingpong`), `cyclic` otherwise. Moving actions that are not cyclic (jumps) play once.
//! Files resolve relative to the library file first, then as `KIND/NAME` in the project's data
//! folder ([`crate::data::data_file`]). All clips must share one skeleton (transitions blend
//! poses joint by joint): a take of another rig is retargeted onto it. The default library
//! (`host/assets/default_clips.json`, built into the binary) maps the recogniser's default
//! actions onto pybullet's DeepMimic clips, with variants for kick, jump and wave, and
//! sidestep onto a LAFAN1 take's sideways steps, retargeted and mirrored;
//! `host/assets/lafan_clips.json` maps walk onto three LAFAN1 gait cycles and wave onto three
//! dance stretches, each of different vigour.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, OnceLock};

use glam::Vec3;
use serde::Deserialize;

use super::clip_spec::check_variants;
pub use super::clip_spec::{ActionEntry, ActionSpec, MAX_VARIANTS};
use super::joint_limits::JointRanges;
use super::mirror::{mirror, MIRRORED_SUFFIX};
use super::retarget::retarget;
use super::variant_effort::variant_efforts;
use super::AnimError;
use crate::graph::GraphError;
use crate::motion::deepmimic::{humanoid_skeleton, read_deepmimic};
use crate::motion::urdf::read_urdf_path;
use crate::motion::{read_bvh_path, Clip, Skeleton};

/// The built-in default library text.
pub const DEFAULT_LIBRARY: &str = include_str!("../../assets/default_clips.json");

/// Where the skeleton of DeepMimic clips comes from.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SkeletonSpec {
    /// `deepmimic-urdf` (the only format that needs a separate skeleton file).
    pub format: String,
    /// The URDF file (same resolution rules as clips).
    pub file: String,
}

/// A parsed clip-library file.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ClipLibrary {
    /// Format version (1).
    pub version: u32,
    /// Skeleton source for DeepMimic clips.
    #[serde(default)]
    pub skeleton: Option<SkeletonSpec>,
    /// Direction the rig faces, in its root joint's frame (see [`ClipLibrary::forward`]).
    #[serde(default = "default_forward")]
    pub forward: [f32; 3],
    /// Action name → its clip variants.
    pub actions: BTreeMap<String, ActionEntry>,
    /// Folder relative paths resolve against (the library file's folder).
    #[serde(skip)]
    pub base: Option<PathBuf>,
    /// Name used in messages (file path or "default clip library").
    #[serde(skip)]
    pub origin: String,
}

fn default_forward() -> [f32; 3] {
    [1.0, 0.0, 0.0]
}

/// A clip ready for assembly (one variant of an action).
#[derive(Debug, Clone)]
pub struct ActionClip {
    /// Action name.
    pub action: String,
    /// Variant name (see [`ActionSpec::variant_name`]).
    pub variant: String,
    /// The clip in metres, +Y up.
    pub clip: Clip,
    /// Travels along the doodle.
    pub moving: bool,
    /// Repeats in cycles.
    pub cyclic: bool,
    /// Repeats seamlessly when the action outlasts the clip (see the module doc).
    pub looping: bool,
    /// In place and anchored: the clip's net ground drift is removed.
    pub anchor: bool,
    /// The source clip file it was cut from (for motion-graph look-ups).
    pub file: PathBuf,
    /// Seconds of the source file where this clip starts (its `frames` range); `None` when
    /// played ping-pong (its time then has no monotone map to the source's).
    pub source_start_s: Option<f32>,
    /// Seconds of the source file the clip was cut from, (first, last) frame.
    pub source_span_s: (f32, f32),
    /// The variant's own Laban effort estimate from its Effort-component LMA features,
    /// standardised over the action's variants (`None` when the action has one clip).
    pub effort: Option<crate::graph::effort::Effort>,
    /// The action's other variants, in library order (empty for a single clip). `self` is the
    /// primary variant.
    pub alternatives: Vec<ActionClip>,
    /// The range each joint moves in over every take of the library (see
    /// [`super::joint_limits::JointRanges`]): effort transfer holds the joints within it.
    /// `None` for clips built outside a library.
    pub ranges: Option<Arc<JointRanges>>,
    /// The clip's mirror image, for clips that step to one side (`both_sides`; see
    /// [`super::mirror::plays_mirrored`]).
    pub mirrored: Option<Box<ActionClip>>,
}

impl ActionClip {
    /// All variants: `self` first, then the alternatives.
    pub fn variants(&self) -> impl Iterator<Item = &ActionClip> {
        std::iter::once(self).chain(self.alternatives.iter())
    }
}

impl ClipLibrary {
    /// The built-in default library.
    pub fn default_library() -> Result<ClipLibrary, AnimError> {
        Self::parse(DEFAULT_LIBRARY, Path::new("default clip library"), None)
    }

    /// Reads a library file.
    pub fn read_path(path: &Path) -> Result<ClipLibrary, AnimError> {
        let text = std::fs::read_to_string(path).map_err(|e| AnimError::Io {
            path: path.to_path_buf(),
            reason: e.to_string(),
        })?;
        Self::parse(&text, path, path.parent().map(Path::to_path_buf))
    }

    /// Parses library JSON; errors name `name` and the line.
    pub fn parse(text: &str, name: &Path, base: Option<PathBuf>) -> Result<ClipLibrary, AnimError> {
        let mut lib: ClipLibrary = serde_json::from_str(text).map_err(|e| AnimError::Spec {
            path: name.to_path_buf(),
            line: e.line().max(1),
            reason: e.to_string(),
        })?;
        if lib.version != 1 {
            return Err(AnimError::Spec {
                path: name.to_path_buf(),
                line: 1,
                reason: format!("unsupported clip-library version {}", lib.version),
            });
        }
        lib.base = base;
        lib.origin = name.display().to_string();
        Ok(lib)
    }

    /// Facing direction of the rig in its root joint's frame (unit): the root's rotation
    /// carries it to the world facing. DeepMimic's root frame is upright (+X); rigs whose root
    /// frame is not (LAFAN's hips have +X up, +Z left) face along another axis (+Y).
    pub fn forward(&self) -> Vec3 {
        let f = Vec3::from(self.forward);
        if f.is_finite() && f.length() > 1e-6 {
            f.normalize()
        } else {
            Vec3::X
        }
    }

    /// Checks that every action has a clip; the error lists all missing mappings.
    pub fn check_actions<'a>(
        &self,
        actions: impl IntoIterator<Item = &'a str>,
    ) -> Result<(), AnimError> {
        let mut missing: Vec<String> = actions
            .into_iter()
            .filter(|a| !self.actions.contains_key(*a))
            .map(str::to_string)
            .collect();
        missing.sort();
        missing.dedup();
        if missing.is_empty() {
            Ok(())
        } else {
            Err(AnimError::MissingClips {
                library: self.origin.clone(),
                missing,
                available: self.actions.keys().cloned().collect(),
            })
        }
    }

    /// Finds a file named in the library.
    pub fn resolve(&self, file: &str) -> Result<PathBuf, AnimError> {
        if let Some(base) = &self.base {
            let p = base.join(file);
            if p.is_file() {
                return Ok(p);
            }
        }
        let p = Path::new(file);
        if p.is_absolute() && p.is_file() {
            return Ok(p.to_path_buf());
        }
        if let Some((kind, name)) = file.split_once('/') {
            if let Some(p) = crate::data::data_file(kind, name) {
                return Ok(p);
            }
        }
        Err(AnimError::Data(format!(
            "clip file {file} (named in {}) not found next to the library nor under {}: run \
             `cargo xtask setup` to fetch the data (or set {})",
            self.origin,
            crate::data::data_dir().display(),
            crate::data::DATA_DIR_ENV
        )))
    }

    fn skeleton_urdf(
        &self,
    ) -> Result<Option<(Skeleton, Vec<crate::motion::urdf::UrdfJoint>)>, AnimError> {
        let Some(spec) = &self.skeleton else {
            return Ok(None);
        };
        if spec.format != "deepmimic-urdf" {
            return Err(AnimError::Data(format!(
                "{}: unknown skeleton format {:?}",
                self.origin, spec.format
            )));
        }
        let path = self.resolve(&spec.file)?;
        let urdf = read_urdf_path(&path)?;
        let sk = humanoid_skeleton(&urdf, &path)?;
        Ok(Some((sk, urdf)))
    }

    /// Loads the clips of the given actions (all must be mapped, see [`Self::check_actions`]):
    /// each action's primary variant, carrying the others as
    /// [`ActionClip::alternatives`] with their effort estimates.
    pub fn load<'a>(
        &self,
        actions: impl IntoIterator<Item = &'a str>,
    ) -> Result<BTreeMap<String, ActionClip>, AnimError> {
        let wanted: Vec<&str> = actions.into_iter().collect();
        let (mut out, ranges) = self.with_joint_ranges(&wanted)?;
        for ac in out.values_mut() {
            set_ranges(ac, &ranges);
        }
        Ok(out)
    }

    /// The `wanted` actions' clips, and the range each joint moves in over every clip the
    /// library maps (all variants), learnt once per library and kept for the process: an
    /// action's effort is held within what the library's actors did, whichever other actions
    /// an animation holds. The first time, every clip is loaded once and the wanted ones taken
    /// from them; should a clip of the library fail to load, the ranges come from the wanted
    /// clips alone.
    fn with_joint_ranges(
        &self,
        wanted: &[&str],
    ) -> Result<(BTreeMap<String, ActionClip>, Arc<JointRanges>), AnimError> {
        static CACHE: OnceLock<Mutex<BTreeMap<String, Arc<JointRanges>>>> = OnceLock::new();
        let key = format!("{:?}|{:?}|{:?}", self.base, self.skeleton, self.actions);
        let cache = CACHE.get_or_init(Default::default);
        if let Some(r) = cache.lock().ok().and_then(|c| c.get(&key).cloned()) {
            return Ok((self.load_clips(wanted.iter().copied())?, r));
        }
        let pool = |clips: &BTreeMap<String, ActionClip>| {
            Arc::new(JointRanges::learn(
                clips
                    .values()
                    .flat_map(|a| a.variants())
                    .flat_map(|v| std::iter::once(v).chain(v.mirrored.as_deref()))
                    .map(|v| &v.clip),
            ))
        };
        self.check_actions(wanted.iter().copied())?;
        match self.load_clips(self.actions.keys().map(String::as_str)) {
            Ok(mut all) => {
                let r = pool(&all);
                if let Ok(mut c) = cache.lock() {
                    c.insert(key, r.clone());
                }
                let out = wanted.iter().filter_map(|w| all.remove_entry(*w)).collect();
                Ok((out, r))
            }
            Err(_) => {
                let out = self.load_clips(wanted.iter().copied())?;
                let r = pool(&out);
                Ok((out, r))
            }
        }
    }

    /// [`Self::load`] without the joint ranges.
    fn load_clips<'a>(
        &self,
        actions: impl IntoIterator<Item = &'a str>,
    ) -> Result<BTreeMap<String, ActionClip>, AnimError> {
        let wanted: Vec<&str> = actions.into_iter().collect();
        self.check_actions(wanted.iter().copied())?;
        let urdf = self.skeleton_urdf()?;
        let mut out = BTreeMap::new();
        let mut names: Option<Vec<String>> = None;
        // Variants often cut several ranges from one long take: read each file once.
        let mut files: BTreeMap<PathBuf, (Clip, bool)> = BTreeMap::new();
        for action in wanted {
            if out.contains_key(action) {
                continue;
            }
            let Some(entry) = self.actions.get(action) else {
                continue;
            };
            check_variants(&entry.variants).map_err(|reason| AnimError::Spec {
                path: PathBuf::from(&self.origin),
                line: 1,
                reason: format!("action {action}: {reason}"),
            })?;
            let mut loaded = Vec::with_capacity(entry.variants.len());
            for spec in &entry.variants {
                let ac = self.load_variant(action, spec, urdf.as_ref(), &mut files)?;
                let joint_names: Vec<String> = ac
                    .clip
                    .skeleton
                    .joints
                    .iter()
                    .map(|j| j.name.clone())
                    .collect();
                match &names {
                    None => names = Some(joint_names),
                    Some(n) if *n != joint_names => {
                        return Err(AnimError::Data(format!(
                        "{}: clip for {action} ({}) has a different skeleton from the other clips",
                        self.origin, spec.file
                    )))
                    }
                    Some(_) => {}
                }
                loaded.push(ac);
            }
            if loaded.len() > 1 {
                sign_variants(&mut loaded).map_err(|e| {
                    AnimError::Data(format!(
                        "{}: action {action}: effort features of its variants: {e}",
                        self.origin
                    ))
                })?;
            }
            let mut it = loaded.into_iter();
            if let Some(mut primary) = it.next() {
                primary.alternatives = it.collect();
                out.insert(action.to_string(), primary);
            }
        }
        Ok(out)
    }

    /// Reads a clip file as stored (its own length unit) and whether it says it loops.
    fn read_clip(
        &self,
        path: &Path,
        spec: &ActionSpec,
        urdf: Option<&(Skeleton, Vec<crate::motion::urdf::UrdfJoint>)>,
    ) -> Result<(Clip, bool), AnimError> {
        if is_bvh_path(path) {
            return Ok((read_bvh_path(path)?.clip, false));
        }
        let (sk, u) = urdf.ok_or_else(|| {
            AnimError::Data(format!(
                "{}: DeepMimic clip {} needs a \"skeleton\" entry",
                self.origin, spec.file
            ))
        })?;
        let text = std::fs::read_to_string(path).map_err(|e| AnimError::Io {
            path: path.to_path_buf(),
            reason: e.to_string(),
        })?;
        let dm = read_deepmimic(&text, path, sk, u)?;
        Ok((dm.clip, dm.looping))
    }

    /// Loads one variant's clip.
    fn load_variant(
        &self,
        action: &str,
        spec: &ActionSpec,
        urdf: Option<&(Skeleton, Vec<crate::motion::urdf::UrdfJoint>)>,
        files: &mut BTreeMap<PathBuf, (Clip, bool)>,
    ) -> Result<ActionClip, AnimError> {
        let path = self.resolve(&spec.file)?;
        if !files.contains_key(&path) {
            let read = self.read_clip(&path, spec, urdf)?;
            files.insert(path.clone(), read);
        }
        let Some((clip, file_loops)) = files.get(&path) else {
            return Err(AnimError::Data(format!(
                "{}: lost {}",
                self.origin, spec.file
            )));
        };
        let (mut clip, file_loops) = (clip.clone(), *file_loops);
        let scale = spec
            .scale
            .unwrap_or(if is_bvh_path(&path) { 0.01 } else { 1.0 });
        clip.scale_lengths(scale);
        clip.name = action.to_string();
        let source_start_s =
            (!spec.pingpong).then(|| spec.frames.map_or(0.0, |[a, _]| a as f32 * clip.frame_time));
        let source_span_s = match spec.frames {
            Some([a, b]) => (a as f32 * clip.frame_time, b as f32 * clip.frame_time),
            None => (0.0, clip.duration()),
        };
        if let Some(rt) = &spec.retarget {
            let (target, _) = urdf.ok_or_else(|| {
                AnimError::Data(format!(
                    "{}: action {action}: retargeting {} needs the library's \"skeleton\"",
                    self.origin, spec.file
                ))
            })?;
            let range = spec
                .frames
                .unwrap_or([0, clip.frames.len().saturating_sub(1)]);
            clip = retarget(&clip, rt.tpose, range, target)
                .map_err(|e| AnimError::Data(format!("{}: action {action}: {e}", self.origin)))?;
            clip.name = action.to_string();
            // The range is cut already.
            let whole = ActionSpec {
                frames: None,
                ..spec.clone()
            };
            select_frames(&mut clip, &whole, &self.origin, action)?;
        } else {
            select_frames(&mut clip, spec, &self.origin, action)?;
        }
        let whole = spec.frames.is_none() && !spec.pingpong;
        let looping = spec.looping.unwrap_or(spec.cyclic || (whole && file_loops));
        let mut ac = ActionClip {
            action: action.to_string(),
            variant: spec.variant_name(),
            clip,
            moving: spec.moving,
            cyclic: spec.cyclic,
            looping: looping || spec.cyclic,
            anchor: spec.anchor && !spec.moving,
            file: path,
            source_start_s,
            source_span_s,
            effort: None,
            alternatives: Vec::new(),
            ranges: None,
            mirrored: None,
        };
        if spec.both_sides {
            let mut m = ac.clone();
            m.clip = mirror(&ac.clip)
                .map_err(|e| AnimError::Data(format!("{}: action {action}: {e}", self.origin)))?;
            m.variant = format!("{}{MIRRORED_SUFFIX}", ac.variant);
            ac.mirrored = Some(Box::new(m));
        }
        Ok(ac)
    }
}

/// Gives a clip, its mirror image and its alternatives the library's joint ranges.
fn set_ranges(ac: &mut ActionClip, ranges: &Arc<JointRanges>) {
    ac.ranges = Some(ranges.clone());
    if let Some(m) = &mut ac.mirrored {
        set_ranges(m, ranges);
    }
    for alt in &mut ac.alternatives {
        set_ranges(alt, ranges);
    }
}

fn is_bvh_path(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("bvh"))
}

fn select_frames(
    clip: &mut Clip,
    spec: &ActionSpec,
    origin: &str,
    action: &str,
) -> Result<(), AnimError> {
    if let Some([a, b]) = spec.frames {
        if a >= b || b >= clip.frames.len() {
            return Err(AnimError::Data(format!(
                "{origin}: action {action}: frame range [{a}, {b}]: a first and a later last \
                 frame of the clip's {} (numbered from 0)",
                clip.frames.len()
            )));
        }
        clip.frames = clip.frames[a..=b].to_vec();
    }
    if spec.pingpong {
        let mut seq: Vec<_> = clip.frames.iter().rev().cloned().collect();
        seq.extend(clip.frames.iter().skip(1).cloned());
        clip.frames = seq;
    }
    if clip.frames.len() < 2 {
        return Err(AnimError::Data(format!(
            "{origin}: action {action}: clip has fewer than 2 frames"
        )));
    }
    Ok(())
}

/// Heights a character may stand in its clips, metres: a child on all fours to a tall adult.
/// Outside it, a clip's length unit is almost surely wrong (a centimetre take read as metres
/// stands a hundred times too tall, and the animation slows to keep its root at a person's
/// speed).
pub const PERSON_HEIGHT_M: (f32, f32) = (0.3, 3.0);

/// One warning per loaded clip (every variant) whose character stands outside
/// [`PERSON_HEIGHT_M`]: the most its joints span vertically in any frame, after the library's
/// `scale`.
pub fn size_warnings(clips: &BTreeMap<String, ActionClip>) -> Vec<String> {
    let mut out = Vec::new();
    for (action, ac) in clips {
        for v in ac.variants() {
            let tallest = (0..v.clip.len())
                .map(|f| {
                    let ys = v.clip.joint_positions(f).into_iter().map(|p| p.y);
                    let (lo, hi) = ys.fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), y| {
                        (lo.min(y), hi.max(y))
                    });
                    hi - lo
                })
                .fold(0.0, f32::max);
            let (least, most) = PERSON_HEIGHT_M;
            if !(least..=most).contains(&tallest) {
                out.push(format!(
                    "action {action}, clip {} ({}): the character stands {tallest:.2} m tall, \
                     not {least}–{most} m; is the library's \"scale\" (metres per unit of the \
                     file: 0.01 for centimetres, the default for BVH) right for it?",
                    v.variant,
                    v.file.display()
                ));
            }
        }
    }
    out
}

/// Sets every variant's [`ActionClip::effort`] from its own LMA measurements, standardised over
/// all the variants' windows ([`variant_efforts`]).
pub(crate) fn sign_variants(variants: &mut [ActionClip]) -> Result<(), GraphError> {
    let clips: Vec<Clip> = variants
        .iter()
        .map(|v| {
            let mut c = v.clip.clone();
            c.name = format!("{} variant {}", v.action, v.variant);
            c
        })
        .collect();
    for (v, e) in variants.iter_mut().zip(variant_efforts(&clips)?) {
        v.effort = e;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_library_maps_the_default_actions() {
        let lib = ClipLibrary::default_library().unwrap();
        let defaults = [
            "walk", "run", "jump", "punch", "throw", "kick", "turn", "sidestep", "crouch", "bow",
            "wave", "spin",
        ];
        lib.check_actions(defaults).unwrap();
        let err = lib
            .check_actions(["walk", "moonwalk", "fly", "fly"])
            .unwrap_err()
            .to_string();
        assert!(
            err.starts_with("no clip for action(s) fly, moonwalk in"),
            "{err}"
        );
    }

    #[test]
    fn malformed_library_names_file_and_line() {
        let text = "{\n\"version\": 1,\n\"actions\": {\n\"walk\": {\"file\": 3}\n}\n}";
        let err = ClipLibrary::parse(text, Path::new("lib.json"), None)
            .unwrap_err()
            .to_string();
        assert!(err.starts_with("lib.json:4:"), "{err}");
    }

    /// A person 1.6 m tall in centimetres, as BVH files usually are: hips 90 cm up, a head end
    /// 70 cm above them, a foot on the floor; 4 frames at 30 Hz, stepping forward.
    const STAND_BVH: &str = "HIERARCHY\nROOT Hips\n{\n  OFFSET 0 90 0\n  CHANNELS 6 Xposition \
        Yposition Zposition Zrotation Xrotation Yrotation\n  JOINT Head\n  {\n    OFFSET 0 60 0\n    \
        CHANNELS 3 Zrotation Xrotation Yrotation\n    End Site\n    {\n      OFFSET 0 10 0\n    }\n  \
        }\n  JOINT Leg\n  {\n    OFFSET 0 -45 0\n    CHANNELS 3 Zrotation Xrotation Yrotation\n    \
        End Site\n    {\n      OFFSET 0 -45 0\n    }\n  }\n}\nMOTION\nFrames: 4\nFrame Time: \
        0.0333333\n0 90 0 0 0 0 0 0 0 0 0 0\n0 90 5 0 0 0 0 0 0 0 0 0\n0 90 10 0 0 0 0 0 0 0 0 0\n\
        0 90 15 0 0 0 0 0 0 0 0 0\n";

    /// Loads `action` from a library of that one action, `{"file": "stand.bvh", …}` plus
    /// `fields`, next to [`STAND_BVH`] in a folder of its own (`tag`).
    fn load_stand(
        tag: &str,
        action: &str,
        fields: &str,
    ) -> Result<BTreeMap<String, ActionClip>, AnimError> {
        let dir = std::env::temp_dir().join(format!("figurine-{tag}-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("stand.bvh"), STAND_BVH).unwrap();
        let text = format!(
            r#"{{ "version": 1, "actions": {{ "{action}": {{ "file": "stand.bvh" {fields} }} }} }}"#
        );
        let lib = ClipLibrary::parse(&text, Path::new("stand.json"), Some(dir.clone())).unwrap();
        let loaded = lib.load([action]);
        std::fs::remove_dir_all(&dir).ok();
        loaded
    }

    #[test]
    fn a_frame_range_must_run_forward_inside_its_clip() {
        let load = |frames: &str| {
            let fields = format!(r#", "moving": true, "cyclic": false, "frames": {frames}"#);
            load_stand("clip-range", "jump", &fields).map(|c| c["jump"].clip.len())
        };
        assert_eq!(load("[1, 3]").unwrap(), 3);
        // One frame is no motion; a range past the end or backwards is a typo.
        for bad in ["[2, 2]", "[1, 4]", "[3, 1]"] {
            let err = load(bad).unwrap_err().to_string();
            assert!(
                err.contains("a first and a later last frame of the clip's 4 (numbered from 0)"),
                "{bad}: {err}"
            );
        }
    }

    #[test]
    fn a_clip_read_at_the_wrong_scale_is_named() {
        let warnings = |scale: &str| {
            let fields = format!(r#", "moving": true, "cyclic": true {scale}"#);
            size_warnings(&load_stand("clip-size", "walk", &fields).unwrap())
        };
        assert!(warnings("").is_empty(), "centimetres by default");
        let metres = warnings(r#", "scale": 1"#);
        assert_eq!(metres.len(), 1, "{metres:?}");
        assert!(metres[0].contains("stands 160.00 m tall"), "{}", metres[0]);
        assert!(warnings(r#", "scale": 0.0001"#)[0].contains("stands 0.02 m tall"));
    }

    #[test]
    fn default_kick_variants_follow_the_effort() {
        if crate::data::data_file("deepmimic", "humanoid.urdf").is_none() {
            eprintln!("skipping: deepmimic data missing — run `cargo xtask setup`");
            return;
        }
        let lib = ClipLibrary::default_library().unwrap();
        let clips = lib.load(["kick", "punch"]).unwrap();
        let kick = &clips["kick"];
        let names: Vec<&str> = kick.variants().map(|v| v.variant.as_str()).collect();
        assert_eq!(names, ["kick", "spinkick"]);
        assert!(!kick.alternatives[0].looping, "spinkick has loop: false");
        assert!(clips["punch"].alternatives.is_empty() && clips["punch"].effort.is_none());
        let e = |t: f32, w: f32| crate::graph::effort::Effort { time: t, weight: w };
        let pick = |t, w| {
            super::super::variants::choose_variant(kick, e(t, w), None)
                .0
                .variant
                .clone()
        };
        assert_eq!(pick(0.8, 0.8), "spinkick");
        assert_eq!(pick(-0.8, -0.8), "kick");
        // Stable: a second load decides the same.
        let again = lib.load(["kick"]).unwrap();
        let (v, c) = super::super::variants::choose_variant(&again["kick"], e(0.8, 0.8), None);
        assert_eq!(v.variant, "spinkick");
        assert_eq!(
            c.unwrap().variant_effort,
            kick.alternatives[0].effort.unwrap()
        );
    }

    #[test]
    fn default_clips_load_with_one_skeleton() {
        if crate::data::data_file("deepmimic", "humanoid.urdf").is_none() {
            eprintln!("skipping: deepmimic data missing — run `cargo xtask setup`");
            return;
        }
        let lib = ClipLibrary::default_library().unwrap();
        let names: Vec<String> = lib.actions.keys().cloned().collect();
        let clips = lib.load(names.iter().map(String::as_str)).unwrap();
        assert_eq!(clips.len(), 12);
        assert_eq!(size_warnings(&clips), Vec::<String>::new());
        let crouch = &clips["crouch"].clip;
        // Ping-pong: starts and ends on the same (standing) pose.
        let (a, b) = (&crouch.frames[0], &crouch.frames[crouch.len() - 1]);
        assert_eq!(a, b);
    }
}
