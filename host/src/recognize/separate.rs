//! Learning against the rest of the library: no action's pattern should accept another
//! action's examples without an edit.
//!
//! Each action is learnt from its own few examples ([`super::learn`]), which leaves its
//! pattern as general as those examples allow: a stroke seen with a small pitch is written
//! with and without it (`f.Xn|f|f.Xp`), a part some example lacks becomes optional. Two
//! actions learnt that way can overlap — a kick whose pitch was small accepts a punch's
//! `b f b` exactly — and the recognizer then has only tie-breaks to tell them apart.
//!
//! [`separate`] narrows such a pattern until it no longer accepts any example of another
//! action exactly. A narrowing step takes a stroke's plain variant out of an alternation of
//! its rotated ones (`f.Xn|f|f.Xp` → `f.Xn|f.Xp`): the rotation is then part of the gesture,
//! and a plain `f` still matches, at a near substitution's half edit. So an exact tie between
//! two actions becomes a half-edit preference.
//!
//! A step is taken only when every example of the narrowed action still matches at a cost no
//! higher than before, and it is the one that leaves the fewest exact matches of other
//! actions' examples (then the fewest matches at all). A pattern written as a mirrored pair
//! (`A|A'`) is narrowed at the same place on both sides. The edit bound stays as learnt.
//!
//! Optional groups are not made mandatory: that can make a pattern win ties it should not
//! (`d+ u+ (u~)*` → `d+ u+ (u~)+` is a longer shortest match, so it outranks a crouch's
//! `d+ u+` on a crouch that rises in two strokes).
//!
//! What narrowing cannot separate is evened out instead. A jump whose examples all pitched
//! (`(d.Xn|d|d.Xp)+ (u.Xn|u|u.Xp)+ …`) and whose landing some example lacked accepts a
//! crouch's plain `d u` exactly, and narrowing it would lose its own examples; a crouch
//! performed with the same small pitch would then cost the crouch two half edits and the
//! jump none. So the action whose examples another pattern still accepts exactly is widened:
//! each plain stroke of its pattern that the other allows rotated is allowed the same
//! rotations (`d+ u+` → `(d.Xn|d|d.Xp)+ (u.Xn|u|u.Xp)+`). Exact ties then go to the more
//! specific pattern, as the recognizer's tie-break has it. A widening that would make the
//! pattern accept more foreign examples exactly is not taken.

use std::collections::{BTreeMap, BTreeSet};

use anyhow::Result;
use figurine_recognizer::token::{Symbol, ANY_LIN, ANY_ROT, NONE_BIN};

use super::library::{full_match, parse_tokens, ActionEntry, LibraryFile};
use super::regex::Regex;

/// Narrowing steps [`separate`] takes at most over a whole library.
pub const MAX_STEPS: usize = 32;

/// One step taken: which action, its pattern before and after, and why.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Step {
    /// The changed action.
    pub action: String,
    /// Its pattern before.
    pub from: String,
    /// Its pattern after.
    pub to: String,
    /// Narrowed or widened, and why.
    pub kind: StepKind,
}

/// Why a pattern changed.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum StepKind {
    /// It accepted these examples of other actions exactly (`action: tokens`), and no longer
    /// does.
    Narrowed(Vec<String>),
    /// Action `.0` still accepts these examples of it exactly: it now allows the rotations of
    /// the shared strokes that action allows.
    Widened(String, Vec<String>),
}

impl std::fmt::Display for Step {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match &self.kind {
            StepKind::Narrowed(no_longer) => write!(
                f,
                "narrowed `{}`: {}  ->  {}  (it accepted {} exactly)",
                self.action,
                self.from,
                self.to,
                no_longer.join(", ")
            ),
            StepKind::Widened(like, examples) => write!(
                f,
                "widened `{}`: {}  ->  {}  (as tolerant of rotations as `{like}`, which accepts \
                 its {} exactly)",
                self.action,
                self.from,
                self.to,
                examples.join(", ")
            ),
        }
    }
}

