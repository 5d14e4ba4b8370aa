//! Sweeps: one graph run for every combination of chosen variable values.
//!
//! A graph's `[sweep]` table lists values for some of its `[vars]`
//! (`mass = [60.0, 110.0]`, `speed = [3.0, 5.0]`); `evflow run` then runs the
//! graph once per combination (here four), the first axis varying slowest.
//! The command line adds or replaces axes (`--sweep speed=3,4,5`), and a
//! variable fixed with `--set` is not swept. Combined with `${var}` in text
//! parameters each run names its own outputs.

use crate::check::{check, Checked, Override};
use crate::diag::Diagnostics;
use crate::graph::{parse_cli_value, Axis, Graph};
use crate::params::Value;
use crate::registry::Registry;
use std::ops::Range;

/// One run of a sweep: the variable values it sets, in axis order.
#[derive(Debug, Clone, PartialEq)]
pub struct Point {
    /// `(variable, value)` pairs.
    pub values: Vec<(String, Value)>,
}

impl Point {
    /// `mass=60 speed=3`, or `(defaults)` for the single run of no sweep.
    pub fn label(&self) -> String {
        if self.values.is_empty() {
            return "(defaults)".into();
        }
        self.values
            .iter()
            .map(|(k, v)| format!("{k}={}", crate::check::interpolate::text_of(v)))
            .collect::<Vec<_>>()
            .join(" ")
    }

    /// The overrides that select this point.
    pub fn overrides(&self) -> Vec<Override> {
        self.values.iter().map(|(k, v)| Override { key: k.clone(), value: v.clone() }).collect()
    }
}

/// Parses a command-line axis `name=a,b,c` or `name=[a, b, c]` (values in
/// TOML syntax; bare words are text).
pub fn parse_axis(s: &str) -> Result<Axis, String> {
    let (k, v) = s.split_once('=').ok_or_else(|| format!("`{s}`: expected `name=v1,v2,…`"))?;
    let name = k.trim();
    if name.is_empty() || name.contains('.') {
        return Err(format!("`{s}`: sweep a graph variable by name (node parameters cannot be swept)"));
    }
    let v = v.trim();
    let values: Vec<Value> = if v.starts_with('[') {
        match parse_cli_value(v) {
            Value::FloatList(l) => l.into_iter().map(Value::Float).collect(),
            Value::TextList(l) => l.into_iter().map(Value::Text).collect(),
            _ => return Err(format!("`{s}`: not a list")),
        }
    } else {
        v.split(',').map(str::trim).filter(|x| !x.is_empty()).map(parse_cli_value).collect()
    };
    if values.is_empty() {
        return Err(format!("`{s}`: no values to sweep"));
    }
    Ok(Axis { name: name.to_string(), values, files: None, linked: Vec::new(), loc: Default::default() })
}

/// The runs of a sweep over `graph_axes` with `extra` axes from the command
/// line (replacing graph axes of the same name, else added after them);
/// axes of a variable fixed by `pinned` (`--set`) are dropped. No axes give
/// one point with no values. A files axis must have been expanded
/// ([`crate::sweep_files::expand`]); each of its points also sets the
/// variables linked to its value (after the axis' own, so they win over a
/// `--set` of the same name: the file's metadata describes the file).
pub fn points(graph_axes: &[Axis], extra: &[Axis], pinned: &[Override]) -> Vec<Point> {
    let mut out = vec![Point { values: Vec::new() }];
    for a in effective_axes(graph_axes, extra, pinned) {
        out = out
            .into_iter()
            .flat_map(|p| {
                a.values.iter().enumerate().map(move |(i, v)| {
                    let mut q = p.clone();
                    q.values.push((a.name.clone(), v.clone()));
                    if let Some(linked) = a.linked.get(i) {
                        q.values.extend(linked.iter().cloned());
                    }
                    q
                })
            })
            .collect();
    }
    out
}

/// The axes [`points`] runs over, in order: `graph_axes` (each replaced
/// by an `extra` axis of its name), then the other `extra` axes, less the
/// axes of variables `pinned` fixes.
pub fn effective_axes<'a>(graph_axes: &'a [Axis], extra: &'a [Axis], pinned: &[Override]) -> Vec<&'a Axis> {
    let mut axes: Vec<&Axis> = Vec::new();
    for a in graph_axes {
        axes.push(extra.iter().find(|e| e.name == a.name).unwrap_or(a));
    }
    for e in extra {
        if !graph_axes.iter().any(|a| a.name == e.name) && !axes.iter().any(|a| a.name == e.name) {
            axes.push(e);
        }
    }
    axes.retain(|a| !pinned.iter().any(|o| o.key == a.name));
    axes
}

/// The most runs a sweep may have: each is validated, and its point and
/// checked graph kept, before the first runs.
pub const MAX_RUNS: usize = 100_000;

