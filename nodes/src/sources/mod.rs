//! Sources: nodes that produce samples at a rate set by their `rate`
//! parameter — the PRBS excitation of the display (dissertation §5.2.1) and
//! test sines.

pub mod prbs;
pub mod prbs_taps;
pub mod pulse;
pub mod sine;

use evflow_engine::NodeSpec;

/// The node types of this family.
pub static SPECS: &[&NodeSpec] = &[&prbs::SPEC, &sine::SPEC, &pulse::SPEC];
