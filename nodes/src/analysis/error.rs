//! `error`: how far a stream is from a reference stream.

use crate::wide_sum::SumSq;
use evflow_engine::ports::InPort;
use evflow_engine::{BuildContext, Io, Node, NodeError, NodeSpec, Params, PortSpec, Role, Summary};

/// Declaration of `error`.
pub static SPEC: NodeSpec = NodeSpec::new(
    "error",
    "analysis",
    Role::Sink,
    "RMS, relative RMS and largest absolute difference between a stream and a reference.",
    build,
)
.doc(
    "The error half of \"error against run time\": at the end of the run reports `rms` = \
√(mean (x − r)²), `rel_rms` = rms / √(mean r²) (∞-free: an error if the reference is all \
zero), `max_abs` = max |x − r| and `samples`. Compare an integrator, a model or a resampler \
(`test`) with a fine-step or exact solution (`reference`); sweep the accuracy knob and plot \
`rel_rms` against the node's run time (`[[plot]]`, x = `NODE.time`) for a work-precision \
diagram. Both inputs at the node's rate. Sums are compensated (TwoSum), so 10⁸ samples lose no \
precision, and scaled by a power of two where a plain sum of squares would over- or underflow, so \
finite inputs near ±f64::MAX or subnormal ones give their true errors (a subnormal reference is \
not zero); a `max_abs`, `rms` or `rel_rms` beyond f64::MAX (differences of samples near \
±f64::MAX) is reported as f64::MAX, with a line saying so. A non-finite input sample is reported as an infinite error, not an error of the run: \
a diverging method belongs on the diagram, at the top.\n\
\n\
**Checked against:** a sine and the same sine shifted by a known small phase (analytic RMS \
difference), identical streams (zero), and a reference of zeros (error).",
)
.ports(PORTS)
.example("");

/// The ports: the stream under test and its reference.
const PORTS: &[PortSpec] = &[
    PortSpec::input("test", "1", "the stream under test"),
    PortSpec::input("reference", "1", "the reference (same unit)"),
];
/// The stream under test.
const TEST: InPort = InPort::named(PORTS, "test");
/// The reference.
const REFERENCE: InPort = InPort::named(PORTS, "reference");

#[derive(Default)]
struct ErrorSink {
    diff2: SumSq,
    ref2: SumSq,
    max_abs: f64,
    /// Some |x − r| overflowed f64 (x, r finite, near ±f64::MAX).
    beyond: bool,
    n: u64,
    diverged: bool,
}

fn build(_: &Params, _: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
    Ok(Box::new(ErrorSink::default()))
}

impl Node for ErrorSink {
    fn process(&mut self, io: &mut Io<'_>) -> Result<(), NodeError> {
        for k in 0..io.len() {
            let (x, r) = (io.input(TEST)[k], io.input(REFERENCE)[k]);
            if !x.is_finite() || !r.is_finite() {
                self.diverged = true;
            } else {
                let d = (x - r).abs();
                self.diff2.add_diff(x, r);
                self.ref2.add(r);
                if d.is_finite() {
                    self.max_abs = self.max_abs.max(d);
                } else {
                    self.beyond = true;
                }
            }
            self.n += 1;
        }
        Ok(())
    }

    fn reset(&mut self) {
        *self = ErrorSink::default();
    }

