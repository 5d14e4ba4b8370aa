//! Rate nodes — the only nodes whose output runs at another rate than
//! their input: `hold` (zero-order hold to another rate) and `decimate`
//! (integer step down with a linear-phase anti-aliasing filter); the exact
//! cross-rate sample ordering they share ([`clock`]), and the numerics
//! behind them ([`kaiser`], [`decimator`]).

pub mod clock;
pub mod decimate;
pub mod decimator;
pub mod hold;
pub mod kaiser;

use evflow_engine::NodeSpec;

/// The node types of this family.
pub static SPECS: &[&NodeSpec] = &[&hold::SPEC, &decimate::SPEC];
