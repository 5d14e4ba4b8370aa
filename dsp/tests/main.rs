//! The crate's checks, as integration tests: a unit-test build of the
//! crate would compile rustfft's planner and rubato's resamplers a second
//! time, which is what the crate exists to avoid (src/lib.rs).

mod fft;
mod resamplers;
