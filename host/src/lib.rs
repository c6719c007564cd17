//! figurine host library: everything the `figurine` CLI does, usable from tests.
//!
//! Modules are named after their stage in the data flow (see DESIGN.md).

pub mod anim;
pub mod chart;
pub mod data;
pub mod events;
pub mod graph;
pub mod link;
pub mod motion;
pub mod poselog;
pub mod raster;
pub mod recognize;
pub mod render;
pub mod synth;
pub mod track;
