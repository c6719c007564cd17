//! Pose-log CSV reading and writing: the recorded-log format of DESIGN.md.
//!
//! ```text
//! t,x,y,z,qw,qx,qy,qz
//! 0.0000,-0.94631,0.84871,0.45586,0.892740,0.016955,0.441882,0.086416
//! ```
//! A header line is required; lines starting with `#` are comments; columns after `qz` are
//! ignored. Time is in seconds, position in metres (world, +Y up), orientation a quaternion
//! (w, x, y, z) mapping object-local vectors to world. A malformed line is an error naming the
//! file and the 1-based line number. Values are parsed as written: non-finite numbers and odd
//! timestamps are the recognizer's business (it counts and skips them), not the reader's.

use std::fmt::Write as _;
use std::io::{BufRead, BufReader, Read, Write};
use std::path::{Path, PathBuf};

use thiserror::Error;

/// The column names the header must start with, in order.
pub const HEADER: [&str; 8] = ["t", "x", "y", "z", "qw", "qx", "qy", "qz"];

/// One recorded pose sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PoseSample {
    /// Time of the sample, seconds on the log's clock.
    pub t: f64,
    /// Position in world metres (x, y, z), +Y up.
    pub pos: [f64; 3],
    /// Orientation quaternion (w, x, y, z), object-local to world; need not be normalised.
    pub quat: [f64; 4],
}

/// A whole pose log, in file order.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PoseLog {
    /// The samples, in the order of the file.
    pub samples: Vec<PoseSample>,
}

/// Why a pose log could not be read.
#[derive(Debug, Error)]
pub enum PoseLogError {
    /// The file could not be opened or read.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// A line of the file is malformed.
    #[error("{path}:{line}: {reason}")]
    Malformed {
        /// The file (or `<input>` for a stream).
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// What is wrong with it.
        reason: String,
    },
}

impl PoseLog {
    /// This log with `seconds` of stillness after it: its last sample repeated at the log's
    /// last step (at least 1 ms), as a figurine left resting would go on reporting. A log of
    /// fewer than two samples is returned as it is.
    pub fn rested(&self, seconds: f64) -> PoseLog {
        let mut out = self.clone();
        let n = self.samples.len();
        if let (Some(a), Some(b)) = (self.samples.get(n.wrapping_sub(2)), self.samples.last()) {
            let dt = (b.t - a.t).max(1e-3);
            let steps = (seconds / dt) as usize;
            out.samples.extend((1..=steps).map(|k| PoseSample {
                t: b.t + dt * k as f64,
                ..*b
            }));
        }
        out
    }

