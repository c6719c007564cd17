//! Replaying a pose log through a device: the same samples `figurine simulate` feeds its
//! in-process recognizer (log sample `i` goes out with sequence number `i` mod 2¹⁶, quantised
//! by `Pose::quantize`), the device's events mapped back to the log's clock.
//!
//! Flow control: poses go out in batches, each followed by a `Ping`; at most
//! [`BATCHES_IN_FLIGHT`] batches are unacknowledged, sized from the device's pose-queue
//! capacity, so a replay at full speed never overflows the device's queue. With a speed
//! factor, samples are also paced on the log's timestamps.

use std::time::{Duration, Instant};

use figurine_protocol::{ActionEvent, HostToDevice, Pose, Stats};

use super::{Device, LinkError};
use crate::events::{fold_revision, ActionRecord};
use crate::poselog::PoseLog;

/// Unacknowledged pose batches allowed on the link.
pub const BATCHES_IN_FLIGHT: usize = 2;

/// How to replay.
#[derive(Debug, Clone, Copy)]
pub struct ReplayOptions {
    /// Real-time factor (2.0 = twice as fast as recorded); `None` = as fast as the link and
    /// the device allow without dropping samples.
    pub speed: Option<f64>,
    /// Pace by acknowledged batches so the device's queue never overflows (default). Off,
    /// samples go out on the clock alone, and the device drops what it cannot keep up with
    /// (counted in `Stats::samples_dropped`) — what benchmarks of the sustained rate need.
    pub flow_control: bool,
}

impl Default for ReplayOptions {
    fn default() -> Self {
        ReplayOptions {
            speed: None,
            flow_control: true,
        }
    }
}

/// What a replay produced.
#[derive(Debug, Clone)]
pub struct Replay {
    /// Events as JSON-lines records (names, log seconds, efforts q/127), like `simulate`:
    /// one per action, revisions folded in.
    pub records: Vec<ActionRecord>,
    /// The device's events as received, each revision in place of the event it revises,
    /// with the moment the host decoded the latest.
    pub events: Vec<(ActionEvent, Instant)>,
    /// Revisions received (each folded into the event it revises).
    pub revised: u32,
    /// When each log sample was sent (`None`: the wire cannot carry it).
    pub sent_at: Vec<Option<Instant>>,
    /// Device statistics at the end of the log (before the closing reset).
    pub stats: Stats,
    /// Log samples the wire could not carry (NaN, beyond ±100 m, zero quaternion).
    pub unsendable: u64,
}

/// Maps a device event's 16-bit sequence numbers back to log sample indices: the end is the
/// latest index at or before `last_sent` with the same low 16 bits.
pub fn event_indices(e: &ActionEvent, last_sent: usize) -> (usize, usize) {
    let back = (last_sent as u16).wrapping_sub(e.end_seq) as usize;
    let end = last_sent.saturating_sub(back);
    (end.saturating_sub(usize::from(e.len)), end)
}

/// The JSON-lines record of a device event (names from the library, times from the log).
pub fn to_record(
    e: &ActionEvent,
    names: &[String],
    log: &PoseLog,
    last_sent: usize,
) -> ActionRecord {
    record_with_times(e, names, last_sent, |i| {
        log.samples.get(i).map_or(f64::NAN, |s| s.t)
    })
}

/// The record of a device event, given the time (seconds) of the `i`-th pose sent.
pub fn record_with_times(
    e: &ActionEvent,
    names: &[String],
    last_sent: usize,
    t: impl Fn(usize) -> f64,
) -> ActionRecord {
    let (start, end) = event_indices(e, last_sent);
    ActionRecord {
        action: names
            .get(usize::from(e.action))
            .cloned()
            .unwrap_or_else(|| format!("#{}", e.action)),
        start: t(start),
        end: t(end),
        time: f64::from(e.time) / 127.0,
        weight: f64::from(e.weight) / 127.0,
        distance: u32::from(e.distance),
    }
}

/// Replays `log` through `dev` (after resetting its session) and returns its events.
/// `on_event` sees each record as soon as it arrives, and whether it revises (replaces) the
/// previous one.
pub fn replay_log(
    dev: &mut Device,
    log: &PoseLog,
    names: &[String],
    opts: ReplayOptions,
    mut on_event: impl FnMut(&ActionRecord, bool),
) -> Result<Replay, LinkError> {
    dev.reset()?;
    dev.take_events()?;
    let batch = (usize::from(dev.hello().capacities.pose_queue) / 4).max(1);
    let mut out = Replay {
        records: Vec::new(),
        events: Vec::new(),
        revised: 0,
        sent_at: vec![None; log.samples.len()],
        stats: Stats::default(),
        unsendable: 0,
    };
    let mut last_sent = 0usize;
    let mut collect =
        |dev: &mut Device, out: &mut Replay, last_sent: usize| -> Result<(), LinkError> {
            for r in dev.take_events()? {
                let rec = to_record(&r.event, names, log, last_sent);
                on_event(&rec, r.revises);
                out.revised += u32::from(r.revises);
                // Only the event it names (same counter) is revised: after a lost message,
                // a revision stands as an event of its own.
                let revises =
                    r.revises && out.events.last().is_some_and(|(e, _)| e.seq == r.event.seq);
                fold_revision(&mut out.records, rec, revises);
                fold_revision(&mut out.events, (r.event, r.at), revises);
            }
            Ok(())
        };
    let t0 = log.samples.first().map_or(0.0, |s| s.t);
    let start = Instant::now();
    let mut in_flight = std::collections::VecDeque::new();
    let mut in_batch = 0usize;
    for (i, s) in log.samples.iter().enumerate() {
        let Ok(pose) = Pose::quantize(i as u16, s.t, s.pos, s.quat) else {
            out.unsendable += 1;
            continue;
        };
        if let Some(speed) = opts.speed.filter(|v| *v > 0.0) {
            let due = start + Duration::from_secs_f64(((s.t - t0) / speed).max(0.0));
            if let Some(wait) = due.checked_duration_since(Instant::now()) {
                std::thread::sleep(wait);
            }
        }
        dev.send(&HostToDevice::Pose(pose))?;
        out.sent_at[i] = Some(Instant::now());
        last_sent = i;
        in_batch += 1;
        if opts.flow_control && in_batch == batch {
            in_batch = 0;
            in_flight.push_back(dev.ping_async()?);
            if in_flight.len() > BATCHES_IN_FLIGHT {
                if let Some(v) = in_flight.pop_front() {
                    dev.wait_pong(v)?;
                }
            }
        }
        collect(dev, &mut out, last_sent)?;
    }
    while let Some(v) = in_flight.pop_front() {
        dev.wait_pong(v)?;
    }
    out.stats = dev.stats()?;
    dev.reset()?;
    collect(dev, &mut out, last_sent)?;
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ev(end_seq: u16, len: u16) -> ActionEvent {
        ActionEvent {
            seq: 0,
            action: 0,
            end_seq,
            len,
            time: 0,
            weight: 0,
            distance: 0,
        }
    }

    #[test]
    fn sequence_numbers_map_back_across_the_16_bit_wrap() {
        assert_eq!(event_indices(&ev(90, 40), 100), (50, 90));
        assert_eq!(event_indices(&ev(5, 10), 65_536 + 20), (65_531, 65_541));
        assert_eq!(event_indices(&ev(65_530, 10), 65_536 + 3), (65_520, 65_530));
        assert_eq!(event_indices(&ev(7, 100), 7), (0, 7));
    }
}
