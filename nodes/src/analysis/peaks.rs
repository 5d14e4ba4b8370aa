//! `peaks`: the mean of the largest peak-to-peak amplitudes of a vibration.

use crate::wide_sum::WideSum;
use evflow_engine::ports::InPort;
use evflow_engine::typed_params::Int;
use evflow_engine::{BuildContext, Io, Node, NodeError, NodeSpec, Params, PortSpec, Role, Summary};
use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// Declaration of `peaks`.
pub static SPEC: NodeSpec = NodeSpec::new(
    "peaks",
    "analysis",
    Role::Sink,
    "Mean of the N largest peak-to-peak amplitudes of a vibratory force (§3.1.2).",
    build,
)
.doc(
    "The vibratory-force measure of dissertation §3.1.2 (Fig. 3.3c): \"we computed the p-p \
amplitudes of the tangential force and then averaged the 50 largest\". The input is split at its \
turning points (samples where it stops rising or falling; a run of equal samples is one point); \
each swing between consecutive turning points is one peak-to-peak amplitude |x_max − x_min| (the \
partial swings before the first and after the last turning point are not counted). At \
the end of the run the node reports `pp_mean`, the mean of the `count` largest swings (of all \
of them if there are fewer), `pp_max`, the largest, and `swings`, how many there were. Low-pass \
the force first (the dissertation used 500 Hz): noise adds small swings, which never rank among \
the largest but split a noisy peak. A swing between samples near ±f64::MAX can exceed f64::MAX: \
it is kept exactly (as its half) and ranked and averaged as it is; a `pp_mean` or `pp_max` beyond \
f64::MAX is reported as f64::MAX, with a line saying so.\n\
\n\
**Port** `in` at any rate. The largest swings are kept in a heap sized when the node is built; \
`process` does not allocate. A NaN or infinite sample is an error naming its index.\n\
\n\
**Checked against:** a sine of amplitude A (every swing 2A), a sum of two sines with a known \
envelope maximum, and a signal with fewer swings than `count`.",
)
.ports(PORTS)
.params(&[COUNT.spec()])
.example("count = 50");

/// The port: the force, at any rate.
const PORTS: &[PortSpec] =
    &[PortSpec::input("in", "N", "the vibratory force (low-passed)").at(evflow_engine::RateSpec::Any)];
/// The vibratory force.
const IN: InPort = InPort::named(PORTS, "in");

/// `count`: how many of the largest swings are averaged.
const COUNT: Int = Int::new("count", 1, 1_000_000, 50, "1", "how many of the largest swings are averaged");

