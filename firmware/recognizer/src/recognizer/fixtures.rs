//! Test fixtures of the recognizer: synthetic sample streams (hops, strokes, twists, a
//! crouch held low) and runs of a recognizer over them.

extern crate std;

use proptest::prelude::*;
use std::vec::Vec;

use super::{ActionEvent, Recognizer};
use crate::intake::Sample;
use crate::note::Note;
use crate::pattern::Library;
use crate::token::Token;

/// A figurine hopping forward `hops` times (up-forward, down-forward), 120 Hz, then still.
pub(crate) fn hops(hops: usize, t0_us: u64) -> Vec<Sample> {
    let mut out = Vec::new();
    let rate = 120.0f32;
    let still = 0.6f32;
    let hop = 0.5f32;
    let total = 2.0 * still + hops as f32 * hop;
    let n = (total * rate) as u32;
    for i in 0..n {
        let t = i as f32 / rate;
        let (mut y, mut z) = (0.0f32, 0.0f32);
        if t > still {
            let h = ((t - still) / hop).min(hops as f32);
            let phase = h - libm::floorf(h);
            z = 0.2 * h;
            if h < hops as f32 {
                y = 0.1 * libm::sinf(core::f32::consts::PI * phase);
            }
        }
        out.push(Sample {
            seq: i,
            t_us: t0_us + (t * 1e6) as u64,
            pos: [0.3, 1.0 + y, z],
            quat: [1.0, 0.0, 0.0, 0.0],
        });
    }
    out
}

pub(crate) fn run(lib: &Library<'_>, samples: &[Sample]) -> Vec<ActionEvent> {
    let mut rec = Recognizer::new(*lib, None);
    let mut ev = Vec::new();
    for s in samples {
        rec.push(s, |e| ev.push(e));
    }
    rec.flush(|e| ev.push(e));
    ev
}

/// [`run`] with the decision stage's notes.
pub(crate) fn run_noted(lib: &Library<'_>, samples: &[Sample]) -> (Vec<ActionEvent>, Vec<Note>) {
    let mut rec = Recognizer::new(*lib, None);
    let (mut ev, mut notes) = (Vec::new(), Vec::new());
    for s in samples {
        rec.push_noted(s, |e| ev.push(e), |n| notes.push(n));
    }
    rec.flush_noted(|e| ev.push(e), |n| notes.push(n));
    (ev, notes)
}

/// `hops` hops forward (as [`hops`]), each pair of hops separated by `pause_s` of stillness.
pub(crate) fn paused_hops(hops: usize, pause_s: f32) -> Vec<Sample> {
    creeping_hops(hops, 0.0, pause_s)
}

/// `hops` hops forward (as [`hops`]), each but the last ending in a creep: `creep_s` of
/// drifting on at 2 cm/s (under the speed floor, so no token, but not at rest), then `pause_s`
/// still.
pub(crate) fn creeping_hops(hops: usize, creep_s: f32, pause_s: f32) -> Vec<Sample> {
    let rate = 120.0f32;
    let (still, hop, creep_m_s) = (0.6f32, 0.5f32, 0.02f32);
    let period = hop + creep_s + pause_s;
    let total = 2.0 * still + hops as f32 * period;
    let n = (total * rate) as u32;
    (0..n)
        .map(|i| {
            let t = i as f32 / rate;
            let (mut y, mut z) = (0.0f32, 0.0f32);
            if t > still {
                let k = libm::floorf((t - still) / period).min(hops as f32 - 1.0);
                let within = (t - still) - k * period;
                z = 0.2 * (k + (within / hop).min(1.0)) + k * creep_m_s * creep_s;
                if within < hop {
                    y = 0.1 * libm::sinf(core::f32::consts::PI * within / hop);
                } else if (k as usize) + 1 < hops {
                    z += creep_m_s * (within - hop).min(creep_s);
                }
            }
            Sample {
                seq: i,
                t_us: (t * 1e6) as u64,
                pos: [0.3, 1.0 + y, z],
                quat: [1.0, 0.0, 0.0, 0.0],
            }
        })
        .collect()
}