/// Whether `s` is a plain stroke (translation, no rotation, no wildcard).
fn plain(s: Symbol) -> bool {
    s & (ANY_LIN | ANY_ROT) == 0 && s / 27 != NONE_BIN && s % 27 == NONE_BIN
}

/// Whether `s` is the stroke `lin` with a rotation (no wildcard).
fn rotated_of(s: Symbol, lin: Symbol) -> bool {
    s & (ANY_LIN | ANY_ROT) == 0 && s / 27 == lin && s % 27 != NONE_BIN
}

/// Number of narrowing sites in `re` (pre-order): alternations of plain and rotated variants
/// of one stroke.
fn sites(re: &Regex) -> usize {
    let own = usize::from(is_site(re));
    own + match re {
        Regex::Sym(_) => 0,
        Regex::Cat(v) | Regex::Alt(v) => v.iter().map(sites).sum(),
        Regex::Star(r) | Regex::Plus(r) | Regex::Opt(r) => sites(r),
    }
}

fn is_site(re: &Regex) -> bool {
    matches!(re, Regex::Alt(v) if plain_with_rotated(v).is_some())
}

/// The index of the plain stroke in an alternation that also has it rotated.
fn plain_with_rotated(v: &[Regex]) -> Option<usize> {
    v.iter().position(|r| match r {
        Regex::Sym(p) if plain(*p) => v
            .iter()
            .any(|o| matches!(o, Regex::Sym(s) if rotated_of(*s, p / 27))),
        _ => false,
    })
}

/// `re` with site `k` (pre-order, see [`sites`]) narrowed; `k` counts down as sites pass.
fn narrow_at(re: &Regex, k: &mut usize) -> Regex {
    if is_site(re) {
        if *k == 0 {
            *k = usize::MAX;
            return match re {
                Regex::Alt(v) => {
                    let skip = plain_with_rotated(v);
                    let mut rest: Vec<Regex> = v
                        .iter()
                        .enumerate()
                        .filter(|(i, _)| Some(*i) != skip)
                        .map(|(_, r)| r.clone())
                        .collect();
                    match rest.len() {
                        1 => rest.remove(0),
                        _ => Regex::Alt(rest),
                    }
                }
                other => other.clone(),
            };
        }
        if *k != usize::MAX {
            *k -= 1;
        }
    }
    match re {
        Regex::Sym(s) => Regex::Sym(*s),
        Regex::Cat(v) => Regex::Cat(v.iter().map(|r| narrow_at(r, k)).collect()),
        Regex::Alt(v) => Regex::Alt(v.iter().map(|r| narrow_at(r, k)).collect()),
        Regex::Star(r) => Regex::Star(Box::new(narrow_at(r, k))),
        Regex::Plus(r) => Regex::Plus(Box::new(narrow_at(r, k))),
        Regex::Opt(r) => Regex::Opt(Box::new(narrow_at(r, k))),
    }
}

/// Every one-step narrowing of `re`; a mirrored pair `A|A'` (two alternatives with as many
/// sites) is narrowed at the same site on both sides.
fn narrowings(re: &Regex) -> Vec<Regex> {
    if let Regex::Alt(v) = re {
        if let [a, b] = v.as_slice() {
            let n = sites(a);
            if n > 0 && n == sites(b) {
                return (0..n)
                    .map(|k| {
                        Regex::Alt(vec![
                            narrow_at(a, &mut k.clone()),
                            narrow_at(b, &mut k.clone()),
                        ])
                    })
                    .collect();
            }
        }
    }
    (0..sites(re))
        .map(|k| narrow_at(re, &mut k.clone()))
        .collect()
}

/// `entry` with pattern `re` and everything else its examples taught kept (name, bound,
/// examples, shape, extent, travel, hold, sub-movements); None when the device could not hold
/// it. Only the pattern changes: a narrowed kick still holds as long as its examples held.
fn rewritten(entry: &ActionEntry, re: &Regex) -> Option<ActionEntry> {
    let mut e = entry.clone();
    e.regex = re.to_source();
    e.refresh().ok()?;
    Some(e)
}

