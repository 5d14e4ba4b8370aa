use super::SPEC;
use evflow_engine::harness::{Single, TAP};
use evflow_engine::{
    check, graph::parse_graph, BuildContext, Io, Node, NodeError, NodeSpec, ParamSpec, Params, Plan, PlanOptions,
    PortSpec, Registry, Role, Summary,
};
use std::path::Path;

/// A test source: `values`, with NaN at the indices in `nan_at` (graph
/// files cannot hold NaN).
static SEQ: NodeSpec = NodeSpec::new("test.seq", "test", Role::Source, "values with NaN (test only)", build_seq)
    .ports(&[PortSpec::output("out", "1", "values")])
    .params(&[
        ParamSpec::float_list("values", -1e300, 1e300, "1", "samples"),
        ParamSpec::float_list("nan_at", 0.0, 1e9, "1", "indices replaced by NaN"),
    ]);

struct Seq(Vec<f64>, usize);

impl Node for Seq {
    fn process(&mut self, io: &mut Io<'_>) -> Result<(), NodeError> {
        for y in io.output(0) {
            *y = self.0.get(self.1).copied().unwrap_or(0.0);
            self.1 += 1;
        }
        Ok(())
    }
    fn reset(&mut self) {
        self.1 = 0;
    }
    fn remaining(&self) -> Option<u64> {
        Some(self.0.len().saturating_sub(self.1) as u64)
    }
}

fn build_seq(p: &Params, _: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
    let mut v = p.float_list("values").to_vec();
    for &i in p.float_list("nan_at") {
        v[i as usize] = f64::NAN;
    }
    Ok(Box::new(Seq(v, 0)))
}

fn run(params: &str, inputs: Vec<(&str, Vec<f64>)>, rate: f64) -> Vec<f64> {
    let ticks = inputs[0].1.len() as u64;
    let out = Single {
        spec: &SPEC,
        params,
        inputs: inputs.into_iter().map(|(n, v)| (n, v, rate)).collect(),
        outputs: vec!["out"],
        base_rate: rate,
        ticks,
        block: 37,
        base_dir: Path::new("."),
    }
    .run()
    .unwrap();
    out.into_iter().next().unwrap()
}

