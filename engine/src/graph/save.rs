//! Writing a graph back to TOML (load → save → load round-trips).

use super::{Graph, FORMAT_VERSION};
use crate::params::{toml_float, toml_string};
use std::fmt::Write;

impl Graph {
    /// The graph as a TOML graph file in the current format.
    pub fn to_toml(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(s, "[graph]");
        let _ = writeln!(s, "format = {FORMAT_VERSION}");
        let _ = writeln!(s, "name = {}", toml_string(&self.name));
        if !self.description.is_empty() {
            let _ = writeln!(s, "description = {}", toml_string(&self.description));
        }
        let _ = writeln!(s, "rate = {}", toml_float(self.rate));
        if let Some(d) = self.duration {
            let _ = writeln!(s, "duration = {}", toml_float(d));
        }
        if self.seed != 0 {
            let _ = writeln!(s, "seed = {}", self.seed);
        }
        let _ = writeln!(s, "connections = [");
        for c in &self.connections {
            let _ = writeln!(s, "  {},", toml_string(&format!("{} -> {}", c.from, c.to)));
        }
        let _ = writeln!(s, "]");
        if !self.vars.is_empty() {
            let _ = writeln!(s, "\n[vars]");
            for v in &self.vars {
                let _ = writeln!(s, "{} = {}", key(&v.name), v.value);
            }
        }
        if !self.sweep.is_empty() {
            let _ = writeln!(s, "\n[sweep]");
            for a in &self.sweep {
                let values: Vec<String> = a.values.iter().map(|v| v.to_string()).collect();
                let _ = writeln!(s, "{} = [{}]", key(&a.name), values.join(", "));
            }
        }
        for n in &self.nodes {
            let _ = writeln!(s, "\n[nodes.{}]", key(&n.name));
            let _ = writeln!(s, "type = {}", toml_string(&n.kind));
            for p in &n.params {
                let _ = writeln!(s, "{} = {}", key(&p.name), p.value);
            }
        }
        s
    }
}

/// A bare key when possible, else a quoted one.
fn key(k: &str) -> String {
    if !k.is_empty() && k.chars().all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-') {
        k.to_string()
    } else {
        toml_string(k)
    }
}
