//! The device's counters, shared by the tasks (reported by `GetStats`, cleared by `Reset`).

use core::cell::Cell;

use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::blocking_mutex::Mutex;
use figurine_protocol::Stats;

static STATS: Mutex<CriticalSectionRawMutex, Cell<Stats>> = Mutex::new(Cell::new(Stats {
    samples: 0,
    invalid_samples: 0,
    samples_dropped: 0,
    seq_gaps: 0,
    events: 0,
    frames_ok: 0,
    crc_errors: 0,
    cobs_errors: 0,
    decode_errors: 0,
    oversize: 0,
    pose_queue_high_water: 0,
    tx_queue_high_water: 0,
    worst_sample_cycles: 0,
}));

/// Changes the counters in one critical section.
pub fn update(f: impl FnOnce(&mut Stats)) {
    STATS.lock(|s| {
        let mut v = s.get();
        f(&mut v);
        s.set(v);
    });
}

/// A copy of the counters.
pub fn snapshot() -> Stats {
    STATS.lock(Cell::get)
}

/// Zeroes every counter.
pub fn clear() {
    STATS.lock(|s| s.set(Stats::default()));
}
