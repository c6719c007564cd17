//! What one rendered trial of `figurine track bench` shares with the others: the motion the
//! generator draws for it, the truths of a kept video (written beside it for `--keep`, read
//! back for `--reuse`), and what the shipped library reads from a log.

use std::fmt::Write as _;

use anyhow::{Context, Result};

use super::eval::{tags_in_sight, FrameTruth, Setup};
use super::render::Scene;
use crate::recognize::simulate::{load_effort, load_library, simulate_log};
use crate::synth::{Knobs, Range};

/// The generator's knobs for tracked gestures: clean truth at 240 Hz (the renderer blurs
/// between samples), small enough to stay in view at half a metre, a toy held a little
/// crooked.
pub fn knobs() -> Knobs {
    Knobs {
        scale: Range::new(0.4, 0.7),
        speed: Range::new(0.8, 1.25),
        tilt_deg: Range::new(0.0, 10.0),
        rate_hz: Range::fixed(240.0),
        ..Knobs::canonical()
    }
}

/// The actions the shipped library and effort model read from `log`.
pub fn actions_of(log: &crate::poselog::PoseLog) -> Result<Vec<String>> {
    Ok(reading_of(log)?.0)
}

/// The actions the shipped library and effort model read from `log`, and the most edits any
/// of them needed to match its pattern (0 when every one matched exactly, or none was read).
pub fn reading_of(log: &crate::poselog::PoseLog) -> Result<(Vec<String>, u32)> {
    let (lib, blob) = load_library(None)?;
    let effort_model = load_effort(None)?;
    let records = simulate_log(log, &lib.names(), &blob, Some(effort_model))?.records;
    let edits = records.iter().map(|r| r.distance).max().unwrap_or(0);
    Ok((records.into_iter().map(|r| r.action).collect(), edits))
}

/// What each frame of `video` showed, when `reuse` asks for a kept video and its truths were
/// kept for this setup.
pub fn kept_truths(
    reuse: bool,
    video: &std::path::Path,
    setup: &Setup,
    scene: &Scene,
) -> Option<Vec<FrameTruth>> {
    (reuse && video.exists())
        .then(|| read_truths(&video.with_extension("frames.csv"), setup, scene).ok())
        .flatten()
}

/// Writes what each frame of a kept video showed, for `--reuse`.
pub fn write_truths(path: &std::path::Path, setup: &Setup, truths: &[FrameTruth]) -> Result<()> {
    let mut text = format!(
        "{}\nt,x,y,z,qw,qx,qy,qz,speed,hidden,log_t\n",
        truths_head(setup)
    );
    for f in truths {
        let p = &f.pose;
        let _ = writeln!(
            text,
            "{},{},{},{},{},{},{},{},{},{},{}",
            f.t,
            p.pos[0],
            p.pos[1],
            p.pos[2],
            p.quat[0],
            p.quat[1],
            p.quat[2],
            p.quat[3],
            f.speed,
            u8::from(f.hidden),
            p.t
        );
    }
    std::fs::write(path, text).with_context(|| format!("writing {}", path.display()))
}

/// Reads what [`write_truths`] wrote; an error when it is missing, malformed or was written
/// for another setup. A frame whose tags were all outside the picture is out of sight even if
/// the file (written before that counted) says otherwise.
pub fn read_truths(
    path: &std::path::Path,
    setup: &Setup,
    scene: &Scene,
) -> Result<Vec<FrameTruth>> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let mut lines = text.lines();
    let head = truths_head(setup);
    anyhow::ensure!(lines.next() == Some(head.as_str()), "another setup");
    lines.next();
    lines
        .map(|line| {
            let v: Vec<f64> = line
                .split(',')
                .map(str::parse)
                .collect::<Result<_, _>>()
                .with_context(|| format!("{}: {line}", path.display()))?;
            anyhow::ensure!(v.len() == 11, "{}: {line}", path.display());
            let pose = crate::poselog::PoseSample {
                t: v[10],
                pos: [v[1], v[2], v[3]],
                quat: [v[4], v[5], v[6], v[7]],
            };
            Ok(FrameTruth {
                t: v[0],
                pose,
                speed: v[8],
                hidden: v[9] != 0.0 || tags_in_sight(scene, &pose) == 0,
            })
        })
        .collect()
}

/// The first line of a kept video's truths: the setup it was drawn with.
fn truths_head(setup: &Setup) -> String {
    let rig = setup.rig_box.map_or(String::new(), |b| {
        let top = b
            .top
            .map_or(String::new(), |h| format!(", top tag {h} m up"));
        format!(", box {} × {} m{top}", b.width, b.depth)
    });
    let tilt = if setup.camera_tilt_deg == 0.0 {
        String::new()
    } else {
        format!(", camera looking {}° down", setup.camera_tilt_deg)
    };
    format!(
        "# tag {} m at {} m, seed {}, {} fps{rig}{tilt}",
        setup.tag_size, setup.distance, setup.seed, setup.fps
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::track::detect::Family;
    use crate::track::eval::scene;

    #[test]
    fn kept_truths_read_back_and_refuse_another_setup() {
        let dir = std::env::temp_dir().join(format!("figurine-trial-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("frames.csv");
        let setup = Setup::default();
        let truths = vec![FrameTruth {
            t: 0.1,
            pose: crate::poselog::PoseSample {
                t: 3.1,
                pos: [0.1, -0.2, -0.7],
                quat: [1.0, 0.0, 0.0, 0.0],
            },
            speed: 0.25,
            hidden: true,
        }];
        write_truths(&path, &setup, &truths).unwrap();
        let sc = scene(&setup, Family::Tag36h11, 0).unwrap();
        assert_eq!(read_truths(&path, &setup, &sc).unwrap(), truths);
        // Written as in sight but the tag is off the picture's left edge: out of sight.
        let off = FrameTruth {
            hidden: false,
            pose: crate::poselog::PoseSample {
                pos: [-0.45, 0.0, -0.7],
                ..truths[0].pose
            },
            ..truths[0]
        };
        write_truths(&path, &setup, &[off]).unwrap();
        assert!(read_truths(&path, &setup, &sc).unwrap()[0].hidden);
        let other = Setup {
            distance: 1.0,
            ..setup
        };
        assert!(read_truths(&path, &other, &sc).is_err());
        // A video kept at another frame rate is not the one asked for.
        let faster = Setup { fps: 60.0, ..setup };
        assert!(read_truths(&path, &faster, &sc).is_err());
        let _ = std::fs::remove_dir_all(&dir);
    }
}
