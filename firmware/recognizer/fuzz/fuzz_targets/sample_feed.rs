//! Fuzzes the sample feed: arbitrary bytes become a stream of samples (any sequence numbers,
//! times, NaN/inf/huge values, zero quaternions, time going backwards) fed to a recognizer with
//! a small library and effort model, with the decision stage's notes asked for or not (the
//! first byte's low bit). Invariants: no panic; every sample is accepted or counted as skipped;
//! events and notes have end ≥ start; a note names an action of the library.
#![no_main]

use figurine_recognizer::bayes::{AxisModel, Classifier, EffortModel, MAX_EFFORT_FEATURES};
use figurine_recognizer::pattern::encode_record;
use figurine_recognizer::token::parse_token;
use figurine_recognizer::{Library, Recognizer, Sample};
use libfuzzer_sys::fuzz_target;

fn library() -> Vec<u8> {
    let mut out = b"FGL\x01\x02\0\0\0".to_vec();
    for toks in [&["uf", "f", "df"][..], &[".Yp", "O"][..]] {
        let syms: Vec<u16> = toks.iter().map(|t| parse_token(t).unwrap()).collect();
        let n = syms.len();
        let mut follow = vec![0u64; n + 1];
        follow[0] = 1 << 1;
        for (i, f) in follow.iter_mut().enumerate().skip(1) {
            *f = (1 << i) | if i < n { 1 << (i + 1) } else { 0 };
        }
        encode_record(&mut out, &syms, &follow, 1 << n, 1, false).unwrap();
    }
    out
}

fn effort() -> EffortModel {
    let mut ax = AxisModel {
        kind: Classifier::NaiveBayes,
        m: 2,
        idx: [0; MAX_EFFORT_FEATURES],
        prior: 0.1,
        params: [[0.0, 1.0, 1.0, 2.0]; MAX_EFFORT_FEATURES],
    };
    ax.idx[1] = 19;
    // Both classifiers run on every committed segment.
    let weight = AxisModel { kind: Classifier::Linear, ..ax };
    EffortModel { time: ax, weight }
}

fuzz_target!(|data: &[u8]| {
    let blob = library();
    let lib = Library::from_bytes(&blob).unwrap();
    let mut rec = Recognizer::new(lib, Some(effort()));
    let mut t = 0u64;
    let mut pushed = 0u32;
    let noted = data.first().is_some_and(|b| b & 1 != 0);
    let note = |n: figurine_recognizer::Note| {
        assert!(n.end_us >= n.start_us);
        assert!(usize::from(n.action) < 2);
    };
    for chunk in data.chunks_exact(16) {
        let w = |i: usize| u16::from_le_bytes([chunk[i], chunk[i + 1]]);
        // Mostly plausible motion (small steps), sometimes raw bit patterns.
        let raw = chunk[15] & 0x80 != 0;
        let f = |v: u16| -> f32 {
            if raw { f32::from_bits(u32::from(v) << 16 | u32::from(v)) } else { (v as i16) as f32 * 1e-4 }
        };
        let dt = u64::from(chunk[14] & 0x7f) * 250;
        t = if chunk[15] & 0x40 != 0 { t.saturating_sub(dt) } else { t + dt };
        let s = Sample {
            seq: pushed,
            t_us: t,
            pos: [f(w(0)), f(w(2)), f(w(4))],
            quat: [f(w(6)) + if raw { 0.0 } else { 1.0 }, f(w(8)), f(w(10)), f(w(12))],
        };
        if noted {
            rec.push_noted(&s, |e| assert!(e.end_us >= e.start_us), note);
        } else {
            rec.push(&s, |e| assert!(e.end_us >= e.start_us));
        }
        pushed += 1;
    }
    if noted {
        rec.flush_noted(|e| assert!(e.end_us >= e.start_us), note);
    } else {
        rec.flush(|e| assert!(e.end_us >= e.start_us));
    }
    let st = rec.stats();
    assert_eq!(st.intake.accepted + st.intake.skipped(), pushed);
});
