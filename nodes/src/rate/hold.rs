//! `hold`: a stream at any rate, held to the node's rate (zero-order hold).

use super::clock::Clock;
use evflow_engine::ports::{InPort, OutPort, SAME_AS_INPUT};
use evflow_engine::spec::{BoundArgs, PortBound};
use evflow_engine::typed_params::Float;
use evflow_engine::{BuildContext, Io, Node, NodeError, NodeSpec, Params, PortSpec, RateSpec, Role};

/// Declaration of `hold`.
pub static SPEC: NodeSpec = NodeSpec::new(
    "hold",
    "rate",
    Role::Filter,
    "Zero-order hold: a stream at any rate, resampled to `rate` by holding its latest sample.",
    build,
)
.doc(
    "Output sample l is the latest input sample at or before it in time (input and output rates are \
integer multiples or divisors of the base rate; the ordering is exact, `nodes/src/rate/clock.rs`; \
every stream's first sample is at t = 0, so there is always one to hold). Used to bring the 40 Hz reports of an IR touch \
frame or a load cell (`sim.user`, a serial device) to the 1 kHz actuation clock, as the user-study \
program of §6.5 held the latest report between frames. Lowering a rate with it keeps the latest \
sample of each output period (no anti-alias filter). Non-finite input samples are passed on as they \
are. Checked against: exact hold timing between 40 Hz and 1 kHz in both directions, block ≡ \
per-sample processing.\n\n\
**Ports.** `in` at any rate; `out` at `rate`.",
)
.ports(PORTS)
.params(&[RATE.spec()])
.rate_param(RATE.name())
.bound(output_bound)
.example("rate = 1000.0");

/// The ports: the stream at any rate in, held at `rate` out.
const PORTS: &[PortSpec] = &[
    PortSpec::input("in", "1", "the stream").at(RateSpec::Any),
    PortSpec::output("out", SAME_AS_INPUT, "the stream held at `rate`"),
];
/// The stream.
const IN: InPort = InPort::named(PORTS, "in");
/// The stream held.
const OUT: OutPort = OutPort::named(PORTS, "out");

/// `rate`: the output rate (the node's rate).
const RATE: Float = Float::new("rate", 1e-3, 1e7, 1000.0, "Hz", "output rate");

struct Hold {
    input: Clock,
    output: Clock,
    value: f64,
    received: u64,
    sent: u64,
}

/// The output bound the stability suite checks: |out| ≤ max |in| (a held input).
fn output_bound(b: &BoundArgs<'_>) -> Option<PortBound> {
    Some(("out", b.input_max(), "a held input".into()))
}

fn build(_p: &Params, ctx: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
    let input = Clock::new(ctx.input_rate(IN), ctx.base_rate, "in")?;
    let output = Clock::new(ctx.rate, ctx.base_rate, "out")?;
    Ok(Box::new(Hold { input, output, value: 0.0, received: 0, sent: 0 }))
}

impl Node for Hold {
    fn process(&mut self, io: &mut Io<'_>) -> Result<(), NodeError> {
        let n_in = io.input_len(IN);
        let mut j = 0;
        let (x, y) = io.io(IN, OUT);
        for out in y.iter_mut() {
            while j < n_in && self.input.at_or_before(self.received + j as u64, &self.output, self.sent) {
                self.value = x[j];
                j += 1;
            }
            *out = self.value;
            self.sent += 1;
        }
        // Input samples after this call's last output sample come before the next one.
        if j < n_in {
            self.value = x[n_in - 1];
        }
        self.received += n_in as u64;
        Ok(())
    }

    fn reset(&mut self) {
        self.value = 0.0;
        self.received = 0;
        self.sent = 0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use evflow_engine::harness::Single;

    fn run(input: Vec<f64>, in_rate: f64, params: &str, ticks: u64, block: usize) -> Vec<f64> {
        Single::new(&SPEC, params)
            .input("in", input, in_rate)
            .output("out")
            .ticks(ticks)
            .block(block)
            .run()
            .unwrap()
            .remove(0)
    }

    #[test]
    fn holds_40_hz_frames_over_25_ticks_each() {
        let frames: Vec<f64> = (0..8).map(|k| k as f64).collect();
        for block in [1, 7, 64] {
            let y = run(frames.clone(), 40.0, "rate = 1000.0", 200, block);
            assert_eq!(y.len(), 200);
            for (l, v) in y.iter().enumerate() {
                assert_eq!(*v, (l / 25) as f64, "block {block}, tick {l}");
            }
        }
    }

    #[test]
    fn lowering_a_rate_keeps_the_latest_sample() {
        let x: Vec<f64> = (0..100).map(|k| k as f64).collect();
        let y = run(x, 1000.0, "rate = 40.0", 100, 13);
        // Output sample l (tick 25·l) holds input sample 25·l.
        assert_eq!(y, vec![0.0, 25.0, 50.0, 75.0]);
    }

    #[test]
    fn equal_rates_are_the_identity() {
        let x: Vec<f64> = (0..50).map(|k| (k as f64).sin()).collect();
        assert_eq!(run(x.clone(), 1000.0, "rate = 1000.0", 50, 8), x);
    }
}
