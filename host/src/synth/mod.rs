//! `figurine synth`: the project's own seeded generator of synthetic spatial motion doodles.
//!
//! A doodle is the 6-DoF trajectory of a toy figurine played by a child or an animator
//! (DESIGN.md conventions: world metres, +Y up; object frame +Z front, +Y up, +X left;
//! quaternion w,x,y,z object→world; time in seconds). The generator plays the twelve actions of
//! [`gesture::Action`] with natural variation between performances, shapes them with the four
//! Laban effort states of [`effort::Effort`] (seed 000 §5), and lays a tracker model over them:
//! sensor noise, hand tremor, drift, jittered sample clocks at 30–240 Hz (up to 2 kHz on
//! request), both quaternion signs. Every nuisance parameter — scale, tempo, heading, tilt,
//! start position — is drawn from wide [`knobs::Knobs`] ranges. Output is deterministic per
//! seed and written with [`crate::poselog`].
//!
//! Data flow, one file per stage: [`rng`] (seeded streams) → [`knobs`] (nuisance draw) →
//! [`effort`] + [`mod@gesture`] (strokes) → [`trajectory`] (clean pose over time) → [`sampling`]
//! (sample instants, quaternion sign) + [`noise`] (sensor, hand, optional glitches) →
//! [`mod@sequence`] (labelled doodles and sets) → [`cli`] / [`plot`] (+ `font` for captions).
//!
//! How the effort classes show in the data (what a recognizer can learn): Time in stroke
//! durations (sustained ≈ 3× sudden) and peak speeds (≥ 1.9× at equal weight); Weight in
//! amplitude (strong ≈ 1.7× light) and in how strokes end — strong strokes stop in a ~20 ms
//! impact with a small bounce, light ones fade out — so peak deceleration over peak
//! acceleration separates them without knowing the doodle's scale. Impacts need ≳ 60 Hz to be
//! seen; at 30 Hz Weight shows mostly through amplitude and speed.
//!
//! [`rest`] makes logs of a figurine that plays *no* action — held in a hand, set on a table,
//! or mounted on a stand — under a chosen tracker level, for false-positive checks;
//! [`handling`] moves it as far as an action does without playing one (carried elsewhere,
//! lifted and set down).
//!
//! Command line: `figurine synth
//! gesture|sequence|handling|effort-set|examples|gallery|plot|rest` (see [`cli`]). Library use
//! (in-process, no files):
//! ```
//! use figurine_host::synth::{gesture, Action, Effort, Knobs};
//! let d = gesture(7, &Knobs::default(), Action::Jump, "sudden-strong".parse().unwrap());
//! assert!(d.log.samples.len() > 30);
//! assert_eq!(d.labels[0].action, "jump");
//! ```

pub mod cli;
pub mod effort;
pub mod gesture;
pub mod handling;
pub mod knobs;
pub mod noise;
pub mod plot;
pub mod rest;
pub mod rng;
pub mod sampling;
pub mod sequence;
pub mod tracker;
pub mod trajectory;

pub use effort::{Effort, TimeClass, WeightClass};
pub use gesture::Action;
pub use handling::Handling;
pub use knobs::{Knobs, Range, Variation};
pub use rest::{rest_log, RestKind, RestLog, RestSpec, TrackerLevel, TRACKER_LEVELS};
pub use sequence::{
    effort_set, examples, gesture, handled, render, sequence, Doodle, Label, Performer,
};
