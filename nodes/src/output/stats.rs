//! `stats`: a sink that reports count, mean, RMS, min, max and peak-to-peak.

use crate::wide_sum::{SumSq, WideSum};
use evflow_engine::ports::{InPort, SAME_AS_INPUT};
use evflow_engine::{BuildContext, Io, Node, NodeError, NodeSpec, PortSpec, Role, Summary};

/// Declaration of `stats`.
pub static SPEC: NodeSpec = NodeSpec::new(
    "stats",
    "output",
    Role::Sink,
    "Reports count, mean, RMS, min, max and peak-to-peak of a stream.",
    build,
)
.doc(
    "A sink for checking a chain's output at a glance: at the end of the run it reports the \
             number of samples, the mean, the RMS (root of the mean square, about zero — not the \
             standard deviation), the minimum, the maximum and the peak-to-peak amplitude. Sums are \
             kept with Kahan–Babuška (Neumaier) compensation so long runs (10⁸ samples) lose no \
             precision, and scaled by a power of two where a plain sum would over- or underflow \
             (samples near ±f64::MAX, or subnormal), so the mean and RMS of any finite samples are \
             right; a peak-to-peak beyond f64::MAX (max − min of samples near ±f64::MAX) is \
             reported as f64::MAX, with a line saying so. Accepts any rate. A NaN or Inf in the input is an error naming the sample \
             index, since no node may let one through. The mean, RMS, minimum, maximum and \
             peak-to-peak are in the unit of what feeds it (followed upstream, as `evflow check` \
             shows it).",
)
.ports(PORTS)
.example("");

/// The port: the stream to summarize, at any rate.
const PORTS: &[PortSpec] = &[PortSpec::input("in", "1", "the stream to summarize").at(evflow_engine::RateSpec::Any)];
/// The stream to summarize.
const IN: InPort = InPort::named(PORTS, "in");

struct Stats {
    n: u64,
    sum: WideSum,
    sum_sq: SumSq,
    min: f64,
    max: f64,
    bad: Option<u64>,
}

impl Stats {
    fn new() -> Self {
        Self {
            n: 0,
            sum: WideSum::default(),
            sum_sq: SumSq::default(),
            min: f64::INFINITY,
            max: f64::NEG_INFINITY,
            bad: None,
        }
    }
}

fn build(_: &evflow_engine::Params, _: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
    Ok(Box::new(Stats::new()))
}

impl Node for Stats {
    fn process(&mut self, io: &mut Io<'_>) -> Result<(), NodeError> {
        for &x in io.input(IN) {
            if !x.is_finite() && self.bad.is_none() {
                self.bad = Some(self.n);
            }
            self.sum.add(x);
            self.sum_sq.add(x);
            self.min = self.min.min(x);
            self.max = self.max.max(x);
            self.n += 1;
        }
        Ok(())
    }

    fn reset(&mut self) {
        *self = Stats::new();
    }

    fn finish(&mut self) -> Result<Summary, NodeError> {
        if let Some(i) = self.bad {
            return Err(NodeError::Data(format!("sample {i} of the input is NaN or infinite")));
        }
        if self.n == 0 {
            return Err(NodeError::Data("no samples reached this sink".into()));
        }
        let n = self.n as f64;
        // The RMS of finite samples is at most the largest |sample|: a cut
        // at f64::MAX only undoes rounding.
        let rms = self.sum_sq.root_mean(n).saturated().0;
        let pp = self.max - self.min;
        let s = Summary::default()
            .value("samples", n, "1")
            .value("mean", self.sum.mean(n), SAME_AS_INPUT)
            .value("rms", rms, SAME_AS_INPUT)
            .value("min", self.min, SAME_AS_INPUT)
            .value("max", self.max, SAME_AS_INPUT)
            .value("pp", pp.min(f64::MAX), SAME_AS_INPUT);
        Ok(if pp.is_finite() {
            s
        } else {
            s.line(format!("peak-to-peak {:e} − ({:e}) is beyond f64::MAX: reported as f64::MAX", self.max, self.min))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn feed(x: &[f64]) -> Result<Summary, NodeError> {
        let mut s = Stats::new();
        let pool = vec![x.to_vec()];
        let mut outs: [Vec<f64>; 0] = [];
        s.process(&mut Io::new(&pool, &[0], &[x.len()], &mut outs, &[], 0))?;
        s.finish()
    }

    fn get(s: &Summary, k: &str) -> f64 {
        s.values.iter().find(|(n, _, _)| n == k).unwrap().1
    }

    #[test]
    fn sine_statistics_are_analytic() {
        // A sine over whole periods: mean 0, RMS A/√2, p-p 2A.
        let a = 3.0;
        let x: Vec<f64> = (0..1000).map(|i| a * (2.0 * std::f64::consts::PI * 5.0 * i as f64 / 1000.0).sin()).collect();
        let s = feed(&x).unwrap();
        assert!(get(&s, "mean").abs() < 1e-12);
        assert!((get(&s, "rms") - a / 2f64.sqrt()).abs() < 1e-12);
        assert!((get(&s, "pp") - 2.0 * a).abs() < 1e-9);
        assert_eq!(get(&s, "samples"), 1000.0);
    }

    #[test]
    fn compensated_sum_keeps_precision() {
        // 1e8 + many small values: a naive sum loses them all.
        let mut x = vec![1e8];
        x.extend(std::iter::repeat_n(1e-8, 100_000));
        x.push(-1e8);
        let s = feed(&x).unwrap();
        let want = 1e-3 / x.len() as f64;
        assert!((get(&s, "mean") - want).abs() < 1e-15, "{}", get(&s, "mean"));
    }

    #[test]
    fn samples_near_max_give_finite_true_statistics() {
        // Steps 0 → +MAX → −MAX → 0: the plain sums overflowed (mean and
        // RMS NaN, p-p inf).
        let mut x = vec![0.0; 10];
        x.extend([f64::MAX; 10]);
        x.extend([-f64::MAX; 10]);
        x.extend([0.0; 10]);
        let s = feed(&x).unwrap();
        assert_eq!(get(&s, "mean"), 0.0);
        let want = f64::MAX * 0.5f64.sqrt();
        assert!((get(&s, "rms") - want).abs() <= 4.0 * f64::EPSILON * want, "{:e}", get(&s, "rms"));
        assert_eq!(get(&s, "pp"), f64::MAX);
        assert!(s.lines.iter().any(|l| l.contains("beyond f64::MAX")), "{:?}", s.lines);
        // One impulse of MAX among 4 samples: mean MAX/4, RMS MAX/2.
        let s = feed(&[0.0, f64::MAX, 0.0, 0.0]).unwrap();
        assert_eq!((get(&s, "mean"), get(&s, "rms"), get(&s, "pp")), (f64::MAX / 4.0, f64::MAX / 2.0, f64::MAX));
        assert!(s.lines.is_empty());
    }

    #[test]
    fn subnormal_samples_have_their_true_rms() {
        // Their squares underflow to 0: the plain RMS was 0.
        let s = feed(&[5e-324, -5e-324, 5e-324, -5e-324]).unwrap();
        assert_eq!(get(&s, "rms"), 5e-324);
        assert_eq!(get(&s, "mean"), 0.0);
    }

    #[test]
    fn nan_and_empty_are_errors() {
        assert!(feed(&[1.0, f64::NAN]).unwrap_err().to_string().contains("sample 1"));
        assert!(feed(&[]).unwrap_err().to_string().contains("no samples"));
    }
}
