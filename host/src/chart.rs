//! Benchmark charts as PNG: grouped bar charts and line panels with axes, tick values, axis
//! labels and a legend, drawn with [`crate::raster`]'s built-in font so they need no font file
//! (`figurine eval rest --plot`, `figurine eval sweep --plot`).
//!
//! Text is upper case (the font has no lower case). Every value axis starts at zero, so bar
//! heights and line heights compare honestly across panels.

use std::path::Path;

use anyhow::{Context, Result};
use image::{Rgb, RgbImage};

use crate::raster::{draw_text, fill_rect, line, text_width, GLYPH_H};

/// Background.
const PAPER: Rgb<u8> = Rgb([252, 252, 250]);
/// Axes and text.
const INK: Rgb<u8> = Rgb([30, 30, 40]);
/// Grid lines.
const GRID: Rgb<u8> = Rgb([222, 222, 228]);
/// Series colours, in order: blue, orange, green, purple, red, brown (colour-blind friendly
/// enough for three or four series; markers tell line series apart as well).
pub const PALETTE: [Rgb<u8>; 6] = [
    Rgb([40, 110, 200]),
    Rgb([230, 120, 30]),
    Rgb([40, 160, 90]),
    Rgb([140, 80, 180]),
    Rgb([200, 50, 50]),
    Rgb([140, 100, 60]),
];

/// Scale of titles, of labels and of small print (font pixels per glyph pixel).
const TITLE: i64 = 3;
const LABEL: i64 = 2;
const SMALL: i64 = 1;

/// Width and height of one panel's plotting area, pixels.
const PLOT_W: i64 = 560;
const PLOT_H: i64 = 380;
/// Room left of a plot for tick values, below it for group/tick labels and axis label, above it
/// for the panel title and the axis label, pixels.
const LEFT: i64 = 70;
const BELOW: i64 = 70;
const ABOVE: i64 = 56;
/// Outer margin, and the band at the top for the chart title and legend, pixels.
const MARGIN: i64 = 24;
const HEADER: i64 = 100;

/// One panel of a [`BarChart`]: groups along x, one bar per series in each group.
#[derive(Debug, Clone, PartialEq)]
pub struct BarPanel {
    /// Caption above the panel.
    pub title: String,
    /// Group names along the x axis.
    pub groups: Vec<String>,
    /// `values[group][series]`, in the chart's y unit.
    pub values: Vec<Vec<f64>>,
}

/// Grouped bars, panels side by side sharing one y scale.
#[derive(Debug, Clone, PartialEq)]
pub struct BarChart {
    /// Caption of the whole chart.
    pub title: String,
    /// What the y axis measures, with its unit.
    pub y_label: String,
    /// What the x axis groups.
    pub x_label: String,
    /// Series names (the legend), one colour each.
    pub series: Vec<String>,
    /// The panels.
    pub panels: Vec<BarPanel>,
}

/// One panel of a [`LineChart`]: evenly spaced x positions, one polyline per series.
#[derive(Debug, Clone, PartialEq)]
pub struct LinePanel {
    /// Caption above the panel.
    pub title: String,
    /// What the x axis measures, with its unit.
    pub x_label: String,
    /// Tick labels of the x positions (categorical: the values need not be evenly spaced).
    pub xs: Vec<String>,
    /// `ys[series][x]`, in the chart's y unit; NaN leaves a gap.
    pub ys: Vec<Vec<f64>>,
}

/// Line panels side by side sharing one fixed y range.
#[derive(Debug, Clone, PartialEq)]
pub struct LineChart {
    /// Caption of the whole chart.
    pub title: String,
    /// What the y axis measures, with its unit.
    pub y_label: String,
    /// Bottom and top of the y axis.
    pub y_range: (f64, f64),
    /// Distance between y grid lines.
    pub y_step: f64,
    /// Series names (the legend), one colour and marker each.
    pub series: Vec<String>,
    /// The panels.
    pub panels: Vec<LinePanel>,
}

/// The smallest 1, 2 or 5 × 10^k at least `x` (1 for nonsense input).
pub fn nice_step(x: f64) -> f64 {
    if !(x.is_finite() && x > 0.0) {
        return 1.0;
    }
    let p = 10f64.powf(x.log10().floor());
    [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * p)
        .find(|v| *v >= x * (1.0 - 1e-12))
        .unwrap_or(10.0 * p)
}

