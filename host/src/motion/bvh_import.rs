//! BVH (Biovision Hierarchy) import for any rig.
//!
//! Accepts what real files contain: per-joint rotation orders (mixed within one file),
//! position channels on any joint (they replace the joint's offset, as Blender reads them),
//! several roots, CRLF / CR / LF line ends, tabs, names with spaces or colons, and a `Frames:`
//! count that disagrees with the data (the data wins; the disagreement is reported in
//! [`BvhImport::notes`]). Frames must be one per line. Anything else that is malformed is an
//! error naming the file and the 1-based line.

use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};

use glam::{Quat, Vec3};

use super::clip::{Clip, Pose};
use super::skeleton::{Axis, Channel, Joint, RotationOrder, Skeleton};
use super::MotionError;

/// Deepest joint nesting accepted (real rigs have < 20 levels; the parser recurses per level).
pub const MAX_DEPTH: usize = 256;

/// Most joints (end sites included) a hierarchy may declare. Real rigs have 20–300 (with
/// fingers and face); the bound keeps a malformed file from multiplying into huge poses.
pub const MAX_JOINTS: usize = 1024;

/// Most joint poses (frames × joints) a file may hold: 2²⁴ ≈ 16.8 M (≈ 470 MB of poses), e.g.
/// an hour of 120 fps capture on a 38-joint rig. A file with more is refused, naming the first
/// frame line beyond the bound, before any frame is built.
pub const MAX_FRAME_JOINTS: usize = 1 << 24;

/// The result of importing a BVH file.
#[derive(Debug, Clone)]
pub struct BvhImport {
    /// The imported clip (lengths in the file's unit, rotations as quaternions).
    pub clip: Clip,
    /// The frame count the `Frames:` line declared.
    pub declared_frames: usize,
    /// Recoverable oddities found while reading (e.g. a frame count mismatch).
    pub notes: Vec<String>,
}

/// Reads a BVH file from disk.
pub fn read_bvh_path(path: &Path) -> Result<BvhImport, MotionError> {
    let bytes = std::fs::read(path).map_err(|source| MotionError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let text = String::from_utf8_lossy(&bytes);
    let name = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "clip".into());
    let mut imp = read_bvh(&text, path)?;
    imp.clip.name = name;
    Ok(imp)
}

/// Parses BVH text; `path` names the source in error messages.
pub fn read_bvh(text: &str, path: &Path) -> Result<BvhImport, MotionError> {
    let lines = split_lines(text);
    let mut p = Parser {
        path: path.to_path_buf(),
        lines: &lines,
        line: 0,
        tokens: Vec::new(),
        tok: 0,
        joints: Vec::new(),
        names: HashSet::new(),
        next_suffix: HashMap::new(),
    };
    p.parse_hierarchy()?;
    let skeleton = Skeleton {
        joints: p.joints.iter().map(|j| j.joint.clone()).collect(),
    };
    skeleton
        .validate()
        .map_err(|reason| p.err_at(p.line.max(1), reason))?;
    let (declared, frame_time, first_data) = p.parse_motion_header()?;
    let n_channels: usize = p.joints.iter().map(|j| j.joint.channels.len()).sum();
    // Counted before any frame is built, so an oversized file fails without allocating.
    let max_frames = MAX_FRAME_JOINTS / p.joints.len().max(1);
    let beyond = lines
        .iter()
        .enumerate()
        .skip(first_data)
        .filter(|(_, l)| !l.trim().is_empty())
        .nth(max_frames);
    if let Some((idx, _)) = beyond {
        return Err(MotionError::parse(
            path,
            idx + 1,
            format!(
                "more than {max_frames} frames of {} joints (at most {MAX_FRAME_JOINTS} joint \
                 poses per file)",
                p.joints.len()
            ),
        ));
    }
    let mut frames = Vec::new();
    let mut values: Vec<f32> = Vec::with_capacity(n_channels);
    for (idx, raw) in lines.iter().enumerate().skip(first_data) {
        let line_no = idx + 1;
        if raw.trim().is_empty() {
            continue;
        }
        values.clear();
        for tok in raw.split_whitespace() {
            let v: f32 = tok
                .parse()
                .map_err(|_| MotionError::parse(path, line_no, format!("not a number: {tok:?}")))?;
            if !v.is_finite() {
                return Err(MotionError::parse(
                    path,
                    line_no,
                    format!("non-finite value {tok:?}"),
                ));
            }
            values.push(v);
        }
        if values.len() != n_channels {
            return Err(MotionError::parse(
                path,
                line_no,
                format!(
                    "frame has {} values, the hierarchy declares {} channels",
                    values.len(),
                    n_channels
                ),
            ));
        }
        frames.push(pose_from_values(&p.joints, &values));
    }
    if frames.is_empty() {
        return Err(MotionError::parse(
            path,
            lines.len().max(1),
            "no motion frames after `Frame Time:`",
        ));
    }
    let mut notes = Vec::new();
    if frames.len() != declared {
        notes.push(format!(
            "{}: `Frames:` declares {declared} frames but the data holds {}; using the data",
            path.display(),
            frames.len()
        ));
    }
    Ok(BvhImport {
        clip: Clip {
            name: "clip".into(),
            skeleton,
            frame_time,
            frames,
        },
        declared_frames: declared,
        notes,
    })
}

