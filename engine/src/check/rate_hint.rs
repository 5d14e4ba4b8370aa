//! The rate node that joins two rates, suggested as the lines to paste into
//! the graph file where a connection joins ports of different rates.
//!
//! The engine knows the node library only by these names (the suggestion
//! is text): `decimate` for an integer step down (it filters out what would
//! alias), `hold` for an integer step up of a stream slower than the base
//! clock — a control stream such as a 40 Hz touch report, held until the
//! next one — and `resample` for every other step (a ratio that is not an
//! integer, or raising a stream at or above the base rate, whose samples
//! are a signal to interpolate rather than hold).

use crate::graph::{Endpoint, Graph};
use crate::params::toml_float;
use crate::rate::Ratio;

/// The rate node that fits a step between two rates.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum RateNode {
    /// Integer step down, anti-aliased.
    Decimate,
    /// Integer step up of a control stream.
    Hold,
    /// Any other ratio.
    Resample,
}

impl RateNode {
    /// The node type's name.
    pub(crate) fn name(self) -> &'static str {
        match self {
            RateNode::Decimate => "decimate",
            RateNode::Hold => "hold",
            RateNode::Resample => "resample",
        }
    }
}

/// True when `a` is a whole multiple of `b` (both ratios to the base rate).
fn divides(a: Ratio, b: Ratio) -> bool {
    // a/b = (a.mul · b.div) / (a.div · b.mul), in exact integers.
    let num = a.mul as u128 * b.div as u128;
    let den = a.div as u128 * b.mul as u128;
    den != 0 && num.is_multiple_of(den)
}

/// The node for a stream at `from` feeding an input at `to` (`from ≠ to`).
pub(crate) fn choose(from: Ratio, to: Ratio) -> RateNode {
    let faster = from.mul as u128 * to.div as u128 > to.mul as u128 * from.div as u128;
    if faster {
        if divides(from, to) {
            RateNode::Decimate
        } else {
            RateNode::Resample
        }
    } else if from.div > 1 && divides(to, from) {
        RateNode::Hold
    } else {
        RateNode::Resample
    }
}

/// A rate in Hz for names: `40`, `1000`, `12_5` for 12.5.
fn hz_word(hz: f64) -> String {
    if hz.fract() == 0.0 && hz.abs() < 1e15 {
        format!("{}", hz as i64)
    } else {
        format!("{hz}").replace(['.', '-', '+'], "_")
    }
}

