//! Texture rendering over the (load, velocity) grid (dissertation §5.3.3,
//! chapter 6): the operators 𝒲𝒜 ([`wa`], Eq. 6.1) and 𝓡𝓢 ([`rs`], §6.2),
//! the basic and improved schemes ([`scheme`], Eq. 6.4), the grid of
//! recordings ([`grid`]), the frequency–velocity relation of §6.3
//! ([`freqvel`]), the alignment of the cells in position ([`align`]), and the nodes `interp` and `playback` (design and figures
//! in `docs/texture.md`).

pub mod align;
pub mod frame;
pub mod freqvel;
pub mod grid;
pub mod interp;
pub mod kernel;
pub mod kernel_mix;
pub mod playback;
pub mod rs;
pub mod rs_precision;
pub mod scheme;
pub mod wa;

use evflow_engine::NodeSpec;

/// The node types of this family.
pub static SPECS: &[&NodeSpec] = &[&interp::SPEC, &playback::SPEC];
