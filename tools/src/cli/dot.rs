//! `evflow dot FILE`: Graphviz output.

use super::graph_args::GraphArgs;
use anyhow::Result;

/// Arguments of `evflow dot`.
#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(flatten)]
    graph: GraphArgs,
}

/// Runs `evflow dot`.
pub fn main(a: Args) -> Result<()> {
    let c = a.graph.load()?;
    print!("{}", evflow_engine::dot::to_dot(&c));
    Ok(())
}
