//! Stage 4 — action patterns in their compiled, device-side form.
//!
//! A pattern is a regular expression over tokens (`*`, `+`, `|`, groups), compiled on the host
//! into a Glushkov automaton: one state per token occurrence ("position", at most
//! [`MAX_POSITIONS`]) plus the initial state. State sets are `u64` bit masks: bit 0 is the
//! initial state, bit `i` (1 ≤ i ≤ n) position `i`. The blob is read in place (from flash);
//! nothing is copied into RAM except [`MAX_ACTIONS`] record offsets (64 bytes).
//!
//! # Library blob layout, version [`LIBRARY_VERSION`] (all integers little-endian)
//! ```text
//! 0   4   magic "FGL" + version byte (11; version 10, whose shape table has only the first 19
//!         bytes of each entry, is still read and its briefest example is not known; version
//!         9, with only 18, is still read and its sub-movements are not known either; version 8,
//!         with only 17, is still read and its travel shares are not known either; version 7,
//!         with only 16, is still read and its travels are not known either; version 6, with
//!         only 15, is still read and its holds are not known either; version 5, with
//!         only 13, is still read and its extents are not known either; versions 4, 3 and
//!         2, with only 7, 6 and 4 bytes, and version 1, without the table, are still read —
//!         their shapes are not used)
//! 4   1   n_actions (≤ MAX_ACTIONS)
//! 5   3   reserved, zero
//! then n_actions records, each 36 + 2·n + 8·(n + 1) bytes:
//! +0  1   n: positions (1 ≤ n ≤ MAX_POSITIONS)
//! +1  1   max_edits: per-action edit bound (≤ MAX_EDITS, < min_len)
//! +2  1   min_len: length of the shortest token string the pattern accepts (≥ 1)
//! +3  1   flags: bit 0 = cyclic (the whole pattern repeats, e.g. `(uf~ df~)+`); others zero
//! +4  8   last: accepting positions
//! +12 8   shift: positions j ≥ 2 with j ∈ follow(j − 1)
//! +20 8   loops: positions i with i ∈ follow(i)
//! +28 8   extra: states whose follow set has more than {i, i + 1}
//! +36 2n  symbol of each position 1..=n (token code < STILL, optionally one wildcard flag:
//!         `token::ANY_ROT` or `token::ANY_LIN`)
//! +.. 8(n+1) follow set of each state 0..=n
//! then the shape table, 20 bytes per action in record order (the mean of its examples'
//! shapes, `features::Shape`, how far they lay from it, how far the least of them went, how
//! long they held still inside, how few sub-movements they made and how briefly they moved):
//! +0  3   mean |velocity| along left, up, front (object frame), each as a share of the mean
//!         speed, × 255 rounded
//! +3  1   0 = shape unknown (all fifteen bytes are zero); otherwise shape known (learnt
//!         from examples; the host writes 1)
//! +4  1   ln(1 + angle turned, rad) × 255 / SHAPE_TURN_MAX, rounded
//! +5  1   share of the time spent still × 255, rounded
//! +6  1   (1 + mean height above the start as a share of the path length) × 255 / 2, rounded
//! +7  6   tolerance of each of the six dimensions above, in their order: the largest
//!         `shape::SHAPE_SCALE`-weighted |example − mean| (at least the learner's floor),
//!         × 255 rounded, at most 255
//! +13 1   the least farthest displacement among the examples (`extent::Extent`), code
//!         `extent::to_byte` in `extent::MOVED_CODE_UNIT_M`; 0 = not known
//! +14 1   the least farthest rotation among them, code in `extent::TURNED_CODE_UNIT_RAD`;
//!         0 = not known (both are known or neither)
//! +15 1   the longest stillness inside an example (between its first and last motion), in
//!         [`HOLD_UNIT_US`]; 0 = none or not known
//! +16 1   the least travel among the examples (how far across the floor from where each
//!         began it ended), code in `extent::MOVED_CODE_UNIT_M`; 0 = not known
//! +17 1   the least share of how far an example went that it travelled (its travel over its
//!         farthest displacement), × 255 rounded; 0 = none or not known
//! +18 1   the fewest sub-movements an example made (`history::Sweeps::count`, counted
//!         against the noise), at most 255; 0 = none or not known
//! +19 1   how long the briefest example moved, from its first motion to its last, in
//!         [`HOLD_UNIT_US`]; 0 = not known
//! ```
//! `shift`, `loops` and `extra` are redundant with `follow` (the loader checks they agree);
//! they make the forward transition `T(D) = ((D≪1) & shift) | (D & loops) | ⋃_{i ∈ D∩extra}
//! follow(i)` cost a few instructions for the mostly-sequential learnt patterns.

use crate::extent::{from_byte, Extent, MOVED_CODE_UNIT_M, TURNED_CODE_UNIT_RAD};
use crate::features::{Shape, SHAPE_DIMS};
use crate::token::{symbol_matches, symbol_valid, Symbol, Token, STILL};
use crate::Error;

