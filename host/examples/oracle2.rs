//! debug: whole-gesture oracle accuracy over all isolated gestures
use figurine_host::recognize::{learn, simulate};
use figurine_host::synth::{self, gesture::Action, knobs::Knobs};
use figurine_recognizer::alignment::weighted_cost;
use figurine_recognizer::segment::shape_penalty;
use figurine_recognizer::Library;
fn main() {
    let pairs: Vec<u64> = std::env::args()
        .skip(1)
        .map(|x| x.parse().unwrap())
        .collect();
    let (mut n, mut ok) = (0, 0);
    for p in pairs {
        let (lib, blob) =
            simulate::load_library(Some(std::path::Path::new(&format!("/tmp/lib{p}.json"))))
                .unwrap();
        let dev = Library::from_bytes(&blob).unwrap();
        for (ai, &action) in Action::ALL.iter().enumerate() {
            for k in 0..30 {
                let seed = synth::sequence::item_seed(1000 * p, (ai * 10_000 + k) as u64);
                let d = synth::examples(seed, &Knobs::default(), action, 1, None).remove(0);
                let toks = learn::tokens_only(&learn::tokenize_gesture(&d.log));
                let sh = learn::motion_shape(&d.log);
                let mut best: Option<(f64, usize)> = None;
                for i in 0..dev.len() {
                    let Some(pn) = dev.pattern(i) else { continue };
                    let aligned = toks.len().max(pn.min_len());
                    let Some(c) = weighted_cost(&pn, &toks, 255.min(aligned * 2) as u8) else {
                        continue;
                    };
                    let pen = match (dev.shape(i), sh) {
                        (Some(e), Some(s)) => shape_penalty(e, dev.shape_tolerance(i), s),
                        _ => 0,
                    } as f64;
                    let sc = (4.0 * toks.len() as f64
                        - 3.0 * c as f64
                        - pen * (aligned as f64 / 2.0).floor().max(1.0))
                        / aligned as f64;
                    if best.is_none_or(|b| sc > b.0) {
                        best = Some((sc, i));
                    }
                }
                n += 1;
                if best.is_some_and(|b| lib.actions[b.1].name == action.name()) {
                    ok += 1;
                }
            }
        }
    }
    println!("oracle {ok}/{n} = {:.1}%", 100.0 * ok as f64 / n as f64);
}