/// The help of a rate-mismatch error: the node that fits, why, and the
/// node table and connections to paste in place of `producer -> consumer`.
pub(crate) fn help(graph: &Graph, producer: &Endpoint, consumer: &Endpoint, from: Ratio, to: Ratio) -> String {
    let base = graph.rate;
    let (from_hz, to_hz) = (from.hz(base), to.hz(base));
    let node = choose(from, to);
    let why = match node {
        RateNode::Decimate => format!(
            "an integer step down, {from_hz} Hz ÷ {}, with the anti-aliasing filter it needs",
            (from_hz / to_hz).round() as u64
        ),
        RateNode::Hold => format!(
            "the {from_hz} Hz stream is slower than the {base} Hz base clock, a control stream: each sample \
             is held until the next; `resample` instead interpolates between them"
        ),
        RateNode::Resample => {
            if from_hz > to_hz {
                format!("a step down by {:.4}, not a whole number, which `decimate` cannot take", from_hz / to_hz)
            } else {
                format!("{from_hz} Hz up to {to_hz} Hz, interpolated; its `quality` sets the filter and the latency")
            }
        }
    };
    let stem = format!("{}_{}hz", producer.node, hz_word(to_hz));
    let mut name = stem.clone();
    let mut k = 2;
    while graph.nodes.iter().any(|n| n.name == name) {
        name = format!("{stem}_{k}");
        k += 1;
    }
    let mut table = format!("[nodes.{name}]\n      type = \"{}\"\n      rate = {}", node.name(), toml_float(to_hz));
    if node == RateNode::Resample {
        table += "\n      quality = \"balanced\"";
    }
    format!(
        "insert a `{}` node ({why}). Add\n      {table}\n    and in `connections` replace \"{producer} -> {consumer}\" \
         with\n      \"{producer} -> {name}.in\",\n      \"{name}.out -> {consumer}\",",
        node.name()
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn r(mul: u64, div: u64) -> Ratio {
        Ratio { mul, div }
    }

    #[test]
    fn the_node_that_fits_each_step() {
        // 10 kHz → 1 kHz, 1 kHz → 40 Hz: integer steps down.
        assert_eq!(choose(r(10, 1), r(1, 1)), RateNode::Decimate);
        assert_eq!(choose(r(1, 1), r(1, 25)), RateNode::Decimate);
        assert_eq!(choose(r(1, 4), r(1, 100)), RateNode::Decimate);
        // 250 Hz → 100 Hz (÷2.5): not an integer.
        assert_eq!(choose(r(1, 4), r(1, 10)), RateNode::Resample);
        // 40 Hz → 1 kHz, 10 Hz → 40 Hz: control streams up.
        assert_eq!(choose(r(1, 25), r(1, 1)), RateNode::Hold);
        assert_eq!(choose(r(1, 100), r(1, 25)), RateNode::Hold);
        // 40 Hz → 100 Hz (×2.5), 1 kHz → 10 kHz (a signal at the base rate): interpolate.
        assert_eq!(choose(r(1, 25), r(1, 10)), RateNode::Resample);
        assert_eq!(choose(r(1, 1), r(10, 1)), RateNode::Resample);
    }

    #[test]
    fn rate_words() {
        assert_eq!(hz_word(40.0), "40");
        assert_eq!(hz_word(12.5), "12_5");
        assert_eq!(hz_word(44_100.0), "44100");
    }
}

/// The rates nearest `hz` that fit a base rate (base ÷ k or base × k),
/// one below and one above (the same when `hz` is beyond the last).
pub(crate) fn nearest_fitting(hz: f64, base: f64) -> (f64, f64) {
    if !(hz.is_finite() && hz > 0.0 && base > 0.0) {
        return (base, base);
    }
    if hz >= base {
        let m = hz / base;
        (base * m.floor().max(1.0), base * m.ceil().max(1.0))
    } else {
        let k = base / hz;
        (base / k.ceil(), base / k.floor().max(1.0))
    }
}

/// The help of a rate that does not fit the base: the nearest that do.
pub(crate) fn fitting_help(hz: f64, base: f64) -> String {
    let (lo, hi) = nearest_fitting(hz, base);
    let show = |r: f64| {
        let ratio = Ratio::of(r, base).unwrap_or(Ratio::ONE);
        let how =
            if ratio.div > 1 { format!("{base} Hz ÷ {}", ratio.div) } else { format!("{base} Hz × {}", ratio.mul) };
        format!("{r} Hz ({how})")
    };
    if lo == hi {
        format!("the nearest rate that fits the base rate {base} Hz is {}", show(lo))
    } else {
        format!("the nearest rates that fit the base rate {base} Hz are {} and {}", show(lo), show(hi))
    }
}

#[cfg(test)]
mod nearest_tests {
    use super::*;

    #[test]
    fn the_nearest_fitting_rates_bracket_the_asked_one() {
        assert_eq!(nearest_fitting(300.0, 1000.0), (250.0, 1000.0 / 3.0));
        assert_eq!(nearest_fitting(1500.0, 1000.0), (1000.0, 2000.0));
        assert_eq!(nearest_fitting(600.0, 1000.0), (500.0, 1000.0));
        let h = fitting_help(300.0, 1000.0);
        assert!(h.contains("250 Hz (1000 Hz ÷ 4)") && h.contains("(1000 Hz ÷ 3)"), "{h}");
    }
}
