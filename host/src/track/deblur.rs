//! Undoing motion blur along a known direction, so a tag smeared by fast motion can be read.
//!
//! A tag moving across the picture during the exposure is smeared along its image motion: the
//! picture is the sharp one averaged over a line segment, the blur vector (pixels). At 1 m/s
//! and 8 ms a 4 cm tag half a metre away is smeared by a fifth of its width, its 5-px cells by
//! 9 px: the library neither fits the border's corners nor reads the bits. The tracker knows
//! the tag's image velocity from the last frames, so the blur vector is predicted (velocity ×
//! exposure), and Richardson–Lucy deconvolution with that line restores edges the library can
//! fit. Richardson–Lucy keeps the picture positive and does not ring as badly as a plain
//! inverse filter on noise; a few iterations suffice, since the library only needs the border
//! and the cells' sides of the threshold back, not a clean picture.
//!
//! Nothing here invents a tag: the library still has to find the border and decode the id in
//! the restored picture, and the pose must still fit the corners it finds.

/// Iterations of Richardson–Lucy: 10 restores a blur of 10–20 px enough for the library on the
/// track bench, and each costs two passes of the line filter over the region.
pub const ITERATIONS: usize = 10;

/// A line blur: the picture averaged along a segment through each pixel.
#[derive(Debug, Clone)]
struct LineKernel {
    /// Per tap: the integer offset (columns, rows) of its top-left neighbour and the bilinear
    /// weights of its four neighbours (top-left, top-right, bottom-left, bottom-right), each
    /// already divided by the tap count.
    taps: Vec<(isize, isize, [f32; 4])>,
    /// Padding needed around the picture so no tap reads outside it, pixels.
    pad: usize,
}

impl LineKernel {
    /// Taps one pixel or less apart along `blur` (pixels), centred on the pixel.
    fn new(blur: [f64; 2]) -> Self {
        let len = blur[0].hypot(blur[1]);
        let n = (len.ceil() as usize).max(1) + 1;
        let w = 1.0 / n as f32;
        let taps = (0..n)
            .map(|i| {
                let s = i as f64 / (n - 1) as f64 - 0.5;
                let (dx, dy) = (s * blur[0], s * blur[1]);
                let (ix, iy) = (dx.floor(), dy.floor());
                let (fx, fy) = ((dx - ix) as f32, (dy - iy) as f32);
                (
                    ix as isize,
                    iy as isize,
                    [
                        (1.0 - fx) * (1.0 - fy) * w,
                        fx * (1.0 - fy) * w,
                        (1.0 - fx) * fy * w,
                        fx * fy * w,
                    ],
                )
            })
            .collect();
        Self {
            taps,
            pad: (len / 2.0).ceil() as usize + 2,
        }
    }

    /// `src` (a `w`×`h` picture) averaged along the line, into `dst`; `padded` is scratch.
    /// The kernel is symmetric about the pixel, so it is its own adjoint.
    fn apply(&self, src: &[f32], w: usize, h: usize, padded: &mut Vec<f32>, dst: &mut [f32]) {
        let p = self.pad;
        let pw = w + 2 * p;
        padded.clear();
        // Edge pixels repeated outward: the region's border is the tag's surroundings, whose
        // continuation beyond the crop is unknown; repeating it keeps the ratio there near 1.
        for y in 0..h + 2 * p {
            let sy = y.saturating_sub(p).min(h - 1);
            let row = &src[sy * w..(sy + 1) * w];
            padded.extend(std::iter::repeat_n(row[0], p));
            padded.extend_from_slice(row);
            padded.extend(std::iter::repeat_n(row[w - 1], p));
        }
        dst.fill(0.0);
        for &(ix, iy, k) in &self.taps {
            for y in 0..h {
                let py = (y as isize + p as isize + iy) as usize;
                let top = py * pw;
                let bottom = top + pw;
                let x0 = (p as isize + ix) as usize;
                let out = &mut dst[y * w..(y + 1) * w];
                for (x, o) in out.iter_mut().enumerate() {
                    let (a, b) = (top + x0 + x, bottom + x0 + x);
                    *o += k[0] * padded[a]
                        + k[1] * padded[a + 1]
                        + k[2] * padded[b]
                        + k[3] * padded[b + 1];
                }
            }
        }
    }
}

