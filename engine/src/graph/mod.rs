//! Graph files: the parsed form of a `.toml` graph (before validation),
//! reading and writing it.
//!
//! The format is documented in `docs/graph-format.md`.

mod model;
mod parse;

pub use parse::parse_cli_value;
pub(crate) use parse::valid_name as valid_port_name;
pub mod plot;
mod save;
pub use plot::{Fit, PlotDecl};

pub use parse::parse_graph;

pub use model::{Axis, Connection, Endpoint, Graph, NodeDecl, ParamDecl, Var, FORMAT_VERSION};
