//! Recognised-action events as the host sees them: the JSON lines of `figurine simulate`.
//!
//! One object per recognised action, in time order:
//! `{"action":"jump","start":1.23,"end":2.01,"time":0.62,"weight":-0.31,"distance":1}`.
//! This is the boundary between recognition and animation: `animate --events` reads it, the
//! renderer draws it as a timeline, the device link prints it.
//!
//! Streams printed while a figurine plays (`figurine live`, `figurine replay`) may also hold
//! revision lines, the same object plus `"revises":true`, which replace the line before: the
//! action went on (a walk's next hops after a short pause: same start, a later end), or a
//! longer action took over one reported early (a punch held at full reach after strides
//! that alone read as a run). [`read_events`] folds them, so such a stream reads as one
//! object per action, like `simulate`'s.

use std::io::{BufRead, BufReader, Read, Write};
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use thiserror::Error;

/// One recognised action with its Laban efforts.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ActionRecord {
    /// Action name from the library (e.g. `"jump"`).
    pub action: String,
    /// Segment start, seconds on the log's clock.
    pub start: f64,
    /// Segment end, seconds on the log's clock.
    pub end: f64,
    /// Laban Time effort Lt in [-1, 1]: > 0 sudden, < 0 sustained.
    pub time: f64,
    /// Laban Weight effort Lw in [-1, 1]: > 0 strong, < 0 light.
    pub weight: f64,
    /// Edit distance of the approximate match, whole edits (0 = exact; a near substitution —
    /// the same stroke with another rotation, or one 45° off — counts half; rounded up).
    pub distance: u32,
}

/// Why an event file could not be read.
#[derive(Debug, Error)]
pub enum EventsError {
    /// The file could not be opened or read.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// A line is not a valid event object.
    #[error("{path}:{line}: {reason}")]
    Malformed {
        /// The file.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// What is wrong with it.
        reason: String,
    },
}

/// Reads JSON-lines events from a file (blank lines ignored); errors name file and line.
pub fn read_events_path(path: &Path) -> Result<Vec<ActionRecord>, EventsError> {
    let file = std::fs::File::open(path).map_err(|source| EventsError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    read_events(file, path)
}

/// Reads JSON-lines events from any reader; `name` is used in error messages.
pub fn read_events<R: Read>(reader: R, name: &Path) -> Result<Vec<ActionRecord>, EventsError> {
    let mut out: Vec<ActionRecord> = Vec::new();
    for (i, line) in BufReader::new(reader).lines().enumerate() {
        let line = line.map_err(|e| EventsError::Malformed {
            path: name.to_path_buf(),
            line: i + 1,
            reason: e.to_string(),
        })?;
        if line.trim().is_empty() {
            continue;
        }
        let Line { rec, revises } =
            serde_json::from_str(&line).map_err(|e| EventsError::Malformed {
                path: name.to_path_buf(),
                line: i + 1,
                reason: e.to_string(),
            })?;
        if !(rec.start.is_finite() && rec.end.is_finite() && rec.end >= rec.start) {
            return Err(EventsError::Malformed {
                path: name.to_path_buf(),
                line: i + 1,
                reason: format!("bad segment times start={} end={}", rec.start, rec.end),
            });
        }
        fold_revision(&mut out, rec, revises);
    }
    Ok(out)
}

/// Appends `item` to a list of actions, or — when it `revises` the last one (a device's
/// `Revised`, a `"revises":true` line) — puts it in that one's place. Every reader of event
/// streams folds revisions this one way.
pub fn fold_revision<T>(list: &mut Vec<T>, item: T, revises: bool) {
    match list.last_mut() {
        Some(last) if revises => *last = item,
        _ => list.push(item),
    }
}

/// One line of an event stream: an action, possibly revising the previous one.
#[derive(Deserialize)]
struct Line {
    #[serde(flatten)]
    rec: ActionRecord,
    #[serde(default)]
    revises: bool,
}

/// Writes one event as a JSON line.
pub fn write_event<W: Write>(mut w: W, rec: &ActionRecord) -> std::io::Result<()> {
    let line = serde_json::to_string(rec).map_err(std::io::Error::other)?;
    writeln!(w, "{line}")
}

/// The JSON line of an action update: `rec` itself when it is a new action, `rec` plus
/// `"revises":true` when it revises (replaces) the previous line's action.
pub fn event_line(rec: &ActionRecord, revises: bool) -> String {
    let mut line = serde_json::to_string(rec).unwrap_or_default();
    if revises && line.ends_with('}') {
        line.pop();
        line.push_str(",\"revises\":true}");
    }
    line
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_revision_line_replaces_the_action_before_it() {
        let walk = ActionRecord {
            action: "walk".into(),
            start: 1.0,
            end: 2.0,
            time: 0.1,
            weight: -0.2,
            distance: 0,
        };
        let longer = ActionRecord {
            end: 3.5,
            distance: 1,
            ..walk.clone()
        };
        let jump = ActionRecord {
            action: "jump".into(),
            start: 4.0,
            end: 4.6,
            ..walk.clone()
        };
        // A run reported early, then taken over by the punch it was the start of.
        let run = ActionRecord {
            action: "run".into(),
            start: 5.0,
            end: 5.4,
            ..walk.clone()
        };
        let punch = ActionRecord {
            action: "punch".into(),
            end: 6.1,
            ..run.clone()
        };
        let text = [
            event_line(&walk, false),
            event_line(&longer, true),
            event_line(&jump, false),
            event_line(&run, false),
            event_line(&punch, true),
        ]
        .join("\n");
        assert!(text.contains(r#""distance":1,"revises":true}"#), "{text}");
        let got = read_events(text.as_bytes(), Path::new("stream.jsonl")).unwrap();
        assert_eq!(got, [longer, jump, punch]);
    }

    #[test]
    fn reads_the_contract_line_and_round_trips() {
        let text =
            r#"{"action":"jump","start":1.23,"end":2.01,"time":0.62,"weight":-0.31,"distance":1}"#;
        let evs = read_events(text.as_bytes(), Path::new("e.jsonl")).unwrap();
        assert_eq!(evs.len(), 1);
        assert_eq!(evs[0].action, "jump");
        assert_eq!(evs[0].distance, 1);
        let mut out = Vec::new();
        write_event(&mut out, &evs[0]).unwrap();
        let back = read_events(&out[..], Path::new("x")).unwrap();
        assert_eq!(back, evs);
    }

    #[test]
    fn malformed_lines_name_file_and_line() {
        let text = "\n{\"action\":\"a\",\"start\":0,\"end\":1,\"time\":0,\"weight\":0,\"distance\":0}\n{oops\n";
        let err = read_events(text.as_bytes(), Path::new("e.jsonl")).unwrap_err();
        assert!(err.to_string().starts_with("e.jsonl:3:"), "{err}");
        let text =
            "{\"action\":\"a\",\"start\":2,\"end\":1,\"time\":0,\"weight\":0,\"distance\":0}";
        assert!(read_events(text.as_bytes(), Path::new("e")).is_err());
    }
}
