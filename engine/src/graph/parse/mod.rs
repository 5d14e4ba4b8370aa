//! Reading a graph file: TOML with spans, so every error names its line.

use super::model::{Axis, Connection, Endpoint, Graph, NodeDecl, ParamDecl, Var, FORMAT_VERSION};
use crate::diag::{Diagnostic, Diagnostics, LineIndex, Loc};
use crate::params::Value;
use crate::suggest;
use std::path::Path;
use toml::de::{DeTable, DeValue};
use toml::Spanned;

impl Graph {
    /// Adds a connection written `"a.out -> b.in"`; returns an error message
    /// when the text is not of that form.
    pub fn connect(&mut self, text: &str) -> Result<&mut Self, String> {
        let (from, to) = parse_connection(text)?;
        self.connections.push(Connection { from, to, loc: Loc::default() });
        Ok(self)
    }
}

const TOP_KEYS: [&str; 5] = ["graph", "vars", "sweep", "plot", "nodes"];

mod plot;
const GRAPH_KEYS: [&str; 7] = ["format", "name", "description", "rate", "duration", "seed", "connections"];

struct Ctx<'t> {
    file: &'t Path,
    text: &'t str,
    lines: LineIndex,
    diags: Vec<Diagnostic>,
}

impl Ctx<'_> {
    fn loc(&self, span: std::ops::Range<usize>) -> Loc {
        self.lines.loc(self.text, span.start)
    }
    fn err(&mut self, loc: Loc, node: Option<&str>, message: impl Into<String>, help: Option<String>) {
        self.diags.push(Diagnostic {
            file: self.file.to_path_buf(),
            loc,
            node: node.map(str::to_string),
            message: message.into(),
            help,
        });
    }
}

/// Parses a graph file's text. `file` is used in error messages and as the
/// graph's `file`. Every problem found is returned, not only the first.
pub fn parse_graph(file: &Path, text: &str) -> Result<Graph, Diagnostics> {
    let mut cx = Ctx { file, text, lines: LineIndex::new(text), diags: Vec::new() };
    let root = match DeTable::parse(text) {
        Ok(t) => t,
        Err(e) => {
            let loc = e.span().map(|s| cx.loc(s)).unwrap_or_default();
            cx.err(loc, None, format!("not valid TOML: {}", e.message().trim()), None);
            return Err(Diagnostics(cx.diags));
        }
    };
    let mut g = Graph::new("", 0.0);
    g.file = file.to_path_buf();

    for (k, _) in root.get_ref().iter() {
        if !TOP_KEYS.contains(&k.get_ref().as_ref()) {
            let loc = cx.loc(k.span());
            let help = suggest::help(k.get_ref(), TOP_KEYS);
            cx.err(loc, None, format!("unknown table `{}`", k.get_ref()), Some(help));
        }
    }

    match root.get_ref().get("graph") {
        None => cx.err(
            Loc { line: 1, col: 1 },
            None,
            "missing `[graph]` table",
            Some("start the file with `[graph]`, `format = 1`, `name = \"…\"`, `rate = 1000`".into()),
        ),
        Some(t) => read_graph_table(&mut cx, t, &mut g),
    }
    if let Some(v) = root.get_ref().get("vars") {
        match v.get_ref() {
            DeValue::Table(t) => {
                for (k, val) in t.iter() {
                    let loc = cx.loc(k.span());
                    if let Some(value) = read_value(&mut cx, val, None, k.get_ref()) {
                        g.vars.push(Var { name: k.get_ref().to_string(), value, loc });
                    }
                }
            }
            _ => {
                let loc = cx.loc(v.span());
                cx.err(loc, None, "`vars` must be a table (`[vars]`)", None);
            }
        }
    }
    if let Some(v) = root.get_ref().get("sweep") {
        read_sweep(&mut cx, v, &mut g);
    }
    if let Some(v) = root.get_ref().get("plot") {
        plot::read_plots(&mut cx, v, &mut g);
    }
    if let Some(v) = root.get_ref().get("nodes") {
        match v.get_ref() {
            DeValue::Table(t) => {
                for (k, val) in t.iter() {
                    read_node(&mut cx, k, val, &mut g);
                }
            }
            _ => {
                let loc = cx.loc(v.span());
                cx.err(loc, None, "`nodes` must hold one table per node (`[nodes.NAME]`)", None);
            }
        }
    }
    if cx.diags.is_empty() {
        Ok(g)
    } else {
        Err(Diagnostics(cx.diags))
    }
}