/// The number of runs of [`points`] over these axes, refused (with the
/// axes' sizes) past [`MAX_RUNS`] before any point is made: a few long
/// `--sweep` lists multiply into more runs than memory holds.
pub fn count(graph_axes: &[Axis], extra: &[Axis], pinned: &[Override]) -> Result<usize, String> {
    let axes = effective_axes(graph_axes, extra, pinned);
    let total = axes.iter().try_fold(1usize, |n, a| n.checked_mul(a.values.len()).filter(|&n| n <= MAX_RUNS));
    total.ok_or_else(|| {
        let sizes: Vec<String> = axes.iter().map(|a| format!("{} ({})", a.name, a.values.len())).collect();
        format!("the sweep {} has more than {MAX_RUNS} runs; split it (e.g. with --set or --shard)", sizes.join(" × "))
    })
}

/// Refuses a command-line axis (`--sweep NAME=…`) that names no variable
/// of `graph`, with the nearest names.
pub fn check_axes(graph: &Graph, axes: &[Axis]) -> Result<(), String> {
    for ax in axes {
        if !graph.vars.iter().any(|v| v.name == ax.name) {
            let help = crate::suggest::help(&ax.name, graph.vars.iter().map(|v| v.name.as_str()));
            return Err(format!("--sweep {}: the graph has no variable `{}`; {help}", ax.name, ax.name));
        }
    }
    Ok(())
}

/// One run of a sweep, validated as `evflow run` runs it.
#[derive(Debug)]
pub struct Validated {
    /// Its place in the whole sweep (from 0).
    pub index: usize,
    /// The variable values it sets.
    pub point: Point,
    /// The graph with `pinned` and the point applied, or why it does not
    /// validate.
    pub checked: Result<Checked, Diagnostics>,
}

/// Validates the runs `range` of `all` (from [`points`]): `graph` with
/// `pinned` (`--set`) and then each point's values applied. The graph's
/// `[vars]` defaults are not validated on their own where the sweep sets
/// them: `evflow check` and `evflow run` both see only the runs.
pub fn validate(
    graph: &Graph,
    registry: &Registry,
    pinned: &[Override],
    all: Vec<Point>,
    range: Range<usize>,
) -> Vec<Validated> {
    all.into_iter()
        .enumerate()
        .skip(range.start)
        .take(range.len())
        .map(|(index, point)| {
            let mut o = pinned.to_vec();
            o.extend(point.overrides());
            Validated { index, checked: check(graph, registry, &o), point }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn axis(s: &str) -> Axis {
        parse_axis(s).unwrap()
    }

    #[test]
    fn a_sweep_past_max_runs_is_refused_before_its_points_are_made() {
        let big =
            |name: &str| axis(&format!("{name}={}", (0..1000).map(|k| k.to_string()).collect::<Vec<_>>().join(",")));
        assert_eq!(
            count(&[big("a"), big("b")], &[], &[]),
            Err(format!(
                "the sweep a (1000) × b (1000) has more than {MAX_RUNS} runs; split it (e.g. with --set or --shard)"
            ))
        );
        let many: Vec<Axis> = (0..20).map(|k| big(&format!("v{k}"))).collect();
        assert!(count(&many, &[], &[]).is_err(), "1000^20 overflows and is refused, not wrapped");
        assert_eq!(count(&[big("a"), axis("b=1,2")], &[], &[]), Ok(2000));
        assert_eq!(count(&[], &[], &[]), Ok(1));
    }

    #[test]
    fn combinations_vary_the_last_axis_fastest() {
        let p = points(&[axis("mass=60,110"), axis("speed=3,5")], &[], &[]);
        let labels: Vec<String> = p.iter().map(Point::label).collect();
        assert_eq!(labels, ["mass=60 speed=3", "mass=60 speed=5", "mass=110 speed=3", "mass=110 speed=5"]);
    }

    #[test]
    fn command_line_axes_replace_or_extend_and_set_pins() {
        let graph = [axis("mass=60,110"), axis("speed=3,5")];
        let p = points(&graph, &[axis("speed=[4.0]"), axis("rep=1,2")], &[]);
        let labels: Vec<String> = p.iter().map(Point::label).collect();
        assert_eq!(
            labels,
            ["mass=60 speed=4 rep=1", "mass=60 speed=4 rep=2", "mass=110 speed=4 rep=1", "mass=110 speed=4 rep=2"]
        );
        let pinned = [Override::parse("mass=85").unwrap()];
        assert_eq!(points(&graph, &[], &pinned).len(), 2);
        assert_eq!(points(&[], &[], &[]), vec![Point { values: vec![] }]);
    }

    #[test]
    fn axes_parse_numbers_and_words() {
        assert_eq!(
            axis("material=felt, canvas").values,
            vec![Value::Text("felt".into()), Value::Text("canvas".into())]
        );
        assert_eq!(axis("m=[1, 2.5]").values, vec![Value::Float(1.0), Value::Float(2.5)]);
        assert!(parse_axis("node.param=1,2").is_err());
        assert!(parse_axis("m=").is_err());
        assert!(parse_axis("m").is_err());
    }
}
