//! Arithmetic on streams.

pub mod mul;

use evflow_engine::NodeSpec;

/// The node types of this family.
pub static SPECS: &[&NodeSpec] = &[&mul::SPEC];