fn noise(len: usize, scale: f64) -> Vec<f64> {
    let mut s = 0x2545_F491_4F6C_DD1Du64;
    (0..len)
        .map(|_| {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            ((s >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0) * scale
        })
        .collect()
}

#[test]
fn clamps_amplitude_and_slew_on_extreme_input() {
    let rate = 10_000.0;
    let mut x = noise(5000, 3.0);
    for (i, v) in x.iter_mut().enumerate().step_by(97) {
        *v = if i % 2 == 0 { 1e300 } else { -1e300 };
    }
    let y = run("amplitude = 0.8\nslew = 4000.0\nramp = 0.001", vec![("in", x)], rate);
    let n = (0.001f64 * rate).round() as usize;
    let step = 4000.0 / rate;
    for (i, v) in y.iter().enumerate() {
        assert!(v.is_finite() && v.abs() <= 0.8, "sample {i}: {v}");
        if i > n {
            assert!((v - y[i - 1]).abs() <= step + 1e-12, "sample {i}: slew {}", v - y[i - 1]);
        }
    }
    // The limit is reached: the clamp is active, not merely never exceeded.
    assert!(y.iter().any(|v| (v.abs() - 0.8).abs() < 1e-12));
}

#[test]
fn fades_in_linearly_at_the_start() {
    let y = run("slew = 1e9\nramp = 0.01", vec![("in", vec![0.5; 30])], 1000.0);
    for (k, v) in y.iter().take(10).enumerate() {
        assert_eq!(*v, 0.5 * (k + 1) as f64 / 10.0, "sample {k}");
    }
    assert!(y[9..].iter().all(|&v| v == 0.5));
}

#[test]
fn nan_fades_to_exactly_zero_within_the_ramp_and_latches() {
    let rate = 1000.0;
    let mut x = vec![0.7; 200];
    x[100] = f64::NAN;
    x[101] = f64::INFINITY;
    let _ = rate;
    let y = drive(&x, "slew = 1e9\nramp = 0.01");
    assert_eq!(y[99], 0.7);
    // Ten samples: 0.9·0.7 at the NaN, … , 0 at the tenth.
    for k in 0..10 {
        assert!((y[100 + k] - 0.7 * (9 - k) as f64 / 10.0).abs() < 1e-15, "sample {}: {}", 100 + k, y[100 + k]);
    }
    assert_eq!(y[109], 0.0);
    // Latched: finite input again does not reopen the gate.
    assert!(y[109..].iter().all(|&v| v == 0.0));
}

#[test]
fn fault_input_closes_the_gate() {
    let mut flag = vec![0.0; 300];
    flag[150] = 1.0;
    let y = run("slew = 1e9\nramp = 0.005\nfaults = [\"link\"]", vec![("in", vec![-0.4; 300]), ("link", flag)], 1000.0);
    assert_eq!(y[149], -0.4);
    assert!(y[150] > -0.4 && y[150] < 0.0);
    assert_eq!(y[154], 0.0);
    assert!(y[154..].iter().all(|&v| v == 0.0));
}

#[test]
fn zero_ramp_cuts_in_one_sample() {
    let mut x = vec![1.0; 20];
    x[10] = f64::NAN;
    let y = drive(&x, "slew = 1e9\nramp = 0.0");
    assert_eq!(y[0], 1.0);
    assert_eq!(y[9], 1.0);
    assert_eq!(y[10], 0.0);
}

/// A plan feed → limit → tap, driven tick by tick with live changes.
fn plan(values: &[f64], params: &str) -> (Plan, usize) {
    let vals: Vec<String> =
        values.iter().map(|v| if v.is_finite() { format!("{v:?}") } else { "0.0".into() }).collect();
    let nans: Vec<String> =
        values.iter().enumerate().filter(|(_, v)| !v.is_finite()).map(|(i, _)| format!("{i}.0")).collect();
    let doc = format!(
        "[graph]\nformat = 1\nname = \"t\"\nrate = 1000.0\nconnections = [\"f.out -> l.in\", \"l.out -> t.in\"]\n\
         [nodes.f]\ntype = \"test.seq\"\nvalues = [{}]\nnan_at = [{}]\n[nodes.l]\ntype = \"limit\"\n{params}\n[nodes.t]\ntype = \"harness.tap\"\n",
        vals.join(", "),
        nans.join(", ")
    );
    let mut reg = Registry::new();
    reg.add(&SEQ).add(&TAP).add(&SPEC);
    let g = parse_graph(Path::new("t.toml"), &doc).unwrap();
    let checked = check(&g, &reg, &[]).unwrap();
    let plan = Plan::build(&checked, &PlanOptions { max_block: 1, timing: false, ..PlanOptions::default() }).unwrap();
    let k = plan.index("l").unwrap();
    (plan, k)
}

/// Runs `plan` to the end, one tick at a time, collecting the limiter's output.
fn drive(x: &[f64], params: &str) -> Vec<f64> {
    let (mut p, k) = plan(x, params);
    (0..x.len())
        .map(|_| {
            p.tick().unwrap();
            p.output_at(k, 0)[0]
        })
        .collect()
}

#[test]
fn disable_fades_out_and_enable_rearms_after_a_latched_fault() {
    let mut x = vec![0.6; 400];
    x[250] = f64::NAN;
    let (mut p, k) = plan(&x, "slew = 1e9\nramp = 0.01");
    let mut y = Vec::new();
    for t in 0..400 {
        if t == 100 {
            p.set(k, "enable", 0.0).unwrap();
        }
        if t == 200 {
            p.set(k, "enable", 1.0).unwrap();
        }
        if t == 300 {
            // Re-arm after the NaN latched the gate at 250.
            p.set(k, "enable", 1.0).unwrap();
        }
        p.tick().unwrap();
        y.push(p.output_at(k, 0)[0]);
    }
    assert_eq!(y[99], 0.6);
    assert_eq!(y[109], 0.0);
    assert!(y[100] > 0.0);
    assert!(y[109..200].iter().all(|&v| v == 0.0));
    assert!((y[200] - 0.06).abs() < 1e-15);
    assert_eq!(y[209], 0.6);
    assert_eq!(y[259], 0.0);
    assert!(y[259..300].iter().all(|&v| v == 0.0));
    assert_eq!(y[309], 0.6);
    assert!(p.set(k, "amplitude", 2.0).is_err(), "only `enable` changes live");
    let summary = p.finish().unwrap();
    let s: &Summary = &summary.iter().find(|(n, _)| n == "l").unwrap().1;
    assert_eq!(s.lines, vec!["fault: non-finite input at sample 250; faded to zero".to_string()]);
}

#[test]
fn output_slope_stays_bounded_through_every_transition() {
    // Square wave ±1 at the slew limit's edge, with faults and re-arms:
    // the output never jumps by more than the slew step plus one gate step.
    let rate = 1000.0;
    let x: Vec<f64> = (0..600).map(|i| if (i / 7) % 2 == 0 { 1.0 } else { -1.0 }).collect();
    let (mut p, k) = plan(&x, "slew = 500.0\nramp = 0.01");
    let mut prev = 0.0;
    for t in 0..600 {
        match t {
            150 => p.set(k, "enable", 0.0).unwrap(),
            170 | 400 => p.set(k, "enable", 1.0).unwrap(),
            _ => {}
        }
        p.tick().unwrap();
        let y = p.output_at(k, 0)[0];
        assert!((y - prev).abs() <= 500.0 / rate + 1.0 / 10.0 + 1e-12, "tick {t}: {prev} -> {y}");
        prev = y;
    }
}
