//! Rate nodes — the only nodes whose output runs at another rate than
//! their input: `hold` (zero-order hold to another rate), `decimate`
//! (integer step down with a linear-phase anti-aliasing filter) and
//! `resample` (any ratio, through rubato, with a fixed latency); the exact
//! cross-rate sample ordering they share ([`clock`]), and the numerics
//! behind them ([`kaiser`], [`decimator`], [`resampler`]).

pub mod clock;
pub mod decimate;
pub mod decimator;
pub mod hold;
pub mod kaiser;
pub mod resample;
pub mod resampler;

use evflow_engine::NodeSpec;

/// The node types of this family.
pub static SPECS: &[&NodeSpec] = &[&hold::SPEC, &decimate::SPEC, &resample::SPEC];
