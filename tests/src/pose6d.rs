//! Real 6-DoF tracker streams (`pose6d/` data: TUM RGB-D and EuRoC MAV ground truth) as
//! figurine pose logs, for replaying through the device.

use std::path::Path;

use anyhow::{bail, Context, Result};
use figurine_host::poselog::{PoseLog, PoseSample};

/// Reads a TUM (`t tx ty tz qx qy qz qw`, seconds) or EuRoC (`ns,x,y,z,qw,qx,qy,qz,…`)
/// trajectory; at most `limit` samples.
pub fn read(path: &Path, limit: usize) -> Result<PoseLog> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let euroc = path.extension().is_some_and(|e| e == "csv");
    let mut samples = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let v: Vec<f64> = line
            .split(|c: char| c == ',' || c.is_whitespace())
            .filter(|s| !s.is_empty())
            .map(str::parse)
            .collect::<Result<_, _>>()
            .with_context(|| format!("{}:{}", path.display(), n + 1))?;
        if v.len() < 8 {
            bail!("{}:{}: expected 8 columns", path.display(), n + 1);
        }
        samples.push(if euroc {
            PoseSample {
                t: v[0] * 1e-9,
                pos: [v[1], v[2], v[3]],
                quat: [v[4], v[5], v[6], v[7]],
            }
        } else {
            PoseSample {
                t: v[0],
                pos: [v[1], v[2], v[3]],
                quat: [v[7], v[4], v[5], v[6]],
            }
        });
        if samples.len() == limit {
            break;
        }
    }
    // The log's clock starts at zero, as recorded logs do.
    let t0 = samples.first().map_or(0.0, |s| s.t);
    for s in &mut samples {
        s.t -= t0;
    }
    Ok(PoseLog { samples })
}
