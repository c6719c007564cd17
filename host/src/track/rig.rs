//! A rig of tags around the figurine, so that some tag faces the camera at every heading.
//!
//! One tag on the chest cannot be seen through the back half of a turn or a spin (turned more
//! than ~70° from the camera). A rig puts a tag on each side of a box around the figurine —
//! the way ArUco and AprilTag cubes are used — and every tag seen gives the figurine's pose
//! through its face's fixed place on the body.
//!
//! Each face has a frame like the chest tag's figurine frame: +Z its outward normal, +Y the
//! tag's printed top, +X the tag's printed right edge as you look at it. A face's `rotation`
//! takes that frame to the figurine's (+Z front, +Y up, +X left) and its `centre` is the tag's
//! centre in the figurine frame, metres. The single chest tag is the rig of one face with no
//! turn and its centre at the figurine's origin.
//!
//! The default box (`--rig box`) carries four consecutive ids, each tag upright and centred
//! on its face: **first id on the front** (+Z), **+1 on the left** (+X), **+2 on the back**
//! (−Z), **+3 on the right** (−X), in the order a figurine turning to its right shows them
//! to the camera.
//! The figurine's origin is the box's centre. With a top (`--box-top H`, the top's height in
//! metres above the side tags' centres) **+4 lies on the top**, facing up, its printed top
//! toward the figurine's back: a figurine bowing to the camera shows it upright, when every
//! side tag has tilted toward the floor.

use std::path::Path;

use glam::{DMat3, DQuat, DVec3};
use serde::Deserialize;

use super::detect::{tag_pattern, CameraPose, Family};
use super::pnp::object_corners;
use super::pose::FLIP_YZ;
use super::TrackError;

/// Box faces in the order of their ids: name and outward normal (figurine frame).
pub const BOX_FACES: [(&str, DVec3); 4] = [
    ("front", DVec3::Z),
    ("left", DVec3::X),
    ("back", DVec3::NEG_Z),
    ("right", DVec3::NEG_X),
];

/// Default box width (across, figurine X) and depth (front to back, Z), metres: room for a
/// 4 cm tag's printed card (6.5 cm with its margin) on every face.
pub const DEFAULT_BOX_M: f64 = 0.08;

/// A box rig's outer size, metres.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoxSize {
    /// Across, along the figurine's X (the front and back faces' width).
    pub width: f64,
    /// Front to back, along its Z (the left and right faces' width).
    pub depth: f64,
    /// With a tag on its top: the top's height above the side tags' centres (the figurine's
    /// origin), metres; `None`: the sides only.
    pub top: Option<f64>,
}

impl BoxSize {
    /// A box with tags on its four sides only.
    pub fn sides(width: f64, depth: f64) -> Self {
        Self {
            width,
            depth,
            top: None,
        }
    }
}

/// One tag of the rig and where it sits on the figurine.
#[derive(Debug, Clone, PartialEq)]
pub struct Face {
    /// The tag's id.
    pub id: u32,
    /// What to call the face ("front", "left", …).
    pub name: String,
    /// The tag's centre in the figurine frame, metres.
    pub centre: DVec3,
    /// The face's frame (+Z out, +Y the tag's top, +X its printed right) → figurine frame.
    pub rotation: DQuat,
}

impl Face {
    /// The tag's frame (detector convention: x printed right, y printed down, z into the tag)
    /// in the rig's body frame — the frame a chest tag at the figurine's origin would have —
    /// as rotation and translation (metres).
    pub fn tag_in_body(&self) -> (DMat3, DVec3) {
        (
            FLIP_YZ * DMat3::from_quat(self.rotation) * FLIP_YZ,
            FLIP_YZ * self.centre,
        )
    }

    /// The tag's four corners (detector order) in the body frame, for a tag of edge `size`.
    pub fn corners_in_body(&self, size: f64) -> [DVec3; 4] {
        let (r, t) = self.tag_in_body();
        object_corners(size).map(|c| r * c + t)
    }

    /// The body's camera-frame pose from this face's tag's camera-frame pose: the pose a
    /// chest tag at the figurine's origin would have, so [`super::pose::figurine_pose`] turns
    /// it into the figurine's.
    pub fn body_from_tag(&self, tag: &CameraPose) -> CameraPose {
        let (r_bt, t_bt) = self.tag_in_body();
        let r_ct = tag.matrix();
        let r_cb = r_ct * r_bt.transpose();
        let t_cb = DVec3::from_array(tag.translation) - r_cb * t_bt;
        CameraPose::from_parts(r_cb, t_cb, tag.error)
    }

