//! Cases generated from every node type's declaration (`NodeSpec`): each
//! numeric parameter at its declared minimum and maximum (and, at full
//! size, one step inside), and every input fed each extreme signal of
//! [`Extreme`]. A node type added to the registry is covered here without
//! a line of this file.

use super::bounds::{bound, capped, from_table};
use super::invariant::{Invariant, Observed};
use super::signals::Extreme;
use super::{single, Case, Env, Group, Size, Work};
use evflow_engine::spec::ParamKind;
use evflow_engine::{Direction, NodeSpec};
use evflow_nodes::example_files::signal;
use toml::{Table, Value};

/// Samples per block of a node case.
const BLOCK: usize = 256;

/// The largest |sample| of [`signal`] (a chirp of amplitude 0.5 plus
/// noise within ±0.15), the input of the parameter cases.
const INPUT_MAX: f64 = 0.65;

/// The pseudo-port holding each variant's largest |output| over its bound.
pub const RATIO: &str = "|out|/bound";

/// The node types cases are generated for: every one of the registry
/// except hardware outputs, which cannot run alone (the loader wants a
/// `limit` in front of them); [`super::graphs`] runs those behind one.
pub fn specs() -> Vec<&'static NodeSpec> {
    evflow_nodes::all_specs().into_iter().filter(|s| !s.hardware).collect()
}

/// The example's node table, parsed; a `cache` folder parameter is set
/// to "none", so that the suite writes nothing outside its own folder.
pub fn example(spec: &NodeSpec) -> Table {
    let mut t: Table = spec.example.parse().unwrap_or_default();
    if spec.param("cache").is_some_and(|p| p.kind == ParamKind::Text) {
        t.insert("cache".into(), Value::String("none".into()));
    }
    t
}

/// The values a parameter is tried at: its limits, and at full size one
/// step inside each (±1 for integers; 0.1 % of the range, or 1e300 for an
/// infinite limit, for numbers).
pub fn limit_values(kind: &ParamKind, size: Size) -> Vec<Value> {
    match *kind {
        ParamKind::Int { min, max } => {
            let mut v = vec![min, max];
            if size.steps_inside() && max - min >= 2 {
                v.extend([min + 1, max - 1]);
            }
            v.into_iter().map(Value::Integer).collect()
        }
        ParamKind::Float { min, max } => {
            let mut v = vec![min, max];
            if size.steps_inside() {
                let step = if (max - min).is_finite() { (max - min) * 1e-3 } else { 0.0 };
                v.push(if min.is_finite() { min + step } else { -1e300 });
                v.push(if max.is_finite() { max - step } else { 1e300 });
            }
            v.into_iter().map(Value::Float).collect()
        }
        _ => Vec::new(),
    }
}

fn as_f64(v: &Value) -> f64 {
    match v {
        Value::Float(x) => *x,
        Value::Integer(i) => *i as f64,
        _ => f64::NAN,
    }
}

/// Watches variant `o`'s largest |output| over the bound of `spec` for its
/// parameters `p` and inputs up to `input_max`, as the pseudo-port [`RATIO`].
fn watch_ratio(o: &mut Observed, spec: &NodeSpec, p: &Table, input_max: f64) {
    if o.error.is_some() {
        return;
    }
    if let Some((port, b, _)) = bound(spec, &from_table(p), input_max) {
        let seen = o.ports.iter().find(|(n, _)| n == port).map(|(_, m)| *m).unwrap_or(0.0);
        let ratio = if seen <= b {
            if b > 0.0 {
                seen / b
            } else {
                0.0
            }
        } else if b > 0.0 {
            (seen / b).min(f64::MAX)
        } else {
            f64::MAX
        };
        o.watch(RATIO, &[ratio]);
    }
}

fn has_inputs(spec: &NodeSpec) -> bool {
    spec.ports.iter().any(|p| p.dir == Direction::In)
}

