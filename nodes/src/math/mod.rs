//! Arithmetic on streams.

pub mod add;
mod binary;
pub mod mul;

use evflow_engine::NodeSpec;

/// The node types of this family.
pub static SPECS: &[&NodeSpec] = &[&add::SPEC, &mul::SPEC];
