//! The live pose feed for puppetry: producers (the device link, the animation assembler) push
//! poses and recognised actions from any thread; the viewer shows the newest pose of every
//! character and reports, per action event, the time from the event's arrival to the first
//! presented frame that shows a pose pushed after it ("event to first frame").
//!
//! Capacities: at most [`MAX_CHARACTERS`] characters (more are dropped and counted), at most
//! [`TIMELINE_CAPACITY`] timeline spans (the oldest are dropped), at most
//! [`LATENCY_CAPACITY`] latency samples (the oldest are dropped; counts keep growing).

use std::collections::{BTreeMap, VecDeque};
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::{Duration, Instant};

use super::scene::{FramePose, TimelineSpan};

/// Most characters (figurines) shown at once.
pub const MAX_CHARACTERS: usize = 16;
/// Most timeline spans kept.
pub const TIMELINE_CAPACITY: usize = 512;
/// Most latency samples kept for statistics.
pub const LATENCY_CAPACITY: usize = 4096;
/// Events whose first frame is still pending, at most; older ones are dropped and counted.
pub const PENDING_CAPACITY: usize = 64;

/// Summary of event-to-first-frame latencies.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct LatencyStats {
    /// Events measured since the feed started.
    pub count: u64,
    /// Median of the kept samples.
    pub median: Duration,
    /// 95th percentile of the kept samples.
    pub p95: Duration,
    /// Largest kept sample.
    pub max: Duration,
    /// Most recent sample.
    pub last: Duration,
}

/// A snapshot for drawing one frame.
#[derive(Debug, Clone, PartialEq)]
pub struct LiveFrame {
    /// Sequence number of the newest pose included (for [`LiveFeed::frame_presented`]).
    pub seq: u64,
    /// Seconds since the feed started (the live clock of the timeline).
    pub now: f32,
    /// All characters' bones together (each bone carries its character index).
    pub pose: FramePose,
    /// Recent recognised actions, on the live clock.
    pub timeline: Vec<TimelineSpan>,
}

#[derive(Debug)]
struct State {
    started: Instant,
    seq: u64,
    poses: BTreeMap<u16, FramePose>,
    timeline: VecDeque<TimelineSpan>,
    /// Events waiting for their first pose: arrival instants.
    waiting: Vec<Instant>,
    /// (first pose seq, arrival) of events waiting to be presented.
    pending: VecDeque<(u64, Instant)>,
    latencies: VecDeque<Duration>,
    measured: u64,
    dropped_characters: u64,
    dropped_events: u64,
    closed: bool,
}

/// A cloneable handle to the shared live state.
#[derive(Debug, Clone)]
pub struct LiveFeed {
    inner: Arc<Mutex<State>>,
}

impl Default for LiveFeed {
    fn default() -> Self {
        Self::new()
    }
}

impl LiveFeed {
    /// An empty feed whose clock starts now.
    pub fn new() -> Self {
        LiveFeed {
            inner: Arc::new(Mutex::new(State {
                started: Instant::now(),
                seq: 0,
                poses: BTreeMap::new(),
                timeline: VecDeque::new(),
                waiting: Vec::new(),
                pending: VecDeque::new(),
                latencies: VecDeque::new(),
                measured: 0,
                dropped_characters: 0,
                dropped_events: 0,
                closed: false,
            })),
        }
    }

    fn lock(&self) -> MutexGuard<'_, State> {
        // A panicking producer must not take the viewer down: use the data as it is.
        self.inner.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Seconds since the feed started.
    pub fn now(&self) -> f32 {
        self.lock().started.elapsed().as_secs_f32()
    }

    /// Replaces the pose of `character` (its bones are re-tagged with that index).
    pub fn push_pose(&self, character: u16, mut pose: FramePose) {
        let mut s = self.lock();
        if !s.poses.contains_key(&character) && s.poses.len() >= MAX_CHARACTERS {
            s.dropped_characters += 1;
            return;
        }
        for seg in &mut pose.segments {
            seg.character = character;
        }
        s.seq += 1;
        let seq = s.seq;
        let waiting = std::mem::take(&mut s.waiting);
        for arrived in waiting {
            if s.pending.len() >= PENDING_CAPACITY {
                s.pending.pop_front();
                s.dropped_events += 1;
            }
            s.pending.push_back((seq, arrived));
        }
        s.poses.insert(character, pose);
    }

    /// Records a recognised action that arrived at `arrived`; the next pushed pose is its first.
    pub fn push_event(&self, span: TimelineSpan, arrived: Instant) {
        let mut s = self.lock();
        if s.timeline.len() >= TIMELINE_CAPACITY {
            s.timeline.pop_front();
        }
        s.timeline.push_back(span);
        if s.waiting.len() >= PENDING_CAPACITY {
            s.waiting.remove(0);
            s.dropped_events += 1;
        }
        s.waiting.push(arrived);
    }

