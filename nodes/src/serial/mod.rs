//! Serial hardware I/O: the framed binary protocol a microcontroller at the
//! display speaks (`docs/serial-protocol.md`) and, with the cargo feature
//! `serial`, the `serial.in` and `serial.out` nodes that talk it over a
//! serial port.
//!
//! * [`crc`], [`frame`], [`message`], [`stream`]: the protocol — always
//!   compiled, no serial port needed (the device emulator `evflow devsim`
//!   and the tests use them too).

pub mod crc;
pub mod examples;
pub mod frame;
pub mod message;
pub mod stream;

use evflow_engine::NodeSpec;

/// The node types of this family (none without the `serial` feature).
pub static SPECS: &[&NodeSpec] = &[];
