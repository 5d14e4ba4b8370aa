//! Output stage: gain, summaries (and, later, the safety limiter and hardware outputs).

pub mod gain;
pub mod stats;

use evflow_engine::NodeSpec;

/// The node types of this family.
pub static SPECS: &[&NodeSpec] = &[&gain::SPEC, &stats::SPEC];