/// Every example of every action, as (action index, source text, tokens).
type Examples = Vec<(usize, String, Vec<figurine_recognizer::token::Token>)>;

fn all_examples(lib: &LibraryFile) -> Result<Examples> {
    let mut out = Vec::new();
    for (i, a) in lib.actions.iter().enumerate() {
        for ex in &a.examples {
            out.push((i, ex.clone(), parse_tokens(ex)?));
        }
    }
    Ok(out)
}

/// How much a pattern overlaps the other actions' examples.
#[derive(Debug, Clone, Default)]
struct Overlap {
    /// Examples it matches exactly.
    exact: usize,
    /// Examples it matches within its bound.
    any: usize,
    /// The exactly matched ones: (action index, example).
    which: Vec<(usize, String)>,
}

impl Overlap {
    fn rank(&self) -> (usize, usize) {
        (self.exact, self.any)
    }
}

/// How much `entry` (action `own`) overlaps the other actions' examples.
fn overlap(entry: &ActionEntry, own: usize, ex: &Examples) -> Result<Overlap> {
    let mut o = Overlap::default();
    for (a, src, t) in ex.iter().filter(|(a, _, _)| *a != own) {
        match full_match(entry, t)? {
            Some(0) => {
                o.exact += 1;
                o.any += 1;
                o.which.push((*a, src.clone()));
            }
            Some(_) => o.any += 1,
            None => {}
        }
    }
    Ok(o)
}

/// Whether `cand` still matches every example of action `own` at no higher cost than
/// `before` did.
fn keeps_own(cand: &ActionEntry, own: usize, ex: &Examples, before: &[Option<u8>]) -> Result<bool> {
    for ((_, _, t), was) in ex.iter().filter(|(a, _, _)| *a == own).zip(before) {
        let now = full_match(cand, t)?;
        let kept = match (was, now) {
            (Some(w), Some(n)) => n <= *w,
            (None, _) => true,
            (Some(_), None) => false,
        };
        if !kept {
            return Ok(false);
        }
    }
    Ok(true)
}

