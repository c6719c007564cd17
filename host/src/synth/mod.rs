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
//! [`effort`] + [`gesture`] (strokes) → [`trajectory`] (clean pose over time) → [`sampling`]
//! (sample instants, quaternion sign) + [`noise`] (sensor and hand) → [`sequence`] (labelled
//! doodles and sets) → [`cli`] / [`plot`].
//!
//! Library use (in-process, no files):
//! ```
//! use figurine_host::synth::{gesture, Action, Effort, Knobs};
//! let d = gesture(7, &Knobs::default(), Action::Jump, "sudden-strong".parse().unwrap());
//! assert!(d.log.samples.len() > 30);
//! assert_eq!(d.labels[0].action, "jump");
//! ```

pub mod cli;
pub mod effort;
pub mod gesture;
pub mod knobs;
pub mod noise;
pub mod plot;
pub mod rng;
pub mod sampling;
pub mod sequence;
pub mod trajectory;

pub use effort::{Effort, TimeClass, WeightClass};
pub use gesture::Action;
pub use knobs::{Knobs, Range, Variation};
pub use sequence::{effort_set, examples, gesture, render, sequence, Doodle, Label};
