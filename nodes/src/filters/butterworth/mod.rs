//! `butterworth`: low-pass or high-pass Butterworth filter as second-order sections.

pub mod design;
pub mod sos;

use design::{butterworth, DesignError, Kind, MIN_RELATIVE_CUTOFF};
use evflow_engine::ports::{InPort, OutPort, SAME_AS_INPUT};
use evflow_engine::typed_params::{Choice, Float, Int};
use evflow_engine::{BuildContext, Io, Node, NodeError, NodeSpec, Params, PortSpec, Role};
use sos::Cascade;

/// Declaration of `butterworth`.
pub static SPEC: NodeSpec = NodeSpec::new(
    "butterworth",
    "filters",
    Role::Filter,
    "Butterworth low-pass or high-pass filter (second-order sections, f64).",
    build,
)
.doc(
    "A digital Butterworth filter of order 1–8, designed like \
     `scipy.signal.butter(order, cutoff, kind, fs=rate, output='sos')`: the analog prototype's \
     poles on the unit circle, frequency pre-warping `K = tan(π·cutoff/rate)` so the −3.01 dB \
     point falls exactly on `cutoff`, and the bilinear transform, one second-order section per \
     conjugate pole pair (an odd order adds one first-order section). The magnitude is \
     `|H|² = 1 / (1 + (tan(ω/2) / tan(ω_c/2))^(2N))` for the low-pass and the same with the ratio \
     inverted for the high-pass: unity gain at DC (low-pass) or at Nyquist (high-pass), no ripple.\n\n\
     Each section runs in transposed direct form II in `f64`; block and per-sample processing give \
     identical output. The filter is causal (not the zero-phase `filtfilt`), so it delays the signal \
     by its group delay.\n\n\
     Ports: `in` → `out`, both at the rate of the input, which is the sample rate of the design.\n\n\
     Parameters: `kind` (`lowpass` or `highpass`), `order`, and `cutoff` in Hz, which must lie below \
     the Nyquist frequency (half the input's rate) and at or above 1e-6 × the rate (below that the \
     rounding of f64 coefficients changes the low-frequency gain by more than about 1e-5; decimate \
     first). A non-finite input sample stops the run with an error rather than leaving the filter's \
     state NaN forever; so does a finite input so large (near ±f64::MAX) that the state overflows.\n\n\
     Dissertation: §5.1.1 removes the force sensor's DC biases with a 10 Hz high-pass on the 1 kHz \
     tribometer forces; §3.1.2 low-passes the 10 kHz force data at 500 Hz before measuring \
     peak-to-peak amplitudes.\n\n\
     Checked against: the analytic digital Butterworth magnitude for orders 1–8 (1e-9 relative), \
     coefficient sets from scipy 1.17.1 `signal.butter(..., output='sos')`, the textbook \
     difference equation, steady-state sine amplitudes of the running filter, and stability at \
     cut-offs of 0.01 Hz and 499 Hz at 1 kHz.",
)
.ports(PORTS)
.params(&[KIND.spec(), ORDER.spec(), CUTOFF.spec()])
.example("kind = \"highpass\"\norder = 4\ncutoff = 10.0");

/// The ports: one signal in, the filtered signal out.
const PORTS: &[PortSpec] =
    &[PortSpec::input("in", "1", "signal"), PortSpec::output("out", SAME_AS_INPUT, "filtered signal")];
/// The signal.
const IN: InPort = InPort::named(PORTS, "in");
/// The filtered signal.
const OUT: OutPort = OutPort::named(PORTS, "out");

/// `kind`: which band passes.
const KIND: Choice<Kind> =
    Choice::new("kind", &["lowpass", "highpass"], &[Kind::Lowpass, Kind::Highpass], "lowpass", "which band passes");
/// `order`: the roll-off.
const ORDER: Int =
    Int::new("order", 1, design::MAX_ORDER as i64, 4, "1", "filter order (roll-off 6·order dB per octave)");
/// `cutoff`: the −3 dB frequency.
const CUTOFF: Float =
    Float::new("cutoff", 0.001, f64::INFINITY, 10.0, "Hz", "−3 dB frequency; below half the input's rate").required();

struct Butterworth {
    cascade: Cascade,
}

