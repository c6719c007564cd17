//! debug: dump per-gesture whole-phrase readings for rule mining
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
                let mut row = format!("{p} {} {seed} {}", action.name(), toks.len());
                for i in 0..dev.len() {
                    let Some(pn) = dev.pattern(i) else { continue };
                    let aligned = toks.len().max(pn.min_len());
                    let c =
                        weighted_cost(&pn, &toks, 255.min(aligned * 2) as u8).map_or(-1, i32::from);
                    let pen = match (dev.shape(i), sh) {
                        (Some(e), Some(s)) => shape_penalty(e, dev.shape_tolerance(i), s) as i32,
                        _ => -1,
                    };
                    row += &format!(" {}:{}:{}:{}", lib.actions[i].name, aligned, c, pen);
                }
                println!("{row}");
            }
        }
    }
}
