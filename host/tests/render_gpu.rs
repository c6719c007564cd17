//! GPU rendering tests on real Vulkan (Mesa lavapipe on machines without a GPU).
//!
//! Golden image: `tests/golden/walk_160x120.png` is the procedural walking figure at t = 0.4 s.
//! After an intended visual change, regenerate it with
//! `FIGURINE_BLESS=1 cargo test -p figurine-host --test render_gpu golden` and look at it.
//! A failing comparison writes the actual frame to `target/render-test/` for inspection.

use std::path::PathBuf;

use figurine_host::render::offscreen::OffscreenRenderer;
use figurine_host::render::procedural::{walking_scene, FigureParams};
use figurine_host::render::video::{render_frames, render_still};
use image::RgbaImage;

fn golden_path() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/golden/walk_160x120.png")
}

fn artefact_dir() -> PathBuf {
    let d = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../target/render-test");
    let _ = std::fs::create_dir_all(&d);
    d
}

/// Pixels that are clearly part of a limb: saturated orange/blue or the cream body colour
/// are far from the grey ground and the pale blue background.
fn figure_pixels(img: &RgbaImage) -> usize {
    img.pixels()
        .filter(|p| {
            let [r, g, b, _] = p.0.map(i32::from);
            let sat = r.max(g).max(b) - r.min(g).min(b);
            sat > 60
        })
        .count()
}

#[test]
fn golden_still_matches_within_tolerance() {
    let scene = walking_scene(1.0, 30.0, &FigureParams::default());
    let mut r = OffscreenRenderer::new(160, 120).expect("GPU (install mesa-vulkan-drivers)");
    let img = render_still(&mut r, &scene, 0.4).expect("render");
    let golden = golden_path();
    if std::env::var_os("FIGURINE_BLESS").is_some() {
        img.save(&golden).expect("write golden");
        eprintln!("blessed {}", golden.display());
        return;
    }
    let want = image::open(&golden)
        .unwrap_or_else(|e| panic!("{}: {e} (bless with FIGURINE_BLESS=1)", golden.display()))
        .to_rgba8();
    assert_eq!(want.dimensions(), img.dimensions());
    let mut sum = 0u64;
    let mut big = 0usize;
    for (a, b) in img.pixels().zip(want.pixels()) {
        let d = (0..3)
            .map(|c| (i32::from(a[c]) - i32::from(b[c])).unsigned_abs())
            .max()
            .unwrap_or(0);
        sum += u64::from(d);
        if d > 48 {
            big += 1;
        }
    }
    let n = (img.width() * img.height()) as f64;
    let mean = sum as f64 / n;
    let big_frac = big as f64 / n;
    if mean > 2.0 || big_frac > 0.01 {
        let out = artefact_dir().join("walk_160x120_actual.png");
        let _ = img.save(&out);
        panic!(
            "frame differs from golden: mean abs diff {mean:.2}, {:.2}% pixels off by > 48; \
             actual written to {}",
            big_frac * 100.0,
            out.display()
        );
    }
}

#[test]
fn every_frame_is_drawn_and_moves() {
    let scene = walking_scene(1.0, 30.0, &FigureParams::default());
    let mut r = OffscreenRenderer::new(160, 120).expect("GPU");
    let mut frames = Vec::new();
    render_frames(&mut r, &scene, 10.0, |i, _, img| {
        assert_eq!(i, frames.len());
        frames.push(img);
        Ok(())
    })
    .expect("render");
    assert_eq!(frames.len(), 11);
    for (i, f) in frames.iter().enumerate() {
        let n = figure_pixels(f);
        assert!(n > 150, "frame {i}: only {n} figure pixels");
    }
    let changed = frames
        .windows(2)
        .filter(|w| w[0].as_raw() != w[1].as_raw())
        .count();
    assert_eq!(changed, frames.len() - 1, "consecutive frames must differ");
}

#[test]
fn units_do_not_change_the_picture() {
    // The same walk in metres and in centimetres frames identically (up to rounding).
    let mut r = OffscreenRenderer::new(160, 120).expect("GPU");
    let m = walking_scene(1.0, 30.0, &FigureParams::default());
    let cm = walking_scene(
        1.0,
        30.0,
        &FigureParams {
            scale: 100.0,
            ..FigureParams::default()
        },
    );
    let a = render_still(&mut r, &m, 0.5).expect("render m");
    let b = render_still(&mut r, &cm, 0.5).expect("render cm");
    let differing = a
        .pixels()
        .zip(b.pixels())
        .filter(|(x, y)| (0..3).any(|c| (i32::from(x[c]) - i32::from(y[c])).abs() > 40))
        .count();
    assert!(
        differing < 200,
        "{differing} pixels differ between m and cm renders"
    );
}