fn read_graph_table(cx: &mut Ctx<'_>, t: &Spanned<DeValue<'_>>, g: &mut Graph) {
    let DeValue::Table(t) = t.get_ref() else {
        let loc = cx.loc(t.span());
        cx.err(loc, None, "`graph` must be a table (`[graph]`)", None);
        return;
    };
    g.loc = t.iter().next().map(|(k, _)| cx.loc(k.span())).unwrap_or(Loc { line: 1, col: 1 });
    for (k, v) in t.iter() {
        let key = k.get_ref().as_ref();
        let loc = cx.loc(k.span());
        match key {
            "format" => match v.get_ref() {
                DeValue::Integer(i) => match int_of(i.as_str(), i.radix()) {
                    Some(f) if f > FORMAT_VERSION => cx.err(
                        loc,
                        None,
                        format!("this graph is written in format {f}, newer than this evflow reads (up to {FORMAT_VERSION})"),
                        Some("upgrade evflow to run it".into()),
                    ),
                    Some(f) if f >= 1 => g.format = f,
                    _ => cx.err(loc, None, "`format` must be a positive integer", None),
                },
                _ => cx.err(loc, None, "`format` must be an integer (e.g. `format = 1`)", None),
            },
            "name" => match v.get_ref().as_str() {
                Some(s) => g.name = s.to_string(),
                None => cx.err(loc, None, "`name` must be text", None),
            },
            "description" => match v.get_ref().as_str() {
                Some(s) => g.description = s.to_string(),
                None => cx.err(loc, None, "`description` must be text", None),
            },
            "rate" => match number(v.get_ref()) {
                Some(r) if r.is_finite() && r > 0.0 && r <= 1e7 => g.rate = r,
                _ => cx.err(loc, None, "`rate` must be a number of Hz in (0, 1e7]", Some("the base rate is the live clock, e.g. `rate = 1000`".into())),
            },
            "duration" => match number(v.get_ref()) {
                Some(d) if d.is_finite() && d > 0.0 && d <= 1e7 => g.duration = Some(d),
                _ => cx.err(loc, None, "`duration` must be a positive number of seconds", None),
            },
            "seed" => match v.get_ref() {
                DeValue::Integer(i) => match int_of(i.as_str(), i.radix()) {
                    Some(s) if s >= 0 => g.seed = s as u64,
                    _ => cx.err(loc, None, "`seed` must be a non-negative integer", None),
                },
                _ => cx.err(loc, None, "`seed` must be an integer", None),
            },
            "connections" => match v.get_ref() {
                DeValue::Array(a) => {
                    for item in a.iter() {
                        let iloc = cx.loc(item.span());
                        match item.get_ref().as_str() {
                            Some(s) => match parse_connection(s) {
                                Ok((from, to)) => g.connections.push(Connection { from, to, loc: iloc }),
                                Err(m) => cx.err(iloc, None, m, Some("write connections as \"node.port -> node.port\"".into())),
                            },
                            None => cx.err(iloc, None, "a connection must be text like \"a.out -> b.in\"", None),
                        }
                    }
                }
                _ => cx.err(loc, None, "`connections` must be a list of \"a.out -> b.in\"", None),
            },
            other => {
                let help = suggest::help(other, GRAPH_KEYS);
                cx.err(loc, None, format!("unknown key `{other}` in [graph]"), Some(help));
            }
        }
    }
    if g.format == 0 {
        cx.err(g.loc, None, "missing `format` in [graph]", Some(format!("add `format = {FORMAT_VERSION}`")));
    }
    if g.rate == 0.0 && !t.contains_key("rate") {
        cx.err(g.loc, None, "missing `rate` in [graph]", Some("add the base rate in Hz, e.g. `rate = 1000`".into()));
    }
}