/// Maximum number of actions in a library.
pub const MAX_ACTIONS: usize = 32;
/// Maximum token positions in one pattern.
pub const MAX_POSITIONS: usize = 32;
/// Maximum edits per action.
pub const MAX_EDITS: usize = 3;
/// Library blob format version written by the host.
pub const LIBRARY_VERSION: u8 = 11;
/// Bytes per action in the shape table.
pub const SHAPE_BYTES: usize = 20;
/// Bytes per action in a version 10 shape table (no briefest example).
const SHAPE_BYTES_V10: usize = 19;
/// Offset of the briefest example's duration in a shape-table entry.
const SHAPE_BRIEF_AT: usize = 19;
/// Bytes per action in a version 9 shape table (no sub-movements).
const SHAPE_BYTES_V9: usize = 18;
/// Offset of the fewest sub-movements in a shape-table entry.
const SHAPE_SWEEPS_AT: usize = 18;
/// Bytes per action in a version 8 shape table (no travel share).
const SHAPE_BYTES_V8: usize = 17;
/// Offset of the travel share in a shape-table entry.
const SHAPE_TRAVEL_SHARE_AT: usize = 17;
/// Bytes per action in a version 7 shape table (no travel).
const SHAPE_BYTES_V7: usize = 16;
/// Offset of the travel in a shape-table entry.
const SHAPE_TRAVEL_AT: usize = 16;
/// Bytes per action in a version 6 shape table (no hold).
const SHAPE_BYTES_V6: usize = 15;
/// Offset of the hold in a shape-table entry.
const SHAPE_HOLD_AT: usize = 15;
/// Unit of the learnt hold's byte code, µs (codes 1–255 span 10 ms – 2.55 s).
pub const HOLD_UNIT_US: u64 = 10_000;
/// Bytes per action in a version 5 shape table (no extents).
const SHAPE_BYTES_V5: usize = 13;
/// Offset of the extents in a shape-table entry.
const SHAPE_EXTENT_AT: usize = 13;
/// Bytes per action in a version 4 shape table (one spread for all dimensions).
const SHAPE_BYTES_V4: usize = 7;
/// Offset of the tolerances in a shape-table entry.
const SHAPE_TOLERANCE_AT: usize = 7;
/// Bytes per action in a version 2 shape table (no turn, no still share, no height).
const SHAPE_BYTES_V2: usize = 4;
/// Bytes per action in a version 3 shape table (no height).
const SHAPE_BYTES_V3: usize = 6;
/// The largest `ln(1 + angle turned)` the shape table holds (about 8.5 turns).
pub const SHAPE_TURN_MAX: f32 = 4.0;
/// Library blob header size, bytes.
pub const LIBRARY_HEADER: usize = 8;
/// Size of one action record with `n` positions, bytes.
pub const fn record_size(n: usize) -> usize {
    36 + 2 * n + 8 * (n + 1)
}
/// Largest valid library blob, bytes (12,296).
pub const MAX_LIBRARY_BYTES: usize =
    LIBRARY_HEADER + MAX_ACTIONS * (record_size(MAX_POSITIONS) + SHAPE_BYTES);

fn rd_u64(b: &[u8], at: usize) -> Option<u64> {
    let s = b.get(at..at + 8)?;
    let mut a = [0u8; 8];
    a.copy_from_slice(s);
    Some(u64::from_le_bytes(a))
}

fn rd_u16(b: &[u8], at: usize) -> Option<u16> {
    let s = b.get(at..at + 2)?;
    Some(u16::from_le_bytes([s[0], s[1]]))
}

/// One action's compiled pattern, borrowed from the library blob.
#[derive(Debug, Clone, Copy)]
pub struct Pattern<'a> {
    rec: &'a [u8],
}

