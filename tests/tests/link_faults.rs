//! Link faults against the real firmware in QEMU: random byte corruption (1 % and 10 %),
//! truncated frames, oversize frames, bursts of zeros, and the host disconnecting and
//! reconnecting mid-frame.
//!
//! Every injected byte is also fed to a host-side model of the firmware's receiver (the same
//! `FrameDecoder` and message decoding), so the device's `Stats` must match the model
//! *exactly*, counter by counter. On top of that, fault-model-independent assertions: no
//! request waits longer than [`ANSWER_BOUND`], every pose frame that reached the wire intact
//! is processed, nothing is dropped, and the host resumes within 1 s of reconnecting.
//! Randomness is seeded (xorshift), so a failure reproduces.

use std::time::{Duration, Instant};

use figurine_e2e::{Qemu, QemuOptions};
use figurine_host::link::device::Device;
use figurine_protocol::{
    encode_frame_guarded, peek_hello_version, FrameDecoder, FrameError, HostToDevice, Pose,
    RawDecoded, Stats, MAX_FRAME_LEN,
};

/// Longest any request (a `Ping` after a burst of faults) may wait for its answer.
const ANSWER_BOUND: Duration = Duration::from_secs(1);
/// Longest the host may take to be talking to the device again after reconnecting.
const RESUME_BOUND: Duration = Duration::from_secs(1);
/// Pose frames sent between two pings (well inside the device's pose queue).
const BATCH: usize = 8;

/// Seeded xorshift64 generator.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }

    /// Uniform in `0..n` (`n` > 0; the modulo bias is irrelevant here).
    fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }

    /// True with probability `p`.
    fn chance(&mut self, p: f64) -> bool {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64 <= p
    }
}

/// What the device's receiver should have counted.
#[derive(Debug, Default, Clone, Copy, PartialEq, Eq)]
struct Counts {
    frames_ok: u32,
    crc_errors: u32,
    cobs_errors: u32,
    decode_errors: u32,
    oversize: u32,
    samples: u32,
    samples_dropped: u32,
}

impl Counts {
    /// Counter increments from `a` to `b`.
    fn between(a: &Stats, b: &Stats) -> Counts {
        Counts {
            frames_ok: b.frames_ok.wrapping_sub(a.frames_ok),
            crc_errors: b.crc_errors.wrapping_sub(a.crc_errors),
            cobs_errors: b.cobs_errors.wrapping_sub(a.cobs_errors),
            decode_errors: b.decode_errors.wrapping_sub(a.decode_errors),
            oversize: b.oversize.wrapping_sub(a.oversize),
            samples: b.samples.wrapping_sub(a.samples),
            samples_dropped: b.samples_dropped.wrapping_sub(a.samples_dropped),
        }
    }

    /// Every frame the receiver delimited, whatever became of it.
    fn accounted(&self) -> u32 {
        self.frames_ok + self.crc_errors + self.cobs_errors + self.decode_errors + self.oversize
    }
}

/// Host-side model of the firmware's receive task (`firmware/app/src/link_rx.rs`).
#[derive(Default)]
struct Model {
    decoder: FrameDecoder<MAX_FRAME_LEN>,
    counts: Counts,
}

impl Model {
    /// Feeds bytes the host wrote, as the device's receiver sees them.
    fn feed(&mut self, mut input: &[u8]) {
        while !input.is_empty() {
            let (raw, rest) = self.decoder.feed_raw(input);
            let outcome = match raw {
                RawDecoded::NeedMore => None,
                RawDecoded::Rejected(e) => Some(Err(e)),
                RawDecoded::Payload(p) => match postcard::from_bytes::<HostToDevice>(p) {
                    Ok(m) => Some(Ok(m)),
                    Err(_) if peek_hello_version(p).is_some() => {
                        panic!("a corrupted frame decoded as a Hello: pick another seed")
                    }
                    Err(_) => Some(Err(FrameError::Decode)),
                },
            };
            input = rest;
            let c = &mut self.counts;
            match outcome {
                None => {}
                Some(Err(FrameError::Oversize)) => c.oversize += 1,
                Some(Err(FrameError::Cobs)) => c.cobs_errors += 1,
                Some(Err(FrameError::Crc)) => c.crc_errors += 1,
                Some(Err(FrameError::Decode)) => c.decode_errors += 1,
                Some(Ok(HostToDevice::Pose(_))) => {
                    c.frames_ok += 1;
                    c.samples += 1;
                }
                Some(Ok(HostToDevice::Ping(_))) => c.frames_ok += 1,
                Some(Ok(other)) => {
                    panic!("a corrupted frame decoded as {other:?}: pick another seed")
                }
            }
        }
    }

    /// A frame `Device` sends itself (ping, stats, hello): guarded, so its leading `0x00`
    /// ends whatever partial frame the receiver held, and it arrives intact.
    fn device_frame(&mut self) {
        self.feed(&[0]);
        self.counts.frames_ok += 1;
    }
}

