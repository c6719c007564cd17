//! Recognition on the host: the device recognizer run on pose logs, and everything that
//! produces what it loads.
//!
//! - [`feed`]: logs → wire-quantised samples → recognizer / front end.
//! - [`regex`]: pattern sources → Glushkov automata → device records.
//! - [`library`] / [`effort_model`]: LIB.json and EFFORT.json, and their device blobs.
//! - [`dtw`] + [`learn`] ([`intent`], [`columns`], [`sides`]) + [`separate`]: `figurine learn`.
//! - [`effort_train`] + [`report`] (+ `font`): `figurine train-effort`.
//! - [`simulate`]: `figurine simulate`.
//! - [`eval_cli`]: `figurine eval`, the accuracy tables of [`eval`] (+ [`eval_pairs`]; events
//!   scored against labels by [`scoring`]) or a benchmark: [`rest_bench`]: `figurine eval rest` (false
//!   alarms per hour at rest); [`sweep`]: `figurine eval sweep` (robustness to noise, rate,
//!   scale); [`repeat_bench`]: `figurine eval repeat` (one action played several times back to
//!   back).
//! - [`doodle`]: `figurine doodle`, a motion-capture take as a figurine pose log;
//!   [`real_bench`]: `figurine eval real` (recognition on labelled real doodles).

pub mod columns;
pub mod doodle;
pub mod dtw;
pub mod effort_model;
pub mod effort_train;
pub mod eval;
pub mod eval_cli;
pub mod eval_pairs;
pub mod feed;
pub mod intent;
pub mod learn;
pub mod library;
pub mod real_bench;
pub mod regex;
pub mod repeat_bench;
pub mod report;
pub mod rest_bench;
pub mod scoring;
pub mod separate;
pub mod sides;
pub mod simulate;
pub mod sweep;
pub mod tokens;
