//! Parameter and port checks for one node.

use super::{ResolvedPort, Sink};
use crate::graph::{NodeDecl, Var};
use crate::params::{Params, Value};
use crate::rate::Ratio;
use crate::spec::{NodeSpec, ParamDefault, ParamKind, PortSpec};
use crate::suggest;
use std::collections::BTreeMap;

/// Checks a node's parameters against its declaration; `None` if any is wrong.
pub(super) fn check_params(decl: &NodeDecl, spec: &NodeSpec, vars: &[Var], sink: &mut Sink) -> Option<Params> {
    let before = sink.diags.len();
    let mut values = BTreeMap::new();
    for (i, p) in decl.params.iter().enumerate() {
        if decl.params[..i].iter().any(|q| q.name == p.name) {
            sink.err(p.loc, Some(&decl.name), format!("parameter `{}` is set twice", p.name), None);
            continue;
        }
        let Some(ps) = spec.param(&p.name) else {
            let help = suggest::help(&p.name, spec.params.iter().map(|q| q.name));
            sink.err(
                p.loc,
                Some(&decl.name),
                format!("node type `{}` has no parameter `{}`", spec.name, p.name),
                Some(help),
            );
            continue;
        };
        let value = match p.value.var_ref() {
            Some(var) => match vars.iter().find(|v| v.name == var) {
                Some(v) => v.value.clone(),
                None => {
                    let help = suggest::help(var, vars.iter().map(|v| v.name.as_str()));
                    sink.err(
                        p.loc,
                        Some(&decl.name),
                        format!("`{}` refers to undeclared variable `${var}`", p.name),
                        Some(help),
                    );
                    continue;
                }
            },
            None => p.value.clone(),
        };
        let value = match super::interpolate::interpolate_value(&value, vars) {
            Ok(v) => v,
            Err(super::interpolate::InterpolateError::Unknown(var)) => {
                let help = suggest::help(&var, vars.iter().map(|v| v.name.as_str()));
                sink.err(
                    p.loc,
                    Some(&decl.name),
                    format!("`{}` refers to undeclared variable `${{{var}}}`", p.name),
                    Some(help),
                );
                continue;
            }
            Err(super::interpolate::InterpolateError::Unclosed) => {
                sink.err(
                    p.loc,
                    Some(&decl.name),
                    format!("`{}`: `${{` without its closing `}}`", p.name),
                    Some("write `${name}` to insert the graph variable `name`".into()),
                );
                continue;
            }
        };
        match conform(&value, &ps.kind) {
            Ok(v) => {
                values.insert(p.name.clone(), v);
            }
            Err(msg) => {
                let unit = if ps.unit.is_empty() || ps.unit == "1" { String::new() } else { format!(" {}", ps.unit) };
                let limits = ps.kind.limits();
                let help = if limits.is_empty() {
                    ps.doc.to_string()
                } else {
                    format!("{}: {}{unit}", ps.doc, limits.replace("\\|", "|"))
                };
                sink.err(p.loc, Some(&decl.name), format!("parameter `{}`: {msg}", p.name), Some(help));
            }
        }
    }
    for ps in spec.params {
        if values.contains_key(ps.name) || decl.params.iter().any(|p| p.name == ps.name) {
            continue;
        }
        let v = match ps.default {
            ParamDefault::Required => {
                sink.err(
                    decl.loc,
                    Some(&decl.name),
                    format!("missing required parameter `{}` ({})", ps.name, ps.doc),
                    None,
                );
                continue;
            }
            ParamDefault::Float(x) => Value::Float(x),
            ParamDefault::Int(i) => Value::Int(i),
            ParamDefault::Bool(b) => Value::Bool(b),
            ParamDefault::Text(t) => Value::Text(t.to_string()),
            ParamDefault::EmptyList => match ps.kind {
                ParamKind::FloatList { .. } => Value::FloatList(Vec::new()),
                _ => Value::TextList(Vec::new()),
            },
        };
        values.insert(ps.name.to_string(), v);
    }
    (sink.diags.len() == before).then(|| Params::from_map(values))
}