/// A tick value as text: no decimals for whole numbers, otherwise as few as needed (≤ 2).
fn tick_text(v: f64) -> String {
    if (v - v.round()).abs() < 1e-9 {
        format!("{v:.0}")
    } else if (v * 10.0 - (v * 10.0).round()).abs() < 1e-9 {
        format!("{v:.1}")
    } else {
        format!("{v:.2}")
    }
}

/// A bar's value as printed above it: whole numbers from 10 up, one decimal below, so that
/// it stays about three characters, as wide as the bar.
fn bar_text(v: f64) -> String {
    if !v.is_finite() {
        "-".into()
    } else if v.abs() >= 10.0 {
        format!("{v:.0}")
    } else {
        tick_text((v * 10.0).round() / 10.0)
    }
}

/// Height of text at `scale`, pixels.
fn text_h(scale: i64) -> i64 {
    i64::from(GLYPH_H) * scale
}

fn width(text: &str, scale: i64) -> i64 {
    i64::from(text_width(text, scale as u32))
}

/// The canvas for `panels` side by side.
fn canvas(panels: usize) -> RgbImage {
    let n = panels.max(1) as i64;
    let w = 2 * MARGIN + n * (LEFT + PLOT_W) + (n - 1) * MARGIN;
    let h = HEADER + ABOVE + PLOT_H + BELOW + MARGIN;
    RgbImage::from_pixel(w as u32, h as u32, PAPER)
}

/// Top-left corner of panel `i`'s plotting area.
fn origin(i: usize) -> (i64, i64) {
    (
        MARGIN + LEFT + i as i64 * (LEFT + PLOT_W + MARGIN),
        HEADER + ABOVE,
    )
}

/// Chart title and a legend of `series` (a swatch per series: a bar, or a line with its
/// marker).
fn header(img: &mut RgbImage, title: &str, series: &[String], lines: bool) {
    draw_text(img, MARGIN, MARGIN, title, TITLE, INK);
    let y = MARGIN + text_h(TITLE) + 22;
    let mut x = MARGIN;
    for (s, name) in series.iter().enumerate() {
        let c = PALETTE[s % PALETTE.len()];
        if lines {
            thick_line(img, (x, y + 7), (x + 36, y + 7), c);
            marker(img, s, x + 18, y + 7, c);
        } else {
            fill_rect(img, x, y, 28, 14, c);
        }
        draw_text(img, x + 46, y, name, LABEL, INK);
        x += 46 + width(name, LABEL) + 40;
    }
}

/// Horizontal grid lines with their values from `lo` to `hi` every `step`, the y axis label
/// above the axis, the x axis label centred below, and the frame.
#[allow(clippy::too_many_arguments)] // one panel's frame: where, its range, its captions
fn frame(
    img: &mut RgbImage,
    (x0, y0): (i64, i64),
    (lo, hi): (f64, f64),
    step: f64,
    title: &str,
    y_label: &str,
    x_label: &str,
) {
    draw_text(img, x0 - LEFT + 4, y0 - ABOVE, title, LABEL, INK);
    draw_text(
        img,
        x0 - LEFT + 4,
        y0 - text_h(LABEL) - 10,
        y_label,
        LABEL,
        INK,
    );
    let n = ((hi - lo) / step).round().max(1.0) as i64;
    for k in 0..=n {
        let v = lo + k as f64 * step;
        let y = y_of(v, (lo, hi), y0);
        line(img, (x0, y), (x0 + PLOT_W, y), GRID);
        let t = tick_text(v);
        draw_text(
            img,
            x0 - 8 - width(&t, LABEL),
            y - text_h(LABEL) / 2,
            &t,
            LABEL,
            INK,
        );
    }
    line(img, (x0, y0), (x0, y0 + PLOT_H), INK);
    line(img, (x0, y0 + PLOT_H), (x0 + PLOT_W, y0 + PLOT_H), INK);
    draw_text(
        img,
        x0 + (PLOT_W - width(x_label, LABEL)) / 2,
        y0 + PLOT_H + BELOW - text_h(LABEL) - 6,
        x_label,
        LABEL,
        INK,
    );
}

