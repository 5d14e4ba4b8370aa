//! Sources: nodes that produce samples at a rate set by their `rate`
//! parameter — the PRBS excitation of the display (dissertation §5.2.1), its
//! multilevel successor (§5.4, §7.2) and
//! test sines.

pub mod prbs;
pub mod prbs_taps;
pub mod prms;
pub mod prms_field;
pub mod pulse;
pub mod sine;

use evflow_engine::NodeSpec;

/// The node types of this family.
pub static SPECS: &[&NodeSpec] = &[&prbs::SPEC, &prms::SPEC, &sine::SPEC, &pulse::SPEC];