    /// The tag's camera-frame rotation for a body rotation (the inverse of
    /// [`Self::body_from_tag`]'s turn): what this tag would show at the body's last pose.
    pub fn tag_rotation(&self, body: DQuat) -> DQuat {
        let (r_bt, _) = self.tag_in_body();
        (body * DQuat::from_mat3(&r_bt)).normalize()
    }
}

/// The tags on a figurine: one on the chest, or one per face of a box.
#[derive(Debug, Clone, PartialEq)]
pub struct Rig {
    /// Edge of every tag's black square, metres.
    pub tag_size: f64,
    /// The faces; ids are distinct.
    pub faces: Vec<Face>,
}

/// A rig file: `{"tag_size": 0.04, "faces": [{"id": 0, "name": "front", "centre": [0, 0,
/// 0.04], "normal": [0, 0, 1], "up": [0, 1, 0]}, …]}` — centres in metres, normal and up in
/// the figurine frame (+Z front, +Y up, +X left); `tag_size` defaults to `--tag-size`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RigFile {
    tag_size: Option<f64>,
    faces: Vec<FaceFile>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct FaceFile {
    id: u32,
    #[serde(default)]
    name: Option<String>,
    centre: [f64; 3],
    normal: [f64; 3],
    up: [f64; 3],
}

impl Rig {
    /// One tag `id` on the chest, its centre the figurine's origin (`figurine track`'s
    /// default).
    pub fn single(id: u32, tag_size: f64) -> Self {
        Self {
            tag_size,
            faces: vec![Face {
                id,
                name: "front".into(),
                centre: DVec3::ZERO,
                rotation: DQuat::IDENTITY,
            }],
        }
    }

    /// A box `width` (figurine X) × `depth` (Z) metres with tags `first_id` … `first_id + 3`
    /// on its front, left, back and right faces, upright and centred; the figurine's origin
    /// at the box's centre.
    pub fn boxed(first_id: u32, tag_size: f64, width: f64, depth: f64) -> Self {
        let faces = BOX_FACES
            .iter()
            .enumerate()
            .map(|(i, &(name, normal))| {
                let half = if normal.z != 0.0 { depth } else { width } / 2.0;
                Face {
                    id: first_id + i as u32,
                    name: name.into(),
                    centre: normal * half,
                    // A turn about the vertical keeps every tag upright.
                    rotation: DQuat::from_rotation_y(normal.x.atan2(normal.z)),
                }
            })
            .collect();
        Self { tag_size, faces }
    }

    /// The box's top face: tag `id` centred on it `height` metres above the figurine's
    /// origin, facing up, its printed top toward the figurine's back (−Z) so that it reads
    /// upright to a camera the figurine bows to.
    pub fn top_face(id: u32, height: f64) -> Face {
        let (normal, up) = (DVec3::Y, DVec3::NEG_Z);
        Face {
            id,
            name: "top".into(),
            centre: normal * height,
            rotation: DQuat::from_mat3(&DMat3::from_cols(up.cross(normal), up, normal)).normalize(),
        }
    }

    /// A box checked against the tags it carries: every id in `family`, the tag's card
    /// (the black square and a white margin) narrower than the face; with a top, its tag
    /// (id `first_id` + 4) above the side tags' cards.
    pub fn checked_box(
        family: Family,
        first_id: u32,
        tag_size: f64,
        size: BoxSize,
    ) -> Result<Self, TrackError> {
        let BoxSize { width, depth, top } = size;
        let card = tag_size * 1.25;
        if let Some(h) = top {
            if !(h.is_finite() && h >= card / 2.0 && h < 1.0) {
                return Err(TrackError::BadRig(format!(
                    "box top {h} m: the top must be above the side tags' cards ({:.0} mm or \
                     more above their centres, metres under 1)",
                    card / 2.0 * 1000.0
                )));
            }
        }
        for (what, v) in [("width", width), ("depth", depth)] {
            if !(v.is_finite() && v >= card && v < 2.0) {
                return Err(TrackError::BadRig(format!(
                    "box {what} {v} m: the faces must hold a {:.0} mm tag with its white \
                     margin ({:.0} mm or more, metres under 2)",
                    tag_size * 1000.0,
                    card * 1000.0
                )));
            }
        }
        let mut rig = Self::boxed(first_id, tag_size, width, depth);
        if let Some(h) = top {
            rig.faces
                .push(Self::top_face(first_id + BOX_FACES.len() as u32, h));
        }
        rig.check(family)?;
        Ok(rig)
    }

