//! `figurine live` against the emulated figurine: the session log is complete even though
//! the link is cut in the middle (a proxy plays the unplugged cable), and the session
//! reconnects and carries on.

use std::io::{Read, Write};
use std::net::{Shutdown, TcpListener, TcpStream};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Arc;
use std::thread;
use std::time::Duration;

use figurine_e2e::{Qemu, QemuOptions};
use figurine_host::link::live::{live, LiveArgs};
use figurine_host::poselog::PoseLog;
use figurine_host::synth::knobs::Knobs;
use figurine_host::synth::sequence::sequence;

/// Forwards one connection at a time between `listener` and `target`; the first connection
/// is cut after `cut_after` bytes from the host (the "unplug").
fn proxy(
    listener: TcpListener,
    target: String,
    cut_after: usize,
    conns: Arc<AtomicUsize>,
    stop: Arc<AtomicBool>,
) {
    listener.set_nonblocking(true).unwrap();
    while !stop.load(Ordering::Relaxed) {
        let Ok((client, _)) = listener.accept() else {
            thread::sleep(Duration::from_millis(10));
            continue;
        };
        client.set_nonblocking(false).unwrap();
        let n = conns.fetch_add(1, Ordering::SeqCst);
        let Ok(device) = TcpStream::connect(&target) else {
            continue;
        };
        let (mut c_rd, mut d_wr) = (client.try_clone().unwrap(), device.try_clone().unwrap());
        let (mut d_rd, mut c_wr) = (device, client);
        let up = thread::spawn(move || {
            let mut buf = [0u8; 256];
            let mut total = 0;
            while let Ok(k) = c_rd.read(&mut buf) {
                if k == 0 || (n == 0 && total > cut_after) {
                    break;
                }
                total += k;
                if d_wr.write_all(&buf[..k]).is_err() {
                    break;
                }
            }
            // Unplugged: both ends see the cable go.
            let _ = c_rd.shutdown(Shutdown::Both);
            let _ = d_wr.shutdown(Shutdown::Both);
        });
        let mut buf = [0u8; 256];
        while let Ok(k) = d_rd.read(&mut buf) {
            if k == 0 || c_wr.write_all(&buf[..k]).is_err() {
                break;
            }
        }
        let _ = up.join();
    }
}

#[test]
fn live_session_survives_an_unplug_and_records_every_pose() {
    let dir = std::env::temp_dir().join(format!("figurine-live-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let log_path = dir.join("in.csv");
    let rec_path = dir.join("session.csv");
    let log = sequence(3, &Knobs::default(), 2, None).log;
    log.write_path(&log_path).unwrap();

    let mut q = Qemu::start(&QemuOptions::default()).unwrap();
    drop(q.connect().unwrap()); // start the guest; QEMU then accepts the proxy's connections
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    let port = listener.local_addr().unwrap().port();
    let conns = Arc::new(AtomicUsize::new(0));
    let stop = Arc::new(AtomicBool::new(false));
    let target = q
        .port_spec()
        .to_string()
        .trim_start_matches("tcp:")
        .to_string();
    let proxy_thread = {
        let (conns, stop) = (conns.clone(), stop.clone());
        thread::spawn(move || proxy(listener, target, 4000, conns, stop))
    };

    live(&LiveArgs {
        ports: vec![format!("tcp:127.0.0.1:{port}")],
        logs: vec![log_path],
        speed: 8.0,
        library: None,
        record: Some(rec_path.clone()),
        view: false,
        clips: None,
        quit_after: None,
    })
    .expect("live session");
    stop.store(true, Ordering::Relaxed);
    proxy_thread.join().unwrap();

    assert!(
        conns.load(Ordering::SeqCst) >= 2,
        "the session never reconnected"
    );
    let rec = PoseLog::read_path(&rec_path).expect("session log");
    assert_eq!(
        rec.samples.len(),
        log.samples.len(),
        "poses lost from the session log"
    );
    for (a, b) in rec.samples.iter().zip(&log.samples) {
        assert!((a.t - b.t).abs() < 1e-6 && (a.pos[0] - b.pos[0]).abs() < 1e-6);
    }
    assert!(q.exited().unwrap().is_none());
    let _ = std::fs::remove_dir_all(&dir);
}
