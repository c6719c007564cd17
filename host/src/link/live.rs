//! `figurine live`: poses from a source (a log replayed in real time, or CSV lines on stdin)
//! streamed to one or more figurines, events printed as they arrive, the session recorded.
//!
//! * The session log (`--record`) gets every pose line written and flushed as it is read, so
//!   Ctrl-C or an unplugged figurine loses nothing.
//! * Unplug/replug: when the link drops, poses keep being recorded while the host retries
//!   every [`RECONNECT_EVERY`]; after the handshake the stream resumes (the library persists
//!   on the device).
//! * Several `--port`s: one figurine per character, each in its own thread with its own
//!   source (`--log` given once per port, in the same order); events carry a `figurine` field.
//! * `--view`: puppetry. A window shows one character per figurine acting each recognised
//!   action as it arrives (see [`crate::render::puppet`]); closing it ends the session, and
//!   the time from event arrival to its first presented frame is reported.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::Sender;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use anyhow::{bail, Context, Result};
use clap::Args;
use figurine_protocol::{HostToDevice, Pose};

use super::blobs;
use super::lines::{PoseLines, MAX_LINE_BYTES};
use super::replay::record_with_times;
use super::{Device, PortSpec};
use crate::events::{event_line, ActionRecord};
use crate::poselog::PoseSample;
use crate::render::puppet::PuppetMessage;

/// Pause between reconnection attempts.
pub const RECONNECT_EVERY: Duration = Duration::from_millis(500);
/// Sample times remembered to map event sequence numbers back to seconds (one per 16-bit seq).
const SEQ_RING: usize = 1 << 16;

/// Arguments of `figurine live`.
#[derive(Args, Debug)]
pub struct LiveArgs {
    /// Serial device or tcp:HOST:PORT; repeat for several figurines (one per character).
    #[arg(long = "port", required = true)]
    pub ports: Vec<String>,
    /// Pose source: a log replayed in real time, one per port; default: CSV on stdin.
    #[arg(long = "log")]
    pub logs: Vec<PathBuf>,
    /// Real-time factor for `--log` sources.
    #[arg(long, default_value_t = 1.0)]
    pub speed: f64,
    /// Library the figurines run, for action names (default: the shipped library).
    #[arg(long)]
    pub library: Option<PathBuf>,
    /// Write the session's poses here (CSV, flushed per line); with several ports, `-N` is
    /// added before the extension for port N ≥ 2.
    #[arg(long)]
    pub record: Option<PathBuf>,
    /// Show the characters acting the recognised actions live in a window (puppetry).
    #[arg(long)]
    pub view: bool,
    /// Clip library for `--view` (action → clip); default: the built-in DeepMimic library.
    #[arg(long)]
    pub clips: Option<PathBuf>,
    /// With `--view`: close the window by itself after this many seconds (timed demos).
    #[arg(long)]
    pub quit_after: Option<f64>,
}

fn record_path(base: &Path, n: usize) -> PathBuf {
    if n == 0 {
        return base.to_path_buf();
    }
    let stem = base
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("session");
    let ext = base.extension().and_then(|s| s.to_str()).unwrap_or("csv");
    base.with_file_name(format!("{stem}-{}.{ext}", n + 1))
}

/// One figurine's live session.
struct Session<'a> {
    spec: PortSpec,
    label: String,
    names: &'a [String],
    dev: Option<Device>,
    next_retry: Instant,
    times: Vec<f64>,
    sent: usize,
    /// Poses [`Pose::quantize`] refused (recorded, not sent).
    unsendable: u64,
    record: Option<BufWriter<File>>,
    print: &'a Mutex<std::io::Stdout>,
    many: bool,
    /// With `--view`: this figurine's character and the puppets' channel.
    puppet: Option<(u16, Sender<PuppetMessage>)>,
    /// The last action sent to the puppet (a revision of the same action plays on from its
    /// end).
    last: Option<ActionRecord>,
}

