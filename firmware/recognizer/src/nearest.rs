//! Stage 6b — a gesture no action matched closely enough: the nearest action, if near.
//!
//! The automata hold every match to its action's edit bound and to
//! [`crate::segment::EDIT_SHARE`], which is what keeps a lone stroke inside a longer motion
//! from being read as an action. But a gesture that stands alone — a phrase of motion with a
//! pause of at least [`HOLD_US`] before it and [`crate::segment::PAUSE_US`] after it, nothing
//! of it matched, and no action's pattern able to go on from it (the pause is no hold inside
//! a gesture) — is plainly meant as one action, even when it strays from the few examples its
//! action was learnt from further than the bound allows: a kick swung straight forward where
//! every example rose, a punch thrown without its wind-up. A child expects the toy to answer
//! it. Such a phrase is compared whole with every action ([`weighted_cost`]) and reported as
//! the nearest one when it is within the share of edits every match is held to
//! ([`EDIT_SHARE`]), without the action's own bound, and did not move plainly unlike that
//! action's examples ([`SHAPE_CAP`]: a talking hand's beat spells a stroke or two of some
//! pattern, but not the way its examples moved) — or as the nearest action within the
//! looser [`PHRASE_SHARE`] whose examples moved as the phrase did (its
//! [`crate::features::Shape`]: a lone sidestep hop, one stroke short of every example);
//! otherwise nothing is reported.
//!
//! A phrase that some action's pattern could still go on from is no gesture of its own while
//! the figurine rests (it may be holding inside that action), but it is once the stream ends
//! or the rest outlasts every hold ([`OPEN_PHRASE_US`]): a sudden sidestep whose landings the
//! smoothing took is still a sidestep.
//!
//! Such a closed phrase — a gesture of two strokes or more, made and then rested after for
//! longer than any hold — was plainly meant as an action even when no action is that near: it
//! is read as the action with the highest merit per aligned token, its shape cost included,
//! among those within [`CLOSED_SHARE`] whose examples it moved not too unlike
//! ([`CLOSED_SHAPE_MAX`]): a small kick whose swing fell under the lever-arm threshold, read
//! as its pitch alone (`.Xn .Xp`), a whole edit per token from the kick's `uf.Xn b.Xp db`.
//! A phrase that lost strokes may be all edits; one with more strokes than the action's
//! shortest match may not (`all_edits`): a toy lifted, looked at and set down (`u .Xn .Xp
//! d`) is no turn, whose `.Yp` is one token long and none of the four strokes. When it
//! moved plainly unlike every action's examples, it is none of them: a toy carried to
//! another spot or lifted and set back down is no action, however its strokes happen to be
//! written.
//!
//! A loose reading also settles a match the automata did make but whose motion is plainly
//! unlike its action's examples ([`reread`]): when another action's pattern nearly fits the
//! same tokens and its examples moved as the match did, that action it is. So does a match
//! that a pause commits while part of its phrase is left unexplained and its motion is unlike
//! its action's ([`whole_phrase`]): the whole phrase is read as the action whose examples it
//! moved like (or least unlike), when one reads it within the same share.
//! And a match that went less far than its action's examples ([`crate::extent`]: a fidget,
//! for that action) is the action whose pattern reads it within one edit and whose examples
//! it moved like, when it went as far as those ([`not_that_far`]): each extent bounds its own
//! action.
//!
//! Pauses shorter than [`HOLD_US`] lie inside the phrase: a crouch held low is not two
//! gestures. The start of the stream bounds a phrase as a pause would (a child who plays right
//! away), and so does the end of a log (the recognizer's `flush`); a match too brief to be an
//! action does not break a phrase (a sudden sidestep's hops, each matched alone). Run once per pause, over at most [`NEAREST_MAX_TOKENS`] tokens; its cost is a
//! rare spike (measured by the firmware bench), not a per-sample one.

use crate::alignment::{weighted_cost, FULL};
use crate::automaton::prefix_alive;
use crate::features::Shape;
use crate::history::{History, HISTORY_RUNS};
use crate::pattern::Library;
use crate::segment::{Candidate, EDIT_SHARE, GAPPED_HOLD_US, HOLD_US};
use crate::shape::{observed_shape, penalty_of, shape_cost, SHAPE_CAP};
use crate::token::{Token, STILL};

/// Longest phrase that is compared with the actions, moving tokens; a longer one is no single
/// gesture (a single long performance matches its action within the bounds anyway).
pub const NEAREST_MAX_TOKENS: usize = 24;

/// The moving tokens of the phrase that ends at run `last` (the run before the current
/// pause): back to the previous pause of at least [`HOLD_US`], or to `floor` when that
/// `bounds` a phrase (the stream began there: a child who starts playing right away). None
/// when the phrase reaches back to any other `floor` (part of it was emitted already) or
/// past the history, or is longer than [`NEAREST_MAX_TOKENS`]. Returns the tokens oldest
/// first, and the phrase's first and last moving runs.
fn phrase(
    hist: &History,
    floor: u32,
    bounds: bool,
    last: u32,
    tok: &mut [Token; NEAREST_MAX_TOKENS],
) -> Option<(usize, u32, u32)> {
    let mut rev = [STILL; NEAREST_MAX_TOKENS];
    let mut n = 0usize;
    let mut first = last;
    let span = last.wrapping_sub(floor);
    if span >= HISTORY_RUNS as u32 {
        // `last` lies below the floor (it was committed), or the floor is long gone.
        return None;
    }
    let mut i = last;
    for _ in 0..HISTORY_RUNS {
        if i.wrapping_sub(floor) > span {
            if bounds {
                break;
            }
            // Below the floor: the phrase is not whole.
            return None;
        }
        let r = hist.get(i)?;
        if r.token == STILL {
            if r.end.1.saturating_sub(r.start.1) >= HOLD_US {
                break;
            }
        } else {
            *rev.get_mut(n)? = r.token;
            n += 1;
            first = i;
        }
        i = i.wrapping_sub(1);
    }
    if n == 0 {
        return None;
    }
    for (k, slot) in tok.iter_mut().take(n).enumerate() {
        *slot = rev.get(n - 1 - k).copied().unwrap_or(STILL);
    }
    Some((n, first, last))
}

