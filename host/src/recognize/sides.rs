//! `figurine learn`, step 5: a pattern accepts the action done to either side.
//!
//! Examples are first brought to one side (`to_one_side`), so a left and a right performance
//! average and align as the same gesture. The pattern is then learnt from them and from their
//! mirror images: two patterns joined, or — when both do not fit the device's positions and the
//! mirror images make the same strokes (a walk or a crouch, whose mirror changes only its
//! wobbles' signs) — one pattern from both sets together ([`learn_regex_mirrored`]); rotation
//! variants of a stroke become wildcards before anything else is shed ([`compact_rotations`]).

use anyhow::Result;
use figurine_recognizer::pattern::MAX_POSITIONS;
use figurine_recognizer::token::{Token, ANY_LIN, ANY_ROT, NONE_BIN};

use super::columns::{edit_distance, learn_regex, learn_regex_within, mandatory_runs, quorum};
use super::intent::{mirror_seq, Tokenized};
use super::regex::Regex;

/// Learns a pattern that also accepts the mirror images (left ↔ right) of the examples: a
/// figurine action done to the other side is the same action. When both sides do not fit the
/// device together:
///
/// | the mirror images … | then |
/// |---|---|
/// | make the same strokes (a walk, a crouch: only the wobbles' signs differ) | one pattern is learnt from the examples and their mirror images together, when it fits whole |
/// | make other strokes (a sidestep's `l` is `r`), or the joint pattern does not fit | each side sheds optional groups evenly, then rotation variants become wildcards ([`compact_rotations`]); only when even that does not fit is it the examples' own side |
///
/// A shed optional group loses the examples that needed it; a joint pattern loses none.
pub fn learn_regex_mirrored(seqs: &[Tokenized]) -> Result<Regex> {
    let direct = learn_regex(seqs)?;
    let mirrored: Vec<Tokenized> = seqs.iter().map(mirror_seq).collect();
    let Ok(mirror) = learn_regex(&mirrored) else {
        return Ok(direct);
    };
    if mirror.to_source() == direct.to_source() {
        return Ok(direct);
    }
    // Both sides within the device's positions: shed optional groups evenly if needed.
    let half = MAX_POSITIONS / 2;
    let both = Regex::Alt(vec![direct.clone(), mirror.clone()]);
    if both.positions() <= MAX_POSITIONS {
        return Ok(both);
    }
    if seqs
        .iter()
        .zip(&mirrored)
        .all(|(a, b)| strokes(a) == strokes(b))
    {
        let joint: Vec<Tokenized> = seqs.iter().chain(&mirrored).cloned().collect();
        // A variation and its mirror image are one performance's: the quorum stays the
        // examples' own.
        if let Ok(re) = learn_regex_within(&joint, usize::MAX, quorum(seqs.len())) {
            if re.positions() <= MAX_POSITIONS && re.compile()?.min_len() != usize::MAX {
                return Ok(re);
            }
        }
    }
    if let (Ok(d), Ok(m)) = (
        learn_regex_within(seqs, half, quorum(seqs.len())),
        learn_regex_within(&mirrored, half, quorum(seqs.len())),
    ) {
        return Ok(Regex::Alt(vec![d, m]));
    }
    // Still too big: a stroke's rotation variants (`lu.Zn|lu|lu.Zp`) become one wildcard
    // (`lu~`) — a rotation that differs costs only half an edit on the device anyway — so
    // that both sides fit; one side alone would never recognise the other.
    let (d, m) = (compact_rotations(&direct), compact_rotations(&mirror));
    let both = Regex::Alt(vec![d, m]);
    if both.positions() <= MAX_POSITIONS {
        Ok(both)
    } else {
        Ok(direct)
    }
}

/// The translation halves (strokes) of a gesture's mandatory runs, in order ([`NONE_BIN`] for a
/// run that only turned).
fn strokes(s: &Tokenized) -> Vec<u16> {
    mandatory_runs(s)
        .iter()
        .map(|m| (m.0 & 0x3ff) / 27)
        .collect()
}

/// `re` with every alternation of plain tokens that share one translation (`f.Zn|f|f.Zp`)
/// written as that translation with any rotation (`f~`).
pub fn compact_rotations(re: &Regex) -> Regex {
    let lin = |r: &Regex| match r {
        Regex::Sym(s) if s & (ANY_LIN | ANY_ROT) == 0 && s / 27 != NONE_BIN => Some(s / 27),
        Regex::Sym(s) if s & ANY_ROT != 0 => Some((s & 0x3ff) / 27),
        _ => None,
    };
    match re {
        Regex::Alt(v) if v.len() > 1 => {
            let first = lin(&v[0]);
            if first.is_some() && v.iter().all(|r| lin(r) == first) {
                let l = first.unwrap_or(NONE_BIN);
                Regex::Sym((l * 27 + NONE_BIN) | ANY_ROT)
            } else {
                Regex::Alt(v.iter().map(compact_rotations).collect())
            }
        }
        Regex::Alt(v) => Regex::Alt(v.iter().map(compact_rotations).collect()),
        Regex::Cat(v) => Regex::Cat(v.iter().map(compact_rotations).collect()),
        Regex::Star(r) => Regex::Star(Box::new(compact_rotations(r))),
        Regex::Plus(r) => Regex::Plus(Box::new(compact_rotations(r))),
        Regex::Opt(r) => Regex::Opt(Box::new(compact_rotations(r))),
        Regex::Sym(s) => Regex::Sym(*s),
    }
}