    /// The newest poses and timeline, if any pose was pushed.
    pub fn snapshot(&self) -> Option<LiveFrame> {
        let s = self.lock();
        if s.poses.is_empty() {
            return None;
        }
        let mut pose = FramePose::default();
        for p in s.poses.values() {
            pose.segments.extend_from_slice(&p.segments);
            if pose.facing.is_none() {
                pose.facing = p.facing;
            }
        }
        Some(LiveFrame {
            seq: s.seq,
            now: s.started.elapsed().as_secs_f32(),
            pose,
            timeline: s.timeline.iter().cloned().collect(),
        })
    }

    /// Tells the feed that a frame including poses up to `seq` was presented at `at`; every
    /// event whose first pose is included gets its latency measured.
    pub fn frame_presented(&self, seq: u64, at: Instant) {
        let mut s = self.lock();
        while let Some(&(first, arrived)) = s.pending.front() {
            if first > seq {
                break;
            }
            s.pending.pop_front();
            if s.latencies.len() >= LATENCY_CAPACITY {
                s.latencies.pop_front();
            }
            s.latencies.push_back(at.saturating_duration_since(arrived));
            s.measured += 1;
        }
    }

    /// Event-to-first-frame statistics so far.
    pub fn latency_stats(&self) -> LatencyStats {
        let s = self.lock();
        let mut v: Vec<Duration> = s.latencies.iter().copied().collect();
        let last = v.last().copied().unwrap_or_default();
        v.sort();
        let pick = |q: f64| -> Duration {
            if v.is_empty() {
                Duration::ZERO
            } else {
                v[((v.len() - 1) as f64 * q).round() as usize]
            }
        };
        LatencyStats {
            count: s.measured,
            median: pick(0.5),
            p95: pick(0.95),
            max: v.last().copied().unwrap_or_default(),
            last,
        }
    }

    /// Events or characters dropped because a capacity was full: (characters, events).
    pub fn dropped(&self) -> (u64, u64) {
        let s = self.lock();
        (s.dropped_characters, s.dropped_events)
    }

    /// Marks the feed finished (the producer is done); the viewer may close.
    pub fn close(&self) {
        self.lock().closed = true;
    }

    /// Whether [`LiveFeed::close`] was called.
    pub fn is_closed(&self) -> bool {
        self.lock().closed
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::scene::BoneSegment;
    use glam::Vec3;

    fn pose() -> FramePose {
        FramePose {
            segments: vec![BoneSegment::new(Vec3::ZERO, Vec3::Y)],
            facing: None,
        }
    }

    fn span() -> TimelineSpan {
        TimelineSpan {
            action: "jump".into(),
            start: 0.0,
            end: 1.0,
            time: 0.5,
            weight: 0.5,
        }
    }

    #[test]
    fn latency_counts_from_event_to_presented_pose() {
        let feed = LiveFeed::new();
        let t0 = Instant::now();
        feed.push_event(span(), t0);
        // A frame presented before any pose for the event does not count.
        feed.frame_presented(0, t0 + Duration::from_millis(5));
        assert_eq!(feed.latency_stats().count, 0);
        feed.push_pose(0, pose());
        let snap = feed.snapshot().expect("pose");
        feed.frame_presented(snap.seq, t0 + Duration::from_millis(20));
        let st = feed.latency_stats();
        assert_eq!(st.count, 1);
        assert_eq!(st.last, Duration::from_millis(20));
        assert_eq!(snap.timeline.len(), 1);
    }

    #[test]
    fn characters_are_tagged_and_bounded() {
        let feed = LiveFeed::new();
        for c in 0..(MAX_CHARACTERS as u16 + 3) {
            feed.push_pose(c, pose());
        }
        let snap = feed.snapshot().expect("poses");
        assert_eq!(snap.pose.segments.len(), MAX_CHARACTERS);
        assert_eq!(snap.pose.segments[3].character, 3);
        assert_eq!(feed.dropped().0, 3);
        // Updating an existing character replaces its pose.
        feed.push_pose(3, pose());
        assert_eq!(
            feed.snapshot().map(|s| s.pose.segments.len()),
            Some(MAX_CHARACTERS)
        );
    }

    #[test]
    fn feed_is_shared_across_threads() {
        let feed = LiveFeed::new();
        let producer = feed.clone();
        let h = std::thread::spawn(move || {
            for _ in 0..100 {
                producer.push_event(span(), Instant::now());
                producer.push_pose(0, pose());
            }
            producer.close();
        });
        h.join().expect("producer");
        assert!(feed.is_closed());
        let snap = feed.snapshot().expect("pose");
        feed.frame_presented(snap.seq, Instant::now());
        assert_eq!(feed.latency_stats().count, PENDING_CAPACITY as u64);
        assert!(feed.dropped().1 > 0);
    }
}
