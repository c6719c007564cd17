//! Fuzzes the live pose stream (`… | figurine live`: pose-log lines on standard input): any
//! bytes give samples and counted drops, never a panic and never an end before the input's
//! end; every sample goes to the wire as `live` sends it (quantised, or counted as one the
//! wire cannot carry).
#![no_main]

use figurine_host::link::lines::PoseLines;
use figurine_protocol::Pose;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let mut lines = PoseLines::new(data);
    let mut n = 0u64;
    while let Some(p) = lines.next_sample().expect("reading memory cannot fail") {
        let _ = Pose::quantize(n as u16, p.t, p.pos, p.quat);
        n += 1;
    }
    let c = lines.counts();
    assert_eq!(c.samples, n);
    let line_count = data.split(|&b| b == b'\n').count() as u64;
    assert!(
        c.samples + c.dropped() <= line_count,
        "{c:?} from {line_count} lines"
    );
});
