//! One connected figurine: handshake, requests with replies, uploads with acknowledgement,
//! and the stream of action events.
//!
//! A reader thread decodes the device's frames into a channel, so writing poses never blocks
//! on reading events. Every frame the host sends is guarded (`encode_frame_guarded`): a
//! leading `0x00` closes any garbage before it.

use std::collections::VecDeque;
use std::io::Write;
use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};
use std::sync::mpsc::{self, Receiver, RecvTimeoutError};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use figurine_protocol::{
    encode_frame_guarded, ActionEvent, BlobKind, Decoded, DeviceError, DeviceHello, DeviceToHost,
    ErrorCode, FrameDecoder, HostHello, HostToDevice, Stats, UploadBegin, UploadChunk,
    MAX_CHUNK_LEN, MAX_FRAME_LEN, PROTOCOL_VERSION,
};

use super::transport::{self, PortSpec, Reader, Writer};
use super::LinkError;

/// How long the device may take to answer a request (a flash page erase included).
pub const REPLY_TIMEOUT: Duration = Duration::from_secs(3);
/// Host build id sent in our `Hello` (FNV-1a of the crate version would do; the value is
/// only logged by the device).
const HOST_BUILD: u32 = 0x0001_0000;

/// What the reader thread hands over.
enum Incoming {
    Msg(DeviceToHost, Instant),
    Closed(String),
}

/// Frames the host rejected from the device (link quality), since connecting.
#[derive(Debug, Default)]
pub struct HostRxCounters {
    /// Frames rejected (CRC, COBS, oversize or undecodable).
    pub rejected: AtomicU32,
}

/// An action event as it arrived from the device.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Received {
    /// The event (for a revision: the event that replaces the previous one).
    pub event: ActionEvent,
    /// It revises the previous event (`DeviceToHost::Revised`) and replaces it.
    pub revises: bool,
    /// When the host decoded its frame.
    pub at: Instant,
}

/// A connected figurine.
pub struct Device {
    spec: PortSpec,
    writer: Box<dyn Writer>,
    rx: Receiver<Incoming>,
    stop: Arc<AtomicBool>,
    reader: Option<JoinHandle<()>>,
    counters: Arc<HostRxCounters>,
    hello: DeviceHello,
    /// Messages received while waiting for something else (events mostly), with the
    /// moment the reader decoded them.
    backlog: VecDeque<(DeviceToHost, Instant)>,
    next_ping: u32,
    /// Set when the device announced itself again without being asked: it rebooted.
    rebooted: bool,
    /// When the message last taken from the reader arrived.
    last_arrival: Instant,
}

fn reader_thread(
    mut reader: Reader,
    tx: mpsc::Sender<Incoming>,
    stop: Arc<AtomicBool>,
    counters: Arc<HostRxCounters>,
) {
    let mut decoder = FrameDecoder::<MAX_FRAME_LEN>::new();
    let mut buf = [0u8; 1024];
    while !stop.load(Ordering::Relaxed) {
        let n = match reader.read(&mut buf) {
            Ok(0) => {
                let _ = tx.send(Incoming::Closed("connection closed".into()));
                return;
            }
            Ok(n) => n,
            Err(e) if transport::is_timeout(&e) => continue,
            Err(e) => {
                let _ = tx.send(Incoming::Closed(e.to_string()));
                return;
            }
        };
        let mut input = &buf[..n];
        loop {
            match decoder.feed::<DeviceToHost>(input) {
                Decoded::NeedMore => break,
                Decoded::Message { msg, remaining } => {
                    if tx.send(Incoming::Msg(msg, Instant::now())).is_err() {
                        return;
                    }
                    input = remaining;
                }
                Decoded::Rejected { remaining, .. } => {
                    counters.rejected.fetch_add(1, Ordering::Relaxed);
                    input = remaining;
                }
            }
        }
    }
}

impl Device {
    /// Opens `spec` and performs the version handshake.
    pub fn connect(spec: &PortSpec) -> Result<Device, LinkError> {
        let (reader, writer) = transport::open(spec)?;
        let (tx, rx) = mpsc::channel();
        let stop = Arc::new(AtomicBool::new(false));
        let counters = Arc::new(HostRxCounters::default());
        let handle = {
            let (stop, counters) = (stop.clone(), counters.clone());
            std::thread::Builder::new()
                .name(format!("figurine-rx {spec}"))
                .spawn(move || reader_thread(reader, tx, stop, counters))
                .map_err(|source| LinkError::Open {
                    port: spec.to_string(),
                    source,
                })?
        };
        let mut dev = Device {
            spec: spec.clone(),
            writer,
            rx,
            stop,
            reader: Some(handle),
            counters,
            hello: DeviceHello {
                protocol_version: 0,
                build_id: 0,
                capacities: figurine_protocol::Capacities {
                    max_actions: 0,
                    max_pattern_len: 0,
                    max_edits: 0,
                    effort_features: 0,
                    max_library_bytes: 0,
                    max_effort_bytes: 0,
                    pose_queue: 0,
                },
                library_crc: 0,
                effort_crc: 0,
            },
            backlog: VecDeque::new(),
            next_ping: 1,
            rebooted: false,
            last_arrival: Instant::now(),
        };
        dev.handshake()?;
        Ok(dev)
    }