fn start() -> (Qemu, Device) {
    let mut q = Qemu::start(&QemuOptions::default()).expect("start QEMU");
    let d = q.connect().expect("connect");
    (q, d)
}

/// A guarded pose frame (`0x00 ‖ COBS(…) ‖ 0x00`) for sample `i` of a smooth 100 Hz motion.
fn pose_frame(i: u32) -> Vec<u8> {
    let t = f64::from(i) * 0.01;
    let p = Pose::quantize(
        i as u16,
        t,
        [0.2 * t.sin(), 1.0, 0.1 * t.cos()],
        [1.0, 0.0, 0.0, 0.0],
    )
    .expect("pose in range");
    let mut f = vec![0u8; MAX_FRAME_LEN + 1];
    let n = encode_frame_guarded(&HostToDevice::Pose(p), &mut f).expect("encode pose");
    f.truncate(n);
    f
}

/// One session's bookkeeping: the model, the answer-time maximum, a stats baseline.
struct Session {
    model: Model,
    worst_answer: Duration,
    requests: u32,
    baseline: Stats,
    next_pose: u32,
}

impl Session {
    fn new(dev: &mut Device) -> Session {
        let baseline = dev.stats().expect("stats");
        Session {
            model: Model::default(),
            worst_answer: Duration::ZERO,
            requests: 0,
            baseline,
            next_pose: 0,
        }
    }

    fn next_pose(&mut self) -> Vec<u8> {
        self.next_pose += 1;
        pose_frame(self.next_pose)
    }

    /// Writes `bytes` as they are and tells the model.
    fn inject(&mut self, dev: &mut Device, bytes: &[u8]) {
        dev.send_raw(bytes).expect("write to the link");
        self.model.feed(bytes);
    }

    /// A ping that must be answered within [`ANSWER_BOUND`].
    fn ping(&mut self, dev: &mut Device) {
        let t0 = Instant::now();
        dev.ping().expect("the device answers a ping after faults");
        let took = t0.elapsed();
        self.model.device_frame();
        self.worst_answer = self.worst_answer.max(took);
        self.requests += 1;
        assert!(took <= ANSWER_BOUND, "ping answered after {took:?}");
    }

    /// Fetches `Stats` and checks every counter against the model; returns the increments.
    fn check(&mut self, dev: &mut Device, name: &str) -> Counts {
        let s = dev.stats().expect("stats");
        self.model.device_frame();
        let got = Counts::between(&self.baseline, &s);
        assert_eq!(
            got, self.model.counts,
            "{name}: device (left) vs model (right)"
        );
        assert_eq!(got.samples_dropped, 0, "{name}: dropped samples");
        got
    }
}

/// Corrupts each byte with probability `p` (XOR with a random non-zero value); returns how
/// many were changed.
fn corrupt(bytes: &mut [u8], p: f64, rng: &mut Rng) -> usize {
    let mut n = 0;
    for b in bytes.iter_mut() {
        if rng.chance(p) {
            *b ^= (rng.below(255) + 1) as u8;
            n += 1;
        }
    }
    n
}

fn random_corruption(rate: f64, frames: usize, seed: u64) {
    let (q, mut dev) = start();
    let mut s = Session::new(&mut dev);
    let mut rng = Rng(seed);
    let (mut intact, mut corrupted_bytes, mut total_bytes) = (0u32, 0usize, 0usize);
    let t0 = Instant::now();
    for _ in 0..frames / BATCH {
        for _ in 0..BATCH {
            let mut f = s.next_pose();
            let hit = corrupt(&mut f, rate, &mut rng);
            intact += u32::from(hit == 0);
            corrupted_bytes += hit;
            total_bytes += f.len();
            s.inject(&mut dev, &f);
        }
        s.ping(&mut dev);
    }
    let got = s.check(&mut dev, &format!("corruption {rate}"));
    let sent = (frames / BATCH * BATCH) as u32;
    // Device-sent frames: one ping per batch and the final GetStats.
    let own = s.requests + 1;
    println!(
        "corruption {:.0} %: {sent} pose frames ({total_bytes} B, {corrupted_bytes} B corrupted, \
         {intact} intact) in {:.2?}: frames_ok {} (incl. {own} pings/stats), crc {} cobs {} \
         decode {} oversize {} → {} frames accounted; samples {}, dropped {}; worst answer {:.2?}",
        rate * 100.0,
        t0.elapsed(),
        got.frames_ok,
        got.crc_errors,
        got.cobs_errors,
        got.decode_errors,
        got.oversize,
        got.accounted(),
        got.samples,
        got.samples_dropped,
        s.worst_answer
    );
    // Every intact pose frame is processed; corrupted ones may survive only by a CRC
    // collision, which the model would have reported.
    assert!(got.samples >= intact, "{got:?}");
    assert!(got.samples <= sent, "{got:?}");
    // Each corrupted byte splits, merges or spoils at most a frame or two; every frame
    // the receiver delimited is in exactly one counter (the model checked which).
    assert!(got.accounted() >= got.samples + own, "{got:?}");
    assert!(
        got.accounted() <= sent + own + corrupted_bytes as u32,
        "{got:?}"
    );
    drop(q);
}

