//! Puppetry demo of the live viewer API: a producer thread plays two procedural figurines,
//! pushes their poses at 60 Hz and a recognised action every second; the window shows them
//! live and prints the event-to-first-frame time when it closes.
//!
//! `cargo run -p figurine-host --example live_view [-- SECONDS]` (needs a display; under CI
//! use `xvfb-run -a cargo run ... -- 5`).

use std::time::{Duration, Instant};

use figurine_host::render::live::LiveFeed;
use figurine_host::render::procedural::{walking_pose, FigureParams};
use figurine_host::render::scene::TimelineSpan;
use figurine_host::render::viewer::{run_live_viewer, ViewerOptions};
use glam::Vec3;

fn main() -> anyhow::Result<()> {
    let seconds: f32 = std::env::args().nth(1).map_or(Ok(10.0), |s| s.parse())?;
    let feed = LiveFeed::new();
    let producer = feed.clone();
    let stop = Instant::now() + Duration::from_secs_f32(seconds);
    let thread = std::thread::spawn(move || {
        let start = Instant::now();
        let mut next_event = 1.0f32;
        let figures = [
            FigureParams::default(),
            FigureParams {
                character: 1,
                offset: Vec3::new(1.2, 0.0, 0.0),
                travel: 0.6,
                ..FigureParams::default()
            },
        ];
        while Instant::now() < stop {
            let t = start.elapsed().as_secs_f32();
            if t >= next_event {
                let action = if (next_event as u32).is_multiple_of(2) {
                    "hop"
                } else {
                    "walk"
                };
                producer.push_event(
                    TimelineSpan {
                        action: action.into(),
                        start: t,
                        end: t + 0.8,
                        time: (t * 1.3).sin(),
                        weight: (t * 0.7).cos(),
                    },
                    Instant::now(),
                );
                next_event += 1.0;
            }
            for (c, p) in figures.iter().enumerate() {
                producer.push_pose(c as u16, walking_pose(t, p));
            }
            std::thread::sleep(Duration::from_millis(16));
        }
        producer.close();
    });
    let report = run_live_viewer(
        feed,
        ViewerOptions {
            size: (960, 540),
            quit_after: Some(Duration::from_secs_f32(seconds)),
        },
    )?;
    let _ = thread.join();
    println!("frames presented: {}", report.frames);
    if let Some(l) = report.latency {
        println!(
            "event to first frame: median {:.1} ms, p95 {:.1} ms, max {:.1} ms ({} events)",
            l.median.as_secs_f64() * 1e3,
            l.p95.as_secs_f64() * 1e3,
            l.max.as_secs_f64() * 1e3,
            l.count
        );
    }
    Ok(())
}