/// A one-hop pattern `uf+ f* df+`, cyclic (the whole may repeat) or not.
pub(crate) fn hop_library(cyclic: bool) -> Vec<u8> {
    let syms: Vec<Token> = ["uf", "f", "df"]
        .iter()
        .map(|t| crate::token::parse_token(t).unwrap())
        .collect();
    let mut follow = [1 << 1, 0b110, 0b1100, 0b1000];
    if cyclic {
        follow[3] |= 1 << 1;
    }
    let mut blob = Vec::from(*b"FGL\x01");
    blob.extend([1, 0, 0, 0]);
    crate::pattern::encode_record(&mut blob, &syms, &follow, 1 << 3, 0, cyclic).unwrap();
    blob
}

/// A slow forward stroke (15 cm in 1.2 s from 1.0 s, minimum jerk: it sets off and
/// settles slowly), then 1.5 s still; 100 Hz, with ±1 mm of white jitter on every axis.
pub(crate) fn slow_stroke() -> Vec<Sample> {
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut jitter = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        ((state >> 40) as f32 / (1u64 << 24) as f32 - 0.5) * 0.002
    };
    (0..370u32)
        .map(|i| {
            let t = i as f32 / 100.0;
            let x = ((t - 1.0) / 1.2).clamp(0.0, 1.0);
            let z = 0.15 * x * x * x * (10.0 - 15.0 * x + 6.0 * x * x);
            Sample {
                seq: i,
                t_us: (t * 1e6) as u64,
                pos: [0.3 + jitter(), 1.0 + jitter(), z + jitter()],
                quat: [1.0, 0.0, 0.0, 0.0],
            }
        })
        .collect()
}

/// A smooth step from 0 (x ≤ 0) to 1 (x ≥ 1): how the test strokes move.
pub(crate) fn ramp(x: f32) -> f32 {
    0.5 - 0.5 * libm::cosf(core::f32::consts::PI * x.clamp(0.0, 1.0))
}

/// A thrust forward (0.4 s), a pause of `hold_s`, the return (0.4 s), at 120 Hz.
pub(crate) fn thrust_and_return(hold_s: f32) -> Vec<Sample> {
    let rate = 120.0f32;
    let (still, stroke) = (0.6f32, 0.4f32);
    let total = 2.0 * still + 2.0 * stroke + hold_s + 0.6;
    (0..(total * rate) as u32)
        .map(|i| {
            let t = i as f32 / rate;
            let out = ramp((t - still) / stroke);
            let back = ramp((t - still - stroke - hold_s) / stroke);
            Sample {
                seq: i,
                t_us: (t * 1e6) as u64,
                pos: [0.3, 1.0, 0.25 * (out - back)],
                quat: [1.0, 0.0, 0.0, 0.0],
            }
        })
        .collect()
}

/// Going down (0.4 s, pitching 0.24 rad in its first half), held low for `hold_s`, back
/// up (0.4 s), at 120 Hz.
pub(crate) fn crouch_held_low(hold_s: f32) -> Vec<Sample> {
    let rate = 120.0f32;
    let (still, stroke) = (0.6f32, 0.4f32);
    let total = 2.0 * still + 2.0 * stroke + hold_s;
    (0..(total * rate) as u32)
        .map(|i| {
            let t = i as f32 / rate;
            let down = ramp((t - still) / stroke);
            let up = ramp((t - still - stroke - hold_s) / stroke);
            let half = 0.12 * ramp((t - still) / (0.5 * stroke));
            Sample {
                seq: i,
                t_us: (t * 1e6) as u64,
                pos: [0.3, 1.0 - 0.15 * (down - up), 0.0],
                quat: [libm::cosf(half), libm::sinf(half), 0.0, 0.0],
            }
        })
        .collect()
}

