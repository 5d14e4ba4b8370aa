//! The end-to-end tests in one binary: each file is a module (one link
//! instead of fifteen). Those that must run alone keep binaries of their
//! own (Cargo.toml says which and why).

#[path = "fuzz_common.rs"]
mod fuzz_common;
#[path = "studio_common.rs"]
mod studio_common;

mod bounded_plans;
mod firmware_core;
mod fuzz_loader;
mod fuzz_numbers;
mod layers;
mod library_from_recordings;
mod live_chain;
mod long_functions;
mod prune;
mod rate_mismatch;
mod rig_recordings;
mod shared_sweep;
mod shipped_graphs;
mod stability;
mod studio_server;
mod texture_quality;
mod texture_study;
