//! Metrics (dissertation §5.2.3): the averaged magnitude spectrum, the
//! relative spectral RMS error E_s, and the `metric` node that reports them.

pub mod node;
pub mod spectral_error;
pub mod spectrum;

use evflow_engine::NodeSpec;

/// The node types of this family.
pub static SPECS: &[&NodeSpec] = &[&node::SPEC];