impl<'a> Pattern<'a> {
    /// Number of positions.
    pub fn positions(&self) -> usize {
        usize::from(self.rec.first().copied().unwrap_or(0))
    }
    /// Edit bound.
    pub fn max_edits(&self) -> usize {
        usize::from(self.rec.get(1).copied().unwrap_or(0))
    }
    /// Shortest accepted token string length.
    pub fn min_len(&self) -> usize {
        usize::from(self.rec.get(2).copied().unwrap_or(0))
    }
    /// Accepting positions.
    pub fn last(&self) -> u64 {
        rd_u64(self.rec, 4).unwrap_or(0)
    }
    fn shift(&self) -> u64 {
        rd_u64(self.rec, 12).unwrap_or(0)
    }
    fn loops(&self) -> u64 {
        rd_u64(self.rec, 20).unwrap_or(0)
    }
    fn extra(&self) -> u64 {
        rd_u64(self.rec, 28).unwrap_or(0)
    }
    /// Symbol of position `i` (1-based); STILL (matches nothing) when out of range.
    pub fn symbol(&self, i: usize) -> Symbol {
        if i == 0 {
            return STILL;
        }
        rd_u16(self.rec, 36 + 2 * (i - 1)).unwrap_or(STILL)
    }
    /// Follow set of state `i` (0 = initial); empty when out of range.
    pub fn follow(&self, i: usize) -> u64 {
        if i > self.positions() {
            return 0;
        }
        rd_u64(self.rec, 36 + 2 * self.positions() + 8 * i).unwrap_or(0)
    }
    /// The first positions (follow set of the initial state).
    pub fn first(&self) -> u64 {
        self.follow(0)
    }
    /// The symbols of positions 1..=n, in order.
    pub fn symbols(&self) -> impl Iterator<Item = Symbol> + 'a {
        let n = self.positions();
        self.rec
            .get(36..36 + 2 * n)
            .unwrap_or(&[])
            .chunks_exact(2)
            .map(|b| match b {
                [lo, hi] => u16::from_le_bytes([*lo, *hi]),
                _ => STILL,
            })
    }
    /// Positions whose symbol is `t`.
    pub fn symbol_mask(&self, t: Token) -> u64 {
        self.symbols()
            .enumerate()
            .take(MAX_POSITIONS)
            .filter(|&(_, s)| symbol_matches(s, t))
            .fold(0, |m, (i, _)| m | (2u64 << i))
    }
    /// Whether the action is cyclic: its whole pattern repeats (walk, wave …), so a short
    /// pause does not end it.
    pub fn cyclic(&self) -> bool {
        self.rec.get(3).is_some_and(|f| f & 1 != 0)
    }
    /// Forward transition: all states reachable from a state of `d` in one step.
    #[inline]
    pub fn forward(&self, d: u64) -> u64 {
        let mut out = ((d << 1) & self.shift()) | (d & self.loops());
        let mut x = d & self.extra();
        while x != 0 {
            let i = x.trailing_zeros() as usize;
            out |= self.follow(i);
            x &= x - 1;
        }
        out
    }
    /// [`Pattern::forward`] kept out of line, for paths that are not per token (flash).
    #[inline(never)]
    pub fn forward_outlined(&self, d: u64) -> u64 {
        self.forward(d)
    }
    /// [`Pattern::backward`] of `d`, only among the states `among` (few: a token's exact or
    /// near positions): reads just their follow sets.
    pub fn backward_among(&self, d: u64, among: u64) -> u64 {
        let mut out = 0u64;
        let mut x = if d == 0 { 0 } else { among };
        while x != 0 {
            let i = x.trailing_zeros() as usize;
            if self.follow(i) & d != 0 {
                out |= 1 << i;
            }
            x &= x - 1;
        }
        out
    }
    /// Backward transition: all states with a successor in `d`.
    pub fn backward(&self, d: u64) -> u64 {
        // Dead cost levels are common in the reverse search; reading every follow set for
        // them cost ~50 instructions per sample on the MCU.
        if d == 0 {
            return 0;
        }
        let n = self.positions();
        let at = 36 + 2 * n;
        let follows = self.rec.get(at..at + 8 * (n + 1)).unwrap_or(&[]);
        let mut out = 0u64;
        for (i, f) in follows.chunks_exact(8).enumerate() {
            let f = match f {
                [a, b, c, e, g, h, k, l] => u64::from_le_bytes([*a, *b, *c, *e, *g, *h, *k, *l]),
                _ => 0,
            };
            if f & d != 0 {
                out |= 1 << i;
            }
        }
        out
    }
}

/// A validated library blob: up to [`MAX_ACTIONS`] patterns, read in place.
#[derive(Debug, Clone, Copy)]
pub struct Library<'a> {
    bytes: &'a [u8],
    n: usize,
    offsets: [u16; MAX_ACTIONS],
    /// Offset of the shape table (0: none — a version 1 blob, or a version 2, 3 or 4 one,
    /// whose shapes lack dimensions or tolerances and are not used).
    shapes: u16,
    /// Bytes per entry of the shape table ([`SHAPE_BYTES`], or an older version's fewer).
    stride: u8,
}

