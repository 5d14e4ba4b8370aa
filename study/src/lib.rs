//! The evflow studies: experiments that run graphs through the node
//! library and turn what they measure into rows, tables and shard records.
//!
//! This crate sits between the node library (`evflow-nodes`, components
//! only) and the command-line program (`evflow`, which parses, calls and
//! prints); the CLI, the tests and the benchmarks share it
//! (docs/architecture.md).
#![deny(missing_docs)]

/// `evflow report stability`: extreme and stiff cases over every node type.
pub mod stability;