    /// Reads a rig file (see [`Rig`]'s file format above); `tag_size` unless it says one.
    pub fn read(path: &Path, family: Family, tag_size: f64) -> Result<Self, TrackError> {
        let bad = |reason: String| TrackError::BadRig(format!("{}: {reason}", path.display()));
        let text = std::fs::read_to_string(path).map_err(|e| bad(e.to_string()))?;
        Self::from_json(&text, path, family, tag_size)
    }

    /// Parses and checks the text of rig file `path` (named in errors); as [`Rig::read`].
    pub fn from_json(
        text: &str,
        path: &Path,
        family: Family,
        tag_size: f64,
    ) -> Result<Self, TrackError> {
        let bad = |reason: String| TrackError::BadRig(format!("{}: {reason}", path.display()));
        let file: RigFile = serde_json::from_str(text).map_err(|e| bad(e.to_string()))?;
        let mut faces = Vec::with_capacity(file.faces.len());
        for (i, f) in file.faces.iter().enumerate() {
            let face = face_from(f).map_err(|e| bad(format!("face {}: {e}", i + 1)))?;
            faces.push(face);
        }
        let rig = Self {
            tag_size: file.tag_size.unwrap_or(tag_size),
            faces,
        };
        rig.check(family).map_err(|e| match e {
            TrackError::BadRig(why) => bad(why),
            other => other,
        })?;
        Ok(rig)
    }

    /// Why the rig cannot be tracked, if it cannot: no face, a repeated id, an id the family
    /// lacks, a tag size that is not a few centimetres, a face far from the figurine.
    pub fn check(&self, family: Family) -> Result<(), TrackError> {
        if !(self.tag_size.is_finite() && self.tag_size > 0.0 && self.tag_size < 1.0) {
            return Err(TrackError::BadRig(format!(
                "tag size {}: the black square's edge in metres, e.g. 0.04",
                self.tag_size
            )));
        }
        if self.faces.is_empty() {
            return Err(TrackError::BadRig("the rig has no faces".into()));
        }
        for (i, f) in self.faces.iter().enumerate() {
            if self.faces[..i].iter().any(|g| g.id == f.id) {
                return Err(TrackError::BadRig(format!(
                    "id {} is on two faces: each face needs its own id",
                    f.id
                )));
            }
            if !(f.centre.is_finite() && f.centre.length() < 2.0) {
                return Err(TrackError::BadRig(format!(
                    "face {} ({}) is centred {} m from the figurine's origin",
                    f.id,
                    f.name,
                    f.centre.length()
                )));
            }
            tag_pattern(family, f.id)?;
        }
        Ok(())
    }

    /// The face carrying tag `id`.
    pub fn face(&self, id: u32) -> Option<&Face> {
        self.faces.iter().find(|f| f.id == id)
    }

    /// One line per face: which id goes where.
    pub fn describe(&self) -> Vec<String> {
        self.faces
            .iter()
            .map(|f| {
                let n = f.rotation * DVec3::Z;
                format!(
                    "id {} on the {}: centre ({:.0}, {:.0}, {:.0}) mm, facing ({:.2}, {:.2}, {:.2})",
                    f.id,
                    f.name,
                    f.centre.x * 1000.0,
                    f.centre.y * 1000.0,
                    f.centre.z * 1000.0,
                    n.x,
                    n.y,
                    n.z
                )
            })
            .collect()
    }
}

