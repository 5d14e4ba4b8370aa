//! Safety: the `limit` node, the only node allowed to feed hardware
//! (amplitude clamp, slew-rate limit, ramp to zero on faults and stop).
//! Behaviour and the reasons behind each default: `docs/safety.md`.

pub mod envelope;
pub mod limit;

use evflow_engine::NodeSpec;

/// The node types of this family.
pub static SPECS: &[&NodeSpec] = &[&limit::SPEC];