fn split_lines(text: &str) -> Vec<&str> {
    if text.contains('\n') {
        text.split('\n')
            .map(|l| l.strip_suffix('\r').unwrap_or(l))
            .collect()
    } else {
        text.split('\r').collect()
    }
}

struct ParsedJoint {
    joint: Joint,
}

fn pose_from_values(joints: &[ParsedJoint], values: &[f32]) -> Pose {
    let mut rotations = Vec::with_capacity(joints.len());
    let mut translations = Vec::with_capacity(joints.len());
    let mut k = 0;
    for pj in joints {
        let j = &pj.joint;
        let mut t = j.offset;
        let mut q = Quat::IDENTITY;
        for ch in &j.channels {
            let v = values.get(k).copied().unwrap_or(0.0);
            k += 1;
            match ch {
                Channel::Position(Axis::X) => t.x = v,
                Channel::Position(Axis::Y) => t.y = v,
                Channel::Position(Axis::Z) => t.z = v,
                // Channel order is the composition order: Rfirst · Rsecond · Rthird.
                Channel::Rotation(a) => q *= Quat::from_axis_angle(a.unit(), v.to_radians()),
            }
        }
        rotations.push(q.normalize());
        translations.push(t);
    }
    Pose {
        rotations,
        translations,
    }
}

struct Parser<'a> {
    path: PathBuf,
    lines: &'a [&'a str],
    /// Index of the next line to tokenize.
    line: usize,
    /// Tokens of the current line, and the index of the next one.
    tokens: Vec<String>,
    tok: usize,
    joints: Vec<ParsedJoint>,
    /// Every joint name given so far, for constant-time uniqueness checks.
    names: HashSet<String>,
    /// Per duplicated base name, the next `#N` suffix to try.
    next_suffix: HashMap<String, usize>,
}

