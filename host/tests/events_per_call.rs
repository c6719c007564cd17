//! How many events one call of the recognizer hands back: the firmware keeps room for
//! `EVENTS_PER_CALL` (6, `firmware/app/src/engine.rs`) between a `push` or `flush` and the
//! transmit queue, because the recognizer's callback cannot wait for the queue. Measured here
//! over the generator's sequences (noise ×1 and ×3), repetitions played without a breath and
//! a hand that talks, read by the shipped library and by one learnt at noise ×3 (504
//! readings): the most is 2 from one sample and 2 from one flush, and the test asks for at
//! most half the room. (Over 1,696 readings that also took in `../shared`'s validation set,
//! the real doodles and seven libraries, 2026-12-07: 2 and 3.)

use figurine_host::link::blobs;
use figurine_host::recognize::eval::learn_synth_library;
use figurine_host::recognize::feed::log_samples;
use figurine_host::recognize::simulate::load_effort;
use figurine_host::synth::{self, Action, Handling, Knobs, Range};
use figurine_recognizer::{Library, Recognizer};

/// Half the firmware's `EVENTS_PER_CALL`.
const HALF_THE_ROOM: usize = 3;

#[test]
fn one_call_hands_back_at_most_half_the_firmwares_room() {
    let shipped = blobs::load(None, None).expect("shipped library").library;
    let noisy = Knobs {
        noise: Range::new(3.0, 3.0),
        ..Knobs::default()
    };
    let learnt = learn_synth_library(7, 3, &noisy)
        .and_then(|mut l| l.blob())
        .expect("a library learnt at noise ×3");
    let effort = load_effort(None).expect("shipped effort model");
    let still = Knobs {
        pause_s: Range::new(0.05, 0.4),
        ..Knobs::default()
    };
    let mut doodles = Vec::new();
    for k in 0..80 {
        doodles.push(synth::sequence(100 + k, &Knobs::default(), 8, None));
        doodles.push(synth::sequence(200 + k, &noisy, 8, None));
        doodles.push(synth::handled(300 + k, &Knobs::default(), Handling::Talk));
    }
    for (i, &action) in Action::ALL.iter().enumerate() {
        let e = synth::sequence::random_state_for(400 + i as u64);
        doodles.push(synth::sequence::render(
            400 + i as u64,
            &still,
            &[(action, e); 4],
        ));
    }
    let (mut per_push, mut per_flush) = (0, 0);
    for d in &doodles {
        let (samples, _) = log_samples(&d.log);
        for blob in [&shipped, &learnt] {
            let lib = Library::from_bytes(blob).expect("library blob");
            let mut rec = Recognizer::new(lib, Some(effort));
            for (_, s) in &samples {
                let mut n = 0;
                rec.push(s, |_| n += 1);
                per_push = per_push.max(n);
            }
            let mut n = 0;
            rec.flush(|_| n += 1);
            per_flush = per_flush.max(n);
        }
    }
    println!(
        "{} readings: at most {per_push} events from one sample, {per_flush} from one flush",
        2 * doodles.len()
    );
    assert!(
        per_push >= 1 && per_flush >= 1,
        "the corpus reads some actions"
    );
    assert!(
        per_push <= HALF_THE_ROOM && per_flush <= HALF_THE_ROOM,
        "{per_push} from one sample, {per_flush} from one flush"
    );
}