    /// Where this device is attached.
    pub fn port(&self) -> &PortSpec {
        &self.spec
    }

    /// The device's latest `Hello` (capacities, build id, CRCs of the blobs in use).
    pub fn hello(&self) -> &DeviceHello {
        &self.hello
    }

    /// Frames from the device the host rejected since connecting.
    pub fn rejected_frames(&self) -> u32 {
        self.counters.rejected.load(Ordering::Relaxed)
    }

    /// True (once) if the device announced itself unasked since the last call: it rebooted.
    pub fn take_rebooted(&mut self) -> bool {
        std::mem::take(&mut self.rebooted)
    }

    /// Sends our `Hello` and waits for the device's; refuses another protocol version. A
    /// `Ping` barrier after it absorbs the device's boot-time `Hello` if one is in flight.
    pub fn handshake(&mut self) -> Result<DeviceHello, LinkError> {
        // Anything queued before the handshake (a boot Hello, old events) is stale.
        self.drain_now()?;
        self.backlog.clear();
        self.send(&HostToDevice::Hello(HostHello {
            protocol_version: PROTOCOL_VERSION,
            host_build: HOST_BUILD,
        }))?;
        let mismatch = |port: &PortSpec, theirs: u16| LinkError::Version {
            port: port.to_string(),
            ours: PROTOCOL_VERSION,
            theirs,
        };
        let deadline = Instant::now() + REPLY_TIMEOUT;
        loop {
            match self.recv_until(deadline)? {
                DeviceToHost::Hello(h) if h.protocol_version != PROTOCOL_VERSION => {
                    return Err(mismatch(&self.spec, h.protocol_version));
                }
                DeviceToHost::Hello(_) => break,
                DeviceToHost::Error(DeviceError {
                    code: ErrorCode::VersionMismatch,
                    detail,
                }) => return Err(mismatch(&self.spec, detail as u16)),
                _ => {}
            }
        }
        let v = self.ping_async()?;
        loop {
            match self.recv_until(deadline)? {
                DeviceToHost::Pong(p) if p == v => break,
                DeviceToHost::Hello(h) => self.hello = h,
                _ => {}
            }
        }
        self.backlog.clear();
        self.rebooted = false;
        Ok(self.hello)
    }

    /// Sends one message as a guarded frame.
    pub fn send(&mut self, msg: &HostToDevice) -> Result<(), LinkError> {
        let mut frame = [0u8; MAX_FRAME_LEN + 1];
        let n = encode_frame_guarded(msg, &mut frame).map_err(LinkError::Encode)?;
        self.send_raw(&frame[..n])
    }

    /// Writes raw bytes to the link (tests use it to inject garbage).
    pub fn send_raw(&mut self, bytes: &[u8]) -> Result<(), LinkError> {
        self.writer
            .write_all(bytes)
            .and_then(|()| self.writer.flush())
            .map_err(|e| LinkError::Disconnected(format!("{}: {e}", self.spec)))
    }

    fn accept(&mut self, msg: DeviceToHost) -> DeviceToHost {
        if let DeviceToHost::Hello(h) = &msg {
            self.hello = *h;
            self.rebooted = true;
        }
        msg
    }

    /// Next message from the device, waiting until `deadline`.
    fn recv_until(&mut self, deadline: Instant) -> Result<DeviceToHost, LinkError> {
        let wait = deadline.saturating_duration_since(Instant::now());
        match self.rx.recv_timeout(wait) {
            Ok(Incoming::Msg(m, at)) => {
                self.last_arrival = at;
                Ok(self.accept(m))
            }
            Ok(Incoming::Closed(why)) => {
                Err(LinkError::Disconnected(format!("{}: {why}", self.spec)))
            }
            Err(RecvTimeoutError::Timeout) => Err(LinkError::Timeout(self.spec.to_string())),
            Err(RecvTimeoutError::Disconnected) => Err(LinkError::Disconnected(format!(
                "{}: reader stopped",
                self.spec
            ))),
        }
    }