fn build(p: &Params, ctx: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
    let (kind, order, cutoff) = (KIND.get(p), ORDER.count(p), CUTOFF.get(p));
    let sections = butterworth(kind, order, cutoff, ctx.rate).map_err(|e| match e {
        DesignError::Order(_) => NodeError::param(ORDER.name(), e.to_string()),
        DesignError::Rate(_) => NodeError::Other(e.to_string()),
        DesignError::AboveNyquist { nyquist, rate, .. } => NodeError::param(
            CUTOFF.name(),
            format!(
                "{cutoff} Hz is not below the Nyquist frequency {nyquist} Hz of this node's input \
                 ({rate} Hz); choose a cut-off below {nyquist} Hz or raise the input's rate"
            ),
        ),
        DesignError::TooLow { min, rate, .. } => NodeError::param(
            CUTOFF.name(),
            format!(
                "{cutoff} Hz is below {min} Hz ({MIN_RELATIVE_CUTOFF} × the input's rate {rate} Hz), where \
                 f64 second-order sections lose their accuracy; decimate the signal first"
            ),
        ),
    })?;
    Ok(Box::new(Butterworth { cascade: Cascade::new(&sections) }))
}

impl Node for Butterworth {
    fn process(&mut self, io: &mut Io<'_>) -> Result<(), NodeError> {
        let start = io.start();
        let (x, y) = io.io(IN, OUT);
        self.cascade.process(x, y);
        // One check of the output, which a non-finite input always makes
        // non-finite (every section adds b0·x to its finite state); only
        // then are the input and the output searched for the sample to name.
        if y.iter().fold(true, |ok, v| ok & v.is_finite()) {
            return Ok(());
        }
        if let Some(i) = x.iter().position(|v| !v.is_finite()) {
            return Err(NodeError::Data(format!(
                "input sample {} is {}; a recursive filter cannot recover from a non-finite value \
                 (its state would stay non-finite), so repair or remove it upstream",
                start + i as u64,
                x[i]
            )));
        }
        // Finite inputs near ±f64::MAX overflow the sections' state (found
        // by `evflow report stability`): stop, naming the sample, rather
        // than let ±∞ or NaN out.
        if let Some(i) = y.iter().position(|v| !v.is_finite()) {
            let peak = x[..=i].iter().fold(0.0f64, |m, v| m.max(v.abs()));
            return Err(NodeError::Data(format!(
                "output sample {} overflows (the input reaches {peak:e}, beyond what the filter's state \
                 can hold); scale the input down upstream",
                start + i as u64
            )));
        }
        Ok(())
    }