impl<'a> Library<'a> {
    /// An empty library (recognises nothing).
    pub const fn empty() -> Library<'static> {
        Library {
            bytes: &[],
            n: 0,
            offsets: [0; MAX_ACTIONS],
            shapes: 0,
            stride: 0,
        }
    }

    /// Validates and wraps a library blob. Never panics; any inconsistency is an error.
    pub fn from_bytes(bytes: &'a [u8]) -> Result<Self, Error> {
        if bytes.len() > MAX_LIBRARY_BYTES {
            return Err(Error::TooLarge);
        }
        let head = bytes.get(..LIBRARY_HEADER).ok_or(Error::Truncated)?;
        if head[..3] != *b"FGL" {
            return Err(Error::BadMagic);
        }
        let version = head[3];
        if !(1..=LIBRARY_VERSION).contains(&version) {
            return Err(Error::Version(version));
        }
        let n = usize::from(head[4]);
        if n > MAX_ACTIONS {
            return Err(Error::Capacity);
        }
        if head[5..8] != [0, 0, 0] {
            return Err(Error::Invalid("reserved bytes"));
        }
        let mut offsets = [0u16; MAX_ACTIONS];
        let mut at = LIBRARY_HEADER;
        for slot in offsets.iter_mut().take(n) {
            let np = usize::from(*bytes.get(at).ok_or(Error::Truncated)?);
            if np == 0 || np > MAX_POSITIONS {
                return Err(Error::Capacity);
            }
            let rec = bytes
                .get(at..at + record_size(np))
                .ok_or(Error::Truncated)?;
            validate(Pattern { rec })?;
            *slot = at as u16;
            at += record_size(np);
        }
        let mut shapes = 0;
        let stride = match version {
            1 => 0,
            2 => SHAPE_BYTES_V2,
            3 => SHAPE_BYTES_V3,
            4 => SHAPE_BYTES_V4,
            5 => SHAPE_BYTES_V5,
            6 => SHAPE_BYTES_V6,
            7 => SHAPE_BYTES_V7,
            8 => SHAPE_BYTES_V8,
            9 => SHAPE_BYTES_V9,
            10 => SHAPE_BYTES_V10,
            _ => SHAPE_BYTES,
        };
        if stride > 0 {
            let table = bytes.get(at..at + stride * n).ok_or(Error::Truncated)?;
            for s in table.chunks_exact(stride) {
                // Known (flag ≠ 0), or unknown and all zero.
                if s.get(3) == Some(&0) && s.iter().any(|&b| b != 0) {
                    return Err(Error::Invalid("shape table"));
                }
                // Both extents known, or neither.
                if let Some(&[m, t]) = s.get(SHAPE_EXTENT_AT..SHAPE_EXTENT_AT + 2) {
                    if (m == 0) != (t == 0) {
                        return Err(Error::Invalid("shape table"));
                    }
                }
            }
            if stride >= SHAPE_BYTES_V5 {
                shapes = at as u16;
            }
            at += stride * n;
        }
        if at != bytes.len() {
            return Err(Error::Invalid("trailing bytes"));
        }
        Ok(Library {
            bytes,
            n,
            offsets,
            shapes,
            stride: stride as u8,
        })
    }

    /// The motion shape of action `i` ([`Shape`]) when it was learnt with one (a version 2, 3
    /// or 4 library's shapes lack dimensions or tolerances and are not used).
    pub fn shape(&self, i: usize) -> Option<Shape> {
        if self.shapes == 0 || i >= self.n {
            return None;
        }
        let at = usize::from(self.shapes) + usize::from(self.stride) * i;
        match *self.bytes.get(at..at + SHAPE_BYTES_V5)? {
            [l, u, f, 1..=255, t, s, h, ..] => Some([
                f32::from(l) / 255.0,
                f32::from(u) / 255.0,
                f32::from(f) / 255.0,
                f32::from(t) * (SHAPE_TURN_MAX / 255.0),
                f32::from(s) / 255.0,
                f32::from(h) * (2.0 / 255.0) - 1.0,
            ]),
            _ => None,
        }
    }

    /// How far the examples' shapes of action `i` lay from [`Library::shape`], per dimension
    /// ([`crate::shape::shape_penalty`]'s tolerance: `shape::SHAPE_SCALE`-weighted
    /// |example − mean|, in the shape's units); all 0 when its shape is not known.
    pub fn shape_tolerance(&self, i: usize) -> Shape {
        let mut out = [0.0; SHAPE_DIMS];
        if self.shapes == 0 || i >= self.n {
            return out;
        }
        let at = usize::from(self.shapes) + usize::from(self.stride) * i + SHAPE_TOLERANCE_AT;
        if let Some(bytes) = self.bytes.get(at..at + SHAPE_DIMS) {
            for (t, &b) in out.iter_mut().zip(bytes) {
                *t = f32::from(b) / 255.0;
            }
        }
        out
    }

    /// How far the least of action `i`'s examples went ([`crate::extent`]); None when not
    /// learnt (a version 5 library, or an action learnt without examples). Its travel is 0
    /// when not known (a version 7 library), and so is its travel share (before version 9).
    pub fn extent(&self, i: usize) -> Option<Extent> {
        if self.shapes == 0 || i >= self.n || usize::from(self.stride) < SHAPE_BYTES_V6 {
            return None;
        }
        let entry = usize::from(self.shapes) + usize::from(self.stride) * i;
        let at = entry + SHAPE_EXTENT_AT;
        let byte = |at: usize| {
            if usize::from(self.stride) > at {
                self.bytes.get(entry + at).copied().unwrap_or(0)
            } else {
                0
            }
        };
        let travel = byte(SHAPE_TRAVEL_AT);
        match *self.bytes.get(at..at + 2)? {
            [m, t] => Some(Extent {
                moved_m: from_byte(m, MOVED_CODE_UNIT_M)?,
                turned_rad: from_byte(t, TURNED_CODE_UNIT_RAD)?,
                travel_m: from_byte(travel, MOVED_CODE_UNIT_M).unwrap_or(0.0),
                travel_share: f32::from(byte(SHAPE_TRAVEL_SHARE_AT)) / 255.0,
            }),
            _ => None,
        }
    }

    /// The fewest sub-movements ([`crate::sweep`]) any of action `i`'s examples made (0: not
    /// learnt, a library older than version 10).
    pub fn least_sweeps(&self, i: usize) -> u8 {
        self.entry_byte(i, SHAPE_SWEEPS_AT)
    }

    /// How long the briefest of action `i`'s examples moved, µs, from its first motion to its
    /// last (0: not learnt, a library older than version 11).
    pub fn briefest_us(&self, i: usize) -> u64 {
        u64::from(self.entry_byte(i, SHAPE_BRIEF_AT)) * HOLD_UNIT_US
    }

    /// The longest stillness inside any of action `i`'s examples, µs: how long a performance
    /// of it may hold still and go on (0 when its examples never held, or not learnt: a
    /// library older than version 7).
    pub fn hold_us(&self, i: usize) -> u64 {
        u64::from(self.entry_byte(i, SHAPE_HOLD_AT)) * HOLD_UNIT_US
    }

    /// Byte `at` of action `i`'s shape-table entry; 0 (not learnt) when the table or the
    /// entry is absent, or the library's version ends its entries before it.
    fn entry_byte(&self, i: usize, at: usize) -> u8 {
        if self.shapes == 0 || i >= self.n || usize::from(self.stride) <= at {
            return 0;
        }
        let at = usize::from(self.shapes) + usize::from(self.stride) * i + at;
        self.bytes.get(at).copied().unwrap_or(0)
    }

    /// Number of actions.
    pub fn len(&self) -> usize {
        self.n
    }

    /// True when the library holds no action.
    pub fn is_empty(&self) -> bool {
        self.n == 0
    }

    /// Pattern of action `i`, if present.
    pub fn pattern(&self, i: usize) -> Option<Pattern<'a>> {
        if i >= self.n {
            return None;
        }
        let at = usize::from(*self.offsets.get(i)?);
        let np = usize::from(*self.bytes.get(at)?);
        let rec = self.bytes.get(at..at + record_size(np))?;
        Some(Pattern { rec })
    }
}