/// Which examples to mirror so that all are performed to the side of the median-length one:
/// those whose mirror image is closer to it, compared by [`side_keys`].
pub(super) fn to_one_side(seqs: &[Tokenized]) -> Vec<bool> {
    let mut order: Vec<usize> = (0..seqs.len()).collect();
    order.sort_by_key(|&i| seqs[i].len());
    let Some(&r) = order.get(order.len() / 2) else {
        return Vec::new();
    };
    let reference = side_keys(&seqs[r]);
    seqs.iter()
        .map(|s| {
            edit_distance(&side_keys(&mirror_seq(s)), &reference)
                < edit_distance(&side_keys(s), &reference)
        })
        .collect()
}

/// What tells a performance's side: each run's translation when it translates, else its
/// rotation — not the wobble marks or the tilt of a stroke, which differ between performances
/// of the same side and would hide a mirrored one.
fn side_keys(s: &Tokenized) -> Vec<Token> {
    s.iter()
        .map(|&(t, _)| {
            let lin = (t & 0x3ff) / 27;
            if t & ANY_LIN == 0 && lin != NONE_BIN {
                lin
            } else {
                27 + (t & 0x3ff) % 27
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::super::intent::testing::seq;
    use super::super::intent::tokens_only;
    use super::super::library::tokens_to_string;
    use super::*;
    use figurine_recognizer::token::parse_token;

    #[test]
    fn examples_to_the_other_side_are_mirrored_whatever_their_wobbles() {
        let seq = |names: &str| -> Tokenized {
            names
                .split_whitespace()
                .map(|n| {
                    let (name, wobble) = n.strip_suffix('~').map_or((n, false), |b| (b, true));
                    let t = parse_token(name).unwrap();
                    (if wobble { t | ANY_ROT } else { t }, 0.2)
                })
                .collect()
        };
        // A sidestep to the left (its hops learnt with roll wobbles), the median one to the
        // left with other marks, and one to the right in plain tokens: only the right one
        // turns, though no token of it equals one of the reference's.
        let seqs = [
            seq("lu.Zn ld~ lu~ ld~ l"),
            seq("lu~ ld.Zp lu.Zn ld~ lu"),
            seq("ru rd ru rd"),
        ];
        assert_eq!(to_one_side(&seqs), [false, false, true]);
        assert!(to_one_side(&[]).is_empty());
    }

    #[test]
    fn a_gesture_that_is_its_own_mirror_image_is_learnt_from_both_sides_at_once() {
        // Walks whose hops rock and roll one way and back: mirrored, they make the same
        // strokes, and two sides with every example's optional runs do not fit the device.
        let seqs = vec![
            seq("uf:0.2 f.Zp:0.1 df.XnZp:0.2 .Zn:0.05 uf:0.2 f.Zn:0.1 df.XnZn:0.2 .Zp:0.05 uf:0.2 df:0.2"),
            seq("uf.Zp:0.2 d.XnZp:0.05 df:0.2 u:0.05 uf:0.2 df.XpZp:0.2 .XnZn:0.05 uf:0.2 df.Zn:0.2"),
            seq("uf:0.2 .Zp:0.05 df.Zp:0.2 ub:0.05 uf.Zn:0.2 f:0.05 df:0.2 .XnZp:0.05 uf:0.2 df:0.2 d:0.05"),
        ];
        let mirrored: Vec<Tokenized> = seqs.iter().map(mirror_seq).collect();
        let sides = Regex::Alt(vec![
            learn_regex_within(&seqs, usize::MAX, 1).unwrap(),
            learn_regex_within(&mirrored, usize::MAX, 1).unwrap(),
        ]);
        assert!(sides.positions() > MAX_POSITIONS, "{}", sides.to_source());
        let re = learn_regex_mirrored(&seqs).unwrap();
        let c = re.compile().unwrap();
        for s in seqs.iter().chain(&mirrored) {
            let t = tokens_only(s);
            assert!(
                c.accepts(&t),
                "{} rejects {}",
                re.to_source(),
                tokens_to_string(&t)
            );
        }
    }

    #[test]
    fn mirrored_patterns_accept_the_other_side() {
        let seqs = vec![seq("l:0.3 .Yp:0.3"), seq("l:0.3 .Yp:0.4")];
        let re = learn_regex_mirrored(&seqs).unwrap();
        let c = re.compile().unwrap();
        assert!(c.accepts(&tokens_only(&seq("l:1 .Yp:1"))));
        assert!(c.accepts(&tokens_only(&seq("r:1 .Yn:1"))));
        assert!(!c.accepts(&tokens_only(&seq("r:1 .Yp:1"))));
    }

    #[test]
    fn a_mirrored_pattern_too_big_for_both_sides_writes_rotations_as_wildcards() {
        let re = Regex::parse("(f.Zn|f|f.Zp)+ (b|d)* lu.Zn").unwrap();
        assert_eq!(compact_rotations(&re).to_source(), "f~+ (b|d)* lu.Zn");
        // Nine strokes, each rolling (and so written plain too, `lu.Zn|lu`): 18 positions a
        // side, too many for two.
        let a = "lu.Zn:0.2 ld.Zp:0.2 u.Zn:0.2 d.Zp:0.2 lb.Zn:0.2 lf.Zp:0.2 ub.Zn:0.2 \
                 df.Zp:0.2 l.Zn:0.2";
        let seqs = vec![seq(a), seq(a), seq(a)];
        assert!(learn_regex(&seqs).unwrap().positions() > MAX_POSITIONS / 2);
        let re = learn_regex_mirrored(&seqs).unwrap();
        assert!(re.to_source().contains("lu~"), "{}", re.to_source());
        let c = re.compile().unwrap();
        assert!(c.accepts(&tokens_only(&seqs[0])), "{}", re.to_source());
        assert!(
            c.accepts(&tokens_only(&mirror_seq(&seqs[0]))),
            "{}",
            re.to_source()
        );
    }
}
