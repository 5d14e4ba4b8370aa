//! The library half of the `evflow` program: what its commands share with
//! tests and benchmarks — plots for reports.
#![deny(missing_docs)]

pub mod batch;
pub mod fit;
pub mod plot;
#[cfg(feature = "studio")]
pub mod studio;
