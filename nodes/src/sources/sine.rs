//! `sine`: a sine wave whose phase is exact at any sample index.

use evflow_engine::ports::OutPort;
use evflow_engine::spec::{BoundArgs, PortBound};
use evflow_engine::typed_params::Float;
use evflow_engine::{BuildContext, Io, Node, NodeError, NodeSpec, Params, PortSpec, Role};
use std::f64::consts::TAU;

/// Declaration of `sine`.
pub static SPEC: NodeSpec = NodeSpec::new(
    "sine",
    "sources",
    Role::Source,
    "Sine wave offset + A·sin(2π·f·n/fs + φ), exact at any sample index.",
    build,
)
.doc(
    "y[n] = offset + A·sin(2π·f·n/fs + φ), an endless source (a run needs a duration). Used as \
the basic actuation signal and as the test signals of the interpolation study (dissertation \
§6.1–6.2, Figs. 6.1–6.4: sines of 10 and 20 Hz).\n\
\n\
**No drift.** Each sample is computed from its own index n (the index at the node's rate since \
t = 0), not by accumulating a phase increment, so block and one-sample processing give identical \
output and `reset` returns to n = 0. The phase f·n/fs is reduced modulo 1 cycle in 128-bit fixed \
point: f/fs is split into a correctly rounded quotient plus its exact remainder (≈ 106 significant \
bits), multiplied by n with wrap-around, so the phase error stays below 10⁻¹⁵ rad at n = 10¹², \
where the naive `sin(2π·f·n/fs)` in f64 is off by about 10⁻⁴ (f/fs ≈ 0.1).\n\
\n\
**Port** `out` at the rate set by `rate`. `frequency` must not exceed the Nyquist frequency \
rate/2 (checked when the node is built).\n\
\n\
**Checked against:** sin() at analytic phases (an exact rational reduction of f·n/fs computed in \
integers), including n around 10⁹ and 10¹², the Nyquist case f = fs/2, f = 0, and the \
rejection of f > fs/2.",
)
.ports(PORTS)
.params(&[FREQUENCY.spec(), AMPLITUDE.spec(), PHASE.spec(), OFFSET.spec(), RATE.spec()])
.rate_param(RATE.name())
.bound(output_bound)
.example("frequency = 10.0\namplitude = 1.0\nrate = 1000.0");

/// The port: the wave out.
const PORTS: &[PortSpec] = &[PortSpec::output("out", "1", "the sine wave")];
/// `out`: the sine wave.
const OUT: OutPort = OutPort::named(PORTS, "out");

/// `frequency`: f, at most rate/2.
const FREQUENCY: Float = Float::new("frequency", 0.0, 5e6, 10.0, "Hz", "frequency f, at most rate/2");
/// `amplitude`: the peak amplitude A.
const AMPLITUDE: Float = Float::new("amplitude", 0.0, 1e6, 1.0, "1", "peak amplitude A");
/// `phase`: φ at sample 0.
const PHASE: Float = Float::new("phase", -1e3, 1e3, 0.0, "rad", "phase φ at sample 0");
/// `offset`: the constant added to the wave.
const OFFSET: Float = Float::new("offset", -1e6, 1e6, 0.0, "1", "constant added to the wave");
/// `rate`: the node's sample rate.
const RATE: Float = Float::new("rate", 1e-3, 1e7, 1000.0, "Hz", "sample rate");

/// 2⁶⁴ and 2¹²⁸ as f64 (exact powers of two).
const TWO64: f64 = 18_446_744_073_709_551_616.0;
const TWO128: f64 = TWO64 * TWO64;

/// `x` in [0, 1] as a 128-bit binary fraction (1.0 wraps to 0). Exact for
/// x ≥ 2⁻⁷⁵; below that the bits under 2⁻¹²⁸ are dropped.
fn fraction_to_fixed(x: f64) -> u128 {
    let a = x * TWO64;
    let hi = a.floor();
    let lo = ((a - hi) * TWO64).floor();
    ((hi as u128) << 64).wrapping_add(lo as u128)
}