/// Narrows the patterns of `lib` until none accepts another action's example exactly, or no
/// step helps, then widens the actions whose examples are still accepted by another (see the
/// module docs). Returns the steps taken, in order.
pub fn separate(lib: &mut LibraryFile) -> Result<Vec<Step>> {
    let ex = all_examples(lib)?;
    let mut steps = Vec::new();
    let mut stuck = vec![false; lib.actions.len()];
    // Each action's overlap with the others' examples: only a narrowed action's changes.
    let mut overlaps: Vec<Overlap> = lib
        .actions
        .iter()
        .enumerate()
        .map(|(i, a)| overlap(a, i, &ex))
        .collect::<Result<_>>()?;
    while steps.len() < MAX_STEPS {
        // The action that accepts the most foreign examples exactly (the first on a tie).
        let worst = (0..lib.actions.len())
            .filter(|&i| !stuck[i] && overlaps[i].exact > 0)
            .min_by_key(|&i| (std::cmp::Reverse(overlaps[i].exact), i));
        let Some(i) = worst else { break };
        let before = &overlaps[i];
        let entry = &lib.actions[i];
        let own_costs: Vec<Option<u8>> = ex
            .iter()
            .filter(|(a, _, _)| *a == i)
            .map(|(_, _, t)| full_match(entry, t))
            .collect::<Result<_>>()?;
        let mut best: Option<(ActionEntry, Overlap)> = None;
        for re in narrowings(&Regex::parse(&entry.regex)?) {
            let Some(cand) = rewritten(entry, &re) else {
                continue;
            };
            if !keeps_own(&cand, i, &ex, &own_costs)? {
                continue;
            }
            let o = overlap(&cand, i, &ex)?;
            let better =
                o.rank() < before.rank() && best.as_ref().is_none_or(|(_, b)| o.rank() < b.rank());
            if better {
                best = Some((cand, o));
            }
        }
        match best {
            Some((cand, after)) if after.exact < before.exact => {
                let no_longer = before
                    .which
                    .iter()
                    .filter(|w| !after.which.contains(w))
                    .map(|(a, src)| format!("{}: {src}", lib.actions[*a].name))
                    .collect();
                steps.push(Step {
                    action: cand.name.clone(),
                    from: lib.actions[i].regex.clone(),
                    to: cand.regex.clone(),
                    kind: StepKind::Narrowed(no_longer),
                });
                lib.actions[i] = cand;
                overlaps[i] = after;
            }
            _ => stuck[i] = true,
        }
    }
    // What narrowing could not separate: the action whose examples another pattern still
    // accepts exactly is made as tolerant of the shared strokes' rotations as that pattern
    // (until nothing changes: a widened pattern may now accept the other's examples).
    let mut changed = true;
    while changed && steps.len() < MAX_STEPS {
        changed = false;
        for i in 0..lib.actions.len() {
            let victims: BTreeSet<usize> = overlaps[i].which.iter().map(|(a, _)| *a).collect();
            if victims.is_empty() {
                continue;
            }
            let mut variants = BTreeMap::new();
            rotations(&Regex::parse(&lib.actions[i].regex)?, &mut variants);
            for b in victims {
                let entry = &lib.actions[b];
                let re = widen(&Regex::parse(&entry.regex)?, &variants);
                let Some(cand) = rewritten(entry, &re) else {
                    continue;
                };
                if cand.regex == entry.regex {
                    continue;
                }
                let after = overlap(&cand, b, &ex)?;
                if after.exact > overlaps[b].exact {
                    continue;
                }
                let shared = overlaps[i]
                    .which
                    .iter()
                    .filter(|(a, _)| *a == b)
                    .map(|(_, src)| src.clone())
                    .collect();
                steps.push(Step {
                    action: cand.name.clone(),
                    from: entry.regex.clone(),
                    to: cand.regex.clone(),
                    kind: StepKind::Widened(lib.actions[i].name.clone(), shared),
                });
                lib.actions[b] = cand;
                overlaps[b] = after;
                changed = true;
            }
        }
    }
    Ok(steps)
}

/// The rotated variants `re` allows each plain stroke in its sites: plain symbol → variants.
fn rotations(re: &Regex, out: &mut BTreeMap<Symbol, BTreeSet<Symbol>>) {
    match re {
        Regex::Sym(_) => {}
        Regex::Alt(v) => {
            if let Some(Regex::Sym(p)) = plain_with_rotated(v).and_then(|k| v.get(k)) {
                let set = out.entry(*p).or_default();
                for r in v {
                    if let Regex::Sym(s) = r {
                        if rotated_of(*s, p / 27) {
                            set.insert(*s);
                        }
                    }
                }
            }
            v.iter().for_each(|r| rotations(r, out));
        }
        Regex::Cat(v) => v.iter().for_each(|r| rotations(r, out)),
        Regex::Star(r) | Regex::Plus(r) | Regex::Opt(r) => rotations(r, out),
    }
}

