//! One action's entry in a clip library (see [`super::library`] for the file): a clip object
//! ([`ActionSpec`]) or a list of them — the action's variants ([`ActionEntry`]) — and the rules
//! a variant list must follow.

use std::path::Path;

use serde::de::{Error as _, MapAccess, SeqAccess, Visitor};
use serde::{Deserialize, Deserializer};

/// Most clip variants one action may list.
pub const MAX_VARIANTS: usize = 16;

/// How one action is played.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ActionSpec {
    /// Variant name (unique within the action; default: the file stem and frame range).
    #[serde(default)]
    pub name: Option<String>,
    /// Clip file: relative to the library, or `KIND/NAME` in the data folder.
    pub file: String,
    /// Whether the character travels along the doodle (false: in place, §6.2).
    pub moving: bool,
    /// Whether the clip is one cycle of a repeating motion (walk, run).
    pub cyclic: bool,
    /// Inclusive frame range of the source clip to use.
    #[serde(default)]
    pub frames: Option<[usize; 2]>,
    /// Play the range backwards, then forwards (e.g. a rise played as down-and-up).
    #[serde(default)]
    pub pingpong: bool,
    /// In-place actions only: remove the clip's net ground drift (linearly over the clip) so
    /// the character ends where it started, as the seed's in-place rule has it. For clips
    /// that travel although their action should not (DeepMimic's spin); feet slide a little.
    #[serde(default)]
    pub anchor: bool,
    /// Length unit → metres for BVH clips (default 0.01).
    #[serde(default)]
    pub scale: Option<f32>,
    /// Whether the clip repeats seamlessly when the action outlasts it (default: the DeepMimic
    /// file's `"Loop": "wrap"` for whole files, else `cyclic`).
    #[serde(default, rename = "loop")]
    pub looping: Option<bool>,
    /// Retarget the clip from its own rig (a BVH take's) onto the library's skeleton (see
    /// [`super::retarget`]): clips of one library must share one skeleton.
    #[serde(default)]
    pub retarget: Option<RetargetSpec>,
    /// The clip steps to one side: its mirror image ([`super::mirror`]) is loaded too, and a
    /// moving action plays whichever keeps the character facing nearest its heading, so it
    /// steps towards the side the doodle moves.
    #[serde(default)]
    pub both_sides: bool,
    /// Why this clip was chosen (substitutions are documented here).
    #[serde(default)]
    pub note: Option<String>,
}

/// How a clip from another rig is retargeted onto the library's skeleton.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RetargetSpec {
    /// A frame of the source file where the performer stands in a T-pose facing forward (it
    /// calibrates each joint's twist; LAFAN1 takes open with one at frame 0).
    pub tpose: usize,
}

impl ActionSpec {
    /// The variant's name: `name`, else the file stem (without DeepMimic's `humanoid3d_`) and
    /// its frame range.
    pub fn variant_name(&self) -> String {
        if let Some(n) = &self.name {
            return n.clone();
        }
        let stem = Path::new(&self.file)
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| self.file.clone());
        let stem = stem
            .strip_prefix("humanoid3d_")
            .unwrap_or(&stem)
            .to_string();
        match self.frames {
            Some([a, b]) => format!("{stem}[{a}-{b}]"),
            None => stem,
        }
    }
}

/// The clips of one action: one or more variants (the first is the primary clip).
#[derive(Debug, Clone)]
pub struct ActionEntry {
    /// The variants in library order (never empty, at most [`MAX_VARIANTS`]).
    pub variants: Vec<ActionSpec>,
}

impl ActionEntry {
    /// The primary (first) variant.
    pub fn primary(&self) -> Option<&ActionSpec> {
        self.variants.first()
    }
}

impl<'de> Deserialize<'de> for ActionEntry {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct EntryVisitor;
        impl<'de> Visitor<'de> for EntryVisitor {
            type Value = ActionEntry;

            fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str("a clip object or a list of clip objects (variants)")
            }

            fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<ActionEntry, A::Error> {
                let spec =
                    ActionSpec::deserialize(serde::de::value::MapAccessDeserializer::new(map))?;
                let variants = vec![spec];
                check_variants(&variants).map_err(A::Error::custom)?;
                Ok(ActionEntry { variants })
            }

            fn visit_seq<A: SeqAccess<'de>>(self, seq: A) -> Result<ActionEntry, A::Error> {
                let variants = Vec::<ActionSpec>::deserialize(
                    serde::de::value::SeqAccessDeserializer::new(seq),
                )?;
                check_variants(&variants).map_err(A::Error::custom)?;
                Ok(ActionEntry { variants })
            }
        }
        d.deserialize_any(EntryVisitor)
    }
}