/// What [`nearest_action`] found for one pause.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Nearest {
    /// The nearest action over the phrase, when near enough (never sought for an open one).
    pub candidate: Option<Candidate>,
    /// Some action's pattern has the phrase as the start of a match that is not over: the
    /// pause may be a hold inside that gesture, so the phrase does not stand alone (the
    /// recognizer reports nothing for it; the automata take it up if the gesture goes on).
    pub open: bool,
}

/// The action nearest the stand-alone phrase ending at run `last`, as a candidate over the
/// phrase, when one is near enough ([`EDIT_SHARE`], or [`PHRASE_SHARE`] as the module docs
/// say; [`CLOSED_SHARE`] for a `closed` phrase). Ties go to the lower action index.
/// None when there is no whole phrase: it reaches back to `floor` or past the history, or is
/// longer than [`NEAREST_MAX_TOKENS`]. `bounds`: `floor` is a phrase boundary (the stream
/// began there), not the end of an event.
// Once per pause at most: kept out of the per-sample path (flash, not speed).
#[cold]
#[inline(never)]
pub fn nearest_action(
    lib: &Library<'_>,
    hist: &History,
    floor: u32,
    bounds: bool,
    last: u32,
    closed: bool,
) -> Option<Nearest> {
    let mut tok = [STILL; NEAREST_MAX_TOKENS];
    let (n, first, last) = phrase(hist, floor, bounds, last, &mut tok)?;
    let tokens = tok.get(..n).unwrap_or(&[]);
    // A phrase some action could still go on from is no gesture of its own: nothing to weigh.
    if !closed
        && (0..lib.len())
            .filter_map(|a| lib.pattern(a))
            .any(|p| prefix_alive(&p, tokens, false))
    {
        return Some(Nearest {
            candidate: None,
            open: true,
        });
    }
    // The nearest action within the share every match is held to, of those whose examples
    // the phrase did not move plainly unlike (a hand that talks beats out a stroke or two
    // that some pattern spells, but not the way that action's examples moved); and within the
    // looser phrase share, the nearest of those whose examples moved as the phrase did (a
    // sudden sidestep's lone hop). One alignment per action, bounded by the share it can use:
    // the shape is checked first, and most actions fail it.
    let mut best: Option<(Candidate, usize)> = None;
    let mut alike: Option<(Candidate, usize)> = None;
    let observed = observed_shape(hist, first, last);
    let (e, t) = EDIT_SHARE;
    for a in 0..lib.len() {
        let penalty = penalty_of(lib, a, &observed);
        if penalty == Some(SHAPE_CAP) {
            continue;
        }
        let moved_alike = penalty == Some(0);
        let share = if moved_alike {
            PHRASE_SHARE
        } else {
            EDIT_SHARE
        };
        let Some((c, aligned)) = loose_reading(lib, a, tokens, first, last, share) else {
            continue;
        };
        if moved_alike && nearer(&c, aligned, alike) {
            alike = Some((c, aligned));
        }
        let within = usize::from(c.cost) * t <= usize::from(FULL) * aligned * e;
        if within && nearer(&c, aligned, best) {
            best = Some((c, aligned));
        }
    }
    let mut candidate = best.or(alike).map(|(c, _)| c);
    if candidate.is_none() && closed && tokens.len() >= 2 {
        candidate = closed_reading(lib, tokens, first, last, &observed);
    }
    Some(Nearest {
        candidate,
        open: false,
    })
}

/// The reading of a closed phrase ([`nearest_action`]) with the highest merit per aligned
/// token, shape cost included ([`Candidate::merit`]), among the actions that read it within
/// [`CLOSED_SHARE`], not `all_edits`, and whose examples it moved at most
/// [`CLOSED_SHAPE_MAX`] unlike.
fn closed_reading(
    lib: &Library<'_>,
    tokens: &[Token],
    first: u32,
    last: u32,
    observed: &Shape,
) -> Option<Candidate> {
    let mut top: Option<(Candidate, usize)> = None;
    for a in 0..lib.len() {
        // An action without a learnt shape gives no evidence the phrase moved like it.
        let Some(penalty) = penalty_of(lib, a, observed).filter(|&p| p <= CLOSED_SHAPE_MAX) else {
            continue;
        };
        let Some((mut c, aligned)) = loose_reading(lib, a, tokens, first, last, CLOSED_SHARE)
        else {
            continue;
        };
        if all_edits(c.cost, tokens.len(), c.min_len) {
            continue;
        }
        c.shape = shape_cost(penalty, aligned);
        // c.merit / aligned > t.merit / t_aligned, cross-multiplied.
        if top.is_none_or(|(t, t_aligned)| {
            i64::from(c.merit()) * t_aligned as i64 > i64::from(t.merit()) * aligned as i64
        }) {
            top = Some((c, aligned));
        }
    }
    top.map(|(c, _)| c)
}

/// Whether a closed phrase of `len` moving tokens, read as an action whose shortest match is
/// `min_len` tokens at `cost` half-edits, is all edits although it has more strokes than the
/// action needs: a whole edit for every stroke, so nothing of it is that action's. A phrase
/// no longer than the shortest match may be (its strokes fell under the thresholds: a small
/// kick's `.Xn .Xp`); a longer one, off by a whole edit in each stroke, only has strokes
/// to spare.
fn all_edits(cost: u8, len: usize, min_len: u8) -> bool {
    len > usize::from(min_len) && usize::from(cost) >= usize::from(FULL) * len
}

