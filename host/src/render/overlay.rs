//! The 2-D overlay: the colour-coded timeline bar of actions and efforts, the playhead and the
//! text labels, as a list of pixel rectangles (the GPU draws them; nothing here touches it).
//!
//! Layout, bottom of the frame: one bar spanning the scene's duration. Each recognised action
//! is a block in its action colour (a stable colour per name); under it two thin strips show
//! the Laban efforts: **Time** (warm yellow = sudden, violet = sustained) and **Weight**
//! (red = strong, pale cyan = light), brighter the larger |L|. A white playhead marks now.
//! Above the bar: the current action with its efforts, and the clock. Text uses the public
//! domain 8×8 bitmap font of the `font8x8` crate (ASCII), scaled by whole pixels.

use super::scene::{Scene, TimelineSpan};

/// One filled rectangle in pixels (origin top-left), colour in linear RGBA (premultiplied
/// alpha is not used: plain alpha blending).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Rect {
    /// Left, top, right, bottom in pixels.
    pub xyxy: [f32; 4],
    /// Linear RGBA colour.
    pub colour: [f32; 4],
}

/// Converts an sRGB-encoded channel (0..1) to linear light.
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Linear RGBA from sRGB components and a (linear) alpha.
pub fn srgba(r: f32, g: f32, b: f32, a: f32) -> [f32; 4] {
    [srgb_to_linear(r), srgb_to_linear(g), srgb_to_linear(b), a]
}

/// Distinct action colours (sRGB), chosen by a hash of the action name.
const ACTION_PALETTE: [[f32; 3]; 10] = [
    [0.90, 0.30, 0.30],
    [0.30, 0.70, 0.35],
    [0.30, 0.50, 0.90],
    [0.95, 0.65, 0.15],
    [0.65, 0.40, 0.85],
    [0.20, 0.75, 0.75],
    [0.90, 0.45, 0.70],
    [0.60, 0.65, 0.20],
    [0.55, 0.35, 0.25],
    [0.45, 0.55, 0.65],
];

/// The colour (sRGB) of an action name: stable across runs and scenes (FNV-1a hash).
pub fn action_colour(name: &str) -> [f32; 3] {
    let mut h: u32 = 0x811c_9dc5;
    for b in name.bytes() {
        h ^= u32::from(b);
        h = h.wrapping_mul(0x0100_0193);
    }
    ACTION_PALETTE[(h % ACTION_PALETTE.len() as u32) as usize]
}

/// sRGB colour of a Time effort value: warm yellow when sudden (> 0), violet when sustained.
pub fn time_colour(lt: f32) -> [f32; 3] {
    effort_colour(lt, [1.0, 0.85, 0.2], [0.55, 0.35, 0.95])
}

/// sRGB colour of a Weight effort value: red when strong (> 0), pale cyan when light.
pub fn weight_colour(lw: f32) -> [f32; 3] {
    effort_colour(lw, [0.85, 0.1, 0.1], [0.6, 0.95, 1.0])
}

fn effort_colour(v: f32, pos: [f32; 3], neg: [f32; 3]) -> [f32; 3] {
    let v = if v.is_finite() {
        v.clamp(-1.0, 1.0)
    } else {
        0.0
    };
    let base = if v >= 0.0 { pos } else { neg };
    let k = 0.25 + 0.75 * v.abs();
    let grey = 0.3;
    [
        grey + (base[0] - grey) * k,
        grey + (base[1] - grey) * k,
        grey + (base[2] - grey) * k,
    ]
}

/// Appends `text` at pixel (`x`, `y`) (top-left) with glyph pixels `scale` wide; returns the
/// x just past the text. Characters the font lacks draw as blanks.
pub fn push_text(
    out: &mut Vec<Rect>,
    text: &str,
    x: f32,
    y: f32,
    scale: f32,
    colour: [f32; 4],
) -> f32 {
    let mut cx = x;
    for ch in text.chars() {
        if let Some(rows) = font8x8::legacy::BASIC_LEGACY.get(ch as usize) {
            for (ry, bits) in rows.iter().enumerate() {
                // Merge runs of lit pixels in a row into one rectangle.
                let mut col = 0u32;
                while col < 8 {
                    if bits & (1 << col) != 0 {
                        let start = col;
                        while col < 8 && bits & (1 << col) != 0 {
                            col += 1;
                        }
                        let y0 = y + ry as f32 * scale;
                        out.push(Rect {
                            xyxy: [
                                cx + start as f32 * scale,
                                y0,
                                cx + col as f32 * scale,
                                y0 + scale,
                            ],
                            colour,
                        });
                    } else {
                        col += 1;
                    }
                }
            }
        }
        cx += 8.0 * scale;
    }
    cx
}

