//! The tables reports write, as library code: the `evflow report` commands
//! print and save them, and `evflow merge` writes them again from the
//! shards of a report (`--shard K/N`), with the same code.

#[cfg(feature = "synth")]
pub mod live;
#[cfg(feature = "synth")]
pub mod narx;
#[cfg(feature = "synth")]
pub mod textures;

/// Whether run times appear in what is printed and written: they differ
/// from run to run, so `--no-times` leaves them out for output that can be
/// compared byte for byte.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Timings {
    /// Run times shown.
    Show,
    /// Run times left out.
    Leave,
}