/// Another reading of candidate `c` (its runs `c.start..=c.end`, at most
/// [`NEAREST_MAX_TOKENS`] moving ones) when its motion shape is as unlike its action's
/// examples' as [`shape_penalty`](crate::shape::shape_penalty) measures ([`SHAPE_CAP`]):
/// the action whose pattern reads the same tokens within [`LOOSE_SHARE`] and whose examples'
/// shape the motion lies within (nearest by cost per aligned token, then the lower index).
/// None when there is none, or the runs' shape is not that unlike. The automata hold every match
/// to [`EDIT_SHARE`], so a performance that lost a stroke its action's examples all had (a
/// sudden jump's flight, too quick for the smoothing, read as a crouch's `d u`) may be matched
/// only by an action it plainly did not move like; the shape then decides, as it does for a
/// stand-alone phrase.
// Once per committed event, not per sample: out of the per-sample path (flash).
#[cold]
#[inline(never)]
pub fn reread(lib: &Library<'_>, hist: &History, c: &Candidate) -> Option<Candidate> {
    let observed = observed_shape(hist, c.start, c.end);
    if penalty_of(lib, usize::from(c.action), &observed) != Some(SHAPE_CAP) {
        return None;
    }
    read_alike(lib, hist, c, &observed)
}

/// Another reading of candidate `c` when its motion did not go as far as its action's
/// examples ([`crate::extent`]: a fidget, for that action): the action other than `c`'s whose
/// pattern reads the same tokens within one edit ([`NOT_THAT_FAR_COST`]) and whose examples
/// the motion moved like, nearest by cost per aligned token. Each action's extent bounds that
/// action alone: a punch thrown without its wind-up (`f f.Zn b.Zp`), which a run's pattern
/// matched but which never went as far as a run goes, is the punch whose pattern reads it
/// bar its wind-up. Whether it went as far as that action's examples is the caller's to ask.
#[cold]
#[inline(never)]
pub fn not_that_far(lib: &Library<'_>, hist: &History, c: &Candidate) -> Option<Candidate> {
    let observed = observed_shape(hist, c.start, c.end);
    read_alike(lib, hist, c, &observed).filter(|r| r.cost <= NOT_THAT_FAR_COST)
}

/// The nearest reading of candidate `c`'s moving tokens within [`LOOSE_SHARE`] by an action
/// other than `c`'s whose examples moved as `observed` (the runs' shape) did; None when there
/// is none, or its runs are gone or more than [`NEAREST_MAX_TOKENS`] moving ones.
fn read_alike(
    lib: &Library<'_>,
    hist: &History,
    c: &Candidate,
    observed: &Shape,
) -> Option<Candidate> {
    let mut tok = [STILL; NEAREST_MAX_TOKENS];
    let mut n = 0usize;
    let mut i = c.start;
    for _ in 0..HISTORY_RUNS {
        let r = hist.get(i)?;
        if r.token != STILL {
            *tok.get_mut(n)? = r.token;
            n += 1;
        }
        if i == c.end {
            break;
        }
        i = i.wrapping_add(1);
    }
    let tokens = tok.get(..n)?;
    nearest_alike(
        lib,
        observed,
        0,
        tokens,
        c.start,
        c.end,
        usize::from(c.action),
    )
}

/// A reading of the whole stand-alone phrase ending at run `last` (bounded as for
/// [`nearest_action`]) when candidate `c`, which a pause is committing, leaves some of its
/// moving tokens unexplained and moved unlike its action's examples: the nearest action within
/// [`LOOSE_SHARE`] among those whose examples the whole phrase moved least unlike (as they
/// did, when any). A kick without its wind-up, whose forward swing a run matched
/// (`uf.Xn f.Xn`) while its backswing (`b.Xp`) matched nothing, is one gesture, and a kick —
/// flicked higher than every example, too.
#[cold]
#[inline(never)]
pub fn whole_phrase(
    lib: &Library<'_>,
    hist: &History,
    floor: u32,
    bounds: bool,
    last: u32,
    c: &Candidate,
) -> Option<Candidate> {
    // A match that moved like its action stands, whatever follows it: no phrase to gather.
    if c.shape == 0 {
        return None;
    }
    let mut tok = [STILL; NEAREST_MAX_TOKENS];
    let (n, first, last) = phrase(hist, floor, bounds, last, &mut tok)?;
    if usize::from(c.len) >= n {
        return None;
    }
    let tokens = tok.get(..n)?;
    let observed = observed_shape(hist, first, last);
    let least = least_penalty(lib, &observed);
    nearest_alike(lib, &observed, least, tokens, first, last, usize::MAX)
}

/// The least shape penalty ([`penalty_of`]) any action has for motion of shape `observed`;
/// 0 when no action has a learnt shape. A phrase that moved unlike every action's examples
/// moved no less like one than another: the shape then tells apart only the actions it moved
/// further unlike than that.
// Two callers, each once per pause at most: one out-of-line copy (flash).
#[inline(never)]
fn least_penalty(lib: &Library<'_>, observed: &Shape) -> i16 {
    (0..lib.len())
        .filter_map(|a| penalty_of(lib, a, observed))
        .min()
        .unwrap_or(0)
}

/// The nearest reading (by cost per aligned token, then the lower index) of `tokens` (the
/// moving tokens of runs `start..=end`) within [`LOOSE_SHARE`], among the actions other than
/// `skip` whose examples `observed` moved `penalty` unlike ([`reread`], [`whole_phrase`]).
#[inline(never)]
fn nearest_alike(
    lib: &Library<'_>,
    observed: &Shape,
    penalty: i16,
    tokens: &[Token],
    start: u32,
    end: u32,
    skip: usize,
) -> Option<Candidate> {
    let mut best: Option<(Candidate, usize)> = None;
    for a in 0..lib.len() {
        // The shape first: it is cheaper than the alignment, and most actions fail it.
        if a == skip || penalty_of(lib, a, observed) != Some(penalty) {
            continue;
        }
        let Some((alt, aligned)) = loose_reading(lib, a, tokens, start, end, LOOSE_SHARE) else {
            continue;
        };
        if nearer(&alt, aligned, best) {
            best = Some((alt, aligned));
        }
    }
    best.map(|(b, _)| b)
}

