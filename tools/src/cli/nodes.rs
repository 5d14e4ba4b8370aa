//! `evflow nodes [TYPE]`: the node catalogue, from the declarations.

use anyhow::{anyhow, Result};
use evflow_engine::reference::{node_text, reference_markdown};
use evflow_engine::suggest;

/// Arguments of `evflow nodes`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// A node type to describe in full (e.g. `butterworth`).
    node_type: Option<String>,
    /// Print the whole reference as Markdown (this is docs/nodes.md).
    #[arg(long)]
    markdown: bool,
}

/// Runs `evflow nodes`.
pub fn main(a: Args) -> Result<()> {
    let reg = evflow_nodes::registry();
    if a.markdown {
        print!("{}", reference_markdown(&reg));
        return Ok(());
    }
    match a.node_type {
        Some(t) => {
            let spec =
                reg.get(&t).ok_or_else(|| anyhow!("unknown node type `{t}`; {}", suggest::help(&t, reg.names())))?;
            print!("{}", node_text(spec));
        }
        None => {
            let mut families: Vec<&str> = Vec::new();
            for s in reg.specs() {
                if !families.contains(&s.family) {
                    families.push(s.family);
                }
            }
            for family in families {
                println!("\n{family}:");
                for s in reg.specs().filter(|s| s.family == family) {
                    println!("  {:<16} {}", s.name, s.summary);
                }
            }
            println!("\n`evflow nodes TYPE` describes one type; docs/nodes.md has them all.");
        }
    }
    Ok(())
}
