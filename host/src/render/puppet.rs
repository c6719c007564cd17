//! Puppetry: recognised actions, as they arrive from figurines, drive characters in the live
//! viewer (`figurine live --view`).
//!
//! Each action is assembled when it arrives by the same assembler as `figurine animate` (clip,
//! effort retiming and reshaping, foot contacts), turned into drawable poses, and played from
//! the moment it arrived; between actions a character holds its last pose, and travelling
//! actions carry it on from where it stopped. One [`Puppet`] per figurine; [`spawn_puppets`]
//! runs them all on one thread that feeds a [`LiveFeed`] at [`PUPPET_HZ`].

use std::collections::BTreeMap;
use std::sync::mpsc::{Receiver, RecvTimeoutError, Sender};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use glam::Vec3;

use crate::anim::assemble::{assemble, AssembleOptions};
use crate::anim::library::ActionClip;
use crate::anim::AnimError;
use crate::events::ActionRecord;
use crate::render::from_clip::scene_from_clip;
use crate::render::live::LiveFeed;
use crate::render::scene::{FramePose, Scene, TimelineSpan};

/// Pose updates per second pushed to the viewer.
pub const PUPPET_HZ: f32 = 60.0;
/// Shortest and longest time an action is played for, seconds (the recognised segment's
/// length is clamped to this, so a glitchy 10 ms or 30 s segment still reads as the action).
pub const PLAY_RANGE_S: (f64, f64) = (0.4, 4.0);
/// Distance between neighbouring characters' home spots, metres.
pub const CHARACTER_SPACING_M: f32 = 2.0;

/// An action being played.
#[derive(Debug, Clone)]
struct Playing {
    scene: Scene,
    /// Feed time the action started, seconds.
    start: f32,
    /// Added to every bone so the action starts where the character stands.
    shift: Vec3,
}

/// One character driven by recognised actions.
#[derive(Debug, Clone)]
pub struct Puppet {
    clips: Arc<BTreeMap<String, ActionClip>>,
    forward: Vec3,
    /// Where the character stands now (ground point, world metres).
    at: Vec3,
    playing: Option<Playing>,
    hold: FramePose,
}

/// Horizontal centre of a pose's bones (y = 0), or `None` for an empty pose.
fn ground_centre(pose: &FramePose) -> Option<Vec3> {
    let n = pose.segments.len();
    if n == 0 {
        return None;
    }
    let sum: Vec3 = pose.segments.iter().map(|s| (s.start + s.end) * 0.5).sum();
    let c = sum / n as f32;
    Some(Vec3::new(c.x, 0.0, c.z))
}

fn shifted(mut pose: FramePose, by: Vec3) -> FramePose {
    for s in &mut pose.segments {
        s.start += by;
        s.end += by;
    }
    pose
}

impl Puppet {
    /// A character standing at `home` (world metres), acting with `clips` (rig facing
    /// `forward`); it starts in the first frame of the first clip.
    pub fn new(clips: Arc<BTreeMap<String, ActionClip>>, forward: Vec3, home: Vec3) -> Self {
        let mut p = Puppet {
            clips,
            forward,
            at: home,
            playing: None,
            hold: FramePose::default(),
        };
        let first = p.clips.keys().next().cloned();
        if let Some(action) = first {
            if let Ok(scene) = p.assemble_one(&action, 0.0, 0.0, 1.0) {
                let pose = scene.pose_at(0.0);
                let c = ground_centre(&pose).unwrap_or(Vec3::ZERO);
                p.hold = shifted(pose, home - c);
            }
        }
        p
    }

    fn assemble_one(
        &self,
        action: &str,
        time: f64,
        weight: f64,
        secs: f64,
    ) -> Result<Scene, AnimError> {
        let event = ActionRecord {
            action: action.to_string(),
            start: 0.0,
            end: secs,
            time,
            weight,
            distance: 0,
        };
        let opts = AssembleOptions {
            hold_s: 0.0,
            ..AssembleOptions::default()
        };
        let asm = assemble(&[event], None, &self.clips, self.forward, &opts)?;
        Ok(scene_from_clip(&asm.clip))
    }

    /// True if this character has a clip for `action`.
    pub fn knows(&self, action: &str) -> bool {
        self.clips.contains_key(action)
    }