/// Action `a`'s reading of `tokens` (the moving tokens of runs `start..=end`) when within
/// `share` (edits, tokens) of its aligned length (the tokens', or the pattern's shortest match if
/// longer): the candidate, without a shape cost, and that aligned length.
// Inlined into its three callers, as the loops were (flash: out of line it is 212 B larger).
#[inline(always)]
fn loose_reading(
    lib: &Library<'_>,
    a: usize,
    tokens: &[Token],
    start: u32,
    end: u32,
    share: (usize, usize),
) -> Option<(Candidate, usize)> {
    let p = lib.pattern(a)?;
    let aligned = tokens.len().max(p.min_len());
    // Within the share: cost ≤ FULL · aligned · e / t half-edits.
    let (e, t) = share;
    let bound = (usize::from(FULL) * aligned * e / t).min(usize::from(u8::MAX)) as u8;
    let cost = weighted_cost(&p, tokens, bound)?;
    let c = Candidate {
        action: a as u8,
        start,
        end,
        cost,
        len: tokens.len().min(usize::from(u16::MAX)) as u16,
        min_len: p.min_len().min(255) as u8,
        positions: p.positions().min(255) as u8,
        cyclic: p.cyclic(),
        shape: 0,
    };
    Some((c, aligned))
}

/// Whether `c` over `aligned` tokens is nearer than `best`: lower cost per aligned token
/// (`c.cost / aligned < b.cost / b_aligned`, cross-multiplied).
#[inline(always)]
fn nearer(c: &Candidate, aligned: usize, best: Option<(Candidate, usize)>) -> bool {
    best.is_none_or(|(b, b_aligned)| {
        usize::from(c.cost) * b_aligned < usize::from(b.cost) * aligned
    })
}

/// Stillness after which a phrase that some action's pattern could still go on from stands
/// alone all the same, µs: no action holds that long inside itself (the longest hold the
/// decider waits for, [`crate::segment::GAPPED_HOLD_US`]) — a sudden sidestep's hops that
/// read only as rising, whose landing the smoothing took, are a sidestep, not half of one.
pub const OPEN_PHRASE_US: u64 = GAPPED_HOLD_US;

/// Edits per token a match the automata made may be off another action that re-reads it
/// ([`reread`]), as (edits, tokens).
pub const LOOSE_SHARE: (usize, usize) = (1, 2);

/// Most a reading may cost, in half-edits ([`crate::alignment`]), to stand in for a match that
/// did not go as far as its action's examples ([`not_that_far`]): one edit. Within the loose
/// share ([`LOOSE_SHARE`]), a run's match over a punch and the kick after it, which went less
/// far than the run's examples, was read as one throw, more than an edit off both.
pub const NOT_THAT_FAR_COST: u8 = FULL;

/// Edits per token a stand-alone phrase may be off an action whose examples moved as it did
/// ([`nearest_action`]), as (edits, tokens): looser than [`LOOSE_SHARE`], because no match
/// claims the phrase (a re-read overrides one the automata made).
pub const PHRASE_SHARE: (usize, usize) = (2, 3);

/// Edits per token a closed phrase (the stream ended, or the figurine rested
/// [`OPEN_PHRASE_US`] after it) may be off the action it is read as when nothing nearer
/// claims it ([`nearest_action`]), as (edits, tokens): up to all of them, for a phrase that
/// lost strokes; one with strokes to spare must keep some (`all_edits`).
pub const CLOSED_SHARE: (usize, usize) = (1, 1);

