//! What one rendered trial of `figurine track bench` shares with the others: the motion the
//! generator draws for it, the truths of a kept video (written beside it for `--keep`, read
//! back for `--reuse`), what the shipped library reads from a log, and how steadily it reads
//! the truth under a tracker's white jitter.

use std::fmt::Write as _;

use anyhow::{Context, Result};

use super::eval::{tags_in_sight, FrameTruth, Setup};
use super::render::Scene;
use crate::poselog::{PoseLog, PoseSample};
use crate::recognize::simulate::{load_effort, load_library, simulate_log};
use crate::synth::rng::{Stream, SynthRng};
use crate::synth::{Knobs, Range};
use figurine_recognizer::bayes::EffortModel;

/// White jitter added to the truth to tell how steadily the recognizer reads it: (position σ
/// per axis, mm; orientation σ about each axis, °). The first is about the tracked log's own
/// jitter at rest (the bench's "tracked jitter at rest": 0.1–0.4 mm, 0.10–0.15° at 0.5–1 m);
/// the second, about a tag near a webcam (the README's `webcam-near` level: 0.5–2 mm,
/// 0.2–0.3°).
pub const JITTER_LEVELS: [(f64, f64); 2] = [(0.3, 0.15), (1.0, 0.5)];

/// Draws of the jitter per gesture and level (one draw's count moves by a gesture or two).
pub const JITTER_DRAWS: u64 = 4;

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

/// The shipped library and effort model, loaded once to read many logs.
pub struct Reader {
    names: Vec<String>,
    blob: Vec<u8>,
    effort: EffortModel,
}

impl Reader {
    /// Loads the shipped library and effort model.
    pub fn shipped() -> Result<Self> {
        let (lib, blob) = load_library(None)?;
        Ok(Reader {
            names: lib.names(),
            blob,
            effort: load_effort(None)?,
        })
    }

    /// The actions read from `log`, and the most edits any of them needed to match its
    /// pattern (0 when every one matched exactly, or none was read).
    pub fn reading(&self, log: &PoseLog) -> Result<(Vec<String>, u32)> {
        let records = simulate_log(log, &self.names, &self.blob, Some(self.effort))?.records;
        let edits = records.iter().map(|r| r.distance).max().unwrap_or(0);
        Ok((records.into_iter().map(|r| r.action).collect(), edits))
    }

    /// The actions read from `log`.
    pub fn actions(&self, log: &PoseLog) -> Result<Vec<String>> {
        Ok(self.reading(log)?.0)
    }
}

/// `log` with white jitter drawn from `seed`: every sample's position moved by a normal σ
/// `pos_mm` on each axis, and its orientation turned by a normal σ `ori_deg` about each of the
/// figurine's own axes.
pub fn jittered(log: &PoseLog, pos_mm: f64, ori_deg: f64, seed: u64) -> PoseLog {
    let mut rng = SynthRng::new(seed, Stream::Sensor);
    let (p, o) = (pos_mm / 1000.0, ori_deg.to_radians());
    let samples = log
        .samples
        .iter()
        .map(|s| {
            let pos = s.pos.map(|x| x + p * rng.normal());
            let turn = glam::DVec3::new(rng.normal(), rng.normal(), rng.normal()) * o;
            let [w, x, y, z] = s.quat;
            let q = glam::DQuat::from_xyzw(x, y, z, w) * glam::DQuat::from_scaled_axis(turn);
            PoseSample {
                t: s.t,
                pos,
                quat: [q.w, q.x, q.y, q.z],
            }
        })
        .collect();
    PoseLog { samples }
}