    /// Moves every message already received into the backlog without waiting.
    fn drain_now(&mut self) -> Result<(), LinkError> {
        loop {
            match self.rx.try_recv() {
                Ok(Incoming::Msg(m, at)) => {
                    let m = self.accept(m);
                    self.backlog.push_back((m, at));
                }
                Ok(Incoming::Closed(why)) => {
                    return Err(LinkError::Disconnected(format!("{}: {why}", self.spec)))
                }
                Err(_) => return Ok(()),
            }
        }
    }

    /// Next message (from the backlog first), waiting at most `timeout`; `None` on timeout.
    pub fn poll(&mut self, timeout: Duration) -> Result<Option<DeviceToHost>, LinkError> {
        if let Some((m, _)) = self.backlog.pop_front() {
            return Ok(Some(m));
        }
        match self.recv_until(Instant::now() + timeout) {
            Ok(m) => Ok(Some(m)),
            Err(LinkError::Timeout(_)) => Ok(None),
            Err(e) => Err(e),
        }
    }

    /// Action events and revisions received so far (removed from the backlog, in order).
    pub fn take_events(&mut self) -> Result<Vec<Received>, LinkError> {
        self.drain_now()?;
        let mut events = Vec::new();
        self.backlog.retain(|(m, at)| {
            let (event, revises) = match m {
                DeviceToHost::Event(e) => (*e, false),
                DeviceToHost::Revised(e) => (*e, true),
                _ => return true,
            };
            events.push(Received {
                event,
                revises,
                at: *at,
            });
            false
        });
        Ok(events)
    }

    /// Sends `msg` and waits for the reply `pick` accepts; other messages are kept in the
    /// backlog. A device `Error` or an unasked `Hello` (reboot) ends the wait with an error.
    fn request<T>(
        &mut self,
        msg: &HostToDevice,
        mut pick: impl FnMut(&DeviceToHost) -> Option<T>,
    ) -> Result<T, LinkError> {
        self.send(msg)?;
        let deadline = Instant::now() + REPLY_TIMEOUT;
        loop {
            let m = self.recv_until(deadline)?;
            if let Some(t) = pick(&m) {
                return Ok(t);
            }
            match m {
                DeviceToHost::Error(e) => return Err(LinkError::Device(e)),
                DeviceToHost::Hello(_) => {
                    return Err(LinkError::Rebooted(self.spec.to_string()));
                }
                other => self.backlog.push_back((other, self.last_arrival)),
            }
        }
    }

    /// Sends a `Ping` without waiting; returns its value (see [`Device::wait_pong`]).
    pub fn ping_async(&mut self) -> Result<u32, LinkError> {
        let v = self.next_ping;
        self.next_ping = self.next_ping.wrapping_add(1);
        self.send(&HostToDevice::Ping(v))?;
        Ok(v)
    }

    /// Waits for `Pong(v)`; everything the device sent before it goes to the backlog.
    /// Since the device answers in order, every message sent before `Ping(v)` was handled.
    pub fn wait_pong(&mut self, v: u32) -> Result<(), LinkError> {
        // `take_events` may already have moved it into the backlog.
        if let Some(i) = self
            .backlog
            .iter()
            .position(|(m, _)| matches!(m, DeviceToHost::Pong(p) if *p == v))
        {
            self.backlog.remove(i);
            return Ok(());
        }
        let deadline = Instant::now() + REPLY_TIMEOUT;
        loop {
            match self.recv_until(deadline)? {
                DeviceToHost::Pong(p) if p == v => return Ok(()),
                DeviceToHost::Hello(_) => return Err(LinkError::Rebooted(self.spec.to_string())),
                DeviceToHost::Pong(_) => {}
                other => self.backlog.push_back((other, self.last_arrival)),
            }
        }
    }

    /// Round trip: every earlier message has been processed when this returns.
    pub fn ping(&mut self) -> Result<(), LinkError> {
        let v = self.ping_async()?;
        self.wait_pong(v)
    }

    /// The device's statistics.
    pub fn stats(&mut self) -> Result<Stats, LinkError> {
        self.request(&HostToDevice::GetStats, |m| match m {
            DeviceToHost::Stats(s) => Some(*s),
            _ => None,
        })
    }

    /// Ends the device's session: pending actions are emitted (collect them with
    /// [`Device::take_events`]), recognition and statistics restart. Returns after the device
    /// handled it.
    pub fn reset(&mut self) -> Result<(), LinkError> {
        self.send(&HostToDevice::Reset)?;
        self.ping()
    }

