//! Filters: `butterworth` (low-/high-pass as second-order sections) and
//! `delay` (whole-sample delay, the node feedback cycles pass through),
//! `foaw` (velocity from sampled positions by adaptive windowing), `segment`
//! (the constant-speed stretches of a scan), `normalize` (a range to [−1, 1]).

pub mod butterworth;
pub mod delay;
pub mod foaw;
pub mod normalize;
pub mod segment;

use evflow_engine::NodeSpec;

/// The node types of this family.
pub static SPECS: &[&NodeSpec] = &[&butterworth::SPEC, &delay::SPEC, &foaw::SPEC, &normalize::SPEC, &segment::SPEC];