impl Parser<'_> {
    fn err_at(&self, line: usize, reason: impl Into<String>) -> MotionError {
        MotionError::parse(&self.path, line, reason)
    }

    /// 1-based number of the line the current token came from.
    fn cur_line(&self) -> usize {
        self.line.max(1)
    }

    fn err(&self, reason: impl Into<String>) -> MotionError {
        self.err_at(self.cur_line(), reason)
    }

    /// Next token, moving across lines; braces are always their own tokens.
    fn next(&mut self) -> Option<String> {
        loop {
            if let Some(t) = self.tokens.get(self.tok) {
                self.tok += 1;
                return Some(t.clone());
            }
            let raw = self.lines.get(self.line)?;
            self.line += 1;
            self.tokens = raw
                .replace('{', " { ")
                .replace('}', " } ")
                .split_whitespace()
                .map(str::to_string)
                .collect();
            self.tok = 0;
        }
    }

    /// The rest of the current line's tokens (used for joint names with spaces).
    fn rest_of_line(&mut self) -> Vec<String> {
        let rest = self.tokens.get(self.tok..).unwrap_or(&[]).to_vec();
        self.tok = self.tokens.len();
        rest
    }

    fn expect(&mut self, what: &str) -> Result<(), MotionError> {
        match self.next() {
            Some(t) if t.eq_ignore_ascii_case(what) => Ok(()),
            Some(t) => Err(self.err(format!("expected `{what}`, found `{t}`"))),
            None => Err(self.err(format!("unexpected end of file, expected `{what}`"))),
        }
    }

    fn number(&mut self, what: &str) -> Result<f32, MotionError> {
        let t = self
            .next()
            .ok_or_else(|| self.err(format!("unexpected end of file in {what}")))?;
        let v: f32 = t
            .parse()
            .map_err(|_| self.err(format!("{what}: not a number: {t:?}")))?;
        if !v.is_finite() {
            return Err(self.err(format!("{what}: non-finite value {t:?}")));
        }
        Ok(v)
    }

    fn parse_hierarchy(&mut self) -> Result<(), MotionError> {
        self.expect("HIERARCHY")?;
        loop {
            match self.next() {
                Some(t) if t.eq_ignore_ascii_case("ROOT") => self.parse_joint(None)?,
                Some(t) if t.eq_ignore_ascii_case("MOTION") => {
                    // The motion header parser starts on the line after MOTION.
                    if self.joints.is_empty() {
                        return Err(self.err("MOTION before any ROOT joint"));
                    }
                    return Ok(());
                }
                Some(t) => {
                    return Err(self.err(format!("expected `ROOT` or `MOTION`, found `{t}`")))
                }
                None => return Err(self.err("unexpected end of file: no MOTION section")),
            }
        }
    }

    fn depth_of(&self, j: usize) -> usize {
        let mut d = 0;
        let mut cur = self.joints.get(j).and_then(|x| x.joint.parent);
        while let Some(p) = cur {
            d += 1;
            cur = self.joints.get(p).and_then(|x| x.joint.parent);
        }
        d
    }

    /// `base`, or `base#N` with the smallest free N ≥ 2 when `base` is taken; the name is
    /// reserved. Amortised constant time per joint, so many same-named joints stay linear.
    fn unique_name(&mut self, base: &str) -> String {
        let name = if self.names.contains(base) {
            let next = self.next_suffix.entry(base.to_string()).or_insert(2);
            loop {
                let candidate = format!("{base}#{next}");
                *next += 1;
                if !self.names.contains(&candidate) {
                    break candidate;
                }
            }
        } else {
            base.to_string()
        };
        self.names.insert(name.clone());
        name
    }

    /// Refuses a joint beyond [`MAX_JOINTS`].
    fn check_joint_count(&self) -> Result<(), MotionError> {
        if self.joints.len() >= MAX_JOINTS {
            return Err(self.err(format!("more than {MAX_JOINTS} joints")));
        }
        Ok(())
    }

    /// Reads a joint and everything nested in it, up to its closing brace. The open joints are
    /// kept on a list rather than the call stack, so a file nested as deep as [`MAX_DEPTH`]
    /// needs no more stack than a flat one (recursing, a debug build used over 1 MiB there:
    /// half a test thread's stack).
    fn parse_joint(&mut self, parent: Option<usize>) -> Result<(), MotionError> {
        let mut open = vec![self.parse_joint_header(parent)?];
        while let Some(&index) = open.last() {
            let t = self
                .next()
                .ok_or_else(|| self.err("unexpected end of file inside a joint"))?;
            if t == "}" {
                open.pop();
            } else if t.eq_ignore_ascii_case("JOINT") {
                open.push(self.parse_joint_header(Some(index))?);
            } else if t.eq_ignore_ascii_case("End") {
                self.expect("Site")?;
                self.parse_end_site(index)?;
            } else {
                return Err(self.err(format!("expected `JOINT`, `End Site` or `}}`, found `{t}`")));
            }
        }
        Ok(())
    }

    /// Reads a joint's name, `{`, OFFSET and CHANNELS, and adds it; returns its index.
    fn parse_joint_header(&mut self, parent: Option<usize>) -> Result<usize, MotionError> {
        let depth = parent.map_or(0, |p| self.depth_of(p) + 1);
        if depth > MAX_DEPTH {
            return Err(self.err(format!("joints nested deeper than {MAX_DEPTH}")));
        }
        self.check_joint_count()?;
        let mut name_toks = self.rest_of_line();
        let brace_on_line = name_toks.last().map(|t| t == "{").unwrap_or(false);
        if brace_on_line {
            name_toks.pop();
        }
        if name_toks.is_empty() {
            return Err(self.err("joint without a name"));
        }
        let name = self.unique_name(&name_toks.join(" "));
        if !brace_on_line {
            self.expect("{")?;
        }
        self.expect("OFFSET")?;
        let offset = Vec3::new(
            self.number("OFFSET")?,
            self.number("OFFSET")?,
            self.number("OFFSET")?,
        );
        let index = self.joints.len();
        let mut joint = Joint {
            name,
            parent,
            offset,
            channels: Vec::new(),
            rotation_order: RotationOrder::ZYX,
            end_site: false,
        };
        self.expect("CHANNELS")?;
        let n = self.number("CHANNELS count")?;
        if !(0.0..=6.0).contains(&n) || n.fract() != 0.0 {
            return Err(self.err(format!("CHANNELS count {n} is not 0..=6")));
        }
        for _ in 0..n as usize {
            let t = self
                .next()
                .ok_or_else(|| self.err("unexpected end of file in CHANNELS"))?;
            let ch =
                Channel::parse(&t).ok_or_else(|| self.err(format!("unknown channel {t:?}")))?;
            if joint.channels.contains(&ch) {
                return Err(self.err(format!("channel {t} repeated")));
            }
            joint.channels.push(ch);
        }
        joint.rotation_order = order_from_channels(&joint.channels);
        self.joints.push(ParsedJoint { joint });
        Ok(index)
    }

    fn parse_end_site(&mut self, parent: usize) -> Result<(), MotionError> {
        self.expect("{")?;
        self.expect("OFFSET")?;
        let offset = Vec3::new(
            self.number("OFFSET")?,
            self.number("OFFSET")?,
            self.number("OFFSET")?,
        );
        self.expect("}")?;
        self.check_joint_count()?;
        let base = self
            .joints
            .get(parent)
            .map(|p| format!("{}_end", p.joint.name))
            .unwrap_or_else(|| "end".into());
        let name = self.unique_name(&base);
        self.joints.push(ParsedJoint {
            joint: Joint {
                name,
                parent: Some(parent),
                offset,
                channels: Vec::new(),
                rotation_order: RotationOrder::ZYX,
                end_site: true,
            },
        });
        Ok(())
    }

    /// Parses `Frames:` and `Frame Time:`; returns (declared frames, frame time, first data
    /// line index).
    fn parse_motion_header(&mut self) -> Result<(usize, f32, usize), MotionError> {
        // The MOTION token was the last one read; header lines follow it.
        let mut idx = self.line;
        let next_nonblank = |idx: &mut usize| -> Option<(usize, &str)> {
            while let Some(l) = self.lines.get(*idx) {
                *idx += 1;
                if !l.trim().is_empty() {
                    return Some((*idx, l));
                }
            }
            None
        };
        let (ln, frames_line) = next_nonblank(&mut idx)
            .ok_or_else(|| MotionError::parse(&self.path, idx.max(1), "missing `Frames:` line"))?;
        let flat = frames_line.replace(':', " ");
        let toks: Vec<&str> = flat.split_whitespace().collect();
        let declared = match toks.as_slice() {
            [k, v] if k.eq_ignore_ascii_case("Frames") => v.parse::<usize>().map_err(|_| {
                MotionError::parse(&self.path, ln, format!("bad frame count {v:?}"))
            })?,
            _ => {
                return Err(MotionError::parse(
                    &self.path,
                    ln,
                    format!("expected `Frames: N`, found {:?}", frames_line.trim()),
                ))
            }
        };
        let (ln, ft_line) = next_nonblank(&mut idx).ok_or_else(|| {
            MotionError::parse(&self.path, idx.max(1), "missing `Frame Time:` line")
        })?;
        let flat = ft_line.replace(':', " ");
        let toks: Vec<&str> = flat.split_whitespace().collect();
        let frame_time = match toks.as_slice() {
            [a, b, v] if a.eq_ignore_ascii_case("Frame") && b.eq_ignore_ascii_case("Time") => v
                .parse::<f32>()
                .map_err(|_| MotionError::parse(&self.path, ln, format!("bad frame time {v:?}")))?,
            _ => {
                return Err(MotionError::parse(
                    &self.path,
                    ln,
                    format!("expected `Frame Time: T`, found {:?}", ft_line.trim()),
                ))
            }
        };
        if !(frame_time.is_finite() && frame_time > 0.0 && frame_time <= 10.0) {
            return Err(MotionError::parse(
                &self.path,
                ln,
                format!("frame time {frame_time} s is not a positive duration"),
            ));
        }
        Ok((declared, frame_time, idx))
    }
}