/// Text with a dark drop shadow, readable on any background.
fn push_label(
    out: &mut Vec<Rect>,
    text: &str,
    x: f32,
    y: f32,
    scale: f32,
    colour: [f32; 4],
) -> f32 {
    push_text(out, text, x + scale, y + scale, scale, [0.0, 0.0, 0.0, 0.7]);
    push_text(out, text, x, y, scale, colour)
}

/// Width in pixels of `text` at `scale`.
pub fn text_width(text: &str, scale: f32) -> f32 {
    text.chars().count() as f32 * 8.0 * scale
}

/// Pixel geometry of the overlay for a frame size.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OverlayLayout {
    /// Left, top, right, bottom of the timeline bar, pixels.
    pub bar: [f32; 4],
    /// Glyph pixel size.
    pub text_scale: f32,
}

impl OverlayLayout {
    /// Layout for a `width` × `height` frame.
    pub fn new(width: u32, height: u32) -> Self {
        let (w, h) = (width as f32, height as f32);
        let pad = (h * 0.02).max(2.0).round();
        let bar_h = (h * 0.05).max(7.0).round();
        let text_scale = (h / 200.0).floor().max(1.0);
        OverlayLayout {
            bar: [pad, h - pad - bar_h, (w - pad).max(pad + 1.0), h - pad],
            text_scale,
        }
    }
}

/// Formats a signed effort value as `+0.62` / `-0.31`.
fn signed(v: f32) -> String {
    if v.is_finite() {
        format!("{v:+.2}")
    } else {
        "?".to_string()
    }
}

/// The overlay rectangles at time `t` seconds for a `width` × `height` frame; `extra` is a
/// line of status text for the top-right corner (e.g. the viewer's play state), may be empty.
pub fn overlay_rects(scene: &Scene, t: f32, width: u32, height: u32, extra: &str) -> Vec<Rect> {
    let layout = OverlayLayout::new(width, height);
    let [x0, y0, x1, y1] = layout.bar;
    let s = layout.text_scale;
    let duration = scene.duration().max(1e-3);
    let to_x = |time: f32| x0 + (x1 - x0) * (time / duration).clamp(0.0, 1.0);
    let mut out = Vec::with_capacity(256);
    out.push(Rect {
        xyxy: [x0 - 1.0, y0 - 1.0, x1 + 1.0, y1 + 1.0],
        colour: [0.02, 0.02, 0.03, 0.55],
    });
    // Elapsed part of the bar, faint.
    out.push(Rect {
        xyxy: [x0, y0, to_x(t), y1],
        colour: [0.5, 0.5, 0.55, 0.25],
    });
    let bar_h = y1 - y0;
    let main_bottom = y0 + bar_h * 0.6;
    let strip_mid = main_bottom + (y1 - main_bottom) * 0.5;
    for span in &scene.timeline {
        if !(span.start.is_finite() && span.end.is_finite()) {
            continue;
        }
        let (sx0, sx1) = (to_x(span.start), to_x(span.end).max(to_x(span.start) + 1.0));
        let [r, g, b] = action_colour(&span.action);
        out.push(Rect {
            xyxy: [sx0, y0, sx1, main_bottom],
            colour: srgba(r, g, b, 0.95),
        });
        let [r, g, b] = time_colour(span.time);
        out.push(Rect {
            xyxy: [sx0, main_bottom, sx1, strip_mid],
            colour: srgba(r, g, b, 0.95),
        });
        let [r, g, b] = weight_colour(span.weight);
        out.push(Rect {
            xyxy: [sx0, strip_mid, sx1, y1],
            colour: srgba(r, g, b, 0.95),
        });
        // Name inside the block when it fits.
        let glyph_h = 8.0 * s;
        if glyph_h <= main_bottom - y0 && text_width(&span.action, s) + 2.0 * s <= sx1 - sx0 {
            let ty = y0 + ((main_bottom - y0) - glyph_h) * 0.5;
            push_text(
                &mut out,
                &span.action,
                sx0 + s,
                ty,
                s,
                [0.0, 0.0, 0.0, 0.85],
            );
        }
    }
    // Playhead.
    let px = to_x(t);
    let pw = (width as f32 / 400.0).max(1.0).round();
    out.push(Rect {
        xyxy: [px - pw * 0.5, y0 - 3.0 * s, px + pw * 0.5, y1 + 1.0],
        colour: [1.0, 1.0, 1.0, 1.0],
    });
    // Current action and efforts, above the bar on the left.
    let line_y = y0 - 3.0 * s - 9.0 * s;
    let white = [0.95, 0.95, 0.95, 1.0];
    if let Some(span) = scene.span_at(t) {
        let [r, g, b] = action_colour(&span.action);
        let x = push_label(&mut out, &span.action, x0, line_y, s, srgba(r, g, b, 1.0));
        let x = push_label(&mut out, " T", x, line_y, s, white);
        let [r, g, b] = time_colour(span.time);
        let x = push_label(
            &mut out,
            &signed(span.time),
            x,
            line_y,
            s,
            srgba(r, g, b, 1.0),
        );
        let x = push_label(&mut out, " W", x, line_y, s, white);
        let [r, g, b] = weight_colour(span.weight);
        push_label(
            &mut out,
            &signed(span.weight),
            x,
            line_y,
            s,
            srgba(r, g, b, 1.0),
        );
    }
    // Clock, right-aligned above the bar.
    let clock = format!("{:.2}s", t.max(0.0));
    push_label(
        &mut out,
        &clock,
        x1 - text_width(&clock, s),
        line_y,
        s,
        white,
    );
    // Title top-left, status top-right.
    let top = (height as f32 * 0.02).max(2.0).round();
    if !scene.title.is_empty() {
        push_label(&mut out, &scene.title, x0, top, s, white);
    }
    if !extra.is_empty() {
        push_label(&mut out, extra, x1 - text_width(extra, s), top, s, white);
    }
    out
}