/// Pixel row of value `v` on a y axis from `lo` (bottom) to `hi` (top) whose top is `y0`.
fn y_of(v: f64, (lo, hi): (f64, f64), y0: i64) -> i64 {
    let f = ((v - lo) / (hi - lo)).clamp(0.0, 1.0);
    y0 + PLOT_H - (f * PLOT_H as f64).round() as i64
}

/// Draws a grouped bar chart.
pub fn bar_chart(c: &BarChart) -> RgbImage {
    let mut img = canvas(c.panels.len());
    header(&mut img, &c.title, &c.series, false);
    let max = c
        .panels
        .iter()
        .flat_map(|p| p.values.iter().flatten())
        .copied()
        .filter(|v| v.is_finite())
        .fold(0.0, f64::max);
    // About five grid lines, with headroom for the value printed above the tallest bar.
    let step = nice_step((max * 1.15).max(1e-9) / 5.0);
    let hi = step * ((max * 1.15) / step).ceil().max(1.0);
    let n_series = c.series.len().max(1) as i64;
    for (i, p) in c.panels.iter().enumerate() {
        let o = origin(i);
        frame(
            &mut img,
            o,
            (0.0, hi),
            step,
            &p.title,
            &c.y_label,
            &c.x_label,
        );
        let gw = PLOT_W / p.groups.len().max(1) as i64;
        // Bars fill 80 % of a group; the rest separates groups.
        let bw = (gw * 4 / 5 / n_series).max(2);
        for (g, name) in p.groups.iter().enumerate() {
            let gx = o.0 + g as i64 * gw;
            draw_text(
                &mut img,
                gx + (gw - width(name, LABEL)) / 2,
                o.1 + PLOT_H + 8,
                name,
                LABEL,
                INK,
            );
            let x_first = gx + (gw - bw * n_series) / 2;
            for (s, &v) in p.values.get(g).into_iter().flatten().enumerate() {
                let colour = PALETTE[s % PALETTE.len()];
                let x = x_first + s as i64 * bw;
                let top = y_of(v.max(0.0), (0.0, hi), o.1);
                // A zero is drawn as a 2-pixel stub so a measured zero differs from no bar.
                let top = top.min(o.1 + PLOT_H - 2);
                fill_rect(&mut img, x + 1, top, bw - 2, o.1 + PLOT_H - top, colour);
                let t = bar_text(v);
                let scale = if width(&t, LABEL) <= bw + 4 {
                    LABEL
                } else {
                    SMALL
                };
                draw_text(
                    &mut img,
                    x + (bw - width(&t, scale)) / 2,
                    top - text_h(scale) - 4,
                    &t,
                    scale,
                    INK,
                );
            }
        }
    }
    img
}

/// A line two pixels thick.
fn thick_line(img: &mut RgbImage, a: (i64, i64), b: (i64, i64), c: Rgb<u8>) {
    for d in 0..2 {
        line(img, (a.0, a.1 + d), (b.0, b.1 + d), c);
        line(img, (a.0 + d, a.1), (b.0 + d, b.1), c);
    }
}

/// Series `s`'s marker centred at (`x`, `y`): a square, a diamond, then alternating.
fn marker(img: &mut RgbImage, s: usize, x: i64, y: i64, c: Rgb<u8>) {
    const R: i64 = 5;
    if s.is_multiple_of(2) {
        fill_rect(img, x - R, y - R, 2 * R + 1, 2 * R + 1, c);
    } else {
        for dy in -R - 1..=R + 1 {
            let half = R + 1 - dy.abs();
            fill_rect(img, x - half, y + dy, 2 * half + 1, 1, c);
        }
    }
}

/// Draws line panels.
pub fn line_chart(c: &LineChart) -> RgbImage {
    let mut img = canvas(c.panels.len());
    header(&mut img, &c.title, &c.series, true);
    let (lo, hi) = c.y_range;
    for (i, p) in c.panels.iter().enumerate() {
        let o = origin(i);
        frame(
            &mut img,
            o,
            (lo, hi),
            c.y_step,
            &p.title,
            &c.y_label,
            &p.x_label,
        );
        // Half a slot of room at either end, so the first and last points clear the axes.
        let slot = PLOT_W / p.xs.len().max(1) as i64;
        let x_of = |k: usize| o.0 + slot / 2 + k as i64 * slot;
        for (k, t) in p.xs.iter().enumerate() {
            let x = x_of(k);
            line(&mut img, (x, o.1 + PLOT_H), (x, o.1 + PLOT_H + 5), INK);
            draw_text(
                &mut img,
                x - width(t, LABEL) / 2,
                o.1 + PLOT_H + 10,
                t,
                LABEL,
                INK,
            );
        }
        for (s, ys) in p.ys.iter().enumerate() {
            let colour = PALETTE[s % PALETTE.len()];
            let pts: Vec<Option<(i64, i64)>> = ys
                .iter()
                .enumerate()
                .map(|(k, &v)| v.is_finite().then(|| (x_of(k), y_of(v, (lo, hi), o.1))))
                .collect();
            for w in pts.windows(2) {
                if let [Some(a), Some(b)] = w {
                    thick_line(&mut img, *a, *b, colour);
                }
            }
            for &(x, y) in pts.iter().flatten() {
                marker(&mut img, s, x, y, colour);
            }
        }
    }
    img
}

