//! Stage 6, told — why the decision stage dropped or changed a match, for a reader.
//!
//! A user whose crouch was not reported, or was reported as a bow, wants to know which rule
//! decided it. [`crate::Recognizer::push_noted`] hands out a [`Note`] wherever a committed
//! match did not become the event its pattern named:
//!
//! | [`Why`] | rule | where |
//! |---|---|---|
//! | [`Why::TooBrief`] | briefer than [`crate::segment::MIN_ACTION_US`], turned less than [`crate::segment::BRIEF_TURN_RAD`], and not a whole gesture, from rest to rest, as quick as its action's examples (half the briefest) and as far as the least of them: a flicker | segment |
//! | [`Why::NotFarEnough`] | a new event that went less far (or, for an action whose examples travelled, ended less far away) than its action's examples allow: a fidget | [`crate::extent`] |
//! | [`Why::OneSweep`] | a new event whose motion, from rest to rest, was one sweep, where its action's examples each made several pushes: a toy carried | [`crate::sweep`] |
//! | [`Why::Settles`] | the settling of the event before it, which moved much more | [`crate::follow`] |
//! | [`Why::WindUp`] | an event taken into the gesture after it: one stroke against that gesture's first, far smaller — its wind-up | [`crate::follow`] |
//! | [`Why::Lost`] | its token runs had already left the history | [`crate::history`] |
//! | [`Why::Reread`] | its motion was plainly unlike its action's examples: reported as the action it moved like | [`crate::nearest`] |
//! | [`Why::NotThatFar`] | a new event that went less far than its action's examples allow: reported as the action whose pattern reads it within an edit, which it moved like and went as far as | [`crate::nearest`] |
//! | [`Why::Nearest`] | a stand-alone phrase no pattern matched closely: reported as its nearest action | [`crate::nearest`] |
//!
//! The notes change nothing: [`crate::Recognizer::push`] is `push_noted` with notes thrown
//! away, and a note is only built when it is asked for (the device builds none).
// No imports: the recognizer hands notes out, so this module must not depend on it.

/// Why a match was dropped, or reported as another action than its pattern's.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Why {
    /// Dropped: briefer than the least action, not turned a quarter turn, and not a whole
    /// gesture its action's examples vouch for.
    TooBrief,
    /// Dropped: a new event that did not go (or travel) as far as its action's examples.
    NotFarEnough,
    /// Dropped: a new event whose motion from rest to rest was one sweep, where each of its
    /// action's examples made several sub-movements.
    OneSweep,
    /// Taken into the event of action `into` right after it, as that gesture's wind-up: one
    /// stroke against its first, under a fifth of its motion.
    WindUp {
        /// The action whose event took it in.
        into: u8,
    },
    /// Dropped: the settling of the event before it.
    Settles,
    /// Dropped: its runs had left the history before it was committed.
    Lost,
    /// Reported as [`Note::action`], though the pattern of action `matched` matched it: it
    /// moved unlike `matched`'s examples and like the reported action's.
    Reread {
        /// The action whose pattern matched.
        matched: u8,
    },
    /// Reported as [`Note::action`], its nearest action: a stand-alone phrase no pattern
    /// matched within its bound.
    Nearest,
    /// Reported as [`Note::action`], though the pattern of action `matched` matched it: it
    /// went less far than `matched`'s examples (a fidget, for that action), and the reported
    /// action's pattern reads it within an edit; it moved like that action's examples and
    /// went as far as they did.
    NotThatFar {
        /// The action whose pattern matched.
        matched: u8,
    },
}

/// One decision about a match, with the span of its token runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Note {
    /// The action (library index) the match was, or became.
    pub action: u8,
    /// Sequence number of the sample that opened the match's first run.
    pub start_seq: u32,
    /// Time of that sample, µs.
    pub start_us: u64,
    /// Sequence number of the sample that closed its last run.
    pub end_seq: u32,
    /// Time of that sample, µs.
    pub end_us: u64,
    /// What was decided.
    pub why: Why,
}