/// The `w`×`h` grey picture `pixels` with a motion blur of `blur` (pixels over the exposure)
/// undone by `iterations` of Richardson–Lucy. A blur under half a pixel, or an empty picture,
/// comes back as it was.
pub fn deblur_line(
    pixels: &[u8],
    w: usize,
    h: usize,
    blur: [f64; 2],
    iterations: usize,
) -> Vec<u8> {
    let len = blur[0].hypot(blur[1]);
    if w == 0 || h == 0 || pixels.len() < w * h || !(len >= 0.5 && len.is_finite()) {
        return pixels.to_vec();
    }
    let kernel = LineKernel::new(blur);
    // One grey level added so a black pixel is no zero to divide by.
    let observed: Vec<f32> = pixels[..w * h].iter().map(|&v| v as f32 + 1.0).collect();
    let mut estimate = observed.clone();
    let (mut blurred, mut ratio, mut padded) = (vec![0.0; w * h], vec![0.0; w * h], Vec::new());
    for _ in 0..iterations {
        kernel.apply(&estimate, w, h, &mut padded, &mut blurred);
        for ((r, o), b) in ratio.iter_mut().zip(&observed).zip(&blurred) {
            *r = o / b.max(1e-3);
        }
        kernel.apply(&ratio, w, h, &mut padded, &mut blurred);
        for (e, c) in estimate.iter_mut().zip(&blurred) {
            *e *= c;
        }
    }
    estimate
        .iter()
        .map(|v| (v - 1.0).round().clamp(0.0, 255.0) as u8)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A bar picture: dark vertical bars `period` px apart on a light ground.
    fn bars(w: usize, h: usize, period: usize) -> Vec<f32> {
        (0..w * h)
            .map(|i| {
                if (i % w / period).is_multiple_of(2) {
                    40.0
                } else {
                    210.0
                }
            })
            .collect()
    }

    fn blurred(src: &[f32], w: usize, h: usize, blur: [f64; 2]) -> Vec<u8> {
        let mut out = vec![0.0; w * h];
        LineKernel::new(blur).apply(src, w, h, &mut Vec::new(), &mut out);
        out.iter().map(|v| v.round() as u8).collect()
    }

    /// Mean absolute difference from the sharp picture, away from the border.
    fn error(a: &[u8], b: &[f32], w: usize, h: usize) -> f64 {
        let mut s = 0.0;
        let mut n = 0.0;
        for y in 10..h - 10 {
            for x in 10..w - 10 {
                s += (a[y * w + x] as f64 - b[y * w + x] as f64).abs();
                n += 1.0;
            }
        }
        s / n
    }

    #[test]
    fn the_line_filter_averages_along_the_blur_and_keeps_flat_grey() {
        let (w, h) = (20, 12);
        let flat = vec![100.0; w * h];
        assert!(blurred(&flat, w, h, [5.3, 2.1]).iter().all(|&v| v == 100));
        // A single bright pixel spreads along the blur only (here across, 4 px).
        let mut dot = vec![0.0; w * h];
        dot[6 * w + 10] = 250.0;
        let out = blurred(&dot, w, h, [4.0, 0.0]);
        let row: Vec<u8> = out[6 * w..7 * w].to_vec();
        assert_eq!(&row[8..13], &[50, 50, 50, 50, 50]);
        assert!(out[5 * w..6 * w].iter().all(|&v| v == 0));
    }

    #[test]
    fn a_blur_across_the_bars_is_mostly_undone() {
        let (w, h) = (80, 40);
        let sharp = bars(w, h, 6);
        let smeared = blurred(&sharp, w, h, [8.0, 0.0]);
        let restored = deblur_line(&smeared, w, h, [8.0, 0.0], ITERATIONS);
        let (before, after) = (
            error(&smeared, &sharp, w, h),
            error(&restored, &sharp, w, h),
        );
        // Bars 6 px wide under an 8 px smear: some of their contrast is gone for good (the
        // line's spectrum has a zero near their frequency), so not all comes back.
        assert!(after < 0.6 * before, "{before:.1} → {after:.1} grey levels");
        // Along the bars nothing was smeared, so undoing a blur along them changes little.
        let along = deblur_line(&smeared, w, h, [0.0, 8.0], ITERATIONS);
        assert!(error(&along, &sharp, w, h) > 0.8 * before);
    }

    #[test]
    fn no_blur_or_no_picture_is_left_alone() {
        let px = vec![7u8, 9, 11, 13];
        assert_eq!(deblur_line(&px, 2, 2, [0.1, 0.0], ITERATIONS), px);
        assert_eq!(deblur_line(&px, 2, 2, [f64::NAN, 0.0], ITERATIONS), px);
        assert!(deblur_line(&[], 0, 0, [5.0, 0.0], ITERATIONS).is_empty());
        assert_eq!(
            deblur_line(&px, 4, 4, [5.0, 0.0], ITERATIONS),
            px,
            "too few pixels"
        );
    }
}
