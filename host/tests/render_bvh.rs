//! Renders every real BVH file the project fetched (`$FIGURINE_DATA_DIR/bvh/*.bvh`, see
//! `figurine_host::data`) through the full path: import → scene → camera → GPU, checking that
//! each sampled frame shows a figure of sensible size inside the picture.

use figurine_host::render::from_clip::load_scene;
use figurine_host::render::offscreen::OffscreenRenderer;
use figurine_host::render::video::render_still;
use image::RgbaImage;

/// Frames sampled per file, spread over the whole clip.
const SAMPLES: usize = 5;

/// Limb pixels: strongly saturated (orange/blue limbs), unlike the grey ground and the pale sky.
fn limb_mask(img: &RgbaImage) -> Vec<(u32, u32)> {
    img.enumerate_pixels()
        .filter(|(_, _, p)| {
            let [r, g, b, _] = p.0.map(i32::from);
            r.max(g).max(b) - r.min(g).min(b) > 60
        })
        .map(|(x, y, _)| (x, y))
        .collect()
}

#[test]
fn every_fetched_bvh_renders_a_visible_figure() {
    let dir = figurine_host::data::data_dir().join("bvh");
    let Ok(entries) = std::fs::read_dir(&dir) else {
        eprintln!(
            "skipping: no BVH folder at {} — run `cargo xtask setup`",
            dir.display()
        );
        return;
    };
    let mut files: Vec<_> = entries
        .filter_map(Result::ok)
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|e| e.eq_ignore_ascii_case("bvh")))
        .collect();
    files.sort();
    if files.is_empty() {
        eprintln!(
            "skipping: no .bvh files in {} — run `cargo xtask setup`",
            dir.display()
        );
        return;
    }
    let (w, h) = (160u32, 120u32);
    let mut r = OffscreenRenderer::new(w, h).expect("GPU (install mesa-vulkan-drivers)");
    let out_dir =
        std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../target/render-test");
    let _ = std::fs::create_dir_all(&out_dir);
    for file in &files {
        let scene = load_scene(file, None, None, 1.0)
            .unwrap_or_else(|e| panic!("{}: {e:#}", file.display()));
        let d = scene.duration();
        for k in 0..SAMPLES {
            let t = d * k as f32 / (SAMPLES - 1) as f32;
            let img = render_still(&mut r, &scene, t)
                .unwrap_or_else(|e| panic!("{}: {e}", file.display()));
            let mask = limb_mask(&img);
            let name = file
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default();
            let keep = out_dir.join(format!("{name}_{k}.png"));
            // A person at 160x120 covers a few hundred limb pixels; a tiny speck or an empty
            // frame means the camera lost the figure.
            if mask.len() < 120 {
                let _ = img.save(&keep);
                panic!(
                    "{} at {t:.2}s: only {} limb pixels (frame saved to {})",
                    file.display(),
                    mask.len(),
                    keep.display()
                );
            }
            // The figure is framed: its limb pixels span a good part of the height and do
            // not pile up against the picture's edges.
            let (ymin, ymax) = mask
                .iter()
                .fold((h, 0), |(a, b), &(_, y)| (a.min(y), b.max(y)));
            let at_edge = mask
                .iter()
                .filter(|&&(x, y)| x == 0 || y == 0 || x == w - 1 || y == h - 1)
                .count();
            if ymax - ymin < h / 4 || at_edge > 8 {
                let _ = img.save(&keep);
                panic!(
                    "{} at {t:.2}s: figure spans rows {ymin}..{ymax}, {at_edge} pixels on the edge (saved to {})",
                    file.display(),
                    keep.display()
                );
            }
        }
        eprintln!(
            "rendered {} ({} frames, {:.1} s)",
            file.display(),
            scene.frames.len(),
            d
        );
    }
}