/// One swing's amplitude, ordered for the heap: `v` itself, or — where
/// the amplitude overflows f64 (samples near ±f64::MAX) — `2·v`, with
/// `double` set; a doubled swing ranks above every other.
#[derive(Clone, Copy, PartialEq)]
struct Swing {
    double: bool,
    v: f64,
}
impl Swing {
    /// |a − b|, exactly.
    fn between(a: f64, b: f64) -> Self {
        let v = (a - b).abs();
        if v.is_finite() {
            Swing { double: false, v }
        } else {
            Swing { double: true, v: (0.5 * a - 0.5 * b).abs() }
        }
    }
}
impl Eq for Swing {}
impl PartialOrd for Swing {
    fn partial_cmp(&self, o: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Swing {
    fn cmp(&self, o: &Self) -> std::cmp::Ordering {
        self.double.cmp(&o.double).then(self.v.total_cmp(&o.v))
    }
}

struct Peaks {
    count: usize,
    /// The largest swings so far (a min-heap: the smallest of them on top).
    best: BinaryHeap<Reverse<Swing>>,
    /// The last turning point's value, once there is one.
    turn: Option<f64>,
    /// The last sample and the direction since the last turning point
    /// (+1 rising, −1 falling, 0 not yet known).
    last: Option<f64>,
    dir: i8,
    swings: u64,
    n: u64,
    bad: Option<u64>,
}

fn build(p: &Params, _: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
    let count = COUNT.count(p);
    Ok(Box::new(Peaks {
        count,
        best: BinaryHeap::with_capacity(count + 1),
        turn: None,
        last: None,
        dir: 0,
        swings: 0,
        n: 0,
        bad: None,
    }))
}

impl Peaks {
    fn swing(&mut self, pp: Swing) {
        self.swings += 1;
        if self.best.len() < self.count {
            self.best.push(Reverse(pp));
        } else if self.best.peek().is_some_and(|Reverse(m)| pp > *m) {
            self.best.pop();
            self.best.push(Reverse(pp));
        }
    }

    fn sample(&mut self, x: f64) {
        let Some(prev) = self.last else {
            self.last = Some(x);
            return;
        };
        let d = if x > prev {
            1
        } else if x < prev {
            -1
        } else {
            0
        };
        if d != 0 {
            if self.dir != 0 && d != self.dir {
                // `prev` was a turning point: the swing from the last one ends there.
                if let Some(t) = self.turn {
                    self.swing(Swing::between(prev, t));
                }
                self.turn = Some(prev);
            }
            self.dir = d;
        }
        self.last = Some(x);
    }
}

impl Node for Peaks {
    fn process(&mut self, io: &mut Io<'_>) -> Result<(), NodeError> {
        for &x in io.input(IN) {
            if !x.is_finite() {
                self.bad.get_or_insert(self.n);
            } else if self.bad.is_none() {
                self.sample(x);
            }
            self.n += 1;
        }
        Ok(())
    }

    fn reset(&mut self) {
        self.best.clear();
        self.turn = None;
        self.last = None;
        self.dir = 0;
        self.swings = 0;
        self.n = 0;
        self.bad = None;
    }

    fn finish(&mut self) -> Result<Summary, NodeError> {
        if let Some(i) = self.bad {
            return Err(NodeError::Data(format!("sample {i} of the input is NaN or infinite")));
        }
        if self.best.is_empty() {
            return Err(NodeError::Data(
                "no complete swing (the input needs at least two turning points): no peak-to-peak amplitude to measure"
                    .into(),
            ));
        }
        let k = self.best.len();
        // A doubled swing is summed as its half twice (exact, and a sum
        // that overflows scales).
        let mut sum = WideSum::<f64>::default();
        for Reverse(s) in &self.best {
            sum.add(s.v);
            if s.double {
                sum.add(s.v);
            }
        }
        let (mean, mean_cut) = sum.mean_scaled(k as f64).saturated();
        let top = self.best.iter().map(|Reverse(s)| *s).max().unwrap_or(Swing { double: false, v: 0.0 });
        let (max, max_cut) = if top.double { (f64::MAX, true) } else { (top.v, false) };
        let s = Summary::default()
            .value("pp_mean", mean, "N")
            .value("pp_max", max, "N")
            .value("swings", self.swings as f64, "1")
            .value("averaged", k as f64, "1");
        Ok(match (mean_cut, max_cut) {
            (false, false) => s,
            (true, _) => s.line("pp_mean and pp_max are beyond f64::MAX: reported as f64::MAX"),
            (false, true) => s.line(format!("pp_max ({:e} × 2) is beyond f64::MAX: reported as f64::MAX", top.v)),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use evflow_engine::harness::Single;
    use std::f64::consts::TAU;

    fn summary(x: Vec<f64>, params: &str) -> Result<Summary, String> {
        let ticks = x.len() as u64;
        let s = Single::new(&SPEC, params).input("in", x, 1000.0).ticks(ticks).block(100);
        s.summary()
    }

    fn get(s: &Summary, k: &str) -> f64 {
        s.get(k).unwrap_or_else(|| panic!("no value `{k}`"))
    }

    #[test]
    fn a_sine_swings_twice_its_amplitude() {
        // 10 Hz sampled at 1 kHz with a phase that puts samples on the peaks.
        let x: Vec<f64> = (0..2000).map(|n| 0.3 * (TAU * 10.0 * n as f64 / 1000.0 + TAU / 4.0).cos()).collect();
        let s = summary(x, "count = 50").unwrap();
        assert!((get(&s, "pp_mean") - 0.6).abs() < 1e-12, "{}", get(&s, "pp_mean"));
        // 20 periods: 40 turning points, 39 complete swings between them.
        assert_eq!(get(&s, "swings"), 39.0);
    }

    #[test]
    fn only_the_largest_swings_are_averaged() {
        // Beats: swings grow and shrink; the top 5 are the largest ones.
        let x: Vec<f64> = (0..4000)
            .map(|n| n as f64 / 1000.0)
            .map(|t| (TAU * 50.0 * t).sin() * (1.0 + (TAU * 0.5 * t).sin()))
            .collect();
        let s = summary(x.clone(), "count = 5").unwrap();
        let all = summary(x, "count = 100000").unwrap();
        assert!(get(&s, "pp_mean") > 3.8 && get(&s, "pp_mean") <= 4.0, "{}", get(&s, "pp_mean"));
        assert!(get(&all, "pp_mean") < get(&s, "pp_mean"));
        assert_eq!(get(&all, "averaged"), get(&all, "swings"));
    }

    #[test]
    fn swings_between_samples_near_max_are_measured() {
        // Steps 0 → +MAX → −MAX → 0: swings of MAX, 2·MAX and MAX; the
        // plain amplitudes overflowed to inf (pp_mean and pp_max inf).
        let mut x = vec![0.0; 5];
        x.extend([f64::MAX; 5]);
        x.extend([-f64::MAX; 5]);
        x.extend([0.0; 5]);
        x.extend([1.0, 0.0]);
        let s = summary(x.clone(), "count = 50").unwrap();
        // Swings 2·MAX (+MAX down to −MAX) and MAX (up to 1): mean 1.5·MAX.
        assert_eq!(get(&s, "swings"), 2.0);
        assert_eq!((get(&s, "pp_mean"), get(&s, "pp_max")), (f64::MAX, f64::MAX));
        assert!(s.lines.iter().any(|l| l.contains("beyond f64::MAX")), "{:?}", s.lines);
        // With 15 more swings of 1 the mean is back in range: (2·MAX + MAX + 15)/17.
        x.extend([0.0, 1.0].repeat(8));
        let s = summary(x, "count = 20").unwrap();
        assert_eq!(get(&s, "swings"), 17.0);
        let want = f64::MAX / 17.0 * 3.0;
        assert!((get(&s, "pp_mean") - want).abs() <= 4.0 * f64::EPSILON * want, "{:e}", get(&s, "pp_mean"));
        assert_eq!(get(&s, "pp_max"), f64::MAX);
        // Two impulses of MAX: three swings of MAX, whose plain sum overflowed.
        let s = summary(vec![0.0, f64::MAX, 0.0, f64::MAX, 0.0, 1.0], "").unwrap();
        assert_eq!(get(&s, "swings"), 3.0);
        assert_eq!((get(&s, "pp_mean"), get(&s, "pp_max")), (f64::MAX, f64::MAX));
        assert!(s.lines.is_empty(), "{:?}", s.lines);
    }

    #[test]
    fn constant_or_monotonic_inputs_are_errors() {
        assert!(summary(vec![1.0; 100], "").unwrap_err().contains("no complete swing"));
        assert!(summary((0..100).map(f64::from).collect(), "").unwrap_err().contains("no complete swing"));
        // One turning point is not a swing; two are.
        let x: Vec<f64> = (0..30).map(|n| -((n as f64 - 10.0).abs())).collect();
        assert!(summary(x, "").is_err());
        let x: Vec<f64> = [0.0, 1.0, 0.5, 2.0, 1.0].to_vec();
        let s = summary(x, "").unwrap();
        assert_eq!((get(&s, "pp_mean"), get(&s, "swings")), (1.0, 2.0));
    }
}