    /// Reads a pose log from a file; errors name the file and line.
    pub fn read_path(path: &Path) -> Result<Self, PoseLogError> {
        let file = std::fs::File::open(path).map_err(|source| PoseLogError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Self::read(file, path)
    }

    /// Reads a pose log from any reader; `name` is used in error messages.
    pub fn read<R: Read>(reader: R, name: &Path) -> Result<Self, PoseLogError> {
        let malformed = |line: usize, reason: String| PoseLogError::Malformed {
            path: name.to_path_buf(),
            line,
            reason,
        };
        let mut samples = Vec::new();
        let mut seen_header = false;
        let mut reader = BufReader::new(reader);
        let mut buf = Vec::new();
        let mut line_no = 0usize;
        loop {
            buf.clear();
            let n = reader
                .read_until(b'\n', &mut buf)
                .map_err(|source| PoseLogError::Io {
                    path: name.to_path_buf(),
                    source,
                })?;
            if n == 0 {
                break;
            }
            line_no += 1;
            let text = std::str::from_utf8(&buf)
                .map_err(|_| malformed(line_no, "not UTF-8 text".into()))?;
            let text = text.trim_end_matches(['\n', '\r']).trim();
            if text.is_empty() || text.starts_with('#') {
                continue;
            }
            if !seen_header {
                let cols: Vec<&str> = text.split(',').map(str::trim).collect();
                if cols.len() < HEADER.len()
                    || !cols
                        .iter()
                        .zip(HEADER)
                        .all(|(c, h)| c.eq_ignore_ascii_case(h))
                {
                    return Err(malformed(
                        line_no,
                        format!(
                            "expected header starting `{}`, found `{text}`",
                            HEADER.join(",")
                        ),
                    ));
                }
                seen_header = true;
                continue;
            }
            let mut values = [0f64; 8];
            let mut fields = text.split(',');
            for (i, v) in values.iter_mut().enumerate() {
                let field = fields
                    .next()
                    .ok_or_else(|| malformed(line_no, format!("expected 8 columns, found {i}")))?;
                *v = field.trim().parse::<f64>().map_err(|_| {
                    malformed(
                        line_no,
                        format!("column `{}`: `{}` is not a number", HEADER[i], field.trim()),
                    )
                })?;
            }
            let [t, x, y, z, qw, qx, qy, qz] = values;
            samples.push(PoseSample {
                t,
                pos: [x, y, z],
                quat: [qw, qx, qy, qz],
            });
        }
        if !seen_header {
            return Err(malformed(
                line_no.max(1),
                "empty file: no header line".into(),
            ));
        }
        Ok(PoseLog { samples })
    }

    /// Writes the log in the canonical format (header, 6 decimals for time, 6 for values).
    pub fn write<W: Write>(&self, mut w: W) -> std::io::Result<()> {
        let mut out = String::with_capacity(64 * (self.samples.len() + 1));
        out.push_str(&HEADER.join(","));
        out.push('\n');
        for s in &self.samples {
            let _ = writeln!(
                out,
                "{:.6},{:.6},{:.6},{:.6},{:.6},{:.6},{:.6},{:.6}",
                s.t, s.pos[0], s.pos[1], s.pos[2], s.quat[0], s.quat[1], s.quat[2], s.quat[3]
            );
        }
        w.write_all(out.as_bytes())
    }

    /// Writes the log to a file.
    pub fn write_path(&self, path: &Path) -> Result<(), PoseLogError> {
        let io = |source| PoseLogError::Io {
            path: path.to_path_buf(),
            source,
        };
        let file = std::fs::File::create(path).map_err(io)?;
        let mut w = std::io::BufWriter::new(file);
        self.write(&mut w).map_err(io)?;
        w.flush().map_err(io)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<PoseLog, PoseLogError> {
        PoseLog::read(text.as_bytes(), Path::new("mem.csv"))
    }

    #[test]
    fn a_rested_log_repeats_its_last_pose_at_its_last_step() {
        let at = |t: f64, x: f64| PoseSample {
            t,
            pos: [x, 1.0, 0.0],
            quat: [1.0, 0.0, 0.0, 0.0],
        };
        let log = PoseLog {
            samples: vec![at(0.0, 0.0), at(0.01, 0.1), at(0.03, 0.2)],
        };
        let r = log.rested(0.1);
        assert_eq!(r.samples.get(..3), Some(&log.samples[..]));
        assert_eq!(r.samples.len(), 3 + 5);
        for (k, s) in r.samples.iter().skip(3).enumerate() {
            assert!(
                (s.t - (0.03 + 0.02 * (k + 1) as f64)).abs() < 1e-12,
                "{}",
                s.t
            );
            assert_eq!((s.pos, s.quat), (at(0.0, 0.2).pos, at(0.0, 0.2).quat));
        }
        // Fewer than two samples give no step to repeat at.
        let one = PoseLog {
            samples: vec![at(0.0, 0.0)],
        };
        assert_eq!(one.rested(1.0), one);
    }

    #[test]
    fn reads_the_design_example_with_comments_and_extra_columns() {
        let log = parse(
            "# recorded by hand\nt,x,y,z,qw,qx,qy,qz,extra\r\n\
             0.0000,-0.94631,0.84871,0.45586,0.892740,0.016955,0.441882,0.086416,7\n\
             # a comment mid-file\n0.0167,1,2,3,1,0,0,0\n",
        )
        .unwrap();
        assert_eq!(log.samples.len(), 2);
        assert_eq!(log.samples[0].pos, [-0.94631, 0.84871, 0.45586]);
        assert_eq!(log.samples[1].t, 0.0167);
        assert_eq!(log.samples[1].quat, [1.0, 0.0, 0.0, 0.0]);
    }

    #[test]
    fn malformed_lines_name_file_and_line() {
        let err =
            parse("t,x,y,z,qw,qx,qy,qz\n0,1,2,3,1,0,0,0\n0.1,1,2,oops,1,0,0,0\n").unwrap_err();
        let msg = err.to_string();
        assert!(msg.starts_with("mem.csv:3:"), "{msg}");
        assert!(msg.contains("oops"), "{msg}");
        let err = parse("t,x,y,z,qw,qx,qy,qz\n0,1,2\n").unwrap_err();
        assert!(err.to_string().starts_with("mem.csv:2:"), "{err}");
        let err = parse("a,b,c\n").unwrap_err();
        assert!(err.to_string().contains("expected header"), "{err}");
        assert!(parse("").is_err());
    }

    #[test]
    fn binary_junk_is_an_error_not_a_panic() {
        let junk: Vec<u8> = (0..=255u8).cycle().take(4096).collect();
        assert!(PoseLog::read(&junk[..], Path::new("junk")).is_err());
    }

    #[test]
    fn write_then_read_round_trips() {
        let log = PoseLog {
            samples: (0..10)
                .map(|i| PoseSample {
                    t: i as f64 / 60.0,
                    pos: [i as f64 * 0.1, 0.5, -0.25],
                    quat: [1.0, 0.0, 0.0, 0.0],
                })
                .collect(),
        };
        let mut bytes = Vec::new();
        log.write(&mut bytes).unwrap();
        let back = PoseLog::read(&bytes[..], Path::new("x")).unwrap();
        assert_eq!(back.samples.len(), 10);
        for (a, b) in log.samples.iter().zip(&back.samples) {
            assert!((a.t - b.t).abs() < 1e-6);
            assert!((a.pos[0] - b.pos[0]).abs() < 1e-6);
        }
    }
}