/// f/fs (≤ 1/2) as a 128-bit binary fraction of a cycle, accurate to about
/// 2⁻¹⁰⁶ relative: the rounded quotient plus the exact remainder of the division.
fn cycles_per_sample(f: f64, fs: f64) -> u128 {
    let q = f / fs;
    // The remainder f − q·fs of a correctly rounded division is exactly
    // representable, and the fused multiply-add computes it exactly.
    let rem = (-q).mul_add(fs, f);
    let lo = rem / fs * TWO128; // |lo| < 2⁷⁵
    let hi = fraction_to_fixed(q);
    if lo >= 0.0 {
        hi.wrapping_add(lo as u128)
    } else {
        hi.wrapping_sub((-lo) as u128)
    }
}

struct Sine {
    step: u128,
    phase: u128,
    amplitude: f64,
    offset: f64,
}

impl Sine {
    /// The sample at index `n`.
    #[inline]
    fn at(&self, n: u64) -> f64 {
        let turn = (n as u128).wrapping_mul(self.step).wrapping_add(self.phase);
        // The top 64 bits as a signed fraction of a cycle in [−1/2, 1/2).
        let x = ((turn >> 64) as u64 as i64) as f64 / TWO64;
        self.offset + self.amplitude * (TAU * x).sin()
    }
}

/// The output bound the stability suite checks: |out| ≤ |offset| + amplitude.
fn output_bound(b: &BoundArgs<'_>) -> Option<PortBound> {
    Some(("out", b.num(&OFFSET.spec()).abs() + b.num(&AMPLITUDE.spec()), "|offset| + amplitude".into()))
}

fn build(p: &Params, ctx: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
    let f = FREQUENCY.get(p);
    let fs = ctx.rate;
    if !(fs.is_finite() && fs > 0.0) {
        return Err(NodeError::param(RATE.name(), format!("the sample rate must be positive, not {fs} Hz")));
    }
    if !(f.is_finite() && f >= 0.0) {
        return Err(NodeError::param(FREQUENCY.name(), format!("must be a frequency ≥ 0 Hz, not {f}")));
    }
    if f > fs / 2.0 {
        return Err(NodeError::param(
            FREQUENCY.name(),
            format!(
                "{f} Hz is above the Nyquist frequency {} Hz of this node (rate = {fs} Hz); \
                 lower `frequency` to at most rate/2 or raise `rate`",
                fs / 2.0
            ),
        ));
    }
    let phase = PHASE.get(p);
    let (amplitude, offset) = (AMPLITUDE.get(p), OFFSET.get(p));
    if ![phase, amplitude, offset].iter().all(|v| v.is_finite()) {
        return Err(NodeError::param(PHASE.name(), "phase, amplitude and offset must be finite numbers"));
    }
    Ok(Box::new(Sine {
        step: cycles_per_sample(f, fs),
        phase: fraction_to_fixed((phase / TAU).rem_euclid(1.0)),
        amplitude,
        offset,
    }))
}

impl Node for Sine {
    fn process(&mut self, io: &mut Io<'_>) -> Result<(), NodeError> {
        let start = io.start();
        for (i, y) in io.output(OUT).iter_mut().enumerate() {
            *y = self.at(start + i as u64);
        }
        Ok(())
    }

    /// Stateless: every sample is a function of its index alone.
    fn reset(&mut self) {}
}

#[cfg(test)]
mod tests {
    use super::*;
    use evflow_engine::harness::Single;
    use evflow_engine::Value;
    use std::collections::BTreeMap;
    use std::path::PathBuf;