/// Writes `img` as PNG at `path`, creating its folder.
pub fn save_png(img: &RgbImage, path: &Path) -> Result<()> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    img.save(path)
        .with_context(|| format!("writing {}", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn has(img: &RgbImage, c: Rgb<u8>) -> usize {
        img.pixels().filter(|p| **p == c).count()
    }

    #[test]
    fn steps_are_round() {
        assert_eq!(nice_step(0.7), 1.0);
        assert_eq!(nice_step(1.0), 1.0);
        assert_eq!(nice_step(1.3), 2.0);
        assert_eq!(nice_step(3.0), 5.0);
        assert_eq!(nice_step(42.0), 50.0);
        assert_eq!(nice_step(f64::NAN), 1.0);
        assert_eq!(tick_text(20.0), "20");
        assert_eq!(tick_text(0.5), "0.5");
        assert_eq!(tick_text(0.25), "0.25");
        assert_eq!(bar_text(34.67), "35");
        assert_eq!(bar_text(2.67), "2.7");
        assert_eq!(bar_text(4.0), "4");
        assert_eq!(bar_text(f64::NAN), "-");
    }

    #[test]
    fn bars_are_as_tall_as_their_values() {
        let chart = BarChart {
            title: "T".into(),
            y_label: "Y".into(),
            x_label: "X".into(),
            series: vec!["A".into(), "B".into()],
            panels: vec![BarPanel {
                title: "P".into(),
                groups: vec!["G1".into(), "G2".into()],
                values: vec![vec![4.0, 0.0], vec![2.0, 1.0]],
            }],
        };
        let img = bar_chart(&chart);
        let (blue, orange) = (PALETTE[0], PALETTE[1]);
        // Column heights of each colour: the 4 bar is twice the 2 bar; the zero is a stub.
        let heights = |c: Rgb<u8>| -> Vec<u32> {
            (0..img.width())
                .map(|x| {
                    (0..img.height())
                        .filter(|&y| *img.get_pixel(x, y) == c)
                        .count() as u32
                })
                .filter(|&n| n > 20)
                .collect()
        };
        let b = heights(blue);
        let tall = *b.iter().max().unwrap();
        assert!(b.iter().any(|&h| h.abs_diff(tall / 2) <= 2), "{b:?}");
        assert!(has(&img, orange) > 0);
        assert_eq!(img.width() as i64, 2 * MARGIN + LEFT + PLOT_W);
    }

    #[test]
    fn lines_draw_every_series_with_gaps_for_nan() {
        let chart = LineChart {
            title: "T".into(),
            y_label: "%".into(),
            y_range: (0.0, 100.0),
            y_step: 20.0,
            series: vec!["A".into(), "B".into()],
            panels: vec![
                LinePanel {
                    title: "P".into(),
                    x_label: "X".into(),
                    xs: vec!["1".into(), "2".into(), "3".into()],
                    ys: vec![vec![10.0, 50.0, 90.0], vec![f64::NAN, 30.0, 30.0]],
                },
                LinePanel {
                    title: "Q".into(),
                    x_label: "X".into(),
                    xs: vec!["1".into()],
                    ys: vec![vec![100.0], vec![0.0]],
                },
            ],
        };
        let img = line_chart(&chart);
        assert!(has(&img, PALETTE[0]) > 100 && has(&img, PALETTE[1]) > 100);
        assert_eq!(
            img.width() as i64,
            2 * MARGIN + 2 * (LEFT + PLOT_W) + MARGIN
        );
    }
}
