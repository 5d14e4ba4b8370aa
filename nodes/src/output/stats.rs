//! `stats`: a sink that reports count, mean, RMS, min, max and peak-to-peak.

use crate::sum::SumPair;
use crate::wide_sum::{ordinary, SumSq, WideSum};
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

    /// Adds a block whose samples are all [`ordinary`] while both sums are
    /// unscaled: the sums in registers, with the same operations in the
    /// same order as the sample-by-sample loop (which keeps them in
    /// memory, as it may rescale), and the extremes from a vectorized
    /// pass. False, having added nothing, where that does not hold.
    fn add_ordinary(&mut self, x: &[f64]) -> bool {
        let Some((peak, lo, hi)) = ordinary_extremes(x, self.min, self.max) else {
            return false;
        };
        // The sum first: the sum of squares' `plain_mut` raises its largest |x|.
        let Some(sum) = self.sum.plain_mut() else { return false };
        let Some(sum_sq) = self.sum_sq.plain_mut(peak) else { return false };
        let mut pair = SumPair::new(*sum, *sum_sq);
        for &v in x {
            pair.add(v, v * v);
        }
        (*sum, *sum_sq) = pair.sums();
        (self.min, self.max) = if lo == 0.0 || hi == 0.0 {
            x.iter().fold((self.min, self.max), |(lo, hi), &v| (lo.min(v), hi.max(v)))
        } else {
            (lo, hi)
        };
        self.n += x.len() as u64;
        true
    }
}

/// If every sample of `x` is [`ordinary`] (so finite): its largest |x|,
/// and its minimum and maximum taken with `lo` and `hi`, in one pass in
/// four lanes that the compiler vectorizes. The extremes are those of an
/// in-order pass but for the sign of a zero (the minimum of a set of
/// finite numbers does not depend on the order it is taken in, except
/// between −0 and +0), so a caller takes a zero extreme again in order.
fn ordinary_extremes(x: &[f64], lo: f64, hi: f64) -> Option<(f64, f64, f64)> {
    const L: usize = 4;
    let (mut ok, mut peak, mut min, mut max) = ([true; L], [0.0f64; L], [lo; L], [hi; L]);
    let chunks = x.chunks_exact(L);
    let rest = chunks.remainder();
    let mut lane = |i: usize, v: f64| {
        ok[i] &= ordinary(v);
        let a = v.abs();
        peak[i] = if a > peak[i] { a } else { peak[i] };
        min[i] = if v < min[i] { v } else { min[i] };
        max[i] = if v > max[i] { v } else { max[i] };
    };
    for c in chunks {
        for (i, &v) in c.iter().enumerate() {
            lane(i, v);
        }
    }
    for (i, &v) in rest.iter().enumerate() {
        lane(i, v);
    }
    if !ok.iter().all(|&o| o) {
        return None;
    }
    let top = |a: [f64; L], better: fn(f64, f64) -> bool| a.into_iter().reduce(|m, v| if better(v, m) { v } else { m });
    Some((top(peak, |v, m| v > m)?, top(min, |v, m| v < m)?, top(max, |v, m| v > m)?))
}

fn build(_: &evflow_engine::Params, _: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
    Ok(Box::new(Stats::new()))
}

impl Node for Stats {
    fn process(&mut self, io: &mut Io<'_>) -> Result<(), NodeError> {
        let x = io.input(IN);
        if self.add_ordinary(x) {
            return Ok(());
        }
        for &x in x {
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

    /// The sample-by-sample loop every block went through before the
    /// ordinary-block path: the reference it must match bit for bit.
    fn reference(x: &[f64]) -> [u64; 5] {
        let (mut sum, mut sum_sq, mut lo, mut hi) = (
            WideSum::<crate::sum::Sum>::default(),
            SumSq::<crate::sum::Sum>::default(),
            f64::INFINITY,
            f64::NEG_INFINITY,
        );
        for &v in x {
            sum.add(v);
            sum_sq.add(v);
            lo = lo.min(v);
            hi = hi.max(v);
        }
        let n = x.len() as f64;
        [sum.mean(n), sum_sq.root_mean(n).saturated().0, lo, hi, (hi - lo).min(f64::MAX)].map(f64::to_bits)
    }

    #[test]
    fn ordinary_blocks_give_the_sample_by_sample_bits() {
        let mut r = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = move || {
            r ^= r << 13;
            r ^= r >> 7;
            r ^= r << 17;
            (r >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let noise: Vec<f64> = (0..5000).map(|_| next() * 1e3).collect();
        let zeros_first: Vec<f64> = [0.0, -0.0, 0.0].into_iter().chain(noise.iter().map(|v| v.abs())).collect();
        let zeros_last: Vec<f64> = noise.iter().map(|v| -v.abs()).chain([-0.0, 0.0, -0.0]).collect();
        // A tiny sample scales the sum of squares for a while, a huge one
        // the sum for good: blocks around them take the per-sample path.
        let mut mixed = noise.clone();
        mixed[700] = 1e-300;
        mixed[3000] = 1e200;
        mixed[4100] = 2e300;
        for x in [&noise, &zeros_first, &zeros_last, &mixed] {
            let want = reference(x);
            for block in [1, 3, 64, 1000, x.len()] {
                let mut s = Stats::new();
                let mut outs: [Vec<f64>; 0] = [];
                for (k, c) in x.chunks(block).enumerate() {
                    let pool = vec![c.to_vec()];
                    s.process(&mut Io::new(&pool, &[0], &[c.len()], &mut outs, &[], (k * block) as u64)).unwrap();
                }
                let got = s.finish().unwrap();
                let got = ["mean", "rms", "min", "max", "pp"].map(|k| get(&got, k).to_bits());
                assert_eq!(got, want, "block {block}");
            }
        }
    }

    #[test]
    fn nan_and_empty_are_errors() {
        assert!(feed(&[1.0, f64::NAN]).unwrap_err().to_string().contains("sample 1"));
        assert!(feed(&[]).unwrap_err().to_string().contains("no samples"));
    }
}