    fn single(params: &str, ticks: u64, block: usize) -> Single<'_> {
        Single::new(&SPEC, params).output("out").ticks(ticks).block(block)
    }

    fn run(params: &str, ticks: u64, block: usize) -> Vec<f64> {
        single(params, ticks, block).run().unwrap().remove(0)
    }

    /// Builds the node directly, for calls at arbitrary start indices.
    fn node(f: f64, amplitude: f64, phase: f64, offset: f64, fs: f64) -> Result<Box<dyn Node>, NodeError> {
        let mut m = BTreeMap::new();
        for (k, v) in [("frequency", f), ("amplitude", amplitude), ("phase", phase), ("offset", offset), ("rate", fs)] {
            m.insert(k.to_string(), Value::Float(v));
        }
        let ctx = BuildContext {
            node: "s".into(),
            base_rate: fs,
            rate: fs,
            input_rates: Vec::new(),
            output_rates: vec![fs],
            base_dir: PathBuf::from("."),
            out_dir: PathBuf::from("."),
            seed: 0,
            check_only: false,
        };
        build(&Params::from_map(m), &ctx)
    }

    /// One call of `len` samples starting at index `start`.
    fn call(node: &mut dyn Node, start: u64, len: usize) -> Vec<f64> {
        let pool: Vec<Vec<f64>> = vec![];
        let mut outs = vec![vec![0.0; len]];
        let lens = [len];
        let mut io = Io::new(&pool, &[], &[], &mut outs, &lens, start);
        node.process(&mut io).unwrap();
        outs.remove(0)
    }

    /// f·n/fs mod 1 computed exactly in integers: f is an f64, so f = m·2^−e
    /// with integers m, e, and f·n/fs = n·m / (fs·2^e) for an integer fs.
    fn exact_cycles(n: u64, f: f64, fs: u64) -> f64 {
        let (mut m, mut e) = (f, 0u32);
        while m.fract() != 0.0 {
            m *= 2.0;
            e += 1;
        }
        let den = (fs as u128) << e;
        let num = (n as u128 * m as u128) % den;
        num as f64 / den as f64
    }

    #[test]
    fn matches_sin_at_analytic_values() {
        // f/fs = 1/20: phase (n mod 20)/20 cycles.
        let y = run("frequency = 50.0\namplitude = 2.0\nphase = 0.3\noffset = 0.5", 1000, 64);
        for (n, v) in y.iter().enumerate() {
            let want = 0.5 + 2.0 * (TAU * (n % 20) as f64 / 20.0 + 0.3).sin();
            assert!((v - want).abs() < 1e-14, "n = {n}: {v} vs {want}");
        }
        // Quarter-rate: exactly 0, 1, 0, −1 up to rounding of sin.
        let y = run("frequency = 250.0", 8, 3);
        for (v, w) in y.iter().zip([0.0, 1.0, 0.0, -1.0, 0.0, 1.0, 0.0, -1.0]) {
            assert!((v - w).abs() < 1e-15, "{v} vs {w}");
        }
    }

    #[test]
    fn accurate_far_into_the_run() {
        let (f, fs, phase) = (123.456, 1000u64, -0.7);
        let mut s = node(f, 1.0, phase, 0.0, fs as f64).unwrap();
        for start in [1_000_000_000u64, 999_999_937, 1_000_000_000_000] {
            let y = call(s.as_mut(), start, 64);
            let mut naive_err = 0.0f64;
            for (i, v) in y.iter().enumerate() {
                let n = start + i as u64;
                let want = (TAU * exact_cycles(n, f, fs) + phase).sin();
                assert!((v - want).abs() < 1e-12, "n = {n}: {v} vs {want}");
                let naive = (TAU * f * n as f64 / fs as f64 + phase).sin();
                naive_err = naive_err.max((naive - want).abs());
            }
            // The reference is sharp enough to reject the naive formula.
            assert!(naive_err > 1e-9, "start {start}: naive error only {naive_err}");
        }
    }

    #[test]
    fn start_index_gives_the_same_samples_as_running_there() {
        let y = run("frequency = 37.3\nphase = 1.0", 3000, 4096);
        let mut s = node(37.3, 1.0, 1.0, 0.0, 1000.0).unwrap();
        assert_eq!(call(s.as_mut(), 2500, 500), &y[2500..]);
        assert_eq!(call(s.as_mut(), 0, 7), &y[..7]);
    }

    #[test]
    fn block_and_per_sample_are_identical() {
        for params in ["frequency = 123.456\nphase = 2.0\noffset = -0.25", "frequency = 500.0", "frequency = 0.0"] {
            assert_eq!(run(params, 2000, 4096), run(params, 2000, 1), "{params}");
        }
    }

    #[test]
    fn reset_restores_the_start() {
        let (mut plan, idx) = single("frequency = 31.0\nphase = 0.5", 0, 64).plan().unwrap();
        let collect = |plan: &mut evflow_engine::Plan| {
            let mut v = Vec::new();
            for _ in 0..4 {
                plan.step(64).unwrap();
                v.extend_from_slice(plan.output("dut", idx[0]).unwrap());
            }
            v
        };
        let first = collect(&mut plan);
        plan.reset();
        assert_eq!(collect(&mut plan), first);
        assert_eq!(plan.remaining_ticks(), None, "the sine is endless");
    }

    #[test]
    fn nyquist_is_the_limit() {
        // f = fs/2: sin(π·n + φ) = (−1)^n · sin φ.
        let y = run("frequency = 500.0\nphase = 0.4", 50, 8);
        for (n, v) in y.iter().enumerate() {
            let want = if n % 2 == 0 { 0.4f64.sin() } else { -(0.4f64.sin()) };
            assert!((v - want).abs() < 1e-15, "n = {n}");
        }
        let err = single("frequency = 500.001", 10, 8).plan().err().expect("above Nyquist must fail");
        assert!(err.contains("frequency") && err.contains("Nyquist"), "{err}");
        let e = node(600.0, 1.0, 0.0, 0.0, 1000.0).err().unwrap();
        assert!(matches!(&e, NodeError::Param { param, .. } if param == "frequency"), "{e}");
    }

    #[test]
    fn extreme_settings_stay_bounded() {
        // Zero frequency: a constant A·sin φ + offset.
        let y = run("frequency = 0.0\namplitude = 3.0\nphase = -1000.0\noffset = 1.0", 100, 16);
        assert!(y.iter().all(|&v| (v - (1.0 + 3.0 * (-1000.0f64).sin())).abs() < 1e-11));
        // Largest amplitude and offset, highest frequency at the highest rate.
        let mut s = node(5e6, 1e6, 1000.0, -1e6, 1e7).unwrap();
        for start in [0, u64::MAX / 2, u64::MAX - 100] {
            let y = call(s.as_mut(), start, 100);
            assert!(y.iter().all(|v| v.is_finite() && (v + 1e6).abs() <= 1e6 * (1.0 + 1e-12)));
        }
        // Lowest rate, a frequency far below one cycle per run.
        let mut s = node(1e-12, 1.0, 0.0, 0.0, 1e-3).unwrap();
        let y = call(s.as_mut(), 1_000_000, 3);
        let want = (TAU * 1e-12 / 1e-3 * 1e6).sin();
        assert!((y[0] - want).abs() < 1e-15);
    }

    #[test]
    fn fixed_point_conversion() {
        assert_eq!(fraction_to_fixed(0.5), 1 << 127);
        assert_eq!(fraction_to_fixed(2f64.powi(-30) + 2f64.powi(-80)), (1 << 98) + (1 << 48));
        assert_eq!(fraction_to_fixed(1.0), 0);
        // 1/3 as a rounded quotient plus remainder: 3 · step wraps to almost 0.
        let step = cycles_per_sample(1.0, 3.0);
        let r = step.wrapping_mul(3);
        assert!(!(1 << 40..=u128::MAX - (1 << 40)).contains(&r), "3·(1/3) = {r:#x}");
    }
}