/// Most shape penalty ([`crate::shape::shape_penalty`], quarter tokens) an action may have
/// for a closed phrase to be read as it ([`nearest_action`]): half the cap, so a phrase is
/// never read as an action whose examples moved altogether otherwise. A phrase that strays
/// from every action's tokens *and* moved unlike all their examples is no action.
pub const CLOSED_SHAPE_MAX: i16 = SHAPE_CAP / 2;

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use crate::alignment::HALF;
    use crate::features::{Accum, Shape, ShapeSums, QUANTITIES, SPEED};
    use crate::pattern::tests::seq_library;
    use crate::shape::{shape_cost, shape_of};
    use crate::token::parse_token;

    /// A history of runs `(token, duration ms)` ("_" for STILL), back to back from t = 0.
    fn history(runs: &[(&str, u64)]) -> History {
        let mut h = History::new();
        let mut t = 0u64;
        for (i, &(name, ms)) in runs.iter().enumerate() {
            let token = if name == "_" {
                STILL
            } else {
                parse_token(name).unwrap()
            };
            h.open(token, (i as u32, t), Accum::new());
            t += ms * 1000;
            h.newest_mut().unwrap().end = (i as u32, t);
        }
        h
    }

    fn lib_blob() -> std::vec::Vec<u8> {
        // 0: punch `b+ f+ b+`, 1: crouch `d+ u+`, 2: kick `uf.Xn+ b.Xp+ db+`.
        seq_library(&[
            (&["b", "f", "b"], 2),
            (&["d", "u"], 1),
            (&["uf.Xn", "b.Xp", "db"], 0),
        ])
    }

    #[test]
    fn a_stand_alone_gesture_is_its_nearest_action() {
        let blob = lib_blob();
        let lib = Library::from_bytes(&blob).unwrap();
        // A punch without its wind-up: one deletion in three aligned tokens.
        let h = history(&[("_", 800), ("f", 200), ("b", 200), ("_", 150)]);
        let n = nearest_action(&lib, &h, 0, false, 2, false).unwrap();
        let c = n.candidate.unwrap();
        assert_eq!(
            (c.action, c.start, c.end, c.distance(), c.cost),
            (0, 1, 2, 1, FULL)
        );
        assert!(!n.open);
        // A kick swung straight forward (`f.Xn`, 45° below `uf.Xn`), past its bound of 0.
        let h = history(&[
            ("_", 800),
            ("f.Xn", 200),
            ("b.Xp", 200),
            ("db", 200),
            ("_", 150),
        ]);
        let c = nearest_action(&lib, &h, 0, false, 3, false)
            .unwrap()
            .candidate
            .unwrap();
        assert_eq!((c.action, c.cost, c.distance()), (2, HALF, 1));
        // Without its drop back as well, it is too far: 1.5 edits in 3 aligned tokens.
        let h = history(&[("_", 800), ("f.Xn", 200), ("b.Xp", 200), ("_", 150)]);
        assert_eq!(
            nearest_action(&lib, &h, 0, false, 2, false)
                .unwrap()
                .candidate,
            None
        );
        // … unless the kick's examples left a shape the phrase moves like (these runs carry
        // no motion sums: no evidence against it): then it is the kick, within the phrase
        // share.
        let shaped = crate::pattern::tests::with_shapes(&blob, &[Some([0, 0, 255, 0, 0, 128]); 3]);
        let with_shapes = Library::from_bytes(&shaped).unwrap();
        let c = nearest_action(&with_shapes, &h, 0, false, 2, false)
            .unwrap()
            .candidate
            .unwrap();
        assert_eq!((c.action, c.cost), (2, HALF + FULL));
    }

    #[test]
    fn the_phrase_share_goes_to_the_nearest_action_the_phrase_moved_like() {
        // A lone `u` that rose: the end of a crouch `d+ u+`, one whole edit in two aligned
        // tokens.
        let (h, rose) = moved(&[("u", 20, [0.0, 0.9, 0.0], 0.01)]);
        let up = Some(shape_bytes(rose));
        let mut sideways = rose;
        (sideways[0], sideways[1]) = (rose[1], rose[0]);
        let left = Some(shape_bytes(sideways));
        let blob = lib_blob();
        let found = |blob: &[u8], shapes: &[Option<[u8; 6]>]| {
            let shaped = crate::pattern::tests::with_shapes(blob, shapes);
            nearest_action(
                &Library::from_bytes(&shaped).unwrap(),
                &h,
                0,
                false,
                1,
                false,
            )
            .unwrap()
            .candidate
            .map(|c| c.action)
        };
        assert_eq!(found(&blob, &[up; 3]), Some(1));
        // Without a shape learnt for it, or with examples that moved otherwise: nothing.
        assert_eq!(found(&blob, &[up, None, up]), None);
        assert_eq!(found(&blob, &[up, left, up]), None);
        // A second action as near (`l+ u+`): the one whose examples moved as the phrase did;
        // when both did, the nearer, and on a tie the lower index.
        let two = seq_library(&[
            (&["b", "f", "b"], 2),
            (&["d", "u"], 1),
            (&["uf.Xn", "b.Xp", "db"], 0),
            (&["l", "u"], 1),
        ]);
        assert_eq!(found(&two, &[up, up, up, left]), Some(1));
        assert_eq!(found(&two, &[up, left, up, up]), Some(3));
        assert_eq!(found(&two, &[up; 4]), Some(1));
        // A phrase further than the phrase share from every action is nothing, whatever its
        // shape: `l r l`, three edits from the crouch.
        let far = history(&[("_", 800), ("l", 200), ("r", 200), ("l", 200), ("_", 150)]);
        let shaped = crate::pattern::tests::with_shapes(&two, &[left; 4]);
        assert_eq!(
            nearest_action(
                &Library::from_bytes(&shaped).unwrap(),
                &far,
                0,
                false,
                3,
                false
            )
            .unwrap()
            .candidate,
            None
        );
    }

    #[test]
    fn a_stand_alone_gesture_moved_plainly_unlike_its_nearest_action_is_none() {
        // A punch without its wind-up (`f b`, one deletion in three aligned tokens), thrust
        // forward and drawn back: its speed along the front axis (|v| per axis).
        let (h, thrust) = moved(&[
            ("f", 20, [0.0, 0.05, 0.9], 0.0),
            ("b", 20, [0.0, 0.05, 0.9], 0.0),
        ]);
        let mut bobbed = thrust;
        (bobbed[1], bobbed[2]) = (thrust[2], thrust[1]);
        let blob = lib_blob();
        let read = |punch: Option<[u8; 6]>| {
            let shaped = crate::pattern::tests::with_shapes(&blob, &[punch, None, None]);
            let lib = Library::from_bytes(&shaped).unwrap();
            let penalty = penalty_of(&lib, 0, &observed_shape(&h, 1, 2));
            let found = nearest_action(&lib, &h, 0, false, 2, false).unwrap();
            (penalty, found.candidate.map(|c| c.action))
        };
        // Its examples thrust forward too, or left no shape: the punch.
        assert_eq!(read(Some(shape_bytes(thrust))), (Some(0), Some(0)));
        assert_eq!(read(None), (None, Some(0)));
        // Its examples bobbed up and down: the strokes spell a punch, the motion does not (a
        // hand that talks beats out such strokes).
        assert_eq!(read(Some(shape_bytes(bobbed))), (Some(SHAPE_CAP), None));
    }

    #[test]
    fn far_phrases_pieces_and_prefixes_are_not_reported() {
        let blob = lib_blob();
        let lib = Library::from_bytes(&blob).unwrap();
        // Nothing like any action.
        let h = history(&[("_", 800), ("l", 200), ("r", 200), ("l", 200), ("_", 150)]);
        assert_eq!(
            nearest_action(&lib, &h, 0, false, 3, false)
                .unwrap()
                .candidate,
            None
        );
        // A crouch's way down, held: the crouch may still rise.
        let h = history(&[("_", 800), ("d", 300), ("_", 150)]);
        assert!(nearest_action(&lib, &h, 0, false, 1, false).unwrap().open);
        // Once the phrase is closed (the stream ended, or no hold lasts that long) it is
        // weighed like any other: a lone `d` is a whole edit from the crouch in two aligned
        // tokens, beyond the share without a shape …
        let closed = nearest_action(&lib, &h, 0, false, 1, true).unwrap();
        assert!(!closed.open);
        assert_eq!(closed.candidate, None);
        // … and the crouch within the loose share when its examples' shape is the phrase's.
        let shaped = crate::pattern::tests::with_shapes(&blob, &[Some([0, 255, 0, 0, 0, 128]); 3]);
        let shaped = Library::from_bytes(&shaped).unwrap();
        assert!(
            nearest_action(&shaped, &h, 0, false, 1, false)
                .unwrap()
                .open
        );
        let c = nearest_action(&shaped, &h, 0, false, 1, true)
            .unwrap()
            .candidate
            .unwrap();
        assert_eq!((c.action, c.start, c.end, c.cost), (1, 1, 1, FULL));
        // A pause shorter than a hold lies inside the phrase, which reaches the floor there.
        let h = history(&[
            ("_", 800),
            ("b", 200),
            ("f", 200),
            ("_", 300),
            ("b", 200),
            ("_", 150),
        ]);
        assert_eq!(nearest_action(&lib, &h, 3, false, 4, false), None);
        let c = nearest_action(&lib, &h, 0, false, 4, false)
            .unwrap()
            .candidate
            .unwrap();
        assert_eq!((c.action, c.start, c.end, c.cost), (0, 1, 4, 0));
        // The last run below the floor (committed), or no motion at all.
        assert_eq!(nearest_action(&lib, &h, 5, false, 4, false), None);
        let h = history(&[("_", 800), ("_", 150)]);
        assert_eq!(nearest_action(&lib, &h, 0, false, 0, false), None);
    }

    /// A history of moving runs `(token, ticks, |velocity| along left/up/front m/s, rise per
    /// tick m)` back to back after 800 ms of stillness, and the shape of those runs.
    fn moved(runs: &[(&str, u32, [f32; 3], f32)]) -> (History, Shape) {
        let mut h = history(&[("_", 800)]);
        let mut sums = ShapeSums::new();
        let mut t = 800_000u64;
        for (i, &(name, ticks, v, rise)) in runs.iter().enumerate() {
            let mut q = [0.0; QUANTITIES];
            q[..3].copy_from_slice(&v);
            q[SPEED] = crate::fmath::norm3(v);
            let mut acc = Accum::new();
            for _ in 0..ticks {
                acc.add(&q, rise);
            }
            sums.add(&acc, false);
            h.open(parse_token(name).unwrap(), (i as u32 + 1, t), acc);
            t += u64::from(ticks) * 10_000;
            h.newest_mut().unwrap().end = (i as u32 + 1, t);
        }
        (h, sums.shape())
    }

    #[test]
    fn a_closed_phrase_is_read_as_the_action_of_highest_merit_it_moved_not_unlike() {
        // A small kick read as its pitch alone (`.Xn .Xp`): its little swing forward and back.
        let (h, swung) = moved(&[
            (".Xn", 20, [0.0, 0.05, 0.1], 0.0),
            (".Xp", 20, [0.0, 0.05, 0.1], 0.0),
        ]);
        let kick = Some(shape_bytes(swung));
        let mut up = swung;
        (up[1], up[2]) = (swung[2], swung[1]);
        let (blob, tokens) = (
            lib_blob(),
            [parse_token(".Xn").unwrap(), parse_token(".Xp").unwrap()],
        );
        // Further from the kick than the phrase share: three edits in three aligned tokens.
        let lib = Library::from_bytes(&blob).unwrap();
        assert_eq!(
            weighted_cost(&lib.pattern(2).unwrap(), &tokens, 255),
            Some(3 * FULL)
        );
        let read = |shapes: &[Option<[u8; 6]>], closed: bool| {
            let shaped = crate::pattern::tests::with_shapes(&blob, shapes);
            nearest_action(
                &Library::from_bytes(&shaped).unwrap(),
                &h,
                0,
                false,
                2,
                closed,
            )
            .unwrap()
            .candidate
            .map(|c| (c.action, c.start, c.end, c.cost))
        };
        let shapes = [Some(shape_bytes(up)), Some(shape_bytes(up)), kick];
        // Not while the figurine only paused; once the phrase is closed, the kick.
        assert_eq!(read(&shapes, false), None);
        assert_eq!(read(&shapes, true), Some((2, 1, 2, 3 * FULL)));
        // Not an action whose examples moved otherwise while the kick's moved as it did (the
        // crouch reads it at a higher merit) — and when it moved unlike every action's
        // examples, as none: a toy carried or lifted strays from every pattern and moves
        // like no action, and is no action.
        let unlike = [shapes[0], shapes[1], Some(shape_bytes(up))];
        assert_eq!(read(&unlike, true), None);
        // Nor an action without a learnt shape.
        assert_eq!(read(&[None; 3], true), None);
        // Among those it moved like, the highest merit per aligned token: the crouch `d u`
        // (two edits in two tokens) over the kick and the punch (three edits in three).
        let all = [kick; 3];
        assert_eq!(read(&all, true).map(|c| c.0), Some(1));
        // A lone stroke is no gesture, closed or not.
        let (lone, _) = moved(&[(".Xn", 20, [0.0, 0.05, 0.1], 0.0)]);
        let shaped = crate::pattern::tests::with_shapes(&blob, &all);
        assert_eq!(
            nearest_action(
                &Library::from_bytes(&shaped).unwrap(),
                &lone,
                0,
                false,
                1,
                true
            )
            .unwrap()
            .candidate,
            None
        );
    }

    #[test]
    fn a_closed_phrase_with_strokes_to_spare_is_not_read_at_a_whole_edit_each() {
        // A toy lifted, looked at (pitched down and back) and set down, against a turn `.Yp+`
        // (one token long) whose examples moved as it did: each stroke is a whole edit off.
        let (h, lifted) = moved(&[
            ("u", 20, [0.0, 0.2, 0.0], 0.002),
            (".Xn", 20, [0.0, 0.02, 0.02], 0.0),
            (".Xp", 20, [0.0, 0.02, 0.02], 0.0),
            ("d", 20, [0.0, 0.2, 0.0], -0.002),
        ]);
        let blob = seq_library(&[(&[".Yp"], 0)]);
        let shaped = crate::pattern::tests::with_shapes(&blob, &[Some(shape_bytes(lifted))]);
        let lib = Library::from_bytes(&shaped).unwrap();
        let toks = |names: &[&str]| -> std::vec::Vec<Token> {
            names.iter().map(|n| parse_token(n).unwrap()).collect()
        };
        let look = toks(&["u", ".Xn", ".Xp", "d"]);
        assert_eq!(
            weighted_cost(&lib.pattern(0).unwrap(), &look, 255),
            Some(4 * FULL)
        );
        let read = |h: &History, last: u32| {
            nearest_action(&lib, h, 0, false, last, true)
                .unwrap()
                .candidate
                .map(|c| (c.action, c.cost))
        };
        assert_eq!(read(&h, 4), None);
        // With one stroke the turn's own, the rest to spare, it is the turn.
        let (h, turned) = moved(&[
            ("u", 20, [0.0, 0.2, 0.0], 0.002),
            (".Yp", 20, [0.0, 0.02, 0.02], 0.0),
            ("d", 20, [0.0, 0.2, 0.0], -0.002),
        ]);
        let shaped = crate::pattern::tests::with_shapes(&blob, &[Some(shape_bytes(turned))]);
        let lib = Library::from_bytes(&shaped).unwrap();
        let read = nearest_action(&lib, &h, 0, false, 3, true)
            .unwrap()
            .candidate
            .map(|c| (c.action, c.cost));
        assert_eq!(read, Some((0, 2 * FULL)));
        // The rule itself: all edits is no reading only with strokes to spare.
        assert!(all_edits(4 * FULL, 4, 1));
        assert!(!all_edits(4 * FULL - HALF, 4, 1));
        assert!(!all_edits(3 * FULL, 2, 3));
        assert!(!all_edits(2 * FULL, 2, 2));
    }

    /// A shape as the shape table holds it ([`crate::pattern::tests::with_shapes`]).
    fn shape_bytes(s: Shape) -> [u8; 6] {
        let q = |x: f32| (x * 255.0 + 0.5) as u8;
        [
            q(s[0]),
            q(s[1]),
            q(s[2]),
            q(s[3] / crate::pattern::SHAPE_TURN_MAX),
            q(s[4]),
            q((s[5] + 1.0) / 2.0),
        ]
    }

    /// An exact match of `action` (a two-token pattern) over runs `start..=end`, one token
    /// each, charged `shape` for its motion.
    fn exact_match(action: u8, start: u32, end: u32, shape: i16) -> Candidate {
        Candidate {
            action,
            start,
            end,
            cost: 0,
            len: (end - start + 1) as u16,
            min_len: 2,
            positions: 2,
            cyclic: false,
            shape,
        }
    }

    #[test]
    fn a_match_unlike_its_action_is_reread_as_the_near_action_it_moved_like() {
        // A jump whose flight the tokens lost (`d u`): it rose well above where it began.
        let (h, rose) = moved(&[
            ("d", 10, [0.0, 0.8, 0.1], -0.002),
            ("u", 20, [0.0, 0.9, 0.3], 0.012),
        ]);
        assert!(rose[5] > 0.1, "{rose:?}");
        // 0: crouch `d+ u+`, held low (height −0.3); 1: jump `d+ u+ uf+ df+`, shaped as this.
        let blob = seq_library(&[(&["d", "u"], 1), (&["d", "u", "uf", "df"], 1)]);
        let mut crouch = rose;
        crouch[5] = -0.3;
        let shaped = crate::pattern::tests::with_shapes(
            &blob,
            &[Some(shape_bytes(crouch)), Some(shape_bytes(rose))],
        );
        let lib = Library::from_bytes(&shaped).unwrap();
        assert_eq!(shape_of(&lib, 0, &h, 1, 2), Some(SHAPE_CAP));
        assert_eq!(shape_of(&lib, 1, &h, 1, 2), Some(0));
        let c = exact_match(0, 1, 2, SHAPE_CAP);
        // The flight's `uf df` left out: within two whole edits in four aligned tokens, the
        // loose share.
        let r = reread(&lib, &h, &c).unwrap();
        assert_eq!(
            (r.action, r.start, r.end, r.min_len, r.shape),
            (1, 1, 2, 4, 0)
        );
        assert!(
            r.cost <= 2 * FULL
                && r.cost
                    == weighted_cost(
                        &lib.pattern(1).unwrap(),
                        &[parse_token("d").unwrap(), parse_token("u").unwrap()],
                        255
                    )
                    .unwrap()
        );
        // The runs' shape decides, not what the candidate was charged (a nearest action's
        // candidate carries none).
        assert_eq!(reread(&lib, &h, &Candidate { shape: 0, ..c }), Some(r));
        // Not when no other action's examples moved like it, nor when the other action is
        // further than the loose share.
        let unlike = crate::pattern::tests::with_shapes(
            &blob,
            &[Some(shape_bytes(crouch)), Some(shape_bytes(crouch))],
        );
        assert_eq!(reread(&Library::from_bytes(&unlike).unwrap(), &h, &c), None);
        let far = seq_library(&[(&["d", "u"], 1), (&["d", "u", "l", "r", "l", "r"], 1)]);
        let far = crate::pattern::tests::with_shapes(
            &far,
            &[Some(shape_bytes(crouch)), Some(shape_bytes(rose))],
        );
        assert_eq!(reread(&Library::from_bytes(&far).unwrap(), &h, &c), None);
        // Nor when the crouch's own shape is only a little off.
        let mut near = rose;
        near[5] -= 0.05;
        let mild = crate::pattern::tests::with_shapes(
            &blob,
            &[Some(shape_bytes(near)), Some(shape_bytes(rose))],
        );
        let mild = Library::from_bytes(&mild).unwrap();
        let penalty = shape_of(&mild, 0, &h, 1, 2).unwrap();
        assert!((1..SHAPE_CAP).contains(&penalty));
        let mild_c = Candidate {
            shape: shape_cost(penalty, 2),
            ..c
        };
        assert_eq!(reread(&mild, &h, &mild_c), None);
    }

    #[test]
    fn a_match_that_went_less_far_than_its_action_is_the_near_action_it_moved_like() {
        // A punch thrown without its wind-up: forward and back.
        let (h, thrust) = moved(&[
            ("f", 15, [0.0, 0.0, 0.5], 0.0),
            ("b", 15, [0.0, 0.0, -0.5], 0.0),
        ]);
        let mut other = thrust;
        other[5] = -0.3;
        let shaped = |actions: &[(&[&str], u8)], shapes: &[Shape]| {
            let blob = seq_library(actions);
            let shapes: std::vec::Vec<_> = shapes.iter().map(|s| Some(shape_bytes(*s))).collect();
            crate::pattern::tests::with_shapes(&blob, &shapes)
        };
        // 0: the action whose pattern matched (`f b`), whose examples went farther; 1: a punch
        // `b f b`, one edit off (its wind-up), whose examples moved like this.
        let blob = shaped(&[(&["f", "b"], 0), (&["b", "f", "b"], 1)], &[other, thrust]);
        let lib = Library::from_bytes(&blob).unwrap();
        let c = exact_match(0, 1, 2, 0);
        let r = not_that_far(&lib, &h, &c).unwrap();
        assert_eq!((r.action, r.start, r.end, r.cost), (1, 1, 2, FULL));
        // Not when the punch's examples moved otherwise …
        let unlike = shaped(&[(&["f", "b"], 0), (&["b", "f", "b"], 1)], &[thrust, other]);
        assert_eq!(
            not_that_far(&Library::from_bytes(&unlike).unwrap(), &h, &c),
            None
        );
        // … nor when its pattern is two edits off (within the loose share of four tokens,
        // beyond the one edit a match that was not far enough may be re-read at).
        let far = shaped(
            &[(&["f", "b"], 0), (&["b", "f", "b", "b"], 2)],
            &[other, thrust],
        );
        let far = Library::from_bytes(&far).unwrap();
        assert_eq!(
            weighted_cost(
                &far.pattern(1).unwrap(),
                &[parse_token("f").unwrap(), parse_token("b").unwrap()],
                255
            ),
            Some(2 * FULL)
        );
        assert_eq!(not_that_far(&far, &h, &c), None);
    }

    #[test]
    fn a_match_that_leaves_its_phrase_half_read_yields_to_the_whole_phrase() {
        // A kick without its wind-up: forward swing `uf f`, backswing `b`, its recovery lost.
        let (h, kicked) = moved(&[
            ("uf", 10, [0.0, 0.5, 0.8], 0.001),
            ("f", 10, [0.0, 0.1, 0.9], 0.0),
            ("b", 10, [0.0, 0.1, 0.9], 0.0),
        ]);
        // 0: a run's strides `uf f`, shaped unlike this; 1: the kick `uf f b db`, shaped as it.
        let blob = seq_library(&[(&["uf", "f"], 1), (&["uf", "f", "b", "db"], 1)]);
        let mut strides = kicked;
        strides[5] = -0.3;
        let lib_of = |shapes: [Shape; 2]| {
            crate::pattern::tests::with_shapes(
                &blob,
                &[Some(shape_bytes(shapes[0])), Some(shape_bytes(shapes[1]))],
            )
        };
        let shaped = lib_of([strides, kicked]);
        let lib = Library::from_bytes(&shaped).unwrap();
        let c = exact_match(
            0,
            1,
            2,
            shape_of(&lib, 0, &h, 1, 2).map_or(0, |p| shape_cost(p, 2)),
        );
        assert!(c.shape > 0);
        // The kick reads all three within the loose share (its `db` left out).
        let w = whole_phrase(&lib, &h, 0, false, 3, &c).unwrap();
        let tokens = ["uf", "f", "b"].map(|n| parse_token(n).unwrap());
        assert_eq!((w.action, w.start, w.end, w.len), (1, 1, 3, 3));
        assert_eq!(
            Some(w.cost),
            weighted_cost(&lib.pattern(1).unwrap(), &tokens, 255)
        );
        // Not when the match moved like its action, or explains the whole phrase.
        assert_eq!(
            whole_phrase(&lib, &h, 0, false, 3, &Candidate { shape: 0, ..c }),
            None
        );
        assert_eq!(whole_phrase(&lib, &h, 0, false, 2, &c), None);
        // Nor when the phrase reaches below the floor (part of it was emitted).
        assert_eq!(whole_phrase(&lib, &h, 2, false, 3, &c), None);
        // When no action's examples moved like the phrase, those it moved least unlike: both
        // alike here, and the kick reads it nearer …
        let read = |shapes: [Shape; 2]| {
            let blob = lib_of(shapes);
            let lib = Library::from_bytes(&blob).unwrap();
            let pens = [shape_of(&lib, 0, &h, 1, 3), shape_of(&lib, 1, &h, 1, 3)];
            (
                pens,
                whole_phrase(&lib, &h, 0, false, 3, &c).map(|w| w.action),
            )
        };
        let (pens, action) = read([strides, strides]);
        assert_eq!((pens, action), ([Some(SHAPE_CAP); 2], Some(1)));
        // … but not an action it moved further unlike than another: the run's examples rose a
        // little less than the phrase, the kick's far less.
        let mut lower = kicked;
        lower[5] -= 0.09;
        let ([run, kick], action) = read([lower, strides]);
        assert!(Some(0) < run && run < kick, "{run:?} {kick:?}");
        assert_eq!(action, Some(0));
    }

    #[test]
    fn the_start_of_the_stream_bounds_a_phrase() {
        let blob = lib_blob();
        let lib = Library::from_bytes(&blob).unwrap();
        // Played right away: less stillness before the punch than a hold.
        let h = history(&[("_", 300), ("f", 200), ("b", 200), ("_", 150)]);
        let c = nearest_action(&lib, &h, 0, true, 2, false)
            .unwrap()
            .candidate
            .unwrap();
        assert_eq!((c.action, c.start, c.end, c.cost), (0, 1, 2, FULL));
        // The same runs after an event that ended at the floor: not a whole phrase.
        assert_eq!(nearest_action(&lib, &h, 0, false, 2, false), None);
        // The stream began in motion: the phrase starts with it.
        let h = history(&[("f", 200), ("b", 200), ("_", 150)]);
        let c = nearest_action(&lib, &h, 0, true, 1, false)
            .unwrap()
            .candidate
            .unwrap();
        assert_eq!((c.start, c.end), (0, 1));
    }

    #[test]
    fn a_phrase_longer_than_the_capacity_is_not_compared() {
        let blob = lib_blob();
        let lib = Library::from_bytes(&blob).unwrap();
        let mut runs = std::vec![("_", 800)];
        runs.extend(core::iter::repeat_n(("f", 50), NEAREST_MAX_TOKENS + 1));
        runs.push(("_", 150));
        let h = history(&runs);
        assert_eq!(
            nearest_action(&lib, &h, 0, false, (NEAREST_MAX_TOKENS + 1) as u32, false),
            None
        );
    }
}