/// The parameter-limit case of one node type.
fn parameter_case(spec: &'static NodeSpec, size: Size) -> Case {
    let base = example(spec);
    let numeric: Vec<_> = spec
        .params
        .iter()
        .filter(|p| matches!(p.kind, ParamKind::Float { .. } | ParamKind::Int { .. }))
        .copied()
        .collect();
    let names: Vec<&str> = numeric.iter().map(|p| p.name).collect();
    let extreme = if names.is_empty() {
        "no numeric parameter: the example as declared".to_string()
    } else {
        format!(
            "each of {} at its declared min and max{}",
            names.join(", "),
            if size.steps_inside() { " and one step inside" } else { "" }
        )
    };
    let bounded = bound(spec, &from_table(&base), 1.0).is_some();
    let invariant = if bounded {
        Invariant::Bound { bound: 1.0, port: Some(RATIO.into()), why: "every variant within its own bound".into() }
    } else {
        Invariant::Finite { refusal_ok: false }
    };
    let ticks = size.ticks();
    let body = move |env: &Env| {
        let input = |k: usize| signal(ticks as usize, 31 * k as u64 + 1);
        let text = toml::to_string(&base).unwrap_or_default();
        // The example must run as declared; its error fails the case.
        let mut o = single::run(spec, &text, &input, ticks, BLOCK, &env.dir);
        watch_ratio(&mut o, spec, &base, INPUT_MAX);
        let (mut tried, mut refused) = (0, 0);
        for p in &numeric {
            for value in limit_values(&p.kind, env.size) {
                let mut table = base.clone();
                let mut value = value;
                if let Some((cap, why)) = capped(spec, p.name, as_f64(&value)) {
                    o.notes.push(format!("{} capped at {cap} ({why})", p.name));
                    value =
                        if matches!(value, Value::Integer(_)) { Value::Integer(cap as i64) } else { Value::Float(cap) };
                }
                let shown = value.to_string();
                table.insert(p.name.to_string(), value);
                let text = toml::to_string(&table).unwrap_or_default();
                let t0 = std::time::Instant::now();
                let mut v = single::run(spec, &text, &input, ticks, BLOCK, &env.dir);
                if std::env::var_os("EVFLOW_STABILITY_TIMES").is_some() {
                    eprintln!("{} {} = {shown}: {:.2} s", spec.name, p.name, t0.elapsed().as_secs_f64());
                }
                tried += 1;
                watch_ratio(&mut v, spec, &table, INPUT_MAX);
                if let Some(e) = v.error.take() {
                    refused += 1;
                    v.notes.push(format!("{} = {shown} refused: {}", p.name, first_line(&e)));
                }
                o.merge(v);
            }
        }
        o.notes.insert(0, format!("{tried} variants, {refused} refused"));
        o
    };
    Case {
        name: format!("{} · parameters at limits", spec.name),
        group: Group::Generated,
        covers: vec![spec.name],
        family: None,
        extreme,
        invariant,
        work: Work::Whole(Box::new(body)),
    }
}

/// The first line of an error, without the harness' file prefix.
pub fn first_line(e: &str) -> String {
    let line = e.lines().next().unwrap_or("");
    line.split_once("(dut): ").or_else(|| line.split_once("`dut`: ")).map(|(_, r)| r).unwrap_or(line).to_string()
}

/// The extreme-input case of one node type.
fn input_case(spec: &'static NodeSpec, e: Extreme, size: Size) -> Case {
    let base = example(spec);
    let len = match e {
        Extreme::LongConstant => size.long_run(),
        _ => size.ticks(),
    } as usize;
    let sample = e.samples(len, 0);
    let input_max = sample.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let sourced = !has_inputs(spec);
    let (invariant, extreme) = match bound(spec, &from_table(&base), if sourced { 0.0 } else { input_max }) {
        Some((port, b, why)) => (
            Invariant::Bound { bound: b, port: Some(port.into()), why },
            if sourced { format!("a long run of {len} samples") } else { e.describe(len) },
        ),
        None if sourced => (Invariant::Finite { refusal_ok: false }, format!("a long run of {len} samples")),
        // A node may refuse an input it cannot take (an error naming it),
        // never let NaN or Inf out.
        None => (Invariant::Finite { refusal_ok: true }, e.describe(len)),
    };
    let body = move |env: &Env| {
        let text = toml::to_string(&base).unwrap_or_default();
        let mut o = single::run(spec, &text, &|k| e.samples(len, k), len as u64, BLOCK, &env.dir);
        if let Some(err) = o.error.take() {
            o.error = Some(first_line(&err));
        }
        o
    };
    Case {
        name: format!("{} · {}", spec.name, if sourced { "long run" } else { e.name() }),
        group: Group::Generated,
        covers: vec![spec.name],
        family: None,
        extreme,
        invariant,
        work: Work::Whole(Box::new(body)),
    }
}