    fn finish(&mut self) -> Result<Summary, NodeError> {
        if self.n == 0 {
            return Err(NodeError::Data("no samples reached this sink".into()));
        }
        let n = self.n as f64;
        let ref_rms = self.ref2.root_mean(n);
        if ref_rms.m == 0.0 && !self.diverged {
            return Err(NodeError::Data("the reference is all zero: a relative error is undefined".into()));
        }
        let (rms, rel, max, cut) = if self.diverged {
            (f64::INFINITY, f64::INFINITY / ref_rms.saturated().0, f64::INFINITY, false)
        } else {
            let d = self.diff2.root_mean(n);
            let (rms, rms_cut) = d.saturated();
            let rel = d.ratio(ref_rms);
            let max = if self.beyond { f64::MAX } else { self.max_abs };
            (rms, rel.min(f64::MAX), max, rms_cut || rel.is_infinite() || self.beyond)
        };
        let mut s = Summary::default()
            .value("rms", rms, "")
            .value("rel_rms", rel, "1")
            .value("max_abs", max, "")
            .value("samples", n, "1");
        if self.diverged {
            s = s.line("the test stream held NaN or infinite samples: it diverged (error reported as infinite)");
        }
        if cut {
            s = s.line(
                "the differences of samples near ±f64::MAX reach beyond f64::MAX: what lies beyond it is reported as f64::MAX",
            );
        }
        Ok(s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use evflow_engine::harness::Single;
    use std::f64::consts::TAU;

    fn run(x: Vec<f64>, r: Vec<f64>) -> Result<Summary, String> {
        let ticks = x.len() as u64;
        let s = Single::new(&SPEC, "").input("test", x, 1000.0).input("reference", r, 1000.0).ticks(ticks).block(128);
        s.summary()
    }

    fn get(s: &Summary, k: &str) -> f64 {
        s.get(k).unwrap_or_else(|| panic!("no value `{k}`"))
    }

    #[test]
    fn a_phase_shift_gives_the_analytic_error() {
        // sin(θ + δ) − sin θ has RMS √2·|sin(δ/2)| over whole periods; relative to 1/√2: 2|sin(δ/2)|.
        let d = 1e-3;
        let r: Vec<f64> = (0..1000).map(|n| (TAU * 5.0 * n as f64 / 1000.0).sin()).collect();
        let x: Vec<f64> = (0..1000).map(|n| (TAU * 5.0 * n as f64 / 1000.0 + d).sin()).collect();
        let s = run(x, r.clone()).unwrap();
        let want = 2.0 * (d / 2.0).sin();
        assert!((get(&s, "rel_rms") - want).abs() < 1e-9 * want + 1e-15, "{} vs {want}", get(&s, "rel_rms"));
        let same = run(r.clone(), r).unwrap();
        assert_eq!(get(&same, "rms"), 0.0);
    }

    #[test]
    fn inputs_near_max_give_finite_true_errors() {
        // ±3e300 against a reference of 1e300: differences of 2e300 and
        // 4e300, whose plain squares overflowed (rms inf, rel_rms NaN).
        let s = run(vec![3e300, -3e300, 3e300, -3e300], vec![1e300; 4]).unwrap();
        assert_eq!(get(&s, "max_abs"), 4e300);
        let want = (0.5 * (2e300f64 / 1e150).powi(2) + 0.5 * (4e300f64 / 1e150).powi(2)).sqrt() * 1e150;
        assert!((get(&s, "rms") - want).abs() <= 1e-15 * want, "{:e} vs {want:e}", get(&s, "rms"));
        assert!((get(&s, "rel_rms") - want / 1e300).abs() <= 1e-15 * want / 1e300, "{:e}", get(&s, "rel_rms"));
        assert!(s.lines.is_empty(), "{:?}", s.lines);
        // Steps to ±MAX against their negation: every difference is 2·MAX
        // or 0. rel_rms is exact (2); rms and max_abs are cut at MAX.
        let x = vec![0.0, f64::MAX, f64::MAX, -f64::MAX];
        let r: Vec<f64> = x.iter().map(|v| -v).collect();
        let s = run(x, r).unwrap();
        assert_eq!((get(&s, "rms"), get(&s, "max_abs")), (f64::MAX, f64::MAX));
        assert_eq!(get(&s, "rel_rms"), 2.0);
        assert!(s.lines.iter().any(|l| l.contains("beyond f64::MAX")), "{:?}", s.lines);
        // An impulse of MAX in both, one sample apart.
        let s = run(vec![0.0, f64::MAX, 0.0, 0.0], vec![0.0, 0.0, f64::MAX, 0.0]).unwrap();
        assert_eq!((get(&s, "max_abs"), get(&s, "rel_rms")), (f64::MAX, 2f64.sqrt()));
        assert_eq!(get(&s, "rms"), f64::MAX * 0.5f64.sqrt());
    }

    #[test]
    fn a_subnormal_reference_gives_a_relative_error() {
        // Its squares underflow to 0: the plain sums called it all zero.
        let r = vec![5e-324, -5e-324, 1e-310, -1e-310];
        let x: Vec<f64> = r.iter().map(|v| v * 2.0).collect();
        let s = run(x, r).unwrap();
        assert_eq!(get(&s, "rel_rms"), 1.0);
        assert_eq!(get(&s, "max_abs"), 1e-310);
    }

    #[test]
    fn a_zero_reference_is_an_error() {
        assert!(run(vec![1.0; 10], vec![0.0; 10]).unwrap_err().contains("all zero"));
    }
}
