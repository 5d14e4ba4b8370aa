//! NARX inverse models of the display (dissertation §5.2.1): a network
//! learns the actuation u\[n\] from the measured lateral force, trained open
//! loop and run closed loop.

pub mod closed_loop;
pub mod error;
pub mod eval;
pub mod exact_tanh;
pub mod exact_tanh_avx2;
pub mod fast_tanh;
pub mod fast_tanh_avx2;
pub mod fit;
pub mod grid;
#[cfg(feature = "lab")]
pub mod labdata;
pub mod mapminmax;
pub mod model;
pub mod nearest;
pub mod net;
pub mod node;
pub mod packed;
pub mod pairs;
pub mod score;
pub mod taps;
pub mod train;
pub mod train_node;

use evflow_engine::NodeSpec;

/// The node types of this family.
pub static SPECS: &[&NodeSpec] = &[&train_node::SPEC, &score::SPEC, &node::SPEC, &grid::SPEC];