    fn reset(&mut self) {
        self.cascade.reset();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use design::ideal_power;
    use evflow_engine::harness::Single;
    use evflow_engine::Value;
    use std::f64::consts::PI;

    fn run(params: &str, x: &[f64], fs: f64, block: usize) -> Result<Vec<f64>, String> {
        Single::new(&SPEC, params)
            .input("in", x.to_vec(), fs)
            .output("out")
            .base_rate(fs)
            .ticks(x.len() as u64)
            .block(block)
            .run()
            .map(|mut o| o.remove(0))
    }

    fn sine(f: f64, fs: f64, n: usize) -> Vec<f64> {
        (0..n).map(|i| (2.0 * PI * f / fs * i as f64).sin()).collect()
    }

    /// Amplitude of the component at `f` over the last `m` samples (a whole
    /// number of periods), by projection on sin and cos.
    fn amplitude(y: &[f64], f: f64, fs: f64, m: usize) -> f64 {
        let w = 2.0 * PI * f / fs;
        let (mut s, mut c) = (0.0, 0.0);
        for (i, v) in y.iter().enumerate().skip(y.len() - m) {
            s += v * (w * i as f64).sin();
            c += v * (w * i as f64).cos();
        }
        (s * s + c * c).sqrt() * 2.0 / m as f64
    }

    /// The node in a real plan: steady-state amplitude of long sines against
    /// the analytic response (§5.1.1's 10 Hz high-pass at 1 kHz and §3.1.2's
    /// 500 Hz low-pass at 10 kHz).
    #[test]
    fn steady_state_response_in_a_plan() {
        let cases = [
            (
                "kind = \"highpass\"\norder = 4\ncutoff = 10.0",
                Kind::Highpass,
                4,
                10.0,
                1000.0,
                [5.0, 10.0, 20.0, 100.0],
            ),
            (
                "kind = \"lowpass\"\norder = 4\ncutoff = 500.0",
                Kind::Lowpass,
                4,
                500.0,
                10_000.0,
                [100.0, 500.0, 1000.0, 2500.0],
            ),
        ];
        for (params, kind, order, fc, fs, freqs) in cases {
            for f in freqs {
                let y = run(params, &sine(f, fs, 4000), fs, 256).unwrap();
                let got = amplitude(&y, f, fs, 2000);
                let want = ideal_power(kind, order, fc, fs, f).sqrt();
                assert!((got - want).abs() < 1e-9 * want, "{params} f={f}: {got} vs {want}");
            }
        }
    }

    #[test]
    fn block_and_per_sample_are_identical() {
        let x: Vec<f64> = (0..700).map(|i| (i as f64 * 0.3).sin() + ((i * 37) % 11) as f64 * 0.1).collect();
        for params in ["kind = \"lowpass\"\norder = 7\ncutoff = 80.0", "kind = \"highpass\"\norder = 2\ncutoff = 3.0"] {
            let one = run(params, &x, 1000.0, 1).unwrap();
            let big = run(params, &x, 1000.0, 4096).unwrap();
            let odd = run(params, &x, 1000.0, 37).unwrap();
            assert_eq!(one.len(), x.len());
            assert_eq!(one, big);
            assert_eq!(one, odd);
        }
    }

    #[test]
    fn reset_restores_the_initial_output() {
        let x = sine(30.0, 1000.0, 300);
        let s = Single::new(&SPEC, "kind = \"lowpass\"\norder = 5\ncutoff = 50.0")
            .input("in", x, 1000.0)
            .output("out")
            .ticks(300);
        let (mut plan, idx) = s.plan().unwrap();
        let pass = |plan: &mut evflow_engine::Plan| {
            let mut out = Vec::new();
            for _ in 0..4 {
                plan.step(64).unwrap();
                out.extend_from_slice(plan.output("dut", idx[0]).unwrap());
            }
            out
        };
        let first = pass(&mut plan);
        assert!(first.iter().any(|v| *v != 0.0));
        plan.reset();
        let again = pass(&mut plan);
        assert_eq!(first, again);
    }

    #[test]
    fn refuses_cutoff_at_or_above_nyquist() {
        let x = vec![0.0; 10];
        for cutoff in ["500.0", "750.0"] {
            let err = run(&format!("cutoff = {cutoff}"), &x, 1000.0, 8).unwrap_err();
            assert!(err.contains("cutoff") && err.contains("Nyquist frequency 500 Hz"), "{err}");
        }
        // 0.005 Hz at 10 kHz is 5e-7 × the rate, below the accuracy floor.
        let err = run("cutoff = 0.005", &x, 10_000.0, 8).unwrap_err();
        assert!(err.contains("cutoff") && err.contains("decimate"), "{err}");
        // Just below Nyquist is fine.
        assert!(run("cutoff = 499.9", &x, 1000.0, 8).is_ok());
    }

    #[test]
    fn refuses_non_finite_input() {
        // The harness's feed refuses NaN values, so the node is driven directly.
        let ctx = BuildContext {
            node: "lp".into(),
            base_rate: 1000.0,
            rate: 1000.0,
            input_rates: vec![1000.0],
            output_rates: vec![1000.0],
            base_dir: ".".into(),
            out_dir: ".".into(),
            seed: 0,
            check_only: false,
        };
        let params = Params::from_map(
            [
                ("kind".to_string(), Value::Text("lowpass".into())),
                ("order".to_string(), Value::Int(2)),
                ("cutoff".to_string(), Value::Float(10.0)),
            ]
            .into_iter()
            .collect(),
        );
        let mut node = build(&params, &ctx).unwrap();
        for bad in [f64::NAN, f64::INFINITY] {
            let mut x = vec![0.5; 20];
            x[13] = bad;
            let pool = vec![x];
            let mut outs = vec![vec![0.0; 20]];
            let mut io = Io::new(&pool, &[0], &[20], &mut outs, &[20], 100);
            let err = node.process(&mut io).unwrap_err().to_string();
            assert!(err.contains(&format!("input sample 113 is {bad}")), "{err}");
        }
    }

    #[test]
    fn an_input_that_overflows_the_state_is_an_error_naming_the_sample() {
        // Steps 0 → +f64::MAX → −f64::MAX: the state overflows.
        let mut x: Vec<f64> = (0..40).map(|i| [0.0, f64::MAX, -f64::MAX][i / 14]).collect();
        let err = run("kind = \"lowpass\"\norder = 4\ncutoff = 100.0", &x, 1000.0, 16).unwrap_err();
        assert!(err.contains("output sample ") && err.contains("overflows"), "{err}");
        // 1e300 does not overflow: the output stays finite.
        x.iter_mut().for_each(|v| *v = v.signum() * 1e300 * f64::from(u8::from(*v != 0.0)));
        let y = run("kind = \"lowpass\"\norder = 4\ncutoff = 100.0", &x, 1000.0, 16).unwrap();
        assert!(y.iter().all(|v| v.is_finite()));
    }

    #[test]
    fn the_example_runs() {
        let y = run(SPEC.example, &sine(50.0, 1000.0, 200), 1000.0, 64).unwrap();
        assert_eq!(y.len(), 200);
        assert!(y.iter().all(|v| v.is_finite()));
    }
}
