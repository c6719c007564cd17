//! Small raster drawing for the PNG reports and plots (effort-training report, synth plots):
//! a 5×7 bitmap font (upper case, digits, a few signs), pixels, rectangles and lines, all
//! clipped to the image, so the pictures explain themselves without a font file.

use image::{Rgb, RgbImage};

/// Glyph width, pixels (before scaling).
pub const GLYPH_W: u32 = 5;
/// Glyph height, pixels (before scaling).
pub const GLYPH_H: u32 = 7;
/// Horizontal advance per character, pixels (before scaling).
pub const ADVANCE: u32 = GLYPH_W + 1;

/// Glyph rows (5 bits, MSB left) for a character; unknown characters draw as a box.
fn glyph(c: char) -> [u8; 7] {
    match c.to_ascii_uppercase() {
        '0' => [14, 17, 19, 21, 25, 17, 14],
        '1' => [4, 12, 4, 4, 4, 4, 14],
        '2' => [14, 17, 1, 2, 4, 8, 31],
        '3' => [30, 1, 1, 14, 1, 1, 30],
        '4' => [2, 6, 10, 18, 31, 2, 2],
        '5' => [31, 16, 30, 1, 1, 17, 14],
        '6' => [6, 8, 16, 30, 17, 17, 14],
        '7' => [31, 1, 2, 4, 8, 8, 8],
        '8' => [14, 17, 17, 14, 17, 17, 14],
        '9' => [14, 17, 17, 15, 1, 2, 12],
        'A' => [14, 17, 17, 31, 17, 17, 17],
        'B' => [30, 17, 17, 30, 17, 17, 30],
        'C' => [14, 17, 16, 16, 16, 17, 14],
        'D' => [28, 18, 17, 17, 17, 18, 28],
        'E' => [31, 16, 16, 30, 16, 16, 31],
        'F' => [31, 16, 16, 30, 16, 16, 16],
        'G' => [14, 17, 16, 23, 17, 17, 15],
        'H' => [17, 17, 17, 31, 17, 17, 17],
        'I' => [14, 4, 4, 4, 4, 4, 14],
        'J' => [7, 2, 2, 2, 2, 18, 12],
        'K' => [17, 18, 20, 24, 20, 18, 17],
        'L' => [16, 16, 16, 16, 16, 16, 31],
        'M' => [17, 27, 21, 21, 17, 17, 17],
        'N' => [17, 17, 25, 21, 19, 17, 17],
        'O' => [14, 17, 17, 17, 17, 17, 14],
        'P' => [30, 17, 17, 30, 16, 16, 16],
        'Q' => [14, 17, 17, 17, 21, 18, 13],
        'R' => [30, 17, 17, 30, 20, 18, 17],
        'S' => [15, 16, 16, 14, 1, 1, 30],
        'T' => [31, 4, 4, 4, 4, 4, 4],
        'U' => [17, 17, 17, 17, 17, 17, 14],
        'V' => [17, 17, 17, 17, 17, 10, 4],
        'W' => [17, 17, 17, 21, 21, 21, 10],
        'X' => [17, 17, 10, 4, 10, 17, 17],
        'Y' => [17, 17, 10, 4, 4, 4, 4],
        'Z' => [31, 1, 2, 4, 8, 16, 31],
        ' ' => [0; 7],
        '.' => [0, 0, 0, 0, 0, 12, 12],
        ',' => [0, 0, 0, 0, 12, 4, 8],
        ':' => [0, 12, 12, 0, 12, 12, 0],
        '-' => [0, 0, 0, 31, 0, 0, 0],
        '+' => [0, 4, 4, 31, 4, 4, 0],
        '%' => [24, 25, 2, 4, 8, 19, 3],
        '(' => [2, 4, 8, 8, 8, 4, 2],
        ')' => [8, 4, 2, 2, 2, 4, 8],
        '/' => [0, 1, 2, 4, 8, 16, 0],
        '=' => [0, 0, 31, 0, 31, 0, 0],
        '_' => [0, 0, 0, 0, 0, 0, 31],
        '>' => [8, 4, 2, 1, 2, 4, 8],
        '<' => [2, 4, 8, 16, 8, 4, 2],
        _ => [31, 17, 17, 17, 17, 17, 31],
    }
}

