//! `error`: how far a stream is from a reference stream.

use crate::sum::Sum;
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
precision. A non-finite input sample is reported as an infinite error, not an error of the run: \
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
    diff2: Sum,
    ref2: Sum,
    max_abs: f64,
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
            let d = x - r;
            if !d.is_finite() || !r.is_finite() {
                self.diverged = true;
            } else {
                self.diff2.add(d * d);
                self.ref2.add(r * r);
                self.max_abs = self.max_abs.max(d.abs());
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
        let ref_rms = (self.ref2.value() / n).sqrt();
        if ref_rms == 0.0 && !self.diverged {
            return Err(NodeError::Data("the reference is all zero: a relative error is undefined".into()));
        }
        let (rms, max) = if self.diverged {
            (f64::INFINITY, f64::INFINITY)
        } else {
            ((self.diff2.value() / n).sqrt(), self.max_abs)
        };
        let mut s = Summary::default()
            .value("rms", rms, "")
            .value("rel_rms", rms / ref_rms, "1")
            .value("max_abs", max, "")
            .value("samples", n, "1");
        if self.diverged {
            s = s.line("the test stream held NaN or infinite samples: it diverged (error reported as infinite)");
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
    fn a_zero_reference_is_an_error() {
        assert!(run(vec![1.0; 10], vec![0.0; 10]).unwrap_err().contains("all zero"));
    }
}