/// `re` with every plain stroke that `variants` lists accepting those rotated variants too.
fn widen(re: &Regex, variants: &BTreeMap<Symbol, BTreeSet<Symbol>>) -> Regex {
    let with = |p: Symbol, have: &[Regex]| -> Vec<Regex> {
        let mut all: BTreeSet<Symbol> = variants.get(&p).cloned().unwrap_or_default();
        all.insert(p);
        all.into_iter()
            .filter(|s| !have.contains(&Regex::Sym(*s)))
            .map(Regex::Sym)
            .collect()
    };
    match re {
        Regex::Sym(p) if plain(*p) && variants.contains_key(p) => {
            let mut v = with(*p, &[]);
            v.sort_by_key(|r| match r {
                Regex::Sym(s) => *s,
                _ => 0,
            });
            Regex::Alt(v)
        }
        Regex::Sym(s) => Regex::Sym(*s),
        Regex::Alt(v) => {
            let mut out: Vec<Regex> = v
                .iter()
                .map(|r| match r {
                    Regex::Sym(s) => Regex::Sym(*s),
                    other => widen(other, variants),
                })
                .collect();
            for r in v {
                if let Regex::Sym(p) = r {
                    if plain(*p) && variants.contains_key(p) {
                        let extra = with(*p, &out);
                        out.extend(extra);
                    }
                }
            }
            Regex::Alt(out)
        }
        Regex::Cat(v) => Regex::Cat(v.iter().map(|r| widen(r, variants)).collect()),
        Regex::Star(r) => Regex::Star(Box::new(widen(r, variants))),
        Regex::Plus(r) => Regex::Plus(Box::new(widen(r, variants))),
        Regex::Opt(r) => Regex::Opt(Box::new(widen(r, variants))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn entry(name: &str, re: &str, edits: u8, examples: &[&str]) -> ActionEntry {
        ActionEntry::new(
            name,
            re,
            Some(edits),
            examples.iter().map(|s| s.to_string()).collect(),
        )
        .unwrap()
    }

    #[test]
    fn sites_are_plain_strokes_among_their_rotations() {
        let re = Regex::parse("b* (f.Xn|f|f.Xp)+ (b|.Xp)* (b|b.Zn)+ (d|f.Xn)").unwrap();
        assert_eq!(sites(&re), 2);
        let all: Vec<String> = narrowings(&re).iter().map(Regex::to_source).collect();
        assert_eq!(
            all,
            [
                "b* (f.Xn|f.Xp)+ (b|.Xp)* (b|b.Zn)+ (d|f.Xn)",
                "b* (f.Xn|f|f.Xp)+ (b|.Xp)* b.Zn+ (d|f.Xn)",
            ]
        );
        // A mirrored pair is narrowed on both sides at once.
        let pair = Regex::parse("(lu|lu.Zn)+ l*|(ru|ru.Zp)+ r*").unwrap();
        let all: Vec<String> = narrowings(&pair).iter().map(Regex::to_source).collect();
        assert_eq!(all, ["lu.Zn+ l*|ru.Zp+ r*"]);
    }

    #[test]
    fn a_kick_that_accepts_a_punch_loses_its_plain_stroke() {
        let mut lib = LibraryFile::default();
        lib.upsert(entry(
            "punch",
            "b* (f.Zn|f|f.Zp)+ b+",
            1,
            &["b f b", "f.Zp b"],
        ));
        lib.upsert(entry(
            "kick",
            "b* (f.Xn|f|f.Xp)+ (b.Xn|b|b.Xp)+ db*",
            1,
            &["b f.Xn b.Xp db", "f.Xn b.Xp", "b f.Xp b"],
        ));
        let steps = separate(&mut lib).unwrap();
        assert_eq!(steps.len(), 1, "{steps:?}");
        assert_eq!(steps[0].action, "kick");
        assert_eq!(
            steps[0].kind,
            StepKind::Narrowed(vec!["punch: b f b".to_string()])
        );
        let kick = &lib.actions[1];
        assert_eq!(kick.regex, "b* (f.Xn|f.Xp)+ (b.Xn|b|b.Xp)+ db*");
        // Its own examples still match exactly; the punch's now needs half an edit.
        for ex in &kick.examples {
            assert_eq!(
                full_match(kick, &parse_tokens(ex).unwrap()).unwrap(),
                Some(0)
            );
        }
        assert_eq!(
            full_match(kick, &parse_tokens("b f b").unwrap()).unwrap(),
            Some(1)
        );
        // Nothing left to separate: a second pass changes nothing.
        assert!(separate(&mut lib).unwrap().is_empty());
    }

    #[test]
    fn a_narrowed_pattern_keeps_what_its_examples_taught() {
        let mut lib = LibraryFile::default();
        lib.upsert(entry("punch", "b* (f.Zn|f|f.Zp)+ b+", 1, &["b f b"]));
        let mut kick = entry(
            "kick",
            "b* (f.Xn|f|f.Xp)+ (b.Xn|b|b.Xp)+ db*",
            1,
            &["b f.Xn b.Xp db", "f.Xn b.Xp", "b f.Xp b"],
        )
        .with_shape(Some([0.1, 0.3, 0.8, 1.2, 0.2, 0.1]))
        .with_hold(Some(0.33))
        .with_sweeps(Some(2))
        .with_briefest(Some(0.21));
        kick.extent = Some([0.05, 0.34]);
        kick.travel_m = Some(0.004);
        kick.travel_share = Some(0.06);
        kick.refresh().unwrap();
        let before = kick.clone();
        lib.upsert(kick);
        assert_eq!(separate(&mut lib).unwrap().len(), 1);
        let after = &lib.actions[1];
        assert_ne!(after.regex, before.regex);
        // Everything but the pattern (and its compiled form) is as learnt.
        let unpatterned = |e: &ActionEntry| ActionEntry {
            regex: String::new(),
            compiled: None,
            ..e.clone()
        };
        assert_eq!(unpatterned(after), unpatterned(&before));
        // And the device reads them from the library's blob.
        let blob = lib.blob().unwrap();
        let dev = figurine_recognizer::pattern::Library::from_bytes(&blob).unwrap();
        assert_eq!((dev.least_sweeps(1), dev.briefest_us(1)), (2, 210_000));
        assert!(
            (320_000..=340_000).contains(&dev.hold_us(1)),
            "{}",
            dev.hold_us(1)
        );
        assert!(dev.extent(1).is_some_and(|e| e.travel_m > 0.0));
    }

    #[test]
    fn a_pattern_that_cannot_be_narrowed_makes_the_other_as_tolerant() {
        let mut lib = LibraryFile::default();
        lib.upsert(entry("crouch", "d+ u+", 1, &["d u"]));
        lib.upsert(entry("jump", "(d|d.Xp)+ u+ d*", 1, &["d u d", "d u"]));
        let before = lib.actions[1].regex.clone();
        let steps = separate(&mut lib).unwrap();
        // Narrowing the jump would lose its own `d u`: its hop stays as it was …
        assert!(lib.actions[1].regex.starts_with("(d|d.Xp)+ u+"), "{before}");
        // … and the crouch, whose `d u` it accepts, takes its pitch too.
        assert_eq!(
            steps[0].kind,
            StepKind::Widened("jump".to_string(), vec!["d u".to_string()])
        );
        let crouch = &lib.actions[0];
        assert_eq!(crouch.regex, "(d|d.Xp)+ u+");
        // Which now accepts the jump's `d u`: the jump's landing takes the pitch as well.
        assert_eq!(steps.len(), 2, "{steps:?}");
        assert_eq!(lib.actions[1].regex, "(d|d.Xp)+ u+ (d|d.Xp)*");
        // A pitched crouch is now exact for both: the tie goes to the simpler pattern.
        let pitched = parse_tokens("d.Xp u").unwrap();
        assert_eq!(full_match(crouch, &pitched).unwrap(), Some(0));
        let again = separate(&mut lib).unwrap();
        assert!(again.is_empty(), "{again:?}");
    }

    #[test]
    fn widening_adds_the_missing_rotations_only_where_the_stroke_is() {
        let mut variants = BTreeMap::new();
        rotations(
            &Regex::parse("(f.Xn|f|f.Xp)+ (b|b.Zn)+ d*").unwrap(),
            &mut variants,
        );
        let re = Regex::parse("b* (f|f.Xp)+ u+ f").unwrap();
        assert_eq!(
            widen(&re, &variants).to_source(),
            "(b.Zn|b)* (f|f.Xp|f.Xn)+ u+ (f.Xn|f|f.Xp)"
        );
    }
}