fn validate(p: Pattern<'_>) -> Result<(), Error> {
    let n = p.positions();
    let valid: u64 = ((1u64 << (n + 1)) - 1) & !1;
    if p.rec.get(3).is_none_or(|f| f & !1 != 0) {
        return Err(Error::Invalid("reserved flag bits"));
    }
    if p.max_edits() > MAX_EDITS {
        return Err(Error::Capacity);
    }
    for i in 1..=n {
        if !symbol_valid(p.symbol(i)) {
            return Err(Error::Invalid("pattern symbol"));
        }
    }
    let (mut shift, mut loops, mut extra) = (0u64, 0u64, 0u64);
    for i in 0..=n {
        let f = p.follow(i);
        if f & !valid != 0 {
            return Err(Error::Invalid("follow set"));
        }
        if i >= 1 && f & (1 << i) != 0 {
            loops |= 1 << i;
        }
        if i >= 1 && i < n && f & (1 << (i + 1)) != 0 {
            shift |= 1 << (i + 1);
        }
        let covered = if i == 0 { 0 } else { (1 << i) | (1 << (i + 1)) };
        if f & !covered != 0 {
            extra |= 1 << i;
        }
    }
    if p.last() & !valid != 0 || p.last() == 0 {
        return Err(Error::Invalid("accepting set"));
    }
    if (shift, loops, extra) != (p.shift(), p.loops(), p.extra()) {
        return Err(Error::Invalid("transition masks"));
    }
    // Shortest accepted string by breadth-first search over state sets.
    let mut reach = p.first();
    let mut len = 1;
    while reach & p.last() == 0 {
        let next = reach | p.forward(reach);
        if next == reach || len > n {
            return Err(Error::Invalid("no accepting path"));
        }
        reach = next;
        len += 1;
    }
    if len != p.min_len() || p.max_edits() >= len {
        return Err(Error::Invalid("min_len / max_edits"));
    }
    Ok(())
}

/// Writes a pattern record (host side / tests): symbols of positions 1..=n and follow sets of
/// states 0..=n. Returns the number of bytes appended, or an error if out of capacity.
#[cfg(any(feature = "std", test))]
pub fn encode_record(
    out: &mut impl Extend<u8>,
    symbols: &[Symbol],
    follow: &[u64],
    last: u64,
    max_edits: u8,
    cyclic: bool,
) -> Result<usize, Error> {
    let n = symbols.len();
    if n == 0 || n > MAX_POSITIONS || follow.len() != n + 1 {
        return Err(Error::Capacity);
    }
    let (mut shift, mut loops, mut extra) = (0u64, 0u64, 0u64);
    for (i, &f) in follow.iter().enumerate() {
        if i >= 1 && f & (1 << i) != 0 {
            loops |= 1 << i;
        }
        if i >= 1 && i < n && f & (1 << (i + 1)) != 0 {
            shift |= 1 << (i + 1);
        }
        let covered = if i == 0 {
            0
        } else {
            (1u64 << i) | (1u64 << (i + 1))
        };
        if f & !covered != 0 {
            extra |= 1 << i;
        }
    }
    // Shortest accepted length, as the loader computes it.
    let mut reach = follow[0];
    let mut min_len = 1u8;
    while reach & last == 0 {
        let mut next = reach;
        for (i, &f) in follow.iter().enumerate() {
            if reach & (1 << i) != 0 {
                next |= f;
            }
        }
        if next == reach || usize::from(min_len) > n {
            return Err(Error::Invalid("no accepting path"));
        }
        reach = next;
        min_len += 1;
    }
    out.extend([n as u8, max_edits, min_len, u8::from(cyclic)]);
    for v in [last, shift, loops, extra] {
        out.extend(v.to_le_bytes());
    }
    for &s in symbols {
        out.extend(s.to_le_bytes());
    }
    for &f in follow {
        out.extend(f.to_le_bytes());
    }
    Ok(record_size(n))
}

#[cfg(test)]
pub(crate) mod tests {
    extern crate std;
    use super::*;
    use crate::token::parse_token;
    use std::vec::Vec;

    /// Tokens from their names (`"u f d.Xp"`), for tests.
    pub fn toks(s: &str) -> Vec<Token> {
        s.split_whitespace()
            .map(|t| parse_token(t).unwrap())
            .collect()
    }

    /// A library of sequential patterns `t1+ t2+ …` (each token repeatable), for tests.
    pub fn seq_library(actions: &[(&[&str], u8)]) -> Vec<u8> {
        let mut out = Vec::from(*b"FGL\x01");
        out.extend([actions.len() as u8, 0, 0, 0]);
        for (toks, k) in actions {
            let syms: Vec<Token> = toks.iter().map(|t| parse_token(t).unwrap()).collect();
            let n = syms.len();
            let mut follow = std::vec![0u64; n + 1];
            follow[0] = 1 << 1;
            for (i, f) in follow.iter_mut().enumerate().skip(1) {
                *f = (1 << i) | if i < n { 1 << (i + 1) } else { 0 };
            }
            encode_record(&mut out, &syms, &follow, 1 << n, *k, false).unwrap();
        }
        out
    }

