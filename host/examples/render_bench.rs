//! Benchmark: time to render 30 s of animation at 30 fps, 1280×720, headless (lavapipe on
//! machines without a GPU). Prints figures; it is not a test.
//!
//! `cargo run --release -p figurine-host --example render_bench [-- SECONDS FPS WxH [OUT.png]]`
//!
//! Measures three things on the procedural walking figure (with doodle and timeline):
//! render + readback only, then the same with GIF encoding and with MP4 encoding to a temp
//! folder (the MP4 figure only when ffmpeg is installed). A fourth argument writes one
//! frame as a PNG to look at; `FIGURINE_BENCH_RENDER_ONLY=1` skips the encoding runs. The CPU
//! time printed is the fair figure on a shared machine (lavapipe renders on the CPU).

use std::time::Instant;

use figurine_host::render::offscreen::OffscreenRenderer;
use figurine_host::render::procedural::{walking_scene, FigureParams};
use figurine_host::render::video::{
    ffmpeg_available, render_frames, render_still, render_to_path, RenderOptions,
};

/// CPU seconds (user + system) this process has used so far, from `/proc/self/stat` (Linux;
/// assumes the usual 100 clock ticks per second). `None` elsewhere.
fn cpu_seconds() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // Fields after the parenthesised command name; utime and stime are fields 14 and 15.
    let rest = stat.rsplit_once(')')?.1;
    let f: Vec<&str> = rest.split_whitespace().collect();
    let utime: f64 = f.get(11)?.parse().ok()?;
    let stime: f64 = f.get(12)?.parse().ok()?;
    Some((utime + stime) / 100.0)
}

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let seconds: f32 = args.first().map_or(Ok(30.0), |s| s.parse())?;
    let fps: f32 = args.get(1).map_or(Ok(30.0), |s| s.parse())?;
    let (w, h) = match args.get(2) {
        Some(s) => {
            let (a, b) = s
                .split_once('x')
                .ok_or_else(|| anyhow::anyhow!("size must be WxH"))?;
            (a.parse()?, b.parse()?)
        }
        None => (1280u32, 720u32),
    };
    let scene = walking_scene(seconds, 30.0, &FigureParams::default());
    let mut r = OffscreenRenderer::new(w, h)?;
    println!("adapter: {}", r.gpu().describe());
    if let Some(out) = args.get(3) {
        render_still(&mut r, &scene, seconds * 0.5)?.save(out)?;
        println!("wrote {out}");
        return Ok(());
    }
    // Warm-up: shader compilation and first-frame allocations.
    render_still(&mut r, &scene, 0.0)?;
    let cpu0 = cpu_seconds();
    let start = Instant::now();
    let mut n = 0;
    let spent = render_frames(&mut r, &scene, fps, |_, _, _| {
        n += 1;
        Ok(())
    })?;
    let wall = start.elapsed().as_secs_f64();
    println!(
        "render+readback: {n} frames {w}x{h} ({seconds} s at {fps} fps) in {wall:.2} s \
         ({:.1} ms/frame, {:.1} fps; goal <= {seconds} s)",
        spent * 1000.0 / n as f64,
        n as f64 / wall
    );
    if let (Some(a), Some(b)) = (cpu0, cpu_seconds()) {
        println!(
            "render+readback CPU time (all threads, lavapipe included): {:.2} s ({:.1} ms/frame); \
             machine load average {}",
            b - a,
            (b - a) * 1000.0 / n as f64,
            std::fs::read_to_string("/proc/loadavg")
                .ok()
                .and_then(|s| s.split_whitespace().next().map(str::to_string))
                .unwrap_or_else(|| "n/a".into())
        );
    }
    if std::env::var_os("FIGURINE_BENCH_RENDER_ONLY").is_some() {
        return Ok(());
    }
    let dir = std::env::temp_dir().join("figurine-render-bench");
    let opts = RenderOptions {
        width: w,
        height: h,
        fps,
    };
    let gif = render_to_path(&scene, opts, &dir.join("bench.gif"), None, false)?;
    println!(
        "with GIF encoding: {} frames in {:.2} s total",
        gif.frames, gif.total_seconds
    );
    if ffmpeg_available() {
        let mp4 = render_to_path(&scene, opts, &dir.join("bench.mp4"), None, false)?;
        println!(
            "with MP4 encoding: {} frames in {:.2} s total",
            mp4.frames, mp4.total_seconds
        );
    } else {
        println!("MP4: ffmpeg not installed, skipped");
    }
    Ok(())
}