#[test]
fn random_corruption_1_percent() {
    random_corruption(0.01, 4000, 0x1234_5678_9ABC_DEF1);
}

#[test]
fn random_corruption_10_percent() {
    random_corruption(0.10, 4000, 0x0F1E_2D3C_4B5A_6978);
}

#[test]
fn truncated_oversize_and_zero_bursts_are_counted_exactly_and_the_next_frame_is_processed() {
    let (mut q, mut dev) = start();
    let mut s = Session::new(&mut dev);
    let mut rng = Rng(0xC0FF_EE00_DEAD_BEEF);
    let (mut truncated, mut oversize, mut bursts, mut split) = (0u32, 0u32, 0u32, 0u32);
    let mut valid = 0u32;
    for round in 0..300u32 {
        match round % 4 {
            0 => {
                // The start of a frame without its end; the next frame's guard closes it.
                let f = s.next_pose();
                let keep = 2 + rng.below(f.len() as u64 - 3) as usize;
                s.inject(&mut dev, &f[..keep]);
                truncated += 1;
            }
            1 => {
                // More non-zero bytes than the receive buffer holds.
                let n = MAX_FRAME_LEN + 1 + rng.below(300) as usize;
                let junk: Vec<u8> = (0..n).map(|_| (rng.next() as u8) | 1).collect();
                s.inject(&mut dev, &junk);
                oversize += 1;
            }
            2 => {
                // A burst of zeros between frames: empty frames, silently skipped.
                let zeros = vec![0u8; 1 + rng.below(500) as usize];
                s.inject(&mut dev, &zeros);
                bursts += 1;
            }
            _ => {
                // A burst of zeros inside a frame: both halves are rejected.
                let mut f = s.next_pose();
                let at = 2 + rng.below(f.len() as u64 - 4) as usize;
                let n = 1 + rng.below(40) as usize;
                f.splice(at..at, std::iter::repeat_n(0u8, n));
                s.inject(&mut dev, &f);
                split += 1;
            }
        }
        let f = s.next_pose();
        s.inject(&mut dev, &f);
        valid += 1;
        if round % 2 == 1 {
            s.ping(&mut dev);
        }
    }
    let got = s.check(&mut dev, "truncated/oversize/zeros");
    println!(
        "{truncated} truncated, {oversize} oversize, {bursts} zero bursts between frames, \
         {split} zero bursts inside frames, {valid} valid poses: {got:?}; worst answer {:.2?}",
        s.worst_answer
    );
    assert_eq!(
        got.samples, valid,
        "every valid frame after a fault is processed"
    );
    assert_eq!(got.oversize, oversize);
    assert_eq!(got.decode_errors, 0);
    // A truncated frame is one rejection, a frame split by zeros two.
    assert_eq!(got.crc_errors + got.cobs_errors, truncated + 2 * split);
    assert_eq!(got.frames_ok, valid + s.requests + 1);
    assert!(q.exited().unwrap().is_none(), "the firmware died");
}

#[test]
fn host_disconnects_mid_frame_and_resumes_within_a_second() {
    let (mut q, mut dev) = start();
    let mut s = Session::new(&mut dev);
    let mut rng = Rng(0x5EED_0000_0000_0042);
    let mut worst_resume = Duration::ZERO;
    let mut resumes = Vec::new();
    let mut valid = 0u32;
    for _ in 0..8 {
        for _ in 0..BATCH {
            let f = s.next_pose();
            s.inject(&mut dev, &f);
            valid += 1;
        }
        // Half a frame, then the cable goes.
        let f = s.next_pose();
        let keep = 2 + rng.below(f.len() as u64 - 3) as usize;
        s.inject(&mut dev, &f[..keep]);
        drop(dev);
        let t0 = Instant::now();
        dev = q.connect().expect("reconnect");
        // The handshake: our Hello and its Ping barrier.
        s.model.device_frame();
        s.model.device_frame();
        s.ping(&mut dev);
        let took = t0.elapsed();
        resumes.push(took);
        worst_resume = worst_resume.max(took);
        assert!(took <= RESUME_BOUND, "resumed after {took:?}");
        assert!(!dev.take_rebooted(), "the device rebooted");
        for _ in 0..BATCH {
            let f = s.next_pose();
            s.inject(&mut dev, &f);
            valid += 1;
        }
        s.ping(&mut dev);
    }
    let got = s.check(&mut dev, "reconnects");
    println!(
        "8 disconnects mid-frame: resumed (connect + handshake + ping) in {resumes:.2?}, \
         worst {worst_resume:.2?}; {got:?}"
    );
    assert_eq!(got.samples, valid);
    assert_eq!(got.crc_errors + got.cobs_errors, 8);
    assert!(q.exited().unwrap().is_none(), "the firmware died");
}
