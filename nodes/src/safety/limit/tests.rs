use super::{State, SPEC, STATE_ARMED, STATE_CLAMPING, STATE_FADED, STATE_FADING, STATE_FAULTED};
use evflow_engine::harness::{Single, TAP};
use evflow_engine::ports::OutPort;
use evflow_engine::typed_params::Floats;
use evflow_engine::{
    check, graph::parse_graph, BuildContext, Io, Node, NodeError, NodeSpec, Params, Plan, PlanOptions, PortSpec,
    Registry, Role, Summary,
};
use std::path::Path;

/// A test source: `values`, with NaN at the indices in `nan_at` (graph
/// files cannot hold NaN).
static SEQ: NodeSpec = NodeSpec::new("test.seq", "test", Role::Source, "values with NaN (test only)", build_seq)
    .ports(SEQ_PORTS)
    .params(&[VALUES.spec(), NAN_AT.spec()]);

/// The test source's port.
const SEQ_PORTS: &[PortSpec] = &[PortSpec::output("out", "1", "values")];
/// `out` of the test source.
const SEQ_OUT: OutPort = OutPort::named(SEQ_PORTS, "out");
/// `values`: the samples.
const VALUES: Floats = Floats::new("values", -1e300, 1e300, "1", "samples");
/// `nan_at`: where NaN replaces a sample.
const NAN_AT: Floats = Floats::new("nan_at", 0.0, 1e9, "1", "indices replaced by NaN");

struct Seq(Vec<f64>, usize);

