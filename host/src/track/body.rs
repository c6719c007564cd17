//! What the test renderer draws: flat panels on the figurine — the chest card on a torso, or
//! a box with a tag on each side (a [`Rig`]) — each with its place in the figurine frame
//! and what is printed on it.
//!
//! A panel's plane coordinates (u, v) are metres from its centre, u to the right and v down as
//! you look at it from outside: for a tag's panel, the detector's tag frame, centred on the
//! tag.

use glam::{DQuat, DVec3};

use super::detect::TagPattern;
use super::rig::Rig;

/// Grey level of the printed white (paper under room light).
const PAPER: f64 = 215.0;
/// Grey level of the printed black.
const INK: f64 = 30.0;
/// Grey level of the figurine's body around the card.
const BODY: f64 = 105.0;
/// Grey level of the figurine's back (the chest card faces away).
const BACK: f64 = 85.0;
/// Grey level of the box's top and bottom: lit from above, a shade lighter than its sides.
const CAP: f64 = 125.0;
/// The body reaches this far above the card's top, metres.
const ABOVE_CARD: f64 = 0.06;
/// And this far below its bottom, metres (a torso).
const BELOW_CARD: f64 = 0.12;
/// Width of the torso the chest card sits on, metres.
const TORSO_WIDTH: f64 = 0.12;

/// One flat panel of the body.
#[derive(Debug, Clone)]
pub struct Panel {
    /// The panel's frame (+Z out, +Y up, +X right as seen from outside) → figurine frame.
    pub rotation: DQuat,
    /// The panel's centre in the figurine frame, metres (a tag's panel: the tag's centre).
    pub centre: DVec3,
    /// Half its width (along u), metres.
    pub half_width: f64,
    /// How far it reaches above its centre (−v), metres.
    pub top: f64,
    /// How far it reaches below its centre (+v), metres.
    pub bottom: f64,
    /// The tag printed on it, centred on a white card; `None`: a plain panel.
    pub tag: Option<TagPattern>,
    /// Whether its back is drawn (a lone plane); a face of a closed box is drawn only from
    /// outside.
    pub two_sided: bool,
}

/// The figurine as the renderer sees it.
#[derive(Debug, Clone)]
pub struct Body {
    /// Its panels. On a closed convex box the panels turned toward the camera never overlap;
    /// the renderer still lets the nearest win per sample.
    pub panels: Vec<Panel>,
    /// Edge of every tag's black square, metres.
    pub tag_size: f64,
}

impl Body {
    /// One tag on the chest of a flat torso: the tag's centre is the figurine's origin.
    pub fn chest(tag: TagPattern, tag_size: f64) -> Self {
        let half_card = half_card(&tag, tag_size);
        Self {
            panels: vec![Panel {
                rotation: DQuat::IDENTITY,
                centre: DVec3::ZERO,
                half_width: TORSO_WIDTH / 2.0,
                top: half_card + ABOVE_CARD,
                bottom: half_card + BELOW_CARD,
                tag: Some(tag),
                two_sided: true,
            }],
            tag_size,
        }
    }

    /// A box `width` × `depth` metres around the figurine's origin with the rig's tags on its
    /// sides (`patterns` in the rig's face order), as tall as the chest's torso, closed by
    /// a plain bottom and a top — the rig's top tag on it if the rig has one (its height then
    /// sets the box's top), plain otherwise.
    pub fn rig_box(rig: &Rig, patterns: Vec<TagPattern>, width: f64, depth: f64) -> Self {
        let half_card = patterns.first().map_or(0.0, |p| half_card(p, rig.tag_size));
        let is_top = |f: &super::rig::Face| (f.rotation * DVec3::Z).y > 0.5;
        let top_face = rig.faces.iter().find(|f| is_top(f));
        let top = top_face.map_or(half_card + ABOVE_CARD, |f| f.centre.y);
        let bottom = half_card + BELOW_CARD;
        let mut panels: Vec<Panel> = rig
            .faces
            .iter()
            .zip(patterns)
            .map(|(f, tag)| {
                let normal = f.rotation * DVec3::Z;
                if is_top(f) {
                    // u along the figurine's X, v (down as seen) toward its front.
                    return Panel {
                        rotation: f.rotation,
                        centre: f.centre,
                        half_width: width / 2.0,
                        top: depth / 2.0,
                        bottom: depth / 2.0,
                        tag: Some(tag),
                        two_sided: false,
                    };
                }
                let across = if normal.z.abs() > normal.x.abs() {
                    width
                } else {
                    depth
                };
                Panel {
                    rotation: f.rotation,
                    centre: f.centre,
                    half_width: across / 2.0,
                    top,
                    bottom,
                    tag: Some(tag),
                    two_sided: false,
                }
            })
            .collect();
        // Plain caps: u along the figurine's X, v along its depth.
        let caps = match top_face {
            None => vec![(DVec3::Y, -top), (DVec3::NEG_Y, bottom)],
            Some(_) => vec![(DVec3::NEG_Y, bottom)],
        };
        for (normal, y) in caps {
            panels.push(Panel {
                rotation: DQuat::from_rotation_arc(DVec3::Z, normal),
                centre: DVec3::new(0.0, -y, 0.0),
                half_width: width / 2.0,
                top: depth / 2.0,
                bottom: depth / 2.0,
                tag: None,
                two_sided: false,
            });
        }
        Self {
            panels,
            tag_size: rig.tag_size,
        }
    }

