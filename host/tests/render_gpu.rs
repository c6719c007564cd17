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

/// A tiny Y-up BVH in centimetres: hips, two legs, spine and head.
const SMALL_BVH: &str = "HIERARCHY
ROOT Hips
{
  OFFSET 0 95 0
  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
  JOINT LeftUpLeg
  {
    OFFSET 10 0 0
    CHANNELS 3 Zrotation Xrotation Yrotation
    JOINT LeftLeg
    {
      OFFSET 0 -45 0
      CHANNELS 3 Zrotation Xrotation Yrotation
      JOINT LeftFoot
      {
        OFFSET 0 -45 0
        CHANNELS 3 Zrotation Xrotation Yrotation
        End Site
        {
          OFFSET 0 -5 12
        }
      }
    }
  }
  JOINT RightUpLeg
  {
    OFFSET -10 0 0
    CHANNELS 3 Zrotation Xrotation Yrotation
    JOINT RightLeg
    {
      OFFSET 0 -45 0
      CHANNELS 3 Zrotation Xrotation Yrotation
      JOINT RightFoot
      {
        OFFSET 0 -45 0
        CHANNELS 3 Zrotation Xrotation Yrotation
        End Site
        {
          OFFSET 0 -5 12
        }
      }
    }
  }
  JOINT Spine
  {
    OFFSET 0 10 0
    CHANNELS 3 Zrotation Xrotation Yrotation
    JOINT Neck
    {
      OFFSET 0 45 0
      CHANNELS 3 Zrotation Xrotation Yrotation
      JOINT Head
      {
        OFFSET 0 12 0
        CHANNELS 3 Zrotation Xrotation Yrotation
        End Site
        {
          OFFSET 0 20 0
        }
      }
    }
  }
}
MOTION
Frames: 3
Frame Time: 0.5
";

#[test]
fn bvh_with_doodle_and_events_shows_every_layer() {
    let dir = std::env::temp_dir().join(format!("figurine-render-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let mut bvh = SMALL_BVH.to_string();
    for (i, x) in [0.0f32, 20.0, 40.0].iter().enumerate() {
        let kick = i as f32 * 20.0;
        // Root position and rotation, then ZXY rotations of the nine joints in file order;
        // the legs swing in opposition (X rotation).
        let mut values = vec![0.0, 95.0, *x, 0.0, 0.0, 0.0];
        for joint in 0..9 {
            let swing = match joint {
                0 => kick,
                3 => -kick,
                _ => 0.0,
            };
            values.extend([0.0, swing, 0.0]);
        }
        let line: Vec<String> = values.iter().map(|v| v.to_string()).collect();
        bvh.push_str(&line.join(" "));
        bvh.push('\n');
    }
    let bvh_path = dir.join("small.bvh");
    std::fs::write(&bvh_path, bvh).expect("write bvh");
    // The doodle: a hop above the path, on a clock starting at 100 s.
    let mut csv = String::from("t,x,y,z,qw,qx,qy,qz\n");
    for i in 0..=50 {
        let t = i as f64 / 50.0;
        let y = 0.3 + 0.3 * (std::f64::consts::PI * t).sin();
        csv.push_str(&format!(
            "{:.4},{:.4},{y:.4},{:.4},1,0,0,0\n",
            100.0 + t,
            0.3 + t * 0.8,
            t * 0.4
        ));
    }
    let log_path = dir.join("doodle.csv");
    std::fs::write(&log_path, csv).expect("write log");
    let ev_path = dir.join("events.jsonl");
    std::fs::write(
        &ev_path,
        "{\"action\":\"jump\",\"start\":100.1,\"end\":100.9,\"time\":0.8,\"weight\":-0.6,\"distance\":0}\n",
    )
    .expect("write events");

    let scene = figurine_host::render::from_clip::load_scene(
        &bvh_path,
        Some(&log_path),
        Some(&ev_path),
        1.0,
    )
    .expect("load scene");
    assert_eq!(scene.frames.len(), 3);
    assert_eq!(scene.timeline.len(), 1);
    assert!(
        (scene.timeline[0].start - 0.1).abs() < 1e-4,
        "events share the doodle clock"
    );
    assert!(scene.doodle.len() > 40);
    let mut r = OffscreenRenderer::new(320, 180).expect("GPU");
    let img = render_still(&mut r, &scene, 0.5).expect("render");
    let _ = img.save(artefact_dir().join("small_bvh_layers.png"));
    // The timeline block of "jump" shows in its action colour in the bottom rows.
    let [cr, cg, cb] =
        figurine_host::render::overlay::action_colour("jump").map(|c| (c * 255.0).round() as i32);
    let bar_hits = img
        .enumerate_pixels()
        .filter(|(_, y, p)| {
            *y > 150
                && (i32::from(p[0]) - cr).abs() < 12
                && (i32::from(p[1]) - cg).abs() < 12
                && (i32::from(p[2]) - cb).abs() < 12
        })
        .count();
    assert!(
        bar_hits > 50,
        "timeline block not drawn ({bar_hits} pixels)"
    );
    // The doodle (magenta-pink) shows above the bar.
    let doodle_hits = img
        .enumerate_pixels()
        .filter(|(_, y, p)| *y < 160 && p[0] > 150 && p[1] < 100 && p[2] > 70)
        .count();
    assert!(doodle_hits > 10, "doodle not drawn ({doodle_hits} pixels)");
    assert!(figure_pixels(&img) > 300);
    let _ = std::fs::remove_dir_all(&dir);
}