fn read_node(cx: &mut Ctx<'_>, key: &Spanned<std::borrow::Cow<'_, str>>, val: &Spanned<DeValue<'_>>, g: &mut Graph) {
    let name = key.get_ref().to_string();
    let loc = cx.loc(key.span());
    if !valid_name(&name) {
        cx.err(loc, Some(&name), "a node name may hold only letters, digits, `_` and `-`", None);
    }
    let DeValue::Table(t) = val.get_ref() else {
        cx.err(loc, Some(&name), "a node must be a table (`[nodes.NAME]` with `type = \"…\"`)", None);
        return;
    };
    let mut decl = NodeDecl { name: name.clone(), kind: String::new(), kind_loc: loc, params: Vec::new(), loc };
    for (k, v) in t.iter() {
        let kloc = cx.loc(k.span());
        if k.get_ref() == "type" {
            match v.get_ref().as_str() {
                Some("") => cx.err(
                    kloc,
                    Some(&name),
                    "`type` is empty",
                    Some("name a node type, e.g. `type = \"gain\"`; `evflow nodes` lists them".into()),
                ),
                Some(s) => {
                    decl.kind = s.to_string();
                    decl.kind_loc = kloc;
                }
                None => cx.err(
                    kloc,
                    Some(&name),
                    "`type` must be text naming a node type",
                    Some("`evflow nodes` lists them".into()),
                ),
            }
        } else if let Some(value) = read_value(cx, v, Some(&name), k.get_ref()) {
            decl.params.push(ParamDecl { name: k.get_ref().to_string(), value, loc: kloc });
        }
    }
    if decl.kind.is_empty() && !t.contains_key("type") {
        cx.err(
            loc,
            Some(&name),
            "missing `type`",
            Some("add e.g. `type = \"gain\"`; `evflow nodes` lists the types".into()),
        );
    }
    g.nodes.push(decl);
}

/// A node name: letters, digits, `_`, `-`.
pub(crate) fn valid_name(s: &str) -> bool {
    !s.is_empty() && s.chars().all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
}

/// `[sweep]`: one non-empty list of values per swept variable, or a table
/// `{ files = "PATTERN" }`.
fn read_sweep(cx: &mut Ctx<'_>, v: &Spanned<DeValue<'_>>, g: &mut Graph) {
    let DeValue::Table(t) = v.get_ref() else {
        let loc = cx.loc(v.span());
        cx.err(loc, None, "`sweep` must be a table (`[sweep]`) of lists", None);
        return;
    };
    for (k, val) in t.iter() {
        let loc = cx.loc(k.span());
        let name = k.get_ref().to_string();
        if let DeValue::Table(spec) = val.get_ref() {
            let pattern = spec.iter().find(|(k, _)| k.get_ref() == "files").map(|(_, v)| v.get_ref());
            match (pattern, spec.len()) {
                (Some(DeValue::String(p)), 1) if !p.trim().is_empty() => {
                    g.sweep.push(Axis { name, values: Vec::new(), files: Some(p.to_string()), linked: Vec::new(), loc })
                }
                _ => cx.err(
                    loc,
                    None,
                    format!("sweep `{name}`: a table here takes one key, `files`, a file pattern"),
                    Some(format!("e.g. `{name} = {{ files = \"recordings/*.json\" }}`")),
                ),
            }
            continue;
        }
        let DeValue::Array(items) = val.get_ref() else {
            cx.err(
                loc,
                None,
                format!("sweep `{name}` must be a list of values"),
                Some(format!("e.g. `{name} = [60.0, 85.0, 110.0]`")),
            );
            continue;
        };
        if items.is_empty() {
            cx.err(loc, None, format!("sweep `{name}` has no values"), None);
            continue;
        }
        let mut values = Vec::new();
        for item in items.iter() {
            if matches!(item.get_ref(), DeValue::Array(_) | DeValue::Table(_)) {
                let at = cx.loc(item.span());
                cx.err(at, None, format!("sweep `{name}`: each value must be a number, text or boolean"), None);
                continue;
            }
            if let Some(x) = read_value(cx, item, None, &name) {
                values.push(x);
            }
        }
        if values.len() == items.len() {
            g.sweep.push(Axis { name, values, files: None, linked: Vec::new(), loc });
        }
    }
}