/// Every generated case at `env.size`.
pub fn cases(env: &Env) -> Vec<Case> {
    let mut v = Vec::new();
    for spec in specs() {
        v.push(parameter_case(spec, env.size));
        if has_inputs(spec) {
            for e in Extreme::ALL {
                v.push(input_case(spec, e, env.size));
            }
        } else {
            v.push(input_case(spec, Extreme::LongConstant, env.size));
        }
    }
    v
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn limit_values_reach_both_ends_and_step_inside_at_full_size() {
        let k = ParamKind::Int { min: 1, max: 8 };
        assert_eq!(limit_values(&k, Size::Ci), vec![Value::Integer(1), Value::Integer(8)]);
        assert_eq!(limit_values(&k, Size::Full).len(), 4);
        let f = ParamKind::Float { min: 0.001, max: f64::INFINITY };
        let v = limit_values(&f, Size::Full);
        assert_eq!(v[1], Value::Float(f64::INFINITY));
        assert_eq!(v[3], Value::Float(1e300));
        assert!(limit_values(&ParamKind::Bool, Size::Full).is_empty());
    }

    #[test]
    fn a_row_names_the_fixtures_folder_not_the_temporary_path() {
        // recording.in at its rate limits is refused naming the recording's path.
        let dir = tempfile::tempdir().unwrap();
        let env = super::super::prepare(dir.path(), dir.path(), Size::Ci).unwrap();
        let spec = *evflow_nodes::registry().get("recording.in").unwrap();
        let row = super::super::run_case(&parameter_case(leak(spec), Size::Ci), &env);
        assert!(row.detail.contains("<fixtures>/recordings/"), "{}", row.detail);
        assert!(!row.detail.contains(&dir.path().display().to_string()), "{}", row.detail);
    }

    /// A node type as the registry holds it, changed and kept for the test's run.
    fn leak(spec: NodeSpec) -> &'static NodeSpec {
        Box::leak(Box::new(spec))
    }

    #[test]
    fn the_bound_a_node_type_declares_is_the_one_its_cases_check() {
        let dir = tempfile::tempdir().unwrap();
        let env = super::super::prepare(dir.path(), dir.path(), Size::Ci).unwrap();
        let gain = *evflow_nodes::registry().get("gain").unwrap();
        let row = super::super::run_case(&input_case(leak(gain), Extreme::ALL[0], Size::Ci), &env);
        assert!(
            row.invariant.contains("|gain|·max|in|") && row.verdict.passed(),
            "{}: {}",
            row.invariant,
            row.verdict.text()
        );
        // The same node declaring a bound it cannot keep: its case fails.
        fn tight(_: &evflow_engine::spec::BoundArgs<'_>) -> Option<evflow_engine::spec::PortBound> {
            Some(("out", 1e-3, "too tight".into()))
        }
        let tight = leak(NodeSpec { bound: Some(tight), ..gain });
        let row = super::super::run_case(&input_case(tight, Extreme::ALL[0], Size::Ci), &env);
        assert!(row.invariant.contains("too tight") && !row.verdict.passed(), "{}", row.verdict.text());
        let row = super::super::run_case(&parameter_case(tight, Size::Ci), &env);
        assert!(!row.verdict.passed(), "every variant within its own bound: {}", row.verdict.text());
    }

    #[test]
    fn every_runnable_node_type_gets_cases() {
        let names: Vec<&str> = specs().iter().map(|s| s.name).collect();
        assert!(names.contains(&"butterworth") && !names.contains(&"serial.out"));
    }
}
