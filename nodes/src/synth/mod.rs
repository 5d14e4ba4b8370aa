//! Optimized synthesis of actuation signals (beyond dissertation §5.2.2):
//! a *forward* model of the display (actuation → force), identified from
//! excitation recordings, and the actuation that makes its force closest
//! to a real texture force, found by bounded optimization with gradients
//! by backpropagation through time.
//!
//! The inverse NARX model of §5.2.1 asks the force to say which actuation
//! made it — ill posed on a square-law display, where u and −u make the
//! same force. The forward question is well posed: every actuation has one
//! force. docs/synthesis.md derives the model class and the objective and
//! gives the measured results.

pub mod error;
pub mod lbfgsb;
pub mod live;
pub mod model_file;
pub mod objective;
pub mod optimize;
pub mod output_filter;
pub mod spectral;
pub mod start;
pub mod synthesize;
pub mod train;
pub mod volterra;
pub mod volterra_fit;

use evflow_engine::NodeSpec;

/// The node types of this family.
pub static SPECS: &[&NodeSpec] = &[&train::SPEC, &optimize::SPEC, &live::node::SPEC];