fn read_value(cx: &mut Ctx<'_>, v: &Spanned<DeValue<'_>>, node: Option<&str>, key: &str) -> Option<Value> {
    let loc = cx.loc(v.span());
    match v.get_ref() {
        DeValue::String(s) => Some(Value::Text(s.to_string())),
        DeValue::Boolean(b) => Some(Value::Bool(*b)),
        DeValue::Integer(i) => match int_of(i.as_str(), i.radix()) {
            Some(x) => Some(Value::Int(x)),
            None => {
                cx.err(loc, node, format!("`{key}`: integer out of range"), None);
                None
            }
        },
        DeValue::Float(f) => match float_of(f.as_str()) {
            Some(x) => Some(Value::Float(x)),
            None => {
                cx.err(loc, node, format!("`{key}`: not a number"), None);
                None
            }
        },
        DeValue::Array(a) => {
            if a.iter().all(|e| e.get_ref().is_str()) {
                Some(Value::TextList(a.iter().filter_map(|e| e.get_ref().as_str().map(str::to_string)).collect()))
            } else if a.iter().all(|e| number(e.get_ref()).is_some()) {
                Some(Value::FloatList(a.iter().filter_map(|e| number(e.get_ref())).collect()))
            } else {
                cx.err(loc, node, format!("`{key}`: a list must hold only text or only numbers"), None);
                None
            }
        }
        DeValue::Datetime(_) => {
            cx.err(loc, node, format!("`{key}`: dates are not parameter values"), None);
            None
        }
        DeValue::Table(_) => {
            cx.err(
                loc,
                node,
                format!("`{key}`: a table is not a parameter value"),
                Some("parameters are numbers, text, booleans or lists".into()),
            );
            None
        }
    }
}

fn number(v: &DeValue<'_>) -> Option<f64> {
    match v {
        DeValue::Integer(i) => int_of(i.as_str(), i.radix()).map(|x| x as f64),
        DeValue::Float(f) => float_of(f.as_str()),
        _ => None,
    }
}

fn int_of(s: &str, radix: u32) -> Option<i64> {
    let clean: String = s.chars().filter(|c| *c != '_').collect();
    let body = clean.trim_start_matches(['+']);
    let body = match radix {
        16 => body.trim_start_matches("0x"),
        8 => body.trim_start_matches("0o"),
        2 => body.trim_start_matches("0b"),
        _ => body,
    };
    i64::from_str_radix(body, radix).ok()
}

fn float_of(s: &str) -> Option<f64> {
    let clean: String = s.chars().filter(|c| *c != '_').collect();
    match clean.as_str() {
        "inf" | "+inf" => Some(f64::INFINITY),
        "-inf" => Some(f64::NEG_INFINITY),
        "nan" | "+nan" | "-nan" => Some(f64::NAN),
        c => c.parse().ok(),
    }
}

/// Parses `"a.out -> b.in"`.
pub(crate) fn parse_connection(s: &str) -> Result<(Endpoint, Endpoint), String> {
    let Some((a, b)) = s.split_once("->") else {
        return Err(format!("connection `{s}` has no `->`"));
    };
    Ok((endpoint(a.trim(), s)?, endpoint(b.trim(), s)?))
}

fn endpoint(e: &str, whole: &str) -> Result<Endpoint, String> {
    match e.split_once('.') {
        Some((n, p)) if valid_name(n) && valid_name(p) => Ok(Endpoint { node: n.to_string(), port: p.to_string() }),
        _ => Err(format!("in connection `{whole}`: `{e}` is not of the form `node.port`")),
    }
}

/// Parses a value given on the command line (`--set k=v`): TOML syntax when
/// it parses as a TOML value, plain text otherwise.
pub fn parse_cli_value(s: &str) -> Value {
    let doc = format!("v = {s}");
    if let Ok(t) = DeTable::parse(&doc) {
        if let Some(v) = t.get_ref().get("v") {
            match v.get_ref() {
                DeValue::Integer(i) => {
                    if let Some(x) = int_of(i.as_str(), i.radix()) {
                        return Value::Int(x);
                    }
                }
                DeValue::Float(f) => {
                    if let Some(x) = float_of(f.as_str()) {
                        return Value::Float(x);
                    }
                }
                DeValue::Boolean(b) => return Value::Bool(*b),
                DeValue::String(s) => return Value::Text(s.to_string()),
                DeValue::Array(a) => {
                    if a.iter().all(|e| e.get_ref().is_str()) {
                        return Value::TextList(
                            a.iter().filter_map(|e| e.get_ref().as_str().map(str::to_string)).collect(),
                        );
                    }
                    if a.iter().all(|e| number(e.get_ref()).is_some()) {
                        return Value::FloatList(a.iter().filter_map(|e| number(e.get_ref())).collect());
                    }
                }
                _ => {}
            }
        }
    }
    Value::Text(s.to_string())
}
