//! The node reference (`docs/nodes.md`, `evflow nodes`), generated from the
//! node declarations — never a second hand-kept list.

use crate::registry::Registry;
use crate::spec::{Direction, NodeSpec, ParamDefault, RateSpec};
use std::fmt::Write;

/// One node type as Markdown: summary, doc, ports, parameters, example.
pub fn node_markdown(spec: &NodeSpec, guards: &str) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "## `{}`\n\n{}\n", spec.name, spec.summary);
    if !spec.doc.is_empty() {
        let _ = writeln!(s, "{}\n", spec.doc.trim());
    }
    let role = format!("{:?}", spec.role).to_lowercase();
    let mut flags = vec![format!("family `{}`", spec.family), role];
    if spec.hardware {
        flags.push(format!("drives hardware (must be fed by {guards})"));
    }
    if spec.is_guard() {
        flags.push("safety guard (may feed hardware)".into());
    }
    if let Some(why) = spec.offline_only {
        flags.push(format!("offline only ({why})"));
    }
    if spec.breaks_cycles {
        flags.push("may close a feedback cycle".into());
    }
    if let Some(p) = spec.rate_param {
        flags.push(format!("rate set by `{p}`"));
    }
    let _ = writeln!(s, "*{}*\n", flags.join(" · "));
    if !spec.ports.is_empty() {
        let _ = writeln!(s, "| port | direction | rate | unit | description |\n|---|---|---|---|---|");
        for p in spec.ports {
            let dir = if p.dir == Direction::In { "in" } else { "out" };
            let rate = match p.rate {
                RateSpec::Node => "node".to_string(),
                RateSpec::Any => "any".to_string(),
                RateSpec::Param(n) => format!("`{n}`"),
            };
            let name = match p.multi {
                Some(list) => format!("one per `{list}` entry"),
                None => format!("`{}`", p.name),
            };
            let _ = writeln!(s, "| {name} | {dir} | {rate} | {} | {} |", p.unit, p.doc);
        }
        s.push('\n');
    }
    if !spec.params.is_empty() {
        let _ = writeln!(s, "| parameter | type | default | limits | unit | description |\n|---|---|---|---|---|---|");
        for p in spec.params {
            let default = match p.default {
                ParamDefault::Required => "**required**".to_string(),
                ParamDefault::Float(x) => crate::params::toml_float(x),
                ParamDefault::Int(i) => i.to_string(),
                ParamDefault::Bool(b) => b.to_string(),
                ParamDefault::Text(t) => format!("`\"{t}\"`"),
                ParamDefault::EmptyList => "`[]`".to_string(),
            };
            let _ = writeln!(
                s,
                "| `{}` | {} | {default} | {} | {} | {} |",
                p.name,
                p.kind.type_name(),
                p.kind.limits(),
                p.unit,
                if p.live { format!("{} *(changeable live)*", p.doc) } else { p.doc.to_string() }
            );
        }
        s.push('\n');
    }
    if !spec.example.is_empty() {
        let _ = writeln!(s, "```toml\n[nodes.example]\ntype = \"{}\"\n{}\n```\n", spec.name, spec.example.trim());
    }
    s
}

/// The whole reference, grouped by family.
pub fn reference_markdown(reg: &Registry) -> String {
    let mut s = String::from("# Node reference\n\n<!-- Generated from the node declarations by `evflow nodes --markdown`; a test checks it is current. Do not edit by hand. -->\n\n");
    let mut families: Vec<&str> = Vec::new();
    for spec in reg.specs() {
        if !families.contains(&spec.family) {
            families.push(spec.family);
        }
    }
    for f in &families {
        let names: Vec<String> =
            reg.specs().filter(|s| s.family == *f).map(|s| format!("[`{}`](#{})", s.name, anchor(s.name))).collect();
        let _ = writeln!(s, "- **{f}**: {}", names.join(", "));
    }
    s.push('\n');
    for f in &families {
        let _ = writeln!(s, "# {f}\n");
        for spec in reg.specs().filter(|s| s.family == *f) {
            s.push_str(&node_markdown(spec, &reg.guard_words()));
        }
    }
    s
}

/// The GitHub-style anchor of a heading `` `name` ``.
fn anchor(name: &str) -> String {
    name.chars().filter(|c| c.is_ascii_alphanumeric() || *c == '-' || *c == '_').collect::<String>().to_lowercase()
}

/// One node type as plain text for the terminal (`evflow nodes TYPE`).
pub fn node_text(spec: &NodeSpec) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "{} — {}\n", spec.name, spec.summary);
    if !spec.doc.is_empty() {
        let _ = writeln!(s, "{}\n", spec.doc.trim());
    }
    if !spec.ports.is_empty() {
        let _ = writeln!(s, "Ports:");
        for p in spec.ports {
            let dir = if p.dir == Direction::In { "in " } else { "out" };
            let rate = match p.rate {
                RateSpec::Node => String::new(),
                RateSpec::Any => " [any rate]".into(),
                RateSpec::Param(n) => format!(" [rate: {n}]"),
            };
            let name = p.multi.map(|l| format!("<each of {l}>")).unwrap_or_else(|| p.name.to_string());
            let _ = writeln!(s, "  {dir} {name:<14} {:<6} {}{rate}", p.unit, p.doc);
        }
        s.push('\n');
    }
    if !spec.params.is_empty() {
        let _ = writeln!(s, "Parameters:");
        for p in spec.params {
            let default = match p.default {
                ParamDefault::Required => "required".to_string(),
                ParamDefault::Float(x) => format!("default {}", crate::params::toml_float(x)),
                ParamDefault::Int(i) => format!("default {i}"),
                ParamDefault::Bool(b) => format!("default {b}"),
                ParamDefault::Text(t) => format!("default \"{t}\""),
                ParamDefault::EmptyList => "default []".to_string(),
            };
            let limits = p.kind.limits().replace("\\|", "|");
            let unit = if p.unit.is_empty() { String::new() } else { format!(" {}", p.unit) };
            let _ = writeln!(
                s,
                "  {:<14} {} ({default}{}{unit}) — {}",
                p.name,
                p.kind.type_name(),
                if limits.is_empty() { String::new() } else { format!("; {limits}") },
                p.doc
            );
        }
        s.push('\n');
    }
    if !spec.example.is_empty() {
        let _ = writeln!(s, "Example:\n  [nodes.example]\n  type = \"{}\"", spec.name);
        for l in spec.example.trim().lines() {
            let _ = writeln!(s, "  {l}");
        }
    }
    s
}
