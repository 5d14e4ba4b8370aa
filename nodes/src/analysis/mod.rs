//! Analysis sinks: measurements of a force at the end of a run, as the
//! device characterization of dissertation §3.1.2 takes them.

pub mod error;
pub mod onoff;
pub mod peaks;

use evflow_engine::NodeSpec;

/// The node types of this family.
pub static SPECS: &[&NodeSpec] = &[&peaks::SPEC, &onoff::SPEC, &error::SPEC];