    /// The panel's world pose (position, orientation: panel frame → world) when the figurine
    /// is at (`pos`, `q`).
    pub fn panel_pose(&self, panel: &Panel, pos: DVec3, q: DQuat) -> (DVec3, DQuat) {
        (pos + q * panel.centre, (q * panel.rotation).normalize())
    }

    /// Half the card's edge on `panel`, metres (0 without a tag).
    pub fn half_card(&self, panel: &Panel) -> f64 {
        panel
            .tag
            .as_ref()
            .map_or(0.0, |t| half_card(t, self.tag_size))
    }

    /// Edge of one cell of the printed patterns, metres.
    pub fn cell(&self, panel: &Panel) -> f64 {
        panel.tag.as_ref().map_or(0.0, |t| cell(t, self.tag_size))
    }

    /// Grey level of `panel` at (u, v), seen from its front or back; `None` off the panel.
    pub fn shade(&self, panel: &Panel, u: f64, v: f64, front: bool) -> Option<f64> {
        if u.abs() > panel.half_width || v < -panel.top || v > panel.bottom {
            return None;
        }
        if !front {
            return Some(BACK);
        }
        let Some(tag) = &panel.tag else {
            return Some(CAP);
        };
        let half_card = half_card(tag, self.tag_size);
        if u.abs() > half_card || v.abs() > half_card {
            return Some(BODY);
        }
        let cell = cell(tag, self.tag_size);
        let half_pattern = cell * tag.width as f64 / 2.0;
        let cx = ((u + half_pattern) / cell).floor();
        let cy = ((v + half_pattern) / cell).floor();
        if cx < 0.0 || cy < 0.0 {
            return Some(PAPER);
        }
        Some(if tag.is_black(cx as usize, cy as usize) {
            INK
        } else {
            PAPER
        })
    }
}

/// Cell edge of a printed pattern whose black square is `tag_size` metres.
fn cell(tag: &TagPattern, tag_size: f64) -> f64 {
    tag_size / tag.border_width.max(1) as f64
}

/// Half the card's edge: the pattern (white ring included) and 1.5 cells of margin.
fn half_card(tag: &TagPattern, tag_size: f64) -> f64 {
    cell(tag, tag_size) * (tag.width as f64 / 2.0 + 1.5)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::track::detect::{tag_pattern, Family};

    #[test]
    fn the_box_s_sides_carry_the_rig_s_tags_and_close_at_its_edges() {
        let rig = Rig::boxed(0, 0.04, 0.08, 0.06);
        let patterns = (0..4)
            .map(|id| tag_pattern(Family::Tag36h11, id).unwrap())
            .collect();
        let body = Body::rig_box(&rig, patterns, 0.08, 0.06);
        assert_eq!(body.panels.len(), 6);
        // The front's right edge (as seen) meets the left side's left edge: the box's corner.
        let (front, left) = (&body.panels[0], &body.panels[1]);
        let edge = |p: &Panel, u: f64| p.centre + p.rotation * DVec3::new(u, 0.0, 0.0);
        let a = edge(front, front.half_width);
        let b = edge(left, -left.half_width);
        assert!((a - b).length() < 1e-12, "{a} vs {b}");
        // The top cap sits at the sides' top edge.
        let top = &body.panels[4];
        assert!((top.centre.y - front.top).abs() < 1e-12);
        // The tag's centre prints black border; off the card it is the body; off the panel
        // nothing.
        let border = body.cell(front) * 3.5;
        assert_eq!(body.shade(front, border, 0.0, true), Some(INK));
        assert_eq!(body.shade(front, 0.038, 0.0, true), Some(BODY));
        assert_eq!(body.shade(front, 0.05, 0.0, true), None);
    }

    #[test]
    fn a_top_tag_replaces_the_plain_top_at_its_height() {
        let mut rig = Rig::boxed(0, 0.04, 0.08, 0.06);
        rig.faces.push(Rig::top_face(4, 0.1));
        let patterns = (0..5)
            .map(|id| tag_pattern(Family::Tag36h11, id).unwrap())
            .collect();
        let body = Body::rig_box(&rig, patterns, 0.08, 0.06);
        // Four sides, the top with its tag, the plain bottom.
        assert_eq!(body.panels.len(), 6);
        let top = &body.panels[4];
        assert!(top.tag.is_some() && (top.centre.y - 0.1).abs() < 1e-12);
        assert!(
            (body.panels[0].top - 0.1).abs() < 1e-12,
            "the sides reach the top"
        );
        // The top spans the box: its v (down as seen from above, the back far) runs front to
        // back over the depth, its u across the width.
        let corner = top.centre + top.rotation * DVec3::new(top.half_width, top.bottom, 0.0);
        let front_edge = body.panels[0].centre.z;
        assert!((corner.z.abs() - front_edge).abs() < 1e-12, "{corner}");
        assert!((corner.x.abs() - 0.04).abs() < 1e-12, "{corner}");
        assert!(body.panels[5].tag.is_none() && body.panels[5].centre.y < 0.0);
    }
}