    /// A library of sequential patterns `t1+ t2+ …` whose tokens from the `end`-th (1-based)
    /// on are optional (`d+ u*` for `(&["d", "u"], 0, 1)`), for tests.
    pub fn seq_library_ending(actions: &[(&[&str], u8, usize)]) -> Vec<u8> {
        let mut out = Vec::from(*b"FGL\x01");
        out.extend([actions.len() as u8, 0, 0, 0]);
        for (toks, k, end) in actions {
            let syms: Vec<Token> = toks.iter().map(|t| parse_token(t).unwrap()).collect();
            let n = syms.len();
            let mut follow = std::vec![0u64; n + 1];
            follow[0] = 1 << 1;
            for (i, f) in follow.iter_mut().enumerate().skip(1) {
                *f = (1 << i) | if i < n { 1 << (i + 1) } else { 0 };
            }
            let last = (*end..=n).fold(0u64, |m, i| m | 1 << i);
            encode_record(&mut out, &syms, &follow, last, *k, false).unwrap();
        }
        out
    }

    /// `blob` (version 1) as the current version with a shape table (`None`: unknown), each
    /// known shape with tolerance 0 in every dimension.
    pub fn with_shapes(blob: &[u8], shapes: &[Option<[u8; 6]>]) -> Vec<u8> {
        let mut out = blob.to_vec();
        out[3] = LIBRARY_VERSION;
        for s in shapes {
            match s {
                Some([l, u, f, t, st, h]) => {
                    out.extend([*l, *u, *f, 1, *t, *st, *h]);
                    out.extend([0; SHAPE_DIMS]);
                    out.extend([0; SHAPE_BYTES - 7 - SHAPE_DIMS]);
                }
                None => out.extend([0; SHAPE_BYTES]),
            }
        }
        out
    }

    /// `blob` (version 1) as the current version in which every action has a shape no match is
    /// charged for (tolerance 1 in every dimension) and its examples' least extents
    /// `(m, rad)` ([`crate::extent`]).
    pub fn with_extents(blob: &[u8], extents: &[(f32, f32)]) -> Vec<u8> {
        use crate::extent::{to_byte, MOVED_CODE_UNIT_M, TURNED_CODE_UNIT_RAD};
        let mut out = blob.to_vec();
        out[3] = LIBRARY_VERSION;
        for &(m, t) in extents {
            out.extend([0, 0, 0, 1, 0, 0, 128]);
            out.extend([255; SHAPE_DIMS]);
            out.extend([
                to_byte(m, MOVED_CODE_UNIT_M),
                to_byte(t, TURNED_CODE_UNIT_RAD),
            ]);
            out.extend([0; SHAPE_BYTES - 7 - SHAPE_DIMS - 2]);
        }
        out
    }

    /// `blob` (the current version, with its shape table) with action `i`'s fewest
    /// sub-movements set to `made`.
    pub fn with_sweeps(blob: &[u8], i: usize, made: u8) -> Vec<u8> {
        with_entry_byte(blob, i, SHAPE_SWEEPS_AT, made)
    }

    /// `blob` (the current version, with its shape table) with byte `at` of action `i`'s
    /// entry set to `b`.
    fn with_entry_byte(blob: &[u8], i: usize, at: usize, b: u8) -> Vec<u8> {
        let mut out = blob.to_vec();
        let n = usize::from(out[4]);
        let at = out.len() - (n - i) * SHAPE_BYTES + at;
        out[at] = b;
        out
    }

    /// `blob` (the current version, with its shape table) with action `i`'s least travel set
    /// to `travel_m` and its least travel share to `share` (0–1).
    pub fn with_travel(blob: &[u8], i: usize, travel_m: f32, share: f32) -> Vec<u8> {
        let mut out = blob.to_vec();
        let n = usize::from(out[4]);
        let at = out.len() - (n - i) * SHAPE_BYTES;
        out[at + SHAPE_TRAVEL_AT] =
            crate::extent::to_byte(travel_m, crate::extent::MOVED_CODE_UNIT_M);
        out[at + SHAPE_TRAVEL_SHARE_AT] = (share * 255.0) as u8;
        out
    }

    /// `blob` (the current version, with its shape table) with action `i`'s briefest example
    /// set to `briefest_us` (rounded down to [`HOLD_UNIT_US`]).
    pub fn with_briefest(blob: &[u8], i: usize, briefest_us: u64) -> Vec<u8> {
        let code = (briefest_us / HOLD_UNIT_US).min(255) as u8;
        with_entry_byte(blob, i, SHAPE_BRIEF_AT, code)
    }

    /// `blob` (the current version, with its shape table) with action `i`'s learnt hold set
    /// to `hold_us` (rounded down to [`HOLD_UNIT_US`]).
    pub fn with_hold(blob: &[u8], i: usize, hold_us: u64) -> Vec<u8> {
        let code = (hold_us / HOLD_UNIT_US).min(255) as u8;
        with_entry_byte(blob, i, SHAPE_HOLD_AT, code)
    }