impl Node for Seq {
    fn process(&mut self, io: &mut Io<'_>) -> Result<(), NodeError> {
        for y in io.output(SEQ_OUT) {
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
    let mut v = VALUES.get(p).to_vec();
    for &i in NAN_AT.get(p) {
        v[i as usize] = f64::NAN;
    }
    Ok(Box::new(Seq(v, 0)))
}

fn run(params: &str, inputs: Vec<(&str, Vec<f64>)>, rate: f64) -> Vec<f64> {
    run_both(params, inputs, rate, 37).0
}

/// `out` and `state`, processed in blocks of `block` samples.
fn run_both(params: &str, inputs: Vec<(&str, Vec<f64>)>, rate: f64, block: usize) -> (Vec<f64>, Vec<f64>) {
    let ticks = inputs[0].1.len() as u64;
    let out = Single::new(&SPEC, params)
        .inputs(inputs.into_iter().map(|(n, v)| (n, v, rate)))
        .outputs(["out", "state"])
        .base_rate(rate)
        .ticks(ticks)
        .block(block)
        .run()
        .unwrap();
    let mut it = out.into_iter();
    (it.next().unwrap(), it.next().unwrap())
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

/// The states of `codes`, panicking on a value that is no state code.
fn states(codes: &[f64]) -> Vec<State> {
    codes.iter().map(|&c| State::from_code(c).unwrap_or_else(|| panic!("{c} is not a state code"))).collect()
}

#[test]
fn state_codes_are_distinct_and_round_trip() {
    let codes = [STATE_ARMED, STATE_CLAMPING, STATE_FADING, STATE_FADED, STATE_FAULTED];
    for (s, c) in State::ALL.into_iter().zip(codes) {
        assert_eq!(s.code(), c);
        assert_eq!(State::from_code(c), Some(s));
    }
    let names: Vec<&str> = State::ALL.iter().map(|s| s.name()).collect();
    assert_eq!(names, ["armed", "clamping", "fading", "faded", "faulted"]);
    for x in [f64::NAN, -1.0, 0.5, 5.0, f64::INFINITY] {
        assert_eq!(State::from_code(x), None, "{x}");
    }
}

#[test]
fn state_reports_clamping_at_exactly_the_clamped_samples() {
    // ramp 0: the gate is open from the first sample.
    let x = vec![0.2, 0.7, 0.3, -0.9, 0.1, -0.5, 0.5];
    let (y, st) = run_both("amplitude = 0.5\nslew = 1e9\nramp = 0.0", vec![("in", x)], 1000.0, 3);
    use State::*;
    assert_eq!(states(&st), [Armed, Clamping, Armed, Clamping, Armed, Armed, Armed]);
    assert_eq!(y, [0.2, 0.5, 0.3, -0.5, 0.1, -0.5, 0.5]);
}

#[test]
fn state_reports_clamping_while_the_slew_limit_acts() {
    // 250 /s at 1 kHz: steps of 0.25 (exact in binary).
    let mut x = vec![0.0; 10];
    x[2..].fill(1.0);
    let (y, st) = run_both("slew = 250.0\nramp = 0.0", vec![("in", x)], 1000.0, 4);
    use State::*;
    assert_eq!(y, [0.0, 0.0, 0.25, 0.5, 0.75, 1.0, 1.0, 1.0, 1.0, 1.0]);
    assert_eq!(states(&st), [Armed, Armed, Clamping, Clamping, Clamping, Armed, Armed, Armed, Armed, Armed]);
}

/// Drives `plan` tick by tick, applying `enable` at the given ticks;
/// returns `out` and `state`.
fn drive_states(x: &[f64], params: &str, enables: &[(usize, bool)]) -> (Vec<f64>, Vec<State>) {
    let (mut p, k) = plan(x, params);
    let mut y = Vec::new();
    let mut st = Vec::new();
    for t in 0..x.len() {
        for &(_, on) in enables.iter().filter(|(at, _)| *at == t) {
            p.set(k, "enable", if on { 1.0 } else { 0.0 }).unwrap();
        }
        p.tick().unwrap();
        y.push(p.output_at(k, 0)[0]);
        st.push(State::from_code(p.output_at(k, 1)[0]).expect("a state code"));
    }
    (y, st)
}

#[test]
fn disable_reports_fading_then_faded_and_rearm_reports_armed_during_the_fade_in() {
    let x = vec![0.6; 300];
    // ramp·rate = 10 samples.
    let (y, st) = drive_states(&x, "slew = 1e9\nramp = 0.01", &[(100, false), (200, true)]);
    // Fading in at the start counts as armed.
    assert!(y[0] > 0.0 && y[0] < 0.6);
    assert!(st[..100].iter().all(|&s| s == State::Armed), "{:?}", &st[..100]);
    // The fade: 9 samples with the output not yet zero, then faded at the
    // tenth (round(ramp·rate)-th), the first exactly zero.
    assert!(st[100..109].iter().all(|&s| s == State::Fading), "{:?}", &st[100..110]);
    assert!(y[100..109].iter().all(|&v| v > 0.0));
    assert_eq!((st[109], y[109]), (State::Faded, 0.0));
    assert!(st[109..200].iter().all(|&s| s == State::Faded));
    // Enable again: armed from the first sample of the fade-in.
    assert!((y[200] - 0.06).abs() < 1e-15);
    assert!(st[200..].iter().all(|&s| s == State::Armed));
}

#[test]
fn zero_ramp_disable_is_faded_at_once() {
    let (y, st) = drive_states(&[0.3; 20], "slew = 1e9\nramp = 0.0", &[(5, false)]);
    assert_eq!((st[4], y[4]), (State::Armed, 0.3));
    assert_eq!((st[5], y[5]), (State::Faded, 0.0));
}

#[test]
fn a_graph_disabled_from_the_start_reports_faded() {
    let (y, st) = drive_states(&[0.3; 20], "enable = false", &[]);
    assert!(y.iter().all(|&v| v == 0.0));
    assert!(st.iter().all(|&s| s == State::Faded), "{st:?}");
}

#[test]
fn nan_reports_faulted_from_its_sample_until_rearmed() {
    let mut x = vec![0.6; 300];
    x[100] = f64::NAN;
    let (y, st) = drive_states(&x, "slew = 1e9\nramp = 0.01", &[(200, true)]);
    assert_eq!(st[99], State::Armed);
    // Faulted while the gate closes and once it is closed.
    assert!(y[100] > 0.0 && y[109] == 0.0);
    assert!(st[100..200].iter().all(|&s| s == State::Faulted), "{:?}", &st[95..115]);
    // Re-armed: armed from the first sample of the fade-in.
    assert!(y[200] > 0.0 && y[200] < 0.6);
    assert!(st[200..].iter().all(|&s| s == State::Armed));
}

#[test]
fn a_fault_outranks_a_disable_and_a_disable_outranks_clamping() {
    let mut x = vec![2.0; 120];
    x[60] = f64::NAN;
    let (_, st) = drive_states(&x, "slew = 1e9\nramp = 0.01", &[(30, false)]);
    assert_eq!(st[29], State::Clamping);
    assert_eq!(st[30], State::Fading, "clamping while fading");
    assert_eq!(st[39], State::Faded);
    assert!(st[60..].iter().all(|&s| s == State::Faulted), "a NaN while disabled latches");
}

#[test]
fn fault_input_reports_faulted_at_its_sample() {
    let mut flag = vec![0.0; 300];
    flag[150] = 1.0;
    let (y, st) = run_both(
        "slew = 1e9\nramp = 0.005\nfaults = [\"link\"]",
        vec![("in", vec![-0.4; 300]), ("link", flag)],
        1000.0,
        37,
    );
    let st = states(&st);
    assert_eq!(st[149], State::Armed);
    assert!(st[150..].iter().all(|&s| s == State::Faulted), "{:?}", &st[148..158]);
    assert_eq!(y[154], 0.0);
}

#[test]
fn a_nan_fault_flag_reports_faulted() {
    // Graph files cannot hold NaN: the flag comes from `test.seq`.
    let doc = "[graph]\nformat = 1\nname = \"t\"\nrate = 1000.0\n\
               connections = [\"f.out -> l.in\", \"flag.out -> l.link\", \"l.out -> t.in\"]\n\
               [nodes.f]\ntype = \"test.seq\"\nvalues = [0.5, 0.5, 0.5, 0.5, 0.5, 0.5]\n\
               [nodes.flag]\ntype = \"test.seq\"\nvalues = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0]\nnan_at = [3.0]\n\
               [nodes.l]\ntype = \"limit\"\nramp = 0.0\nfaults = [\"link\"]\n[nodes.t]\ntype = \"harness.tap\"\n";
    let mut reg = Registry::new();
    reg.add(&SEQ).add(&TAP).add(&SPEC);
    let g = parse_graph(Path::new("t.toml"), doc).unwrap();
    let checked = check(&g, &reg, &[]).unwrap();
    let mut p = Plan::build(&checked, &PlanOptions { max_block: 1, timing: false, ..PlanOptions::default() }).unwrap();
    let k = p.index("l").unwrap();
    let st: Vec<State> = (0..6)
        .map(|_| {
            p.tick().unwrap();
            State::from_code(p.output_at(k, 1)[0]).unwrap()
        })
        .collect();
    use State::*;
    assert_eq!(st, [Armed, Armed, Armed, Faulted, Faulted, Faulted]);
}

#[test]
fn state_in_blocks_matches_state_per_sample() {
    let rate = 2000.0;
    // (The harness's feed cannot carry NaN; the fault input latches here.)
    let mut x = noise(3000, 2.5);
    for i in [700, 701, 2222] {
        x[i] = 1e300;
    }
    let mut flag = vec![0.0; 3000];
    flag[1500] = 1.0;
    let params = "amplitude = 0.9\nslew = 3000.0\nramp = 0.004\nfaults = [\"trip\"]";
    let one = run_both(params, vec![("in", x.clone()), ("trip", flag.clone())], rate, 1);
    let s = states(&one.1);
    // Every state but fading/faded (no disable here) shows up.
    for want in [State::Armed, State::Clamping, State::Faulted] {
        assert!(s.contains(&want), "{want:?} never reported");
    }
    for block in [7, 64, 1000] {
        let b = run_both(params, vec![("in", x.clone()), ("trip", flag.clone())], rate, block);
        assert_eq!(
            b.0.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
            one.0.iter().map(|v| v.to_bits()).collect::<Vec<_>>()
        );
        assert_eq!(b.1, one.1, "block {block}");
    }
}

#[test]
fn only_out_may_feed_hardware_not_state() {
    static DAC: NodeSpec = NodeSpec::new("test.dac", "test", Role::Sink, "hardware (test only)", build_dac)
        .ports(&[PortSpec::input("u", "1", "actuation")])
        .hardware();
    struct Dac;
    impl Node for Dac {
        fn process(&mut self, _: &mut Io<'_>) -> Result<(), NodeError> {
            Ok(())
        }
        fn reset(&mut self) {}
    }
    fn build_dac(_: &Params, _: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
        Ok(Box::new(Dac))
    }
    let mut reg = Registry::new();
    reg.add(&SEQ).add(&SPEC).add(&DAC);
    let load = |port: &str| {
        let doc = format!(
            "[graph]\nformat = 1\nname = \"hw\"\nrate = 1000.0\nconnections = [\"f.out -> l.in\", \"l.{port} -> d.u\"]\n\
             [nodes.f]\ntype = \"test.seq\"\nvalues = [0.1]\n[nodes.l]\ntype = \"limit\"\n[nodes.d]\ntype = \"test.dac\"\n"
        );
        let g = parse_graph(Path::new("hw.toml"), &doc).unwrap();
        check(&g, &reg, &[]).map(|_| ()).map_err(|e| e.to_string())
    };
    load("out").unwrap();
    let e = load("state").unwrap_err();
    assert!(e.contains("hardware output `d.u` is not fed by a `limit` node"), "{e}");
}
