//! The third-party signal processing the nodes use — rustfft's FFTs and
//! rubato's resamplers — instantiated for `f64` once, here.
//!
//! Both crates are generic over the sample type, and a generic is compiled
//! where it is first named with a concrete type. Named inside the node
//! library, rustfft's planner with every butterfly it may choose (scalar,
//! SSE and AVX) was 43 % of that crate's code and was compiled twice, for
//! the library and again for its unit tests (docs/benchmarks.md, "Build
//! and test time"). The functions below are the only places the planner
//! and the resamplers' constructors are named; callers hold what they
//! return behind `dyn` and call it through the trait, which compiles
//! nothing of rustfft or rubato again.
//!
//! The arithmetic is the crates' own: an FFT or a resampler made here is
//! the one the caller would have made, bit for bit.
#![deny(missing_docs)]

pub mod fft;
pub mod resamplers;