impl Session<'_> {
    fn ensure_connected(&mut self) {
        if self.dev.is_some() || Instant::now() < self.next_retry {
            return;
        }
        match Device::connect(&self.spec) {
            Ok(d) => {
                eprintln!(
                    "{}: connected (library {:08x})",
                    self.label,
                    d.hello().library_crc
                );
                self.dev = Some(d);
            }
            Err(e) => {
                self.next_retry = Instant::now() + RECONNECT_EVERY;
                eprintln!("{}: {e}; retrying", self.label);
            }
        }
    }

    fn lost(&mut self, e: &dyn std::fmt::Display) {
        eprintln!(
            "{}: {e}; reconnecting (poses are still recorded)",
            self.label
        );
        self.dev = None;
        self.next_retry = Instant::now() + RECONNECT_EVERY;
    }

    fn print_events(&mut self) {
        let Some(dev) = self.dev.as_mut() else { return };
        let events = match dev.take_events() {
            Ok(e) => e,
            Err(e) => return self.lost(&e),
        };
        for r in events {
            let times = &self.times;
            let rec = record_with_times(&r.event, self.names, self.sent.saturating_sub(1), |i| {
                times.get(i % SEQ_RING).copied().unwrap_or(f64::NAN)
            });
            // Same JSON line as `simulate --jsonl` (a revision marked as such), plus the
            // port with several figurines.
            let mut line = event_line(&rec, r.revises);
            if self.many && line.ends_with('}') {
                line.pop();
                let label = serde_json::to_string(&self.label).unwrap_or_default();
                line.push_str(&format!(",\"figurine\":{label}}}"));
            }
            if let Ok(mut out) = self.print.lock() {
                let _ = writeln!(out, "{line}");
                let _ = out.flush();
            }
            if let Some((character, tx)) = &self.puppet {
                // A revision of the same action (its next cycles) plays on from where the
                // action had got to: the puppet is sent only the new part. Another action
                // replaces the one playing.
                let play = match self.last.replace(rec.clone()) {
                    Some(prev) if r.revises && prev.action == rec.action => ActionRecord {
                        start: prev.end.min(rec.end),
                        ..rec
                    },
                    _ => rec,
                };
                // The viewer may already be gone; the session goes on regardless.
                let _ = tx.send((*character, play, Instant::now()));
            }
        }
    }

    fn pose(&mut self, s: &PoseSample) -> Result<()> {
        if let Some(w) = self.record.as_mut() {
            writeln!(
                w,
                "{:.6},{:.6},{:.6},{:.6},{:.6},{:.6},{:.6},{:.6}",
                s.t, s.pos[0], s.pos[1], s.pos[2], s.quat[0], s.quat[1], s.quat[2], s.quat[3]
            )?;
            w.flush()?;
        }
        let i = self.sent;
        if let Some(slot) = self.times.get_mut(i % SEQ_RING) {
            *slot = s.t;
        }
        self.sent += 1;
        self.ensure_connected();
        match Pose::quantize(i as u16, s.t, s.pos, s.quat) {
            Ok(p) => {
                if let Some(dev) = self.dev.as_mut() {
                    if let Err(e) = dev.send(&HostToDevice::Pose(p)) {
                        self.lost(&e);
                    }
                }
            }
            // Recorded all the same: only the wire cannot carry it.
            Err(_) => self.unsendable += 1,
        }
        self.print_events();
        Ok(())
    }

    fn finish(&mut self) {
        if let Some(dev) = self.dev.as_mut() {
            if let Err(e) = dev.reset() {
                self.lost(&e);
            }
        }
        self.print_events();
        if self.unsendable > 0 {
            eprintln!(
                "{}: {} poses the wire cannot carry (a time or position out of its range, or \
                 not a number) were recorded but not sent",
                self.label, self.unsendable
            );
        }
    }
}

/// One figurine's part of a `live` run.
struct Plan {
    spec: PortSpec,
    source: Option<PathBuf>,
    speed: f64,
    record: Option<PathBuf>,
    puppet: Option<(u16, Sender<PuppetMessage>)>,
}

fn run_session(
    plan: Plan,
    names: &[String],
    print: &Mutex<std::io::Stdout>,
    many: bool,
    stop: &AtomicBool,
) -> Result<()> {
    let Plan {
        spec,
        source,
        speed,
        record,
        puppet,
    } = plan;
    let label = spec.to_string();
    let record = match record {
        Some(p) => {
            let mut w = BufWriter::new(
                File::create(&p).with_context(|| format!("creating {}", p.display()))?,
            );
            writeln!(w, "t,x,y,z,qw,qx,qy,qz")?;
            w.flush()?;
            Some(w)
        }
        None => None,
    };
    let mut s = Session {
        spec,
        label,
        names,
        dev: None,
        next_retry: Instant::now(),
        times: vec![f64::NAN; SEQ_RING],
        sent: 0,
        unsendable: 0,
        record,
        print,
        many,
        puppet,
        last: None,
    };
    s.ensure_connected();
    if let Some(dev) = s.dev.as_mut() {
        dev.reset()?;
        dev.take_events()?;
    }
    match source {
        Some(path) => {
            let log = crate::poselog::PoseLog::read_path(&path)?;
            let t0 = log.samples.first().map_or(0.0, |p| p.t);
            let start = Instant::now();
            for p in &log.samples {
                if stop.load(Ordering::Relaxed) {
                    break;
                }
                let due = start + Duration::from_secs_f64(((p.t - t0) / speed.max(1e-6)).max(0.0));
                if let Some(w) = due.checked_duration_since(Instant::now()) {
                    std::thread::sleep(w);
                }
                s.pose(p)?;
            }
        }
        None => {
            let stdin = std::io::stdin();
            let mut lines = PoseLines::new(stdin.lock());
            while let Some(p) = lines.next_sample()? {
                if stop.load(Ordering::Relaxed) {
                    break;
                }
                s.pose(&p)?;
            }
            let c = lines.counts();
            if c.dropped() > 0 {
                eprintln!(
                    "{}: {} input lines were not pose samples (t,x,y,z,qw,qx,qy,qz) and were \
                     dropped: {} malformed, {} longer than {MAX_LINE_BYTES} bytes",
                    s.label,
                    c.dropped(),
                    c.malformed,
                    c.too_long
                );
            }
        }
    }
    s.finish();
    Ok(())
}