    /// Starts playing a recognised action at feed time `now` (seconds). Unmapped actions are
    /// an error (and leave the character as it was).
    pub fn act(&mut self, rec: &ActionRecord, now: f32) -> Result<(), AnimError> {
        self.settle(now, true);
        let secs = (rec.end - rec.start).clamp(PLAY_RANGE_S.0, PLAY_RANGE_S.1);
        let secs = if secs.is_finite() {
            secs
        } else {
            PLAY_RANGE_S.0
        };
        let scene = self.assemble_one(&rec.action, rec.time, rec.weight, secs)?;
        let first = ground_centre(&scene.pose_at(0.0)).unwrap_or(Vec3::ZERO);
        self.playing = Some(Playing {
            scene,
            start: now,
            shift: self.at - first,
        });
        Ok(())
    }

    /// Ends the playing action if it is over (or `force`), keeping its pose and position.
    fn settle(&mut self, now: f32, force: bool) {
        let Some(p) = &self.playing else { return };
        let t = now - p.start;
        if !force && t <= p.scene.pose_duration() {
            return;
        }
        let pose = shifted(p.scene.pose_at(t), p.shift);
        if let Some(c) = ground_centre(&pose) {
            self.at = c;
        }
        self.hold = pose;
        self.playing = None;
    }

    /// The character's pose at feed time `now`, seconds.
    pub fn pose_at(&mut self, now: f32) -> FramePose {
        self.settle(now, false);
        match &self.playing {
            Some(p) => shifted(p.scene.pose_at(now - p.start), p.shift),
            None => self.hold.clone(),
        }
    }

    /// Whether an action is being played at `now`.
    pub fn is_acting(&self, now: f32) -> bool {
        self.playing
            .as_ref()
            .is_some_and(|p| now - p.start <= p.scene.pose_duration())
    }
}

/// A recognised action for character `.0`, received at `.2`.
pub type PuppetMessage = (u16, ActionRecord, Instant);

/// Runs one puppet per character on a thread: actions sent on the returned channel are played,
/// and every character's pose is pushed to `feed` [`PUPPET_HZ`] times a second, until the feed
/// is closed. Characters stand [`CHARACTER_SPACING_M`] apart.
pub fn spawn_puppets(
    feed: LiveFeed,
    clips: Arc<BTreeMap<String, ActionClip>>,
    forward: Vec3,
    characters: u16,
) -> (Sender<PuppetMessage>, JoinHandle<()>) {
    let (tx, rx) = std::sync::mpsc::channel();
    let handle = std::thread::spawn(move || run_puppets(&feed, &clips, forward, characters, &rx));
    (tx, handle)
}