/// Rules of a variant list: 1..=MAX_VARIANTS clips, distinct names, one `moving`, a positive
/// `scale` where one is given.
pub(crate) fn check_variants(variants: &[ActionSpec]) -> Result<(), String> {
    if variants.is_empty() {
        return Err("empty variant list: an action needs at least one clip".into());
    }
    if variants.len() > MAX_VARIANTS {
        return Err(format!(
            "{} variants: at most {MAX_VARIANTS} clips per action",
            variants.len()
        ));
    }
    let mut names: Vec<String> = Vec::with_capacity(variants.len());
    for v in variants {
        // Zero, negative or not a number would collapse, mirror or blank out every pose.
        if let Some(s) = v.scale.filter(|s| !(s.is_finite() && *s > 0.0)) {
            return Err(format!(
                "\"scale\" {s}: metres per unit of the clip file, a positive number (0.01 for \
                 centimetres)"
            ));
        }
        let n = v.variant_name();
        if names.contains(&n) {
            return Err(format!(
                "two variants are named {n:?}: give each a distinct \"name\""
            ));
        }
        names.push(n);
    }
    if variants.iter().any(|v| v.moving != variants[0].moving) {
        return Err(
            "variants disagree on \"moving\": all clips of one action must travel, or none".into(),
        );
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::anim::library::ClipLibrary;

    #[test]
    fn single_clip_libraries_still_read() {
        let text = r#"{ "version": 1, "actions": {
            "walk": { "file": "w.bvh", "moving": true, "cyclic": true },
            "hop":  { "file": "h.bvh", "moving": true, "cyclic": false, "frames": [3, 9] } } }"#;
        let lib = ClipLibrary::parse(text, Path::new("old.json"), None).unwrap();
        assert_eq!(lib.actions["walk"].variants.len(), 1);
        let hop = lib.actions["hop"].primary().unwrap();
        assert_eq!(hop.variant_name(), "h[3-9]");
        assert_eq!(hop.looping, None);
    }

    #[test]
    fn variant_lists_read_in_order() {
        let text = r#"{ "version": 1, "actions": {
            "kick": [ { "file": "deepmimic/humanoid3d_kick.txt", "moving": false, "cyclic": false },
                      { "name": "spin", "file": "deepmimic/humanoid3d_spinkick.txt",
                        "moving": false, "cyclic": false, "loop": false } ] } }"#;
        let lib = ClipLibrary::parse(text, Path::new("v.json"), None).unwrap();
        let names: Vec<String> = lib.actions["kick"]
            .variants
            .iter()
            .map(ActionSpec::variant_name)
            .collect();
        assert_eq!(names, ["kick", "spin"]);
        assert_eq!(lib.actions["kick"].variants[1].looping, Some(false));
    }

    #[test]
    fn malformed_variant_lists_name_file_and_line() {
        let clip = r#"{ "file": "a.bvh", "moving": false, "cyclic": false }"#;
        let moving = r#"{ "file": "b.bvh", "moving": true, "cyclic": false }"#;
        let many = vec![clip; MAX_VARIANTS + 1].join(",");
        let cases = [
            ("[]".to_string(), "empty variant list"),
            (format!("[{clip}, {clip}]"), "two variants are named \"a\""),
            (format!("[{clip}, {moving}]"), "disagree on \"moving\""),
            (format!("[{clip}, 3]"), "expected struct ActionSpec"),
            (
                format!("[{clip}, {{\"file\": \"x.bvh\"}}]"),
                "missing field `moving`",
            ),
            (
                "\"walk.bvh\"".to_string(),
                "a clip object or a list of clip objects",
            ),
            (format!("[{many}]"), "at most 16 clips"),
            (
                r#"{ "file": "a.bvh", "moving": false, "cyclic": false, "scale": 0 }"#.to_string(),
                "\"scale\" 0: metres per unit",
            ),
            (
                r#"[{ "file": "a.bvh", "moving": false, "cyclic": false, "scale": -0.01 }]"#
                    .to_string(),
                "a positive number",
            ),
        ];
        for (entry, want) in cases {
            let text = format!("{{\n\"version\": 1,\n\"actions\": {{\n\"kick\": {entry}\n}}\n}}");
            let err = ClipLibrary::parse(&text, Path::new("bad.json"), None)
                .unwrap_err()
                .to_string();
            assert!(err.starts_with("bad.json:4:"), "{entry}: {err}");
            assert!(err.contains(want), "{entry}: {err}");
        }
    }
}
