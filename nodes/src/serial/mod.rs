//! Serial hardware I/O: the framed binary protocol a microcontroller at the
//! display speaks (`docs/serial-protocol.md`) and, with the cargo feature
//! `serial` (on by default), the `serial.in` and `serial.out` nodes that
//! talk it over a serial port.
//!
//! * [`crc`], [`frame`], [`message`], [`stream`], [`host`]: the protocol —
//!   always compiled, no serial port needed (the device emulator
//!   `evflow devsim` and the tests use them too).
//! * `link`, `io`: one I/O thread per port, exchanging samples with the
//!   nodes through lock-free rings (feature `serial`).
//! * `input`, `output`: the nodes (feature `serial`).

pub mod crc;
pub mod device;
pub mod examples;
pub mod frame;
pub mod host;
pub mod message;
pub mod stream;

#[cfg(feature = "serial")]
pub mod input;
#[cfg(feature = "serial")]
mod io;
#[cfg(feature = "serial")]
pub use io::set_notices;
#[cfg(feature = "serial")]
pub mod link;
pub mod link_state;
#[cfg(feature = "serial")]
pub mod output;
#[cfg(feature = "serial")]
pub mod params;

use evflow_engine::NodeSpec;

/// The node types of this family (none without the `serial` feature).
#[cfg(feature = "serial")]
pub static SPECS: &[&NodeSpec] = &[&input::SPEC, &output::SPEC];
/// The node types of this family (none without the `serial` feature).
#[cfg(not(feature = "serial"))]
pub static SPECS: &[&NodeSpec] = &[];

#[cfg(all(test, feature = "serial", unix))]
mod node_tests;