/// Rotation order from a channel list: the rotation axes in file order, with any axes the file
/// omits appended (their angle is always zero, so where they go does not matter).
fn order_from_channels(channels: &[Channel]) -> RotationOrder {
    let mut axes: Vec<Axis> = channels
        .iter()
        .filter_map(|c| match c {
            Channel::Rotation(a) => Some(*a),
            Channel::Position(_) => None,
        })
        .collect();
    for a in [Axis::Z, Axis::Y, Axis::X] {
        if !axes.contains(&a) {
            axes.push(a);
        }
    }
    match axes.as_slice() {
        [a, b, c] => RotationOrder([*a, *b, *c]),
        _ => RotationOrder::ZYX,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const SMALL: &str = "HIERARCHY\r\nROOT Hips\r\n{\r\n\tOFFSET 0 0 0\r\n\tCHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation\r\n\tJOINT Left Leg\r\n\t{\r\n\t\tOFFSET 1 -2 0\r\n\t\tCHANNELS 6 Xposition Yposition Zposition Yrotation Xrotation Zrotation\r\n\t\tEnd Site\r\n\t\t{\r\n\t\t\tOFFSET 0 -3 0\r\n\t\t}\r\n\t}\r\n}\r\nMOTION\r\nFrames: 5\r\nFrame Time: 0.008333\r\n0 10 0 90 0 0 1 -2 0 0 0 0\r\n1 10 0 0 0 0 1 -2 0 0 90 0\r\n";

    #[test]
    fn reads_crlf_spaces_in_names_mixed_orders_and_frame_mismatch() {
        let imp = read_bvh(SMALL, Path::new("small.bvh")).unwrap();
        let c = &imp.clip;
        assert_eq!(c.skeleton.len(), 3);
        assert_eq!(c.skeleton.joints[1].name, "Left Leg");
        assert_eq!(c.skeleton.joints[2].name, "Left Leg_end");
        assert!(c.skeleton.joints[2].end_site);
        assert_eq!(
            c.skeleton.joints[1].rotation_order,
            RotationOrder([Axis::Y, Axis::X, Axis::Z])
        );
        assert_eq!(c.len(), 2);
        assert_eq!(imp.declared_frames, 5);
        assert_eq!(imp.notes.len(), 1);
        assert!((c.fps() - 120.0).abs() < 0.1);
        // Frame 0: root rotated 90° about Z: the leg offset (1,-2,0) maps to (2,1,0).
        let p = c.joint_positions(0);
        assert!(
            (p[1] - Vec3::new(2.0, 11.0, 0.0)).length() < 1e-4,
            "{}",
            p[1]
        );
        // Frame 1: leg rotated 90° about X: the end site (0,-3,0) maps to (0,0,-3).
        let p = c.joint_positions(1);
        assert!(
            (p[2] - Vec3::new(2.0, 8.0, -3.0)).length() < 1e-4,
            "{}",
            p[2]
        );
    }

    #[test]
    fn malformed_input_names_file_and_line() {
        let cases: [(&str, usize); 5] = [
            (
                &SMALL.replace("1 10 0 0 0 0 1 -2 0 0 90 0", "1 10 0 0 0 0 1 -2 0 0 90"),
                20,
            ),
            (&SMALL.replace("1 10 0 0", "1 10 x 0"), 20),
            (&SMALL.replace("OFFSET 1 -2 0", "OFFSET 1 -2"), 9),
            (&SMALL.replace("Frame Time: 0.008333", "Frame Time: -1"), 18),
            (
                &SMALL.replace(
                    "Yrotation Xrotation Zrotation",
                    "Yrotation Xrotation Yrotation",
                ),
                9,
            ),
        ];
        for (text, line) in cases {
            let err = read_bvh(text, Path::new("bad.bvh"))
                .unwrap_err()
                .to_string();
            assert!(err.starts_with(&format!("bad.bvh:{line}:")), "{err}");
        }
        assert!(read_bvh("", Path::new("e.bvh")).is_err());
        let deep = format!(
            "HIERARCHY\nROOT a\n{{\nOFFSET 0 0 0\nCHANNELS 0\n{}",
            "JOINT b\n{\nOFFSET 0 0 0\nCHANNELS 0\n".repeat(100_000)
        );
        let err = read_bvh(&deep, Path::new("deep.bvh"))
            .unwrap_err()
            .to_string();
        assert!(err.contains("nested deeper"), "{err}");
        assert!(read_bvh("HIERARCHY\nMOTION\n", Path::new("e.bvh")).is_err());
        let cut = &SMALL[..SMALL.find("MOTION").unwrap_or(0)];
        assert!(read_bvh(cut, Path::new("e.bvh")).is_err());
    }

    /// A root with `n` children all named `a` (1 channel each), then `frames` frame lines.
    fn many_joints(n: usize, frames: usize) -> String {
        let mut t = String::from("HIERARCHY\nROOT r\n{\nOFFSET 0 0 0\nCHANNELS 1 Xrotation\n");
        t.push_str(&"JOINT a\n{\nOFFSET 0 1 0\nCHANNELS 0\n}\n".repeat(n));
        t.push_str(&format!("}}\nMOTION\nFrames: {frames}\nFrame Time: 0.01\n"));
        t.push_str(&"0\n".repeat(frames));
        t
    }

    #[test]
    fn same_named_joints_get_unique_names() {
        let imp = read_bvh(&many_joints(1000, 2), Path::new("same.bvh")).unwrap();
        let names: Vec<&str> = imp
            .clip
            .skeleton
            .joints
            .iter()
            .map(|j| j.name.as_str())
            .collect();
        assert_eq!(&names[..4], ["r", "a", "a#2", "a#3"]);
        assert_eq!(names[1000], "a#1000");
        // A literal `a#2` already taken: the duplicate gets the next free suffix.
        let text = SMALL.replace("JOINT Left Leg", "JOINT Hips");
        let imp = read_bvh(&text, Path::new("dup.bvh")).unwrap();
        assert_eq!(imp.clip.skeleton.joints[1].name, "Hips#2");
    }

    #[test]
    fn oversized_hierarchies_and_frame_counts_fail_fast() {
        let err = read_bvh(&many_joints(MAX_JOINTS, 1), Path::new("wide.bvh"))
            .unwrap_err()
            .to_string();
        assert!(err.contains("more than 1024 joints"), "{err}");
        // 2 bytes per frame line would otherwise become 1000 joint poses each.
        let frames = MAX_FRAME_JOINTS / 1001 + 1;
        let err = read_bvh(&many_joints(1000, frames), Path::new("long.bvh"))
            .unwrap_err()
            .to_string();
        let first_frame_line = 5 + 5 * 1000 + 5;
        assert!(
            err.starts_with(&format!("long.bvh:{}:", first_frame_line + frames - 1)),
            "{err}"
        );
        assert!(err.contains("joint poses"), "{err}");
    }

    #[test]
    fn every_shared_bvh_file_imports() {
        let dir = crate::data::data_dir().join("bvh");
        let Ok(entries) = std::fs::read_dir(&dir) else {
            eprintln!("skipping: no {} — run `cargo xtask setup`", dir.display());
            return;
        };
        let mut n = 0;
        for e in entries.flatten() {
            let p = e.path();
            if p.extension().and_then(|x| x.to_str()) != Some("bvh") {
                continue;
            }
            let imp = read_bvh_path(&p).unwrap_or_else(|e| panic!("{e}"));
            let c = &imp.clip;
            assert!(c.len() > 10, "{}", p.display());
            assert!(
                (23.9..=121.0).contains(&c.fps()),
                "{} fps {}",
                p.display(),
                c.fps()
            );
            assert_eq!(imp.declared_frames, c.len(), "{}", p.display());
            for f in [0, c.len() / 2, c.len() - 1] {
                assert!(c.joint_positions(f).iter().all(|v| v.is_finite()));
            }
            n += 1;
        }
        if n == 0 {
            eprintln!(
                "skipping: no BVH files in {} — run `cargo xtask setup`",
                dir.display()
            );
        }
    }
}
