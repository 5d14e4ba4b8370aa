//! Output stage: gain (and, later, the safety limiter and hardware outputs).

pub mod gain;

use evflow_engine::NodeSpec;

/// The node types of this family.
pub static SPECS: &[&NodeSpec] = &[&gain::SPEC];