/// Converts a written value to the declared kind, or says why it cannot.
pub(crate) fn conform(v: &Value, kind: &ParamKind) -> Result<Value, String> {
    let shown = v.to_string();
    match (kind, v) {
        (ParamKind::Float { min, max }, Value::Float(_) | Value::Int(_)) => {
            let x = v.as_f64().unwrap_or(f64::NAN);
            if x.is_nan() {
                Err("NaN is not a value".into())
            } else if x < *min || x > *max {
                Err(format!("{shown} is outside its limits"))
            } else {
                Ok(Value::Float(x))
            }
        }
        (ParamKind::Int { min, max }, Value::Int(i)) => {
            if i < min || i > max {
                Err(format!("{i} is outside its limits"))
            } else {
                Ok(Value::Int(*i))
            }
        }
        (ParamKind::Int { .. }, Value::Float(x)) => {
            Err(format!("expected an integer, found {}", crate::params::toml_float(*x)))
        }
        (ParamKind::Bool, Value::Bool(b)) => Ok(Value::Bool(*b)),
        (ParamKind::Text, Value::Text(s)) => Ok(Value::Text(s.clone())),
        (ParamKind::Choice(words), Value::Text(s)) => {
            if words.contains(&s.as_str()) {
                Ok(Value::Text(s.clone()))
            } else {
                let hint = suggest::closest(s, words.iter().copied())
                    .map(|c| format!(" (did you mean `{c}`?)"))
                    .unwrap_or_default();
                Err(format!("`{s}` is not one of {}{hint}", words.join(", ")))
            }
        }
        (ParamKind::TextList, Value::TextList(l)) => Ok(Value::TextList(l.clone())),
        (ParamKind::TextList, Value::FloatList(l)) if l.is_empty() => Ok(Value::TextList(Vec::new())),
        (ParamKind::FloatList { min, max }, Value::FloatList(l)) => {
            match l.iter().find(|x| x.is_nan() || **x < *min || **x > *max) {
                Some(x) => Err(format!("element {} is outside its limits", crate::params::toml_float(*x))),
                None => Ok(Value::FloatList(l.clone())),
            }
        }
        (ParamKind::FloatList { .. }, Value::TextList(l)) if l.is_empty() => Ok(Value::FloatList(Vec::new())),
        (k, _) => Err(format!("expected {}, found {shown}", k.type_name())),
    }
}

/// Expands `multi` ports; rates are resolved later by the topology pass.
pub(super) fn resolve_ports(decl: &NodeDecl, spec: &NodeSpec, params: &Params, sink: &mut Sink) -> Vec<ResolvedPort> {
    let mut ports = Vec::new();
    let push = |ports: &mut Vec<ResolvedPort>, name: &str, ps: &PortSpec, sink: &mut Sink| {
        if ports.iter().any(|p: &ResolvedPort| p.name == name && p.dir == ps.dir) {
            sink.err(
                decl.loc,
                Some(&decl.name),
                format!("two ports named `{name}`"),
                Some("port names from a list parameter must be unique".into()),
            );
        }
        ports.push(ResolvedPort {
            name: name.to_string(),
            dir: ps.dir,
            unit: ps.unit,
            rate: ps.rate,
            ratio: Ratio::ONE,
        });
    };
    for ps in spec.ports {
        match ps.multi {
            Some(list) => {
                for name in params.text_list(list) {
                    if !crate::graph::valid_port_name(name) {
                        sink.err(
                            decl.loc,
                            Some(&decl.name),
                            format!("`{list}` entry `{name}` is not a valid port name (letters, digits, `_`, `-`)"),
                            None,
                        );
                        continue;
                    }
                    push(&mut ports, name, ps, sink);
                }
            }
            None => push(&mut ports, ps.name, ps, sink),
        }
    }
    ports
}
