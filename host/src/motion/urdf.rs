//! A small URDF reader: the joint tree (names, parents, origins, axes) of a robot description.
//!
//! Only what a kinematic skeleton needs is read: each `<joint>`'s name, type, parent and child
//! links, `<origin xyz>` and `<axis xyz>`. Link geometry is ignored. The pybullet humanoid's
//! file ends in a NUL byte and uses CRLF; both are tolerated. Errors name file and line.

use std::path::Path;

use glam::Vec3;

use super::MotionError;

/// One URDF joint.
#[derive(Debug, Clone, PartialEq)]
pub struct UrdfJoint {
    /// Joint name (`right_knee`).
    pub name: String,
    /// Joint type (`spherical`, `revolute`, `fixed`, …).
    pub kind: String,
    /// Parent link name.
    pub parent: String,
    /// Child link name.
    pub child: String,
    /// Origin of the child frame in the parent frame, in URDF units.
    pub origin: Vec3,
    /// Rotation axis for revolute joints (defaults to +X as in the URDF spec).
    pub axis: Vec3,
}

/// Reads the joints of a URDF file, in file order.
pub fn read_urdf_path(path: &Path) -> Result<Vec<UrdfJoint>, MotionError> {
    let bytes = std::fs::read(path).map_err(|source| MotionError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    read_urdf(&String::from_utf8_lossy(&bytes), path)
}

/// Parses URDF text; `path` names it in errors.
pub fn read_urdf(text: &str, path: &Path) -> Result<Vec<UrdfJoint>, MotionError> {
    let line_of = |pos: usize| text.get(..pos).map_or(1, |s| s.matches('\n').count() + 1);
    let mut out = Vec::new();
    let mut pos = 0;
    while let Some(rel) = text.get(pos..).and_then(|s| s.find("<joint")) {
        let start = pos + rel;
        let line = line_of(start);
        let tag_end = text
            .get(start..)
            .and_then(|s| s.find('>'))
            .map(|e| start + e)
            .ok_or_else(|| MotionError::parse(path, line, "unterminated <joint> tag"))?;
        let open_tag = text.get(start..=tag_end).unwrap_or("");
        let self_closing = open_tag.trim_end_matches('>').trim_end().ends_with('/');
        let (body, next) = if self_closing {
            ("", tag_end + 1)
        } else {
            let close = text
                .get(tag_end..)
                .and_then(|s| s.find("</joint>"))
                .map(|e| tag_end + e)
                .ok_or_else(|| MotionError::parse(path, line, "<joint> without </joint>"))?;
            (text.get(tag_end + 1..close).unwrap_or(""), close + 8)
        };
        let name = attr(open_tag, "name")
            .ok_or_else(|| MotionError::parse(path, line, "<joint> without a name"))?;
        let kind = attr(open_tag, "type").unwrap_or_else(|| "fixed".into());
        let sub = |tag: &str| -> Option<&str> {
            let i = body.find(&format!("<{tag}"))?;
            let j = body.get(i..)?.find('>')?;
            body.get(i..=i + j)
        };
        let parent = sub("parent").and_then(|t| attr(t, "link")).ok_or_else(|| {
            MotionError::parse(path, line, format!("joint {name}: no <parent link>"))
        })?;
        let child = sub("child").and_then(|t| attr(t, "link")).ok_or_else(|| {
            MotionError::parse(path, line, format!("joint {name}: no <child link>"))
        })?;
        let vec = |tag: &str, default: Vec3| -> Result<Vec3, MotionError> {
            match sub(tag).and_then(|t| attr(t, "xyz")) {
                None => Ok(default),
                Some(s) => parse_vec3(&s).ok_or_else(|| {
                    MotionError::parse(path, line, format!("joint {name}: bad <{tag} xyz={s:?}>"))
                }),
            }
        };
        let origin = vec("origin", Vec3::ZERO)?;
        let axis = vec("axis", Vec3::X)?;
        out.push(UrdfJoint {
            name,
            kind,
            parent,
            child,
            origin,
            axis,
        });
        pos = next;
    }
    if out.is_empty() {
        return Err(MotionError::parse(path, 1, "no <joint> elements"));
    }
    Ok(out)
}

/// Value of `key="…"` (spaces allowed around `=`) inside one tag's text.
fn attr(tag: &str, key: &str) -> Option<String> {
    let mut from = 0;
    while let Some(i) = tag.get(from..)?.find(key) {
        let at = from + i;
        from = at + key.len();
        // Require a word boundary before the key.
        let before = tag.get(..at)?.chars().last();
        if before.is_some_and(|c| c.is_alphanumeric() || c == '_') {
            continue;
        }
        let rest = tag.get(from..)?.trim_start();
        let Some(rest) = rest.strip_prefix('=') else {
            continue;
        };
        let rest = rest.trim_start();
        let quote = rest.chars().next()?;
        if quote != '"' && quote != '\'' {
            return None;
        }
        let inner = rest.get(1..)?;
        let end = inner.find(quote)?;
        return inner.get(..end).map(str::to_string);
    }
    None
}

fn parse_vec3(s: &str) -> Option<Vec3> {
    let v: Vec<f32> = s
        .split_whitespace()
        .map(|t| t.parse::<f32>().ok().filter(|x| x.is_finite()))
        .collect::<Option<Vec<_>>>()?;
    match v.as_slice() {
        [x, y, z] => Some(Vec3::new(*x, *y, *z)),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_joints_with_spaced_attributes() {
        let text = "<robot>\r\n<joint name=\"knee\" type=\"revolute\" >\r\n<parent link = \"hip\" />\r\n<child link=\"shin\"/>\r\n<origin rpy = \"0 0 0\" xyz = \"0 -1.5 0\" />\r\n<axis xyz=\"0 0 1\"/>\r\n</joint>\r\n</robot>\r\n\0";
        let j = read_urdf(text, Path::new("r.urdf")).unwrap();
        assert_eq!(j.len(), 1);
        assert_eq!(j[0].name, "knee");
        assert_eq!(j[0].parent, "hip");
        assert_eq!(j[0].origin, Vec3::new(0.0, -1.5, 0.0));
        assert_eq!(j[0].axis, Vec3::Z);
    }

    #[test]
    fn errors_name_the_line() {
        let text = "<robot>\n\n<joint name=\"a\">\n<parent link=\"p\"/>\n<origin xyz=\"0 x 0\"/>\n</joint>";
        let e = read_urdf(text, Path::new("r.urdf"))
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("r.urdf:3:"), "{e}");
        assert!(read_urdf("<robot/>", Path::new("r.urdf")).is_err());
    }
}
