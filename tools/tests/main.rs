//! The command-line tests in one binary: each file is a module (one link
//! instead of fourteen). The serial tests that run a live session against
//! a device (serial_e2e, serial_chains, firmware_qemu) keep binaries of
//! their own, so no study runs beside them while they keep time.

#[path = "common/files.rs"]
mod files;

mod batch_cli;
mod bench_narx;
mod bench_report;
mod characterize;
mod check_streams;
mod cli;
mod merge_gaps;
mod report_live;
mod report_narx;
mod report_precision;
mod report_stability;
mod score;
mod signals;
mod slurm_scripts;
