//! One module per subcommand.

pub mod bench;
pub mod check;
#[cfg(all(feature = "serial", feature = "lab"))]
pub mod devsim;
pub mod dot;
#[cfg(feature = "lab")]
pub mod family;
#[cfg(feature = "synth")]
pub mod from_recordings;
pub mod graph_args;
pub mod import;
#[cfg(feature = "synth")]
pub mod library;
pub mod live;
pub mod merge;
pub mod nodes;
pub mod replay;
pub mod report;
pub mod run;
pub mod run_report;
#[cfg(feature = "synth")]
pub mod score;
#[cfg(feature = "studio")]
pub mod studio;
