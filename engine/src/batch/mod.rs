//! Batch runs: many independent items (the runs of a sweep, the rows of a
//! report, the sessions of a replay) on several threads, with results
//! handed back in the items' order so that what a batch prints and writes
//! does not depend on how many threads ran it.
//!
//! - [`pool`]: the worker pool ([`pool::for_each_ordered`]).
//! - [`failures`]: one failing item does not lose the others; the list of
//!   failures with their reasons for the batch's summary.
//! - [`clash`]: runs that would write the same output file, refused
//!   before anything runs.
//! - [`shard`]: `K/N`, the K-th of N deterministic slices of a batch, for
//!   a cluster's job arrays.

pub mod clash;
pub mod failures;
pub mod pool;
pub mod shard;

pub use clash::{check_outputs, output_files, ClashError};
pub use failures::Failures;
pub use pool::{default_jobs, for_each_ordered, for_each_ordered_ahead, panic_message, Outcome};
pub use shard::{Shard, ShardError};