    #[test]
    fn the_shape_table_carries_a_shape_per_action_and_older_versions_still_load() {
        let v1 = seq_library(&[(&["u", "d"], 0), (&["f", "b"], 0)]);
        let old = Library::from_bytes(&v1).unwrap();
        assert_eq!((old.len(), old.shape(0)), (2, None));
        let cur = with_shapes(&v1, &[Some([0, 255, 51, 51, 255, 153]), None]);
        let lib = Library::from_bytes(&cur).unwrap();
        let near = |a: Option<Shape>, b: Shape| {
            a.is_some_and(|a| (0..6).all(|k| (a[k] - b[k]).abs() < 1e-6))
        };
        let want = [0.0, 1.0, 0.2, 0.8, 1.0, 0.2];
        assert!(near(lib.shape(0), want), "{:?}", lib.shape(0));
        assert_eq!(lib.shape(1), None);
        assert_eq!(lib.shape(2), None);
        assert_eq!(lib.pattern(1).unwrap().positions(), 2);
        assert_eq!(lib.shape_tolerance(0), [0.0; 6]);
        assert_eq!(lib.shape_tolerance(1), [0.0; 6]);
        // The tolerances follow the shape, one byte per dimension: 51 → 0.2.
        let mut tol = cur.clone();
        let entry = tol.len() - 2 * SHAPE_BYTES;
        tol[entry + SHAPE_TOLERANCE_AT + 1] = 51;
        tol[entry + SHAPE_TOLERANCE_AT + 5] = 255;
        let lib = Library::from_bytes(&tol).unwrap();
        assert!(near(lib.shape(0), want));
        assert_eq!(lib.shape_tolerance(0), [0.0, 0.2, 0.0, 0.0, 0.0, 1.0]);
        assert_eq!(lib.shape_tolerance(2), [0.0; 6]);
        // A missing or partial table, a known shape without its flag, stray bytes after an
        // unknown shape.
        assert_eq!(
            Library::from_bytes(&cur[..cur.len() - 1]).err(),
            Some(Error::Truncated)
        );
        let mut bad = tol.clone();
        bad[entry + 3] = 0;
        assert!(Library::from_bytes(&bad).is_err());
        let mut bad = cur.clone();
        let last = bad.len() - 2;
        bad[last] = 7;
        assert!(Library::from_bytes(&bad).is_err());
        // An older version's library: action 0's entry `first`, action 1's all zero.
        let older = |version: u8, first: &[u8]| {
            let mut old = v1.clone();
            old[3] = version;
            old.extend(first);
            old.extend(core::iter::repeat_n(0, first.len()));
            old
        };
        // Versions 2, 3 and 4: four, six and seven bytes per entry; their patterns load,
        // their shapes (which lack the turn and the still share, the height, or a tolerance
        // per dimension) are not used.
        for (version, entry) in [
            (2u8, &[0u8, 255, 51, 52][..]),
            (3, &[0, 255, 51, 52, 9, 9]),
            (4, &[0, 255, 51, 52, 9, 9, 128]),
        ] {
            let mut old = older(version, entry);
            let lib = Library::from_bytes(&old).unwrap();
            assert_eq!((lib.len(), lib.shape(0)), (2, None), "version {version}");
            assert_eq!(lib.shape_tolerance(0), [0.0; 6]);
            assert_eq!(lib.pattern(1).unwrap().positions(), 2);
            old.push(0);
            assert!(Library::from_bytes(&old).is_err(), "version {version}");
        }
        // Version 5: thirteen bytes per entry, the shape without the extents.
        let v5 = older(5, &[0, 255, 51, 1, 51, 255, 153, 0, 51, 0, 0, 0, 255]);
        let lib = Library::from_bytes(&v5).unwrap();
        assert!(near(lib.shape(0), want));
        assert_eq!(lib.shape_tolerance(0), [0.0, 0.2, 0.0, 0.0, 0.0, 1.0]);
        assert_eq!(lib.extent(0), None);
        // Version 6: fifteen bytes per entry, the extents without the hold.
        let mut v6 = v1.clone();
        v6[3] = 6;
        v6.extend([
            0,
            255,
            51,
            1,
            51,
            255,
            153,
            0,
            51,
            0,
            0,
            0,
            255,
            1 + 16 * 10,
            1 + 16 * 5,
        ]);
        v6.extend([0; 15]);
        let lib = Library::from_bytes(&v6).unwrap();
        assert!(near(lib.shape(0), want));
        assert!(lib
            .extent(0)
            .is_some_and(|e| (e.moved_m - 0.1024).abs() < 1e-5));
        assert_eq!(lib.hold_us(0), 0);
        // The hold, in steps of 10 ms.
        let mut held = cur.clone();
        held[entry + SHAPE_HOLD_AT] = 92;
        let lib = Library::from_bytes(&held).unwrap();
        assert_eq!(
            (lib.hold_us(0), lib.hold_us(1), lib.hold_us(2)),
            (920_000, 0, 0)
        );
        // Version 7: sixteen bytes per entry, the hold without the travel.
        let v7 = older(7, &held[entry..entry + SHAPE_BYTES_V7]);
        let lib = Library::from_bytes(&v7).unwrap();
        assert_eq!((lib.hold_us(0), lib.hold_us(1)), (920_000, 0));
        assert!(near(lib.shape(0), want));
        // The travel, in the moved extent's code; 0 when not known.
        let mut ext = held.clone();
        ext[entry + 13] = 1 + 16 * 10;
        ext[entry + 14] = 1 + 16 * 5;
        assert_eq!(lib_extent(&ext).map(|e| e.travel_m), Some(0.0));
        ext[entry + SHAPE_TRAVEL_AT] = 1 + 16 * 9;
        let e = lib_extent(&ext).unwrap();
        assert!((e.travel_m - 0.0512).abs() < 1e-5, "{e:?}");
        assert_eq!(Library::from_bytes(&ext).unwrap().hold_us(0), 920_000);
        // The travel share, in 255ths (0: not known, as in a version 8 library, whose entries
        // end at the travel).
        assert_eq!(e.travel_share, 0.0);
        ext[entry + SHAPE_TRAVEL_SHARE_AT] = 153;
        let e = lib_extent(&ext).unwrap();
        assert!((e.travel_share - 0.6).abs() < 1e-6, "{e:?}");
        let v8 = older(8, &ext[entry..entry + SHAPE_BYTES_V8]);
        let e = lib_extent(&v8).unwrap();
        assert!(
            (e.travel_m - 0.0512).abs() < 1e-5 && e.travel_share == 0.0,
            "{e:?}"
        );
        // The fewest sub-movements, a count (0: not known, as in a version 9 library, whose
        // entries end at the travel share).
        assert_eq!(Library::from_bytes(&ext).unwrap().least_sweeps(0), 0);
        ext[entry + SHAPE_SWEEPS_AT] = 4;
        let lib = Library::from_bytes(&ext).unwrap();
        assert_eq!(
            (
                lib.least_sweeps(0),
                lib.least_sweeps(1),
                lib.least_sweeps(9)
            ),
            (4, 0, 0)
        );
        let v9 = older(9, &ext[entry..entry + SHAPE_BYTES_V9]);
        let lib = Library::from_bytes(&v9).unwrap();
        assert_eq!(lib.least_sweeps(0), 0);
        assert!(lib_extent(&v9).is_some_and(|e| (e.travel_share - 0.6).abs() < 1e-6));
        // The briefest example's moving time, in the hold's unit (0: not known, as in a
        // version 10 library, whose entries end at the sub-movements).
        assert_eq!(Library::from_bytes(&ext).unwrap().briefest_us(0), 0);
        ext[entry + SHAPE_BRIEF_AT] = 18;
        let lib = Library::from_bytes(&ext).unwrap();
        assert_eq!([0, 1, 9].map(|i| lib.briefest_us(i)), [180_000, 0, 0]);
        let v10 = older(10, &ext[entry..entry + SHAPE_BYTES_V10]);
        let lib = Library::from_bytes(&v10).unwrap();
        assert_eq!((lib.briefest_us(0), lib.least_sweeps(0)), (0, 4));
        // The extents, both known or neither.
        assert_eq!(lib_extent(&tol), None);
        let mut ext = tol.clone();
        ext[entry + 13] = 1 + 16 * 10;
        assert!(Library::from_bytes(&ext).is_err());
        ext[entry + 14] = 1 + 16 * 5;
        let e = lib_extent(&ext).unwrap();
        assert!(
            (e.moved_m - 0.1024).abs() < 1e-5 && (e.turned_rad - 0.032).abs() < 1e-6,
            "{e:?}"
        );
        let mut next = cur.clone();
        next[3] = LIBRARY_VERSION + 1;
        assert_eq!(
            Library::from_bytes(&next).err(),
            Some(Error::Version(LIBRARY_VERSION + 1))
        );
    }