    /// Uploads a blob in acknowledged chunks and commits it; returns its CRC-32 as the
    /// device reports it. `progress(done, total)` is called after each acknowledged chunk.
    pub fn upload(
        &mut self,
        kind: BlobKind,
        blob: &[u8],
        mut progress: impl FnMut(usize, usize),
    ) -> Result<u32, LinkError> {
        let crc32 = figurine_protocol::frame::CRC32.checksum(blob);
        let len = u32::try_from(blob.len()).map_err(|_| LinkError::TooLarge(blob.len()))?;
        let cap = match kind {
            BlobKind::Library => self.hello.capacities.max_library_bytes,
            BlobKind::Effort => self.hello.capacities.max_effort_bytes,
        };
        if len > cap {
            return Err(LinkError::TooLarge(blob.len()));
        }
        let ack = |want: u32| {
            move |m: &DeviceToHost| match m {
                DeviceToHost::UploadAck {
                    kind: k,
                    next_offset,
                } if *k == kind && *next_offset == want => Some(()),
                _ => None,
            }
        };
        self.request(
            &HostToDevice::UploadBegin(UploadBegin { kind, len, crc32 }),
            ack(0),
        )?;
        let mut offset = 0usize;
        for piece in blob.chunks(MAX_CHUNK_LEN) {
            let data =
                heapless::Vec::from_slice(piece).map_err(|_| LinkError::TooLarge(piece.len()))?;
            let next = (offset + piece.len()) as u32;
            self.request(
                &HostToDevice::UploadChunk(UploadChunk {
                    kind,
                    offset: offset as u32,
                    data,
                }),
                ack(next),
            )?;
            offset += piece.len();
            progress(offset, blob.len());
        }
        let done = self.request(&HostToDevice::UploadCommit(kind), |m| match m {
            DeviceToHost::UploadDone { kind: k, crc32 } if *k == kind => Some(*crc32),
            _ => None,
        })?;
        if done != crc32 {
            return Err(LinkError::Device(DeviceError {
                code: ErrorCode::UploadCrc,
                detail: done,
            }));
        }
        match kind {
            BlobKind::Library => self.hello.library_crc = done,
            BlobKind::Effort => self.hello.effort_crc = done,
        }
        Ok(done)
    }
}

impl Drop for Device {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        self.writer.shutdown();
        if let Some(h) = self.reader.take() {
            let _ = h.join();
        }
    }
}

#[cfg(test)]
mod tests {
    use std::io::Read;
    use std::net::TcpListener;

    use figurine_protocol::{encode_frame, Capacities};

    use super::*;

    /// A fake figurine on a TCP port that answers every frame with a `Hello` of `version`.
    fn fake_device(version: u16) -> (PortSpec, std::thread::JoinHandle<()>) {
        let listener = TcpListener::bind("127.0.0.1:0").unwrap();
        let spec = PortSpec::Tcp(listener.local_addr().unwrap().to_string());
        let handle = std::thread::spawn(move || {
            let (mut sock, _) = listener.accept().unwrap();
            let hello = DeviceToHost::Hello(DeviceHello {
                protocol_version: version,
                build_id: 7,
                capacities: Capacities {
                    max_actions: 32,
                    max_pattern_len: 32,
                    max_edits: 3,
                    effort_features: 16,
                    max_library_bytes: 1000,
                    max_effort_bytes: 100,
                    pose_queue: 32,
                },
                library_crc: 0,
                effort_crc: 0,
            });
            let mut frame = [0u8; MAX_FRAME_LEN];
            let n = encode_frame(&hello, &mut frame).unwrap();
            let mut buf = [0u8; 256];
            while let Ok(k) = sock.read(&mut buf) {
                if k == 0 || sock.write_all(&frame[..n]).is_err() {
                    break;
                }
            }
        });
        (spec, handle)
    }

    #[test]
    fn a_device_with_another_protocol_version_is_refused_naming_both() {
        let (spec, handle) = fake_device(PROTOCOL_VERSION + 1);
        let err = Device::connect(&spec).err().expect("must refuse");
        let text = err.to_string();
        assert!(matches!(err, LinkError::Version { theirs, .. } if theirs == PROTOCOL_VERSION + 1));
        assert!(
            text.contains(&format!("version {}", PROTOCOL_VERSION + 1)),
            "{text}"
        );
        assert!(
            text.contains(&format!("version {PROTOCOL_VERSION}")),
            "{text}"
        );
        assert!(text.contains("update the host"), "{text}");
        handle.join().unwrap();
    }

    #[test]
    fn an_unreachable_port_is_an_open_error() {
        let l = TcpListener::bind("127.0.0.1:0").unwrap();
        let spec = PortSpec::Tcp(l.local_addr().unwrap().to_string());
        drop(l);
        assert!(matches!(
            Device::connect(&spec),
            Err(LinkError::Open { .. })
        ));
    }
}