fn run_puppets(
    feed: &LiveFeed,
    clips: &Arc<BTreeMap<String, ActionClip>>,
    forward: Vec3,
    characters: u16,
    rx: &Receiver<PuppetMessage>,
) {
    let mut puppets: Vec<Puppet> = (0..characters)
        .map(|c| {
            let home = Vec3::new(c as f32 * CHARACTER_SPACING_M, 0.0, 0.0);
            Puppet::new(Arc::clone(clips), forward, home)
        })
        .collect();
    let tick = Duration::from_secs_f32(1.0 / PUPPET_HZ);
    let mut warned = std::collections::BTreeSet::new();
    let mut channel_open = true;
    while !feed.is_closed() {
        let next = Instant::now() + tick;
        while channel_open {
            let wait = next.saturating_duration_since(Instant::now());
            match rx.recv_timeout(wait) {
                Ok((c, rec, arrived)) => {
                    let now = feed.now();
                    let Some(p) = puppets.get_mut(usize::from(c)) else {
                        continue;
                    };
                    match p.act(&rec, now) {
                        Ok(()) => {
                            let span = TimelineSpan {
                                action: rec.action.clone(),
                                start: now,
                                end: now
                                    + (rec.end - rec.start).clamp(PLAY_RANGE_S.0, PLAY_RANGE_S.1)
                                        as f32,
                                time: rec.time as f32,
                                weight: rec.weight as f32,
                            };
                            feed.push_event(span, arrived);
                            feed.push_pose(c, p.pose_at(now));
                        }
                        Err(e) => {
                            if warned.insert(rec.action.clone()) {
                                eprintln!("live view: cannot play `{}`: {e}", rec.action);
                            }
                        }
                    }
                }
                Err(RecvTimeoutError::Timeout) => break,
                Err(RecvTimeoutError::Disconnected) => channel_open = false,
            }
        }
        let now = feed.now();
        for (c, p) in puppets.iter_mut().enumerate() {
            feed.push_pose(c as u16, p.pose_at(now));
        }
        if !channel_open {
            std::thread::sleep(next.saturating_duration_since(Instant::now()));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::anim::library::ClipLibrary;

    fn default_clips() -> Option<(Arc<BTreeMap<String, ActionClip>>, Vec3)> {
        let lib = ClipLibrary::default_library().ok()?;
        let clips = lib.load(["walk", "jump", "punch"]).ok()?;
        Some((Arc::new(clips), lib.forward()))
    }

    fn rec(action: &str, dur: f64) -> ActionRecord {
        ActionRecord {
            action: action.into(),
            start: 10.0,
            end: 10.0 + dur,
            time: 0.5,
            weight: -0.5,
            distance: 0,
        }
    }

    #[test]
    fn actions_play_from_arrival_then_hold_and_carry_on_from_where_they_stopped() {
        let Some((clips, forward)) = default_clips() else {
            eprintln!("skipping: DeepMimic clips not found — run `cargo xtask setup`");
            return;
        };
        let mut p = Puppet::new(clips, forward, Vec3::new(4.0, 0.0, 0.0));
        let idle = p.pose_at(0.0);
        assert!(
            !idle.segments.is_empty(),
            "a character is visible before any action"
        );
        let c0 = ground_centre(&idle).unwrap();
        assert!(
            (c0 - Vec3::new(4.0, 0.0, 0.0)).length() < 0.05,
            "stands at home: {c0}"
        );

        p.act(&rec("walk", 2.0), 1.0).unwrap();
        assert!(p.is_acting(1.5));
        let a = p.pose_at(1.0);
        let b = p.pose_at(2.0);
        assert_ne!(a, b, "the action moves the character");
        let start = ground_centre(&a).unwrap();
        assert!(
            (start - c0).length() < 0.3,
            "the action starts where the character stood"
        );
        // Long after the action: held still, displaced by the walk.
        let end1 = p.pose_at(10.0);
        let end2 = p.pose_at(20.0);
        assert_eq!(end1, end2);
        assert!(!p.is_acting(10.0));
        let moved = ground_centre(&end1).unwrap() - c0;
        assert!(moved.length() > 0.3, "a walk travels: {moved}");
        // The next action starts from there, not from home.
        p.act(&rec("punch", 1.0), 30.0).unwrap();
        let next = ground_centre(&p.pose_at(30.0)).unwrap();
        assert!((next - ground_centre(&end1).unwrap()).length() < 0.3);
    }

    #[test]
    fn unknown_actions_are_refused_and_change_nothing() {
        let Some((clips, forward)) = default_clips() else {
            eprintln!("skipping: DeepMimic clips not found — run `cargo xtask setup`");
            return;
        };
        let mut p = Puppet::new(clips, forward, Vec3::ZERO);
        let before = p.pose_at(0.0);
        assert!(!p.knows("moonwalk"));
        assert!(p.act(&rec("moonwalk", 1.0), 0.5).is_err());
        assert_eq!(p.pose_at(0.6), before);
    }

    #[test]
    fn the_puppet_thread_feeds_every_character_and_times_events() {
        let Some((clips, forward)) = default_clips() else {
            eprintln!("skipping: DeepMimic clips not found — run `cargo xtask setup`");
            return;
        };
        let feed = LiveFeed::new();
        let (tx, handle) = spawn_puppets(feed.clone(), clips, forward, 2);
        tx.send((1, rec("jump", 1.0), Instant::now())).unwrap();
        // Wait for the thread to place the jump; a loaded machine (a whole test suite on two
        // cores) may take far longer than the usual few milliseconds.
        // A fast build may publish the jump's timeline before the second character's pose.
        let characters = |s: &crate::render::live::LiveFrame| {
            s.pose
                .segments
                .iter()
                .map(|s| s.character)
                .collect::<std::collections::BTreeSet<u16>>()
        };
        let deadline = Instant::now() + Duration::from_secs(20);
        let snap = loop {
            match feed.snapshot() {
                Some(s) if !s.timeline.is_empty() && characters(&s).len() == 2 => break s,
                Some(s) if Instant::now() > deadline => panic!(
                    "within 20 s: {} timeline entries, characters drawn {:?}",
                    s.timeline.len(),
                    characters(&s)
                ),
                None if Instant::now() > deadline => panic!("no poses with the jump within 20 s"),
                _ => std::thread::sleep(Duration::from_millis(20)),
            }
        };
        assert_eq!(snap.timeline.len(), 1);
        assert_eq!(snap.timeline[0].action, "jump");
        feed.close();
        drop(tx);
        handle.join().unwrap();
    }
}
