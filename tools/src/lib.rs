//! The library half of the `evflow` program: what its commands share with
//! tests and benchmarks: plots for reports, fits, and batch computations
//! (a sweep's tables, shard records, the merge of shards) and the live
//! session (`evflow live`'s recording, read back by `replay` and
//! `studio`). The studies
//! and the tables of reports are in the study crate (`evflow_study`).
#![deny(missing_docs)]

pub mod batch;
pub mod fit;
pub mod floor_fit;
pub mod live_session;
pub mod plan_description;
pub mod plot;
#[cfg(feature = "studio")]
pub mod studio;