/// A face from the file's normal and up vectors.
fn face_from(f: &FaceFile) -> Result<Face, String> {
    let (c, n, u) = (
        DVec3::from_array(f.centre),
        DVec3::from_array(f.normal),
        DVec3::from_array(f.up),
    );
    if !(c.is_finite() && n.is_finite() && u.is_finite()) {
        return Err("centre, normal and up must be numbers".into());
    }
    let n = n
        .try_normalize()
        .ok_or("the normal must not be zero".to_string())?;
    let u = u.try_normalize().ok_or("up must not be zero".to_string())?;
    if n.dot(u).abs() > 0.1 {
        return Err("up must be square to the normal (along the tag's face)".into());
    }
    // Up made exactly square to the normal; x completes a right-handed frame.
    let y = (u - n * n.dot(u)).normalize();
    let x = y.cross(n);
    Ok(Face {
        id: f.id,
        name: f.name.clone().unwrap_or_else(|| format!("tag {}", f.id)),
        centre: c,
        rotation: DQuat::from_mat3(&DMat3::from_cols(x, y, n)).normalize(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::track::pose::{angle_between_deg, camera_pose, figurine_pose};

    /// The camera-frame pose of face `f`'s tag when the figurine is at (p, q).
    fn tag_seen(f: &Face, p: DVec3, q: DQuat) -> CameraPose {
        let (r, t) = camera_pose(p + q * f.centre, q * f.rotation);
        CameraPose::from_parts(r, t, 0.0)
    }

    #[test]
    fn every_face_gives_the_same_figurine_pose() {
        let mut rig = Rig::boxed(4, 0.04, 0.08, 0.06);
        rig.faces.push(Rig::top_face(8, 0.09));
        let p = DVec3::new(0.05, -0.02, -0.7);
        for yaw in [0.0, 0.8, 2.0, -2.5] {
            let q = DQuat::from_euler(glam::EulerRot::YXZ, yaw, 0.2, -0.1);
            for f in &rig.faces {
                let (p2, q2) = figurine_pose(&f.body_from_tag(&tag_seen(f, p, q)));
                assert!((p2 - p).length() < 1e-12, "{}: {p2} vs {p}", f.name);
                assert!(angle_between_deg(q, q2) < 1e-4, "{}", f.name);
                // And back: the tag's rotation predicted from the body's.
                let body = f.body_from_tag(&tag_seen(f, p, q)).quat();
                let want = tag_seen(f, p, q).quat();
                assert!(f.tag_rotation(body).dot(want).abs() > 1.0 - 1e-12);
            }
        }
    }

    #[test]
    fn the_box_puts_consecutive_ids_front_left_back_right() {
        let rig = Rig::boxed(0, 0.04, 0.08, 0.06);
        let names: Vec<(u32, &str)> = rig.faces.iter().map(|f| (f.id, f.name.as_str())).collect();
        assert_eq!(
            names,
            [(0, "front"), (1, "left"), (2, "back"), (3, "right")]
        );
        let left = rig.face(1).unwrap();
        assert!((left.centre - DVec3::new(0.04, 0.0, 0.0)).length() < 1e-12);
        // Upright: the tag's top is the figurine's up on every face.
        for f in &rig.faces {
            assert!((f.rotation * DVec3::Y - DVec3::Y).length() < 1e-12);
        }
        // The front tag's corners sit 3 cm ahead of the origin (body frame z is −front).
        let c = rig.faces[0].corners_in_body(0.04);
        assert!(c.iter().all(|p| (p.z + 0.03).abs() < 1e-12));
        // The top tag faces up, its printed top toward the back, its right edge (as seen from
        // above, the back far) toward the figurine's left.
        let top = Rig::checked_box(
            Family::Tag36h11,
            0,
            0.04,
            BoxSize {
                top: Some(0.09),
                ..BoxSize::sides(0.08, 0.06)
            },
        )
        .unwrap();
        let t = top.face(4).unwrap();
        assert_eq!(t.name, "top");
        assert!((t.rotation * DVec3::Z - DVec3::Y).length() < 1e-12);
        assert!((t.rotation * DVec3::Y - DVec3::NEG_Z).length() < 1e-12);
        assert!((t.rotation * DVec3::X - DVec3::X).length() < 1e-12);
        assert!((t.centre - DVec3::new(0.0, 0.09, 0.0)).length() < 1e-12);
        // A one-face rig is the chest tag: its body is its tag.
        let one = Rig::single(7, 0.04);
        assert_eq!(one.faces[0].corners_in_body(0.04), object_corners(0.04));
    }

    /// The seed of the `track_files` fuzz target (a rig file, a NUL, a calibration file) is
    /// accepted whole: the box rig with its top tag and a 60° camera.
    #[test]
    fn the_fuzz_seed_is_a_rig_and_a_calibration_the_readers_accept() {
        let seed = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("fuzz/seeds/track_files/box-rig-and-calibration.txt");
        let bytes = std::fs::read(seed).unwrap();
        let nul = bytes.iter().position(|&b| b == 0).unwrap();
        let rig_text = std::str::from_utf8(&bytes[..nul]).unwrap();
        let cal_text = std::str::from_utf8(&bytes[nul + 1..]).unwrap();
        let rig = Rig::from_json(rig_text, Path::new("RIG.json"), Family::Tag36h11, 0.04).unwrap();
        let mut boxed = Rig::boxed(0, 0.04, 0.08, 0.08);
        boxed.faces.push(Rig::top_face(4, 0.09));
        assert_eq!(rig.faces.len(), boxed.faces.len());
        for (a, b) in rig.faces.iter().zip(&boxed.faces) {
            assert!(
                (a.centre - b.centre).length() < 1e-12,
                "{} {}",
                a.name,
                b.name
            );
            assert!(a.rotation.dot(b.rotation).abs() > 1.0 - 1e-12, "{}", a.name);
        }
        let cal =
            crate::track::pose::Calibration::from_json(cal_text, Path::new("CAL.json")).unwrap();
        assert_eq!((cal.width, cal.height), (640, 480));
    }

    #[test]
    fn a_rig_file_reads_and_bad_ones_say_why() {
        let dir = std::env::temp_dir().join(format!("figurine-rig-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("rig.json");
        let face = |id: u32, c: &str, n: &str, u: &str| {
            format!(r#"{{"id":{id},"centre":[{c}],"normal":[{n}],"up":[{u}]}}"#)
        };
        let good = format!(
            r#"{{"faces":[{},{}]}}"#,
            face(0, "0,0,0.03", "0,0,1", "0,1,0"),
            face(1, "0.04,0,0", "1,0,0", "0,1,0")
        );
        std::fs::write(&path, &good).unwrap();
        let rig = Rig::read(&path, Family::Tag36h11, 0.04).unwrap();
        let boxed = Rig::boxed(0, 0.04, 0.08, 0.06);
        assert!(rig.faces[1].rotation.dot(boxed.faces[1].rotation).abs() > 1.0 - 1e-12);
        for (text, why) in [
            ("{ not json".to_string(), "rig.json"),
            (r#"{"faces":[]}"#.to_string(), "no faces"),
            (
                format!(r#"{{"faces":[{}]}}"#, face(0, "0,0,0", "0,0,0", "0,1,0")),
                "normal must not be zero",
            ),
            (
                format!(r#"{{"faces":[{}]}}"#, face(0, "0,0,0", "0,1,0", "0,1,0")),
                "square to the normal",
            ),
            (
                format!(
                    r#"{{"faces":[{},{}]}}"#,
                    face(2, "0,0,0", "0,0,1", "0,1,0"),
                    face(2, "0,0,0", "1,0,0", "0,1,0")
                ),
                "id 2 is on two faces",
            ),
            (
                format!(r#"{{"faces":[{}]}}"#, face(9999, "0,0,0", "0,0,1", "0,1,0")),
                "not 9999",
            ),
            (
                format!(r#"{{"faces":[{}]}}"#, face(0, "5,0,0", "0,0,1", "0,1,0")),
                "from the figurine's origin",
            ),
        ] {
            std::fs::write(&path, text).unwrap();
            let e = Rig::read(&path, Family::Tag36h11, 0.04)
                .unwrap_err()
                .to_string();
            assert!(e.contains(why), "`{why}` not in: {e}");
        }
        let e =
            Rig::checked_box(Family::Tag36h11, 0, 0.04, BoxSize::sides(0.03, 0.08)).unwrap_err();
        assert!(e.to_string().contains("box width 0.03 m"), "{e}");
        let sides = BoxSize::sides(0.08, 0.08);
        assert!(Rig::checked_box(Family::Tag36h11, 585, 0.04, sides).is_err());
        let low = BoxSize {
            top: Some(0.01),
            ..sides
        };
        let e = Rig::checked_box(Family::Tag36h11, 0, 0.04, low).unwrap_err();
        assert!(e.to_string().contains("box top 0.01 m"), "{e}");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