/// Width in pixels of `text` drawn at `scale`.
pub fn text_width(text: &str, scale: u32) -> u32 {
    text.chars().count() as u32 * ADVANCE * scale
}

/// Draws `text` with its top-left corner at (`x`, `y`) pixels, each font pixel a
/// `scale`×`scale` block (at least 1); pixels outside the image are skipped.
pub fn draw_text(
    img: &mut RgbImage,
    x: i64,
    y: i64,
    text: &str,
    scale: impl Into<i64>,
    colour: Rgb<u8>,
) {
    let scale = scale.into().max(1);
    for (k, c) in text.chars().enumerate() {
        let ox = x + k as i64 * i64::from(ADVANCE) * scale;
        for (row, bits) in glyph(c).iter().enumerate() {
            for col in 0..i64::from(GLYPH_W) {
                if bits & (1 << (i64::from(GLYPH_W) - 1 - col)) == 0 {
                    continue;
                }
                fill_rect(
                    img,
                    ox + col * scale,
                    y + row as i64 * scale,
                    scale,
                    scale,
                    colour,
                );
            }
        }
    }
}

/// Sets a pixel if inside the image.
pub fn put(img: &mut RgbImage, x: i64, y: i64, c: Rgb<u8>) {
    if x >= 0 && y >= 0 && (x as u32) < img.width() && (y as u32) < img.height() {
        img.put_pixel(x as u32, y as u32, c);
    }
}

/// Fills a rectangle (clipped).
pub fn fill_rect(img: &mut RgbImage, x0: i64, y0: i64, w: i64, h: i64, c: Rgb<u8>) {
    for y in y0..y0 + h {
        for x in x0..x0 + w {
            put(img, x, y, c);
        }
    }
}

/// Draws a line (clipped, Bresenham).
pub fn line(img: &mut RgbImage, (x0, y0): (i64, i64), (x1, y1): (i64, i64), c: Rgb<u8>) {
    let (dx, dy) = ((x1 - x0).abs(), -(y1 - y0).abs());
    let (sx, sy) = (if x0 < x1 { 1 } else { -1 }, if y0 < y1 { 1 } else { -1 });
    let (mut x, mut y, mut err) = (x0, y0, dx + dy);
    loop {
        put(img, x, y, c);
        if x == x1 && y == y1 {
            break;
        }
        let e2 = 2 * err;
        if e2 >= dy {
            err += dy;
            x += sx;
        }
        if e2 <= dx {
            err += dx;
            y += sy;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn draws_inside_and_clips_outside() {
        let mut img = RgbImage::from_pixel(40, 20, Rgb([255, 255, 255]));
        draw_text(&mut img, 1, 1, "A1", 1u32, Rgb([0, 0, 0]));
        let ink = img.pixels().filter(|p| p.0 == [0, 0, 0]).count();
        // 'A' has 18 pixels on, '1' has 10.
        assert_eq!(ink, 28);
        draw_text(&mut img, -100, -100, "WAVE", 3u32, Rgb([0, 0, 0]));
        draw_text(&mut img, 35, 15, "WAVE", 3u32, Rgb([0, 0, 0]));
        assert_eq!(text_width("ab", 2), 24);
        assert_eq!(glyph('a'), glyph('A'));
    }

    #[test]
    fn lines_and_rects_are_clipped() {
        let mut img = RgbImage::from_pixel(10, 10, Rgb([0, 0, 0]));
        line(&mut img, (-5, -5), (20, 20), Rgb([255, 0, 0]));
        fill_rect(&mut img, 8, 8, 10, 10, Rgb([0, 255, 0]));
        assert_eq!(img.get_pixel(0, 0).0, [255, 0, 0]);
        assert_eq!(img.get_pixel(9, 9).0, [0, 255, 0]);
    }
}
