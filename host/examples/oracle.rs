//! debug: whole-gesture oracle for misreads
use figurine_host::recognize::{learn, simulate};
use figurine_host::synth::{self, gesture::Action, knobs::Knobs};
use figurine_recognizer::alignment::weighted_cost;
use figurine_recognizer::segment::shape_penalty;
use figurine_recognizer::Library;
use std::collections::BTreeMap;
fn main() {
    let list = std::fs::read_to_string("/tmp/mis.txt").unwrap();
    let mut stat: BTreeMap<String, [usize; 3]> = BTreeMap::new();
    for line in list.lines() {
        let f: Vec<&str> = line.split_whitespace().collect();
        let (p, a, g, seed) = (f[0], f[1], f[2], f[3].parse::<u64>().unwrap());
        let (lib, blob) =
            simulate::load_library(Some(std::path::Path::new(&format!("/tmp/lib{p}.json"))))
                .unwrap();
        let dev = Library::from_bytes(&blob).unwrap();
        let action: Action = a.parse().unwrap();
        let d = synth::examples(seed, &Knobs::default(), action, 1, None).remove(0);
        let toks = learn::tokens_only(&learn::tokenize_gesture(&d.log));
        let Some(sh) = learn::motion_shape(&d.log) else {
            continue;
        };
        // score: 4*aligned - 3*cost - shape_cost ; per aligned token
        let mut scores: Vec<(f64, usize)> = (0..dev.len())
            .filter_map(|i| {
                let pn = dev.pattern(i)?;
                let aligned = toks.len().max(pn.min_len());
                let c = weighted_cost(&pn, &toks, 255.min(aligned * 2) as u8)?;
                let pen = dev
                    .shape(i)
                    .map_or(0, |e| shape_penalty(e, dev.shape_tolerance(i), sh))
                    as f64;
                let sc = (4.0 * toks.len() as f64
                    - 3.0 * c as f64
                    - pen * (aligned as f64 / 2.0).max(1.0))
                    / aligned as f64;
                Some((sc, i))
            })
            .collect();
        scores.sort_by(|x, y| y.0.total_cmp(&x.0));
        let top = scores
            .first()
            .map(|x| lib.actions[x.1].name.clone())
            .unwrap_or_default();
        let e = stat.entry(format!("{a}->{g}")).or_default();
        e[0] += 1;
        if top == a {
            e[1] += 1;
        }
        if top == g {
            e[2] += 1;
        }
    }
    let mut t = [0; 3];
    for (k, v) in &stat {
        println!("{k:20} n {} oracle-true {} oracle-got {}", v[0], v[1], v[2]);
        for i in 0..3 {
            t[i] += v[i];
        }
    }
    println!("total {t:?}");
}
