//! Rate nodes: `hold` (zero-order hold to another rate), and the exact
//! cross-rate sample ordering it and the multi-rate nodes share
//! ([`clock`]).

pub mod clock;
pub mod hold;

use evflow_engine::NodeSpec;

/// The node types of this family.
pub static SPECS: &[&NodeSpec] = &[&hold::SPEC];
