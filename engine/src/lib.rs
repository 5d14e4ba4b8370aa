//! # evflow-engine
//!
//! A block-based, multi-rate dataflow engine. It knows nothing about haptics:
//! node types are declared as data ([`spec::NodeSpec`]), graphs are TOML
//! files ([`graph`]), validated completely before anything is built
//! ([`check`](mod@check)), compiled into a flat [`plan::Plan`] that leaves out every node
//! no sink needs, and driven either offline ([`run`]) or live, one tick at a
//! time, through the same [`plan::Plan::step`].
#![deny(missing_docs)]

pub mod atomic_file;
pub mod batch;
pub mod check;
pub mod diag;
pub mod dot;
pub mod files;
pub mod graph;
pub mod harness;
pub mod live;
pub mod load;
pub mod node;
pub mod params;
pub mod plan;
pub mod ports;
pub mod rate;
pub mod reference;
pub mod registry;
pub mod run;
pub mod spec;
pub mod suggest;
pub mod sweep;
pub mod sweep_files;
pub mod sweep_shared;
pub mod typed_params;

pub use check::{check, Checked, Override};
pub use diag::{Diagnostic, Diagnostics};
pub use graph::Graph;
pub use load::{load_file, read_graph, LoadError};
pub use node::{BuildContext, Change, Io, Node, NodeError, PrepareContext, Refused, RunMode, Summary};
pub use params::{Params, Value};
pub use plan::{Plan, PlanOptions};
pub use registry::Registry;
pub use run::{check_duration, run_offline, RunOptions, RunReport};
pub use spec::{Direction, NodeSpec, ParamSpec, PortSpec, RateSpec, Role};
