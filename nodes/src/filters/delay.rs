//! `delay`: delays a stream by a whole number of samples; the node that
//! lets a feedback cycle through.

use evflow_engine::ports::{InPort, OutPort, SAME_AS_INPUT};
use evflow_engine::spec::{BoundArgs, PortBound};
use evflow_engine::typed_params::Int;
use evflow_engine::{BuildContext, Io, Node, NodeError, NodeSpec, Params, PortSpec, Role};

/// Largest delay in samples (80 MB of history).
pub const MAX_SAMPLES: i64 = 10_000_000;

/// Declaration of `delay`.
pub static SPEC: NodeSpec =
    NodeSpec::new("delay", "filters", Role::Filter, "Delays a stream by a whole number of samples.", build)
        .doc(
            "y[n] = x[n − d] with d = `samples`, and y[n] = 0 for n < d (zero initial state). Runs at \
             the rate of its input; `d` counts samples at that rate.\n\n\
             `delay` is the only node a feedback cycle may pass through: its output for a block depends \
             only on inputs that arrived before the block, so the engine can run a cycle such as \
             y[n] = x[n] + a·y[n − d] by letting the delay emit its outputs early in each step and take \
             its inputs at the end of the step. Inside a cycle the engine limits blocks to at most `d` \
             samples; outside a cycle any block length works.\n\n\
             Ports: `in` → `out`, same rate. Parameter: `samples` (d ≥ 1). The history is a ring \
             buffer of d samples allocated when the node is built.\n\n\
             It lets a graph close a loop, e.g. to run a model of the friction response in closed loop \
             (dissertation §5.2). Checked against: a delayed ramp for blocks shorter and longer than d, and a feedback \
             accumulator against its recursion for block sizes 1 and d.",
        )
        .ports(PORTS)
        .params(&[SAMPLES.spec()])
        .breaks_cycles()
        .bound(output_bound)
        .example("samples = 1");

/// The ports: one signal in, the same signal d samples later out.
const PORTS: &[PortSpec] =
    &[PortSpec::input("in", "1", "signal"), PortSpec::output("out", SAME_AS_INPUT, "signal, d samples later")];
/// The signal.
const IN: InPort = InPort::named(PORTS, "in");
/// The delayed signal.
const OUT: OutPort = OutPort::named(PORTS, "out");

/// `samples`: the delay d.
const SAMPLES: Int = Int::new("samples", 1, MAX_SAMPLES, 1, "samples", "delay d at the input's rate");

/// A ring buffer holding the last `d` inputs; `pos` is the oldest one, the
/// next to come out.
struct Delay {
    ring: Vec<f64>,
    pos: usize,
}

/// The output bound the stability suite checks: |out| ≤ max |in| (a delayed input).
fn output_bound(b: &BoundArgs<'_>) -> Option<PortBound> {
    Some(("out", b.input_max(), "a delayed input".into()))
}

fn build(p: &Params, _: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
    let d = SAMPLES.count(p);
    if d == 0 {
        return Err(NodeError::param(SAMPLES.name(), "a delay must be at least 1 sample"));
    }
    Ok(Box::new(Delay { ring: vec![0.0; d], pos: 0 }))
}

impl Delay {
    /// Writes `y.len()` (≤ d) outputs from the history, without consuming it.
    fn read(&self, y: &mut [f64]) {
        let d = self.ring.len();
        let first = y.len().min(d - self.pos);
        let (a, b) = y.split_at_mut(first);
        a.copy_from_slice(&self.ring[self.pos..self.pos + first]);
        b.copy_from_slice(&self.ring[..b.len()]);
    }

    /// Appends `x.len()` (≤ d) inputs to the history, dropping the oldest.
    fn write(&mut self, x: &[f64]) {
        let d = self.ring.len();
        let first = x.len().min(d - self.pos);
        self.ring[self.pos..self.pos + first].copy_from_slice(&x[..first]);
        let rest = &x[first..];
        self.ring[..rest.len()].copy_from_slice(rest);
        self.pos = (self.pos + x.len()) % d;
    }

