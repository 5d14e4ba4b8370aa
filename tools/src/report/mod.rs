//! The tables reports write, as library code: the `evflow report` commands
//! print and save them, and `evflow merge` writes them again from the
//! shards of a report (`--shard K/N`), with the same code.

#[cfg(feature = "synth")]
pub mod live_table;
#[cfg(feature = "synth")]
pub mod narx_table;
#[cfg(feature = "synth")]
pub mod textures_table;