/// `figurine live`.
pub fn live(args: &LiveArgs) -> Result<()> {
    if args.view && !cfg!(feature = "render") {
        bail!("--view needs the window viewer: build figurine with its default `render` feature");
    }
    let names = blobs::load(args.library.as_deref(), None)?.names;
    let specs = args
        .ports
        .iter()
        .map(|p| p.parse::<PortSpec>())
        .collect::<Result<Vec<_>, _>>()?;
    if specs.len() > 1 && args.logs.len() != specs.len() {
        bail!("with several --port, give one --log per port (stdin feeds a single figurine)");
    }
    if args.logs.len() > specs.len() {
        bail!("more --log than --port");
    }
    let print = Mutex::new(std::io::stdout());
    let many = specs.len() > 1;
    let stop = AtomicBool::new(false);
    let view = if args.view {
        Some(start_view(args, &names, specs.len())?)
    } else {
        None
    };
    std::thread::scope(|scope| {
        let handles: Vec<_> = specs
            .into_iter()
            .enumerate()
            .map(|(n, spec)| {
                let plan = Plan {
                    spec,
                    source: args.logs.get(n).cloned(),
                    speed: args.speed,
                    record: args.record.as_deref().map(|r| record_path(r, n)),
                    puppet: view.as_ref().map(|v| (n as u16, v.tx.clone())),
                };
                let (names, print, stop) = (&names, &print, &stop);
                scope.spawn(move || run_session(plan, names, print, many, stop))
            })
            .collect();
        #[cfg(feature = "render")]
        if let Some(v) = &view {
            // The window must live on the main thread; closing it ends the session.
            let opts = crate::render::viewer::ViewerOptions {
                quit_after: args
                    .quit_after
                    .filter(|s| s.is_finite() && *s > 0.0)
                    .map(Duration::from_secs_f64),
                ..Default::default()
            };
            let shown = crate::render::viewer::run_live_viewer(v.feed.clone(), opts);
            stop.store(true, Ordering::Relaxed);
            v.feed.close();
            if let Err(e) = shown {
                eprintln!("live view: {e}");
            }
        }
        handles
            .into_iter()
            .map(|h| {
                h.join()
                    .unwrap_or_else(|_| bail!("a session thread panicked"))
            })
            .collect::<Result<Vec<()>>>()
    })?;
    if let Some(v) = view {
        v.feed.close();
        drop(v.tx);
        let _ = v.thread.join();
    }
    Ok(())
}

/// The puppetry side of `live --view`: the feed the window shows and the puppets' channel.
struct View {
    feed: crate::render::live::LiveFeed,
    tx: Sender<PuppetMessage>,
    thread: std::thread::JoinHandle<()>,
}

fn start_view(args: &LiveArgs, names: &[String], characters: usize) -> Result<View> {
    use crate::anim::library::ClipLibrary;
    let lib = match &args.clips {
        Some(p) => ClipLibrary::read_path(p)?,
        None => ClipLibrary::default_library()?,
    };
    let mapped: Vec<&str> = names
        .iter()
        .map(String::as_str)
        .filter(|n| lib.actions.contains_key(*n))
        .collect();
    let unmapped: Vec<&str> = names
        .iter()
        .map(String::as_str)
        .filter(|n| !lib.actions.contains_key(*n))
        .collect();
    if !unmapped.is_empty() {
        eprintln!(
            "live view: no clip for {}; those actions are printed but not acted",
            unmapped.join(", ")
        );
    }
    if mapped.is_empty() {
        bail!(
            "live view: the clip library {} maps none of the figurine's actions",
            lib.origin
        );
    }
    let clips = Arc::new(lib.load(mapped)?);
    let feed = crate::render::live::LiveFeed::new();
    let characters = u16::try_from(characters).unwrap_or(u16::MAX);
    let (tx, thread) =
        crate::render::puppet::spawn_puppets(feed.clone(), clips, lib.forward(), characters);
    Ok(View { feed, tx, thread })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn record_paths_number_extra_figurines() {
        assert_eq!(
            record_path(Path::new("/tmp/s.csv"), 0),
            PathBuf::from("/tmp/s.csv")
        );
        assert_eq!(
            record_path(Path::new("/tmp/s.csv"), 1),
            PathBuf::from("/tmp/s-2.csv")
        );
    }
}