/// The span (if any) whose block contains pixel column `x` of a `width`-wide frame; used by the
/// viewer to show what the mouse points at.
pub fn span_at_pixel(scene: &Scene, x: f32, width: u32, height: u32) -> Option<&TimelineSpan> {
    let [x0, _, x1, _] = OverlayLayout::new(width, height).bar;
    if x < x0 || x > x1 {
        return None;
    }
    let t = (x - x0) / (x1 - x0) * scene.duration();
    scene.span_at(t)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene_with_spans() -> Scene {
        Scene {
            title: "test".into(),
            fps: 30.0,
            frames: vec![Default::default(); 61],
            doodle: vec![],
            timeline: vec![
                TimelineSpan {
                    action: "jump".into(),
                    start: 0.2,
                    end: 0.8,
                    time: 0.7,
                    weight: -0.4,
                },
                TimelineSpan {
                    action: "walk".into(),
                    start: 1.0,
                    end: 1.9,
                    time: -0.5,
                    weight: 0.9,
                },
            ],
        }
    }

    #[test]
    fn action_colours_are_stable_and_distinct() {
        assert_eq!(action_colour("jump"), action_colour("jump"));
        assert_ne!(action_colour("jump"), action_colour("walk"));
    }

    #[test]
    fn effort_colours_encode_sign() {
        let sudden = time_colour(1.0);
        let sustained = time_colour(-1.0);
        assert!(sudden[0] > sustained[0] && sustained[2] > sudden[2]);
        assert!(weight_colour(1.0)[0] > weight_colour(-1.0)[0]);
        assert_eq!(time_colour(f32::NAN), time_colour(0.0));
    }

    #[test]
    fn spans_land_in_the_bar() {
        let s = scene_with_spans();
        let rects = overlay_rects(&s, 0.5, 640, 360, "");
        let layout = OverlayLayout::new(640, 360);
        let [x0, y0, x1, _] = layout.bar;
        let jump = srgba(0.0, 0.0, 0.0, 0.0);
        let [r, g, b] = action_colour("jump");
        let jump_colour = srgba(r, g, b, 0.95);
        let block = rects
            .iter()
            .find(|r| r.colour == jump_colour && r.xyxy[1] == y0)
            .expect("jump block");
        let expect_x0 = x0 + (x1 - x0) * 0.2 / 2.0;
        assert!((block.xyxy[0] - expect_x0).abs() < 0.5, "{block:?}");
        assert_ne!(jump, jump_colour);
        // Playhead is the only opaque white rectangle taller than a glyph pixel.
        assert!(rects.iter().any(|r| r.colour == [1.0, 1.0, 1.0, 1.0]));
        assert_eq!(
            span_at_pixel(&s, expect_x0 + 2.0, 640, 360).map(|s| s.action.as_str()),
            Some("jump")
        );
    }

    #[test]
    fn text_draws_pixels_for_letters_only() {
        let mut out = Vec::new();
        let end = push_text(&mut out, "A ", 0.0, 0.0, 2.0, [1.0; 4]);
        assert_eq!(end, 32.0);
        assert!(!out.is_empty());
        assert!(out.iter().all(|r| r.xyxy[2] <= 16.0));
    }

    #[test]
    fn tiny_frames_do_not_break_layout() {
        let s = scene_with_spans();
        for (w, h) in [(1, 1), (16, 9), (160, 120)] {
            let rects = overlay_rects(&s, 1.0, w, h, "paused");
            assert!(rects.iter().all(|r| r.xyxy.iter().all(|v| v.is_finite())));
        }
    }
}