/// For each of [`JITTER_LEVELS`], how many of [`JITTER_DRAWS`] jittered copies of `truth`
/// `reader` reads as `reading` (what it reads from `truth` itself); `seed` draws them.
pub fn steady_readings(
    reader: &Reader,
    truth: &PoseLog,
    reading: &[String],
    seed: u64,
) -> Result<Vec<u32>> {
    JITTER_LEVELS
        .iter()
        .enumerate()
        .map(|(level, &(pos_mm, ori_deg))| {
            (0..JITTER_DRAWS).try_fold(0, |same, draw| {
                let draw_seed = seed
                    .wrapping_mul(JITTER_LEVELS.len() as u64 * JITTER_DRAWS)
                    .wrapping_add(level as u64 * JITTER_DRAWS + draw);
                let log = jittered(truth, pos_mm, ori_deg, draw_seed);
                Ok(same + u32::from(reader.actions(&log)? == reading))
            })
        })
        .collect()
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
            let pose = PoseSample {
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

    /// A figurine held still for `n` frames at 30 Hz, turned a radian about its up axis.
    fn held(n: usize) -> PoseLog {
        let q = glam::DQuat::from_rotation_y(1.0);
        PoseLog {
            samples: (0..n)
                .map(|i| PoseSample {
                    t: i as f64 / 30.0,
                    pos: [0.1, 0.2, -0.7],
                    quat: [q.w, q.x, q.y, q.z],
                })
                .collect(),
        }
    }

    #[test]
    fn jitter_has_the_stated_spread_in_position_and_orientation() {
        let log = held(4000);
        let noisy = jittered(&log, 1.0, 0.5, 7);
        assert_eq!(noisy, jittered(&log, 1.0, 0.5, 7), "seeded");
        assert_ne!(noisy, jittered(&log, 1.0, 0.5, 8));
        let n = log.samples.len() as f64;
        let (mut pos, mut ori) = (0.0, 0.0);
        for (a, b) in log.samples.iter().zip(&noisy.samples) {
            assert_eq!(a.t, b.t);
            pos += (0..3).map(|k| (b.pos[k] - a.pos[k]).powi(2)).sum::<f64>();
            let qa = glam::DQuat::from_xyzw(a.quat[1], a.quat[2], a.quat[3], a.quat[0]);
            let qb = glam::DQuat::from_xyzw(b.quat[1], b.quat[2], b.quat[3], b.quat[0]);
            ori += qa.angle_between(qb).powi(2);
        }
        // Per axis: the three axes' mean square, a third of the sum.
        let pos_mm = (pos / n / 3.0).sqrt() * 1000.0;
        let ori_deg = (ori / n / 3.0).sqrt().to_degrees();
        assert!((pos_mm - 1.0).abs() < 0.05, "{pos_mm} mm");
        assert!((ori_deg - 0.5).abs() < 0.025, "{ori_deg}°");
        // No jitter, no change.
        let still = jittered(&log, 0.0, 0.0, 7);
        for (a, b) in log.samples.iter().zip(&still.samples) {
            assert_eq!(a.pos, b.pos);
            assert!(a
                .quat
                .iter()
                .zip(b.quat)
                .all(|(x, y)| (x - y).abs() < 1e-12));
        }
    }

    #[test]
    fn a_held_figurine_is_read_as_nothing_under_every_jitter_level() {
        // Nothing is read from the held pose, and nothing from any jittered copy of it.
        let log = held(90);
        let reader = Reader::shipped().unwrap();
        let (reading, _) = reader.reading(&log).unwrap();
        assert!(reading.is_empty(), "{reading:?}");
        let steady = steady_readings(&reader, &log, &reading, 3).unwrap();
        assert_eq!(steady, vec![JITTER_DRAWS as u32; JITTER_LEVELS.len()]);
        // Against a reading it does not give, no draw agrees.
        let walk = vec!["walk".to_string()];
        assert_eq!(
            steady_readings(&reader, &log, &walk, 3).unwrap(),
            vec![0; JITTER_LEVELS.len()]
        );
    }

    #[test]
    fn kept_truths_read_back_and_refuse_another_setup() {
        let dir = std::env::temp_dir().join(format!("figurine-trial-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("frames.csv");
        let setup = Setup::default();
        let truths = vec![FrameTruth {
            t: 0.1,
            pose: PoseSample {
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
            pose: PoseSample {
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