    fn too_long(&self, n: usize) -> NodeError {
        NodeError::Other(format!(
            "a feedback block of {n} samples is longer than the delay of {} samples",
            self.ring.len()
        ))
    }
}

impl Node for Delay {
    fn process(&mut self, io: &mut Io<'_>) -> Result<(), NodeError> {
        let (x, y) = io.io(IN, OUT);
        // Chunks of at most d samples: each reads d-old samples, then stores
        // its own inputs in their place.
        let d = self.ring.len();
        for (x, y) in x.chunks(d).zip(y.chunks_mut(d)) {
            self.read(y);
            self.write(x);
        }
        Ok(())
    }

    fn emit(&mut self, io: &mut Io<'_>) -> Result<(), NodeError> {
        let y = io.output(OUT);
        if y.len() > self.ring.len() {
            return Err(self.too_long(y.len()));
        }
        self.read(y);
        Ok(())
    }

    fn absorb(&mut self, io: &mut Io<'_>) -> Result<(), NodeError> {
        let x = io.input(IN);
        if x.len() > self.ring.len() {
            return Err(self.too_long(x.len()));
        }
        self.write(x);
        Ok(())
    }

    fn cycle_delay(&self) -> usize {
        self.ring.len()
    }

    fn reset(&mut self) {
        self.ring.fill(0.0);
        self.pos = 0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use evflow_engine::harness::{Single, FEED, TAP};
    use evflow_engine::{check, run_offline, Graph, Plan, PlanOptions, Registry, RunOptions, Value};

    fn run(d: usize, x: &[f64], block: usize) -> Vec<f64> {
        Single::new(&SPEC, &format!("samples = {d}"))
            .input("in", x.to_vec(), 1000.0)
            .output("out")
            .ticks(x.len() as u64)
            .block(block)
            .run()
            .unwrap()
            .remove(0)
    }

    #[test]
    fn delays_a_ramp_for_any_block_length() {
        let x: Vec<f64> = (1..=100).map(|i| i as f64).collect();
        for d in [1, 3, 7, 64, 100, 150] {
            let want: Vec<f64> = (0..100).map(|n| if n >= d { x[n - d] } else { 0.0 }).collect();
            for block in [1, 2, 5, 7, 16, 64, 99, 4096] {
                assert_eq!(run(d, &x, block), want, "d={d} block={block}");
            }
        }
    }

    #[test]
    fn reset_restores_the_initial_output() {
        let x: Vec<f64> = (0..40).map(|i| (i * i) as f64).collect();
        let s = Single::new(&SPEC, "samples = 5").input("in", x, 1000.0).output("out").ticks(40).block(8);
        let (mut plan, idx) = s.plan().unwrap();
        let pass = |plan: &mut Plan| {
            let mut out = Vec::new();
            for _ in 0..5 {
                plan.step(8).unwrap();
                out.extend_from_slice(plan.output("dut", idx[0]).unwrap());
            }
            out
        };
        let first = pass(&mut plan);
        assert_eq!(&first[..7], &[0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0]);
        plan.reset();
        assert_eq!(pass(&mut plan), first);
    }

    // A two-input sum, only for these tests (the library has no adder yet).
    static SUM: NodeSpec =
        NodeSpec::new("test.sum", "test", Role::Filter, "a + b (test only)", build_sum).ports(SUM_PORTS);

    /// The test sum's ports.
    const SUM_PORTS: &[PortSpec] = &[
        PortSpec::input("a", "1", "first term"),
        PortSpec::input("b", "1", "second term"),
        PortSpec::output("out", "1", "a + b"),
    ];
    /// The first term.
    const A: InPort = InPort::named(SUM_PORTS, "a");
    /// The second term.
    const B: InPort = InPort::named(SUM_PORTS, "b");
    /// The sum.
    const SUM_OUT: OutPort = OutPort::named(SUM_PORTS, "out");

    struct Sum;

    impl Node for Sum {
        fn process(&mut self, io: &mut Io<'_>) -> Result<(), NodeError> {
            for i in 0..io.len() {
                let v = io.input(A)[i] + io.input(B)[i];
                io.output(SUM_OUT)[i] = v;
            }
            Ok(())
        }
        fn reset(&mut self) {}
    }

    fn build_sum(_: &Params, _: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
        Ok(Box::new(Sum))
    }

    fn registry() -> Registry {
        let mut reg = Registry::new();
        reg.add(&SPEC).add(&SUM).add(&crate::output::gain::SPEC).add(&FEED).add(&TAP);
        reg
    }

    /// y[n] = x[n] + a·y[n − d]: feed → sum.a, sum → delay → gain(a) → sum.b.
    fn accumulator(x: &[f64], a: f64, d: Option<usize>) -> Graph {
        let mut g = Graph::new("accumulator", 1000.0);
        g.add_node("x", "harness.feed", &[("values", Value::FloatList(x.to_vec())), ("rate", Value::Float(1000.0))])
            .add_node("sum", "test.sum", &[])
            .add_node("a", "gain", &[("gain", Value::Float(a))])
            .add_node("tap", "harness.tap", &[]);
        g.connect("x.out -> sum.a").unwrap().connect("a.out -> sum.b").unwrap().connect("sum.out -> tap.in").unwrap();
        match d {
            Some(d) => {
                g.add_node("z", "delay", &[("samples", Value::Int(d as i64))]);
                g.connect("sum.out -> z.in").unwrap().connect("z.out -> a.in").unwrap();
            }
            None => {
                g.connect("sum.out -> a.in").unwrap();
            }
        }
        g
    }

    #[test]
    fn feedback_accumulator_follows_its_recursion() {
        let x: Vec<f64> = (0..300).map(|i| ((i * 31) % 17) as f64 / 8.0 - 1.0).collect();
        let a = 0.75;
        for d in [1usize, 3, 10] {
            let mut want = vec![0.0; x.len()];
            for n in 0..x.len() {
                want[n] = x[n] + if n >= d { a * want[n - d] } else { 0.0 };
            }
            let checked = check(&accumulator(&x, a, Some(d)), &registry(), &[]).unwrap();
            for requested in [1usize, 4096] {
                let opts = PlanOptions {
                    max_block: requested,
                    seed: None,
                    base_dir: None,
                    timing: false,
                    out_dir: None,
                    mode: evflow_engine::RunMode::Offline,
                    check_only: false,
                };
                let mut plan = Plan::build(&checked, &opts).unwrap();
                // The cycle limits blocks to the delay.
                assert_eq!(plan.max_block(), requested.min(d), "d={d}");
                let mut y = Vec::new();
                while y.len() < x.len() {
                    let n = plan.max_block().min(x.len() - y.len());
                    plan.step(n).unwrap();
                    y.extend_from_slice(plan.output("sum", 0).unwrap());
                }
                for (n, (got, want)) in y.iter().zip(&want).enumerate() {
                    assert!((got - want).abs() <= 1e-12 * want.abs().max(1.0), "d={d} block={requested} n={n}");
                }
                // And the offline driver runs the same plan to the end.
                plan.reset();
                let report = run_offline(&mut plan, RunOptions::default()).unwrap();
                assert_eq!(report.ticks, x.len() as u64);
            }
        }
    }

    #[test]
    fn a_cycle_without_delay_is_refused() {
        let x = vec![1.0; 10];
        let err = check(&accumulator(&x, 0.5, None), &registry(), &[]).unwrap_err().to_string();
        assert!(err.contains("delay"), "{err}");
        assert!(err.contains("feedback cycle"), "{err}");
    }

    #[test]
    fn emit_refuses_blocks_longer_than_the_delay() {
        let mut node = Delay { ring: vec![0.0; 2], pos: 0 };
        let pool = vec![vec![1.0; 3]];
        let mut outs = vec![vec![0.0; 3]];
        let mut io = Io::new(&pool, &[0], &[3], &mut outs, &[3], 0);
        assert!(node.emit(&mut io).unwrap_err().to_string().contains("longer than the delay of 2"));
        let mut none: [Vec<f64>; 0] = [];
        let mut io = Io::new(&pool, &[0], &[3], &mut none, &[], 0);
        assert!(node.absorb(&mut io).is_err());
        assert_eq!(node.cycle_delay(), 2);
    }
}
