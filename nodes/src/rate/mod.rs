//! Rate nodes: `hold` (raise a rate by an integer factor), `decimate`
//! (lower it, with an anti-alias filter) and `resample` (rubato), and the
//! exact cross-rate sample ordering they and multi-rate nodes share
//! ([`clock`]).

pub mod clock;

use evflow_engine::NodeSpec;

/// The node types of this family.
pub static SPECS: &[&NodeSpec] = &[];