    fn lib_extent(blob: &[u8]) -> Option<crate::extent::Extent> {
        Library::from_bytes(blob).unwrap().extent(0)
    }

    #[test]
    fn round_trip_and_transitions() {
        let blob = seq_library(&[(&["u", "d"], 0), (&["f", "b", "f", "b"], 1)]);
        let lib = Library::from_bytes(&blob).unwrap();
        assert_eq!(lib.len(), 2);
        let p = lib.pattern(1).unwrap();
        assert_eq!(p.positions(), 4);
        assert_eq!(p.min_len(), 4);
        assert_eq!(p.forward(1), 0b10);
        assert_eq!(p.forward(0b10), 0b110);
        assert_eq!(p.backward(0b100), 0b110);
        assert_eq!(p.symbol_mask(parse_token("b").unwrap()), 0b10100);
        assert!(lib.pattern(2).is_none());
        assert!(blob.len() <= MAX_LIBRARY_BYTES);
    }

    #[test]
    fn rejects_every_truncation_and_corruption_without_panicking() {
        let blob = seq_library(&[(&["u", "d"], 0), (&["f", "b", "f"], 1)]);
        for cut in 0..blob.len() {
            assert!(Library::from_bytes(&blob[..cut]).is_err(), "cut {cut}");
        }
        for i in 0..blob.len() {
            for bit in 0..8 {
                let mut b = blob.clone();
                b[i] ^= 1 << bit;
                // Must not panic; many flips are detected.
                let _ = Library::from_bytes(&b);
            }
        }
        let mut b = blob.clone();
        b[3] = LIBRARY_VERSION + 1;
        assert_eq!(
            Library::from_bytes(&b).unwrap_err(),
            Error::Version(LIBRARY_VERSION + 1)
        );
        let too_many_edits = seq_library(&[(&["u", "d"], 2)]);
        assert!(Library::from_bytes(&too_many_edits).is_err());
    }
}
