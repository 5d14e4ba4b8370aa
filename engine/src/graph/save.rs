//! Writing a graph back to TOML (load → save → load round-trips).

use super::model::{Graph, FORMAT_VERSION};
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
                if let Some(files) = &a.files {
                    let _ = writeln!(s, "{} = {{ files = {} }}", key(&a.name), toml_string(files));
                    continue;
                }
                let values: Vec<String> = a.values.iter().map(|v| v.to_string()).collect();
                let _ = writeln!(s, "{} = [{}]", key(&a.name), values.join(", "));
            }
        }
        for p in &self.plots {
            let _ = writeln!(s, "\n[[plot]]");
            let _ = writeln!(s, "file = {}", toml_string(&p.file));
            if !p.title.is_empty() {
                let _ = writeln!(s, "title = {}", toml_string(&p.title));
            }
            let _ = writeln!(s, "x = {}", toml_string(&p.x));
            let ys: Vec<String> = p.y.iter().map(|y| toml_string(y)).collect();
            let _ = writeln!(s, "y = [{}]", ys.join(", "));
            if !p.series.is_empty() {
                let _ = writeln!(s, "series = {}", toml_string(&p.series));
            }
            if p.log_x {
                let _ = writeln!(s, "log_x = true");
            }
            if p.log_y {
                let _ = writeln!(s, "log_y = true");
            }
            if p.fit != super::plot::Fit::None {
                let _ = writeln!(s, "fit = {}", toml_string(p.fit.name()));
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