/// Lifted 15 cm (0.4 s), held up for a second, set back down where it rested (0.4 s), held
/// for a second, lifted again (0.4 s), at 120 Hz: a toy picked up, looked at, put down and
/// picked up again.
pub(crate) fn lifted_set_down_lifted() -> Vec<Sample> {
    let rate = 120.0f32;
    let (still, stroke, hold) = (0.6f32, 0.4f32, 1.0f32);
    let total = 2.0 * still + 3.0 * stroke + 2.0 * hold;
    (0..(total * rate) as u32)
        .map(|i| {
            let t = i as f32 / rate;
            let up = ramp((t - still) / stroke);
            let down = ramp((t - still - stroke - hold) / stroke);
            let again = ramp((t - still - 2.0 * (stroke + hold)) / stroke);
            Sample {
                seq: i,
                t_us: (t * 1e6) as u64,
                pos: [0.3, 1.0 + 0.15 * (up - down + again), 0.0],
                quat: [1.0, 0.0, 0.0, 0.0],
            }
        })
        .collect()
}

/// Quick strokes (0.12 s each, 5 cm, along `dirs`), 0.15 s apart, played right after the
/// stream starts; then still.
pub(crate) fn quick_strokes(dirs: &[[f32; 3]]) -> Vec<Sample> {
    let rate = 200.0f32;
    let (lead, stroke, gap) = (0.3f32, 0.12f32, 0.15f32);
    let total = lead + dirs.len() as f32 * (stroke + gap) + 1.0;
    (0..(total * rate) as u32)
        .map(|i| {
            let t = i as f32 / rate;
            let mut pos = [0.3f32, 1.0, 0.0];
            for (k, d) in dirs.iter().enumerate() {
                let x = ramp((t - lead - k as f32 * (stroke + gap)) / stroke);
                for (p, v) in pos.iter_mut().zip(d) {
                    *p += 0.05 * x * v;
                }
            }
            Sample {
                seq: i,
                t_us: (t * 1e6) as u64,
                pos,
                quat: [1.0, 0.0, 0.0, 0.0],
            }
        })
        .collect()
}

/// A twist about the vertical axis by `angle` rad in 0.12 s, after 0.6 s of stillness and
/// before 0.8 s more, at 200 Hz.
pub(crate) fn quick_twist(angle: f32) -> Vec<Sample> {
    twists(angle, 0.12, None)
}

/// A twist about the vertical axis by `angle` rad in `twist` s after 0.6 s of stillness,
/// and, `back` s later if given, the same twist back; then 0.8 s of stillness; 200 Hz.
pub(crate) fn twists(angle: f32, twist: f32, back: Option<f32>) -> Vec<Sample> {
    let rate = 200.0f32;
    let lead = 0.6f32;
    let moving = back.map_or(twist, |hold| 2.0 * twist + hold);
    (0..((lead + moving + 0.8) * rate) as u32)
        .map(|i| {
            let t = i as f32 / rate;
            let there = ramp((t - lead) / twist);
            let back = back.map_or(0.0, |hold| ramp((t - lead - twist - hold) / twist));
            let half = 0.5 * angle * (there - back);
            Sample {
                seq: i,
                t_us: (t * 1e6) as u64,
                pos: [0.3, 1.0, 0.0],
                quat: [libm::cosf(half), 0.0, libm::sinf(half), 0.0],
            }
        })
        .collect()
}

pub(crate) fn any_sample() -> impl Strategy<Value = Sample> {
    let f = prop_oneof![
        8 => -3.0f32..3.0,
        1 => Just(f32::NAN),
        1 => Just(f32::INFINITY),
        1 => Just(0.0f32),
        1 => any::<f32>(),
    ];
    (
        any::<u32>(),
        0u64..3_000_000,
        [f.clone(), f.clone(), f.clone()],
        [f.clone(), f.clone(), f.clone(), f],
    )
        .prop_map(|(seq, t_us, pos, quat)| Sample {
            seq,
            t_us,
            pos,
            quat,
        })
}
