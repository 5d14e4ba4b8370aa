//! `prbs`: a maximum-length pseudo-random binary signal, sample for sample
//! the one MATLAB `idinput` generates.

use super::prbs_taps::{self, Taps};
use evflow_engine::ports::OutPort;
use evflow_engine::spec::{BoundArgs, PortBound};
use evflow_engine::typed_params::{Float, Int};
use evflow_engine::{BuildContext, Io, Node, NodeError, NodeSpec, Params, PortSpec, Role};

/// Declaration of `prbs`.
pub static SPEC: NodeSpec = NodeSpec::new(
    "prbs",
    "sources",
    Role::Source,
    "Maximum-length pseudo-random binary signal ±c, compatible with MATLAB idinput 'prbs'.",
    build,
)
.doc(
    "A periodic two-level signal with white-noise-like properties, the actuation signal used to \
identify the electrovibration display (dissertation §5.2.1, *Pseudo-Random Binary Signals*, Fig. 5.2: \
PRBS9, c = 1, B = 1, six periods = 3066 samples at 1 kHz).\n\
\n\
**Generator.** A shift register of order n holds the last n values u[k−1] … u[k−n] (±1), started at \
all −1; each chip is u[k] = Π u[k − t] over the taps t below, and the value leaving the register is \
the output. The output is c·u, each chip held for `clock` = B samples; one period is (2ⁿ − 1)·B \
samples, with 2ⁿ⁻¹ chips at −c and 2ⁿ⁻¹ − 1 at +c. This is MATLAB's algorithm: the output equals \
`idinput([(2^n-1)*B, 1, periods], 'prbs', [0 1/B], [-c c])` (orders 3–18, where `idinput` picks \
order n for that period). For n = 9 the signal starts `---------++++----+---++++-+--++-`.\n\
\n\
**Ends** after `periods` × (2ⁿ − 1) × B samples (a finite source: an offline run stops there); if \
asked for samples past the end it writes 0.\n\
\n\
**Port** `out` at the rate set by `rate`.\n\
\n\
**Taps per order** (lags t in u[k] = Π u[k − t]):\n\
\n\
| n | taps | source |\n\
|---|---|---|\n\
| 2 | 1, 2 | x²+x+1 (unique) |\n\
| 3 | 1, 3 | MATLAB idinput |\n\
| 4 | 1, 4 | MATLAB idinput |\n\
| 5 | 2, 5 | MATLAB idinput |\n\
| 6 | 1, 6 | MATLAB idinput |\n\
| 7 | 1, 7 | MATLAB idinput |\n\
| 8 | 1, 2, 7, 8 | MATLAB idinput |\n\
| 9 | 4, 9 | MATLAB idinput |\n\
| 10 | 3, 10 | MATLAB idinput |\n\
| 11 | 9, 11 | MATLAB idinput |\n\
| 12 | 6, 8, 11, 12 | MATLAB idinput |\n\
| 13 | 9, 10, 12, 13 | MATLAB idinput |\n\
| 14 | 4, 8, 13, 14 | MATLAB idinput |\n\
| 15 | 14, 15 | MATLAB idinput |\n\
| 16 | 4, 13, 15, 16 | MATLAB idinput |\n\
| 17 | 14, 17 | MATLAB idinput |\n\
| 18 | 11, 18 | MATLAB idinput |\n\
| 19 | 1, 2, 6, 19 | Xilinx XAPP052 |\n\
| 20 | 17, 20 | Xilinx XAPP052 |\n\
| 21 | 19, 21 | Xilinx XAPP052 |\n\
| 22 | 21, 22 | Xilinx XAPP052 |\n\
| 23 | 18, 23 | Xilinx XAPP052 |\n\
| 24 | 17, 22, 23, 24 | Xilinx XAPP052 |\n\
| 25 | 22, 25 | Xilinx XAPP052 |\n\
| 26 | 1, 2, 6, 26 | Xilinx XAPP052 |\n\
| 27 | 1, 2, 5, 27 | Xilinx XAPP052 |\n\
| 28 | 25, 28 | Xilinx XAPP052 |\n\
| 29 | 27, 29 | Xilinx XAPP052 |\n\
| 30 | 1, 4, 6, 30 | Xilinx XAPP052 |\n\
\n\
MATLAB idinput = System Identification Toolbox `idinput.m` rev. 1.13.2.2 (2004), whose table covers \
orders 3–18 (later releases moved the generator elsewhere; their table was not available to check). \
Xilinx XAPP052 = P. Alfke, *Efficient Shift Registers, LFSR Counters, and Long Pseudo-Random \
Sequence Generators*, XAPP 052 v1.1 (1996), Table 3.\n\
\n\
**Checked against:** the first 32 samples of MATLAB's PRBS9 above; for PRBS9 the period 511 with \
255/256 samples at ±c, the two-valued periodic autocorrelation R(0) = 1, R(k) = −1/511, and a flat \
spectrum (every non-DC bin of the 511-point DFT has |X|² = 512·c²); maximal period 2ⁿ − 1 for every \
order 2–30 (full walk up to n = 22, and for all orders the register's return after exactly 2ⁿ − 1 \
steps and after no proper divisor, by GF(2) matrix powers).",
)
.ports(PORTS)
.params(&[ORDER.spec(), CLOCK.spec(), LEVEL.spec(), PERIODS.spec(), RATE.spec()])
.rate_param(RATE.name())
.bound(output_bound)
.example("order = 9\nclock = 1\nlevel = 1.0\nperiods = 6\nrate = 1000.0");

/// The port: the signal out.
const PORTS: &[PortSpec] = &[PortSpec::output("out", "1", "the signal, ±level")];
/// `out`: the signal.
const OUT: OutPort = OutPort::named(PORTS, "out");

/// `order`: the shift register's order n.
const ORDER: Int = Int::new("order", 2, 30, 9, "1", "shift-register order n: the period is 2^n − 1 chips");
/// `clock`: samples each chip is held.
const CLOCK: Int = Int::new("clock", 1, 100_000, 1, "samples", "clock period B: samples each chip is held");
/// `level`: the signal level c.
const LEVEL: Float = Float::new("level", 1e-9, 1e6, 1.0, "1", "signal level c: the output is +c or −c");
/// `periods`: full periods before the source ends.
const PERIODS: Int = Int::new("periods", 1, 100_000, 6, "1", "full periods to play before the source ends");
/// `rate`: the node's sample rate.
const RATE: Float = Float::new("rate", 1e-3, 1e7, 1000.0, "Hz", "sample rate");

/// The shift register: bit i holds u[k−1−i] with −1 as 1 and +1 as 0, so
/// the ±1 product of the tapped values is the parity of the tapped bits.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Lfsr {
    reg: u32,
    /// Bit positions of the taps (lag − 1); rows with two taps repeat one
    /// position twice in the last two slots, where the two cancel in the XOR.
    shifts: [u32; 4],
    top: u32,
    full: u32,
}

impl Lfsr {
    /// A register of the row's order, started at all −1 (all ones), as `idinput`.
    fn new(taps: &Taps) -> Self {
        let full = (1u32 << taps.order) - 1;
        let mut shifts = [0; 4];
        for (s, &t) in shifts.iter_mut().zip(taps.lags) {
            *s = t - 1;
        }
        Self { reg: full, shifts, top: 1 << (taps.order - 1), full }
    }

    /// Shifts once; returns the value that leaves the register (`true` = −1).
    #[inline]
    fn next(&mut self) -> bool {
        let out = self.reg & self.top != 0;
        let r = self.reg;
        let [a, b, c, d] = self.shifts;
        // The parity of the tapped bits: the product of ±1 values in GF(2).
        let fb = ((r >> a) ^ (r >> b) ^ (r >> c) ^ (r >> d)) & 1;
        self.reg = ((self.reg << 1) | fb) & self.full;
        out
    }
}

/// The register eight steps on, in one go: a step is linear over GF(2)
/// (a shift and an exclusive-or of bits), so eight are too, and their
/// image of a register is the exclusive-or of the images of its four
/// bytes, tabulated once per order (4 KiB). For orders ≥ 8 the eight
/// chips those steps put out are the register's top eight bits as they
/// stand (a chip leaves n steps after it entered), so a block is written
/// eight chips per table look-up instead of one chip per step.
struct Jump8 {
    bytes: [[u32; 256]; 4],
}

impl Jump8 {
    /// The tables for `lfsr`'s taps; `None` below order 8.
    fn new(lfsr: &Lfsr) -> Option<Box<Self>> {
        if lfsr.top < 1 << 7 {
            return None;
        }
        let image = |bit: u32| {
            let mut r = Lfsr { reg: 1 << bit, ..*lfsr };
            (0..8).for_each(|_| {
                r.next();
            });
            r.reg
        };
        let basis: Vec<u32> = (0..32).map(|b| if 1u32 << b <= lfsr.full { image(b) } else { 0 }).collect();
        let mut bytes = [[0u32; 256]; 4];
        for (k, table) in bytes.iter_mut().enumerate() {
            for (v, e) in table.iter_mut().enumerate() {
                *e = (0..8).filter(|b| v >> b & 1 == 1).fold(0, |acc, b| acc ^ basis[8 * k + b]);
            }
        }
        Some(Box::new(Self { bytes }))
    }

    /// The register eight steps after `r`.
    #[inline]
    fn apply(&self, r: u32) -> u32 {
        let [b0, b1, b2, b3] = r.to_le_bytes();
        self.bytes[0][usize::from(b0)]
            ^ self.bytes[1][usize::from(b1)]
            ^ self.bytes[2][usize::from(b2)]
            ^ self.bytes[3][usize::from(b3)]
    }
}

struct Prbs {
    start: Lfsr,
    lfsr: Lfsr,
    /// Eight steps at once, for orders ≥ 8 at one chip per sample.
    jump: Option<Box<Jump8>>,
    level: f64,
    clock: u64,
    total: u64,
    pos: u64,
    held: u64,
    value: f64,
}

/// The output bound the stability suite checks: |out| ≤ `level`.
fn output_bound(b: &BoundArgs<'_>) -> Option<PortBound> {
    Some(("out", b.num(&LEVEL.spec()), "the level c".into()))
}

fn build(p: &Params, _: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
    let order = ORDER.get(p);
    let taps = u32::try_from(order).ok().and_then(prbs_taps::taps).ok_or_else(|| {
        NodeError::param(
            ORDER.name(),
            format!("{order} is not a supported order ({} ..= {})", prbs_taps::MIN_ORDER, prbs_taps::MAX_ORDER),
        )
    })?;
    let clock = u64::try_from(CLOCK.get(p)).ok().filter(|&b| b >= 1);
    let clock = clock.ok_or_else(|| NodeError::param(CLOCK.name(), "the clock period must be at least 1 sample"))?;
    let periods = u64::try_from(PERIODS.get(p)).ok().filter(|&m| m >= 1);
    let periods = periods.ok_or_else(|| NodeError::param(PERIODS.name(), "at least one period is needed"))?;
    let level = LEVEL.get(p);
    if !(level.is_finite() && level > 0.0) {
        return Err(NodeError::param(LEVEL.name(), format!("the level must be a positive number, not {level}")));
    }
    let chips = (1u64 << taps.order) - 1;
    let total = periods.checked_mul(chips).and_then(|x| x.checked_mul(clock)).ok_or_else(|| {
        NodeError::param(PERIODS.name(), "periods × (2^order − 1) × clock is too many samples to count")
    })?;
    let lfsr = Lfsr::new(taps);
    let jump = if clock == 1 { Jump8::new(&lfsr) } else { None };
    Ok(Box::new(Prbs { start: lfsr, lfsr, jump, level, clock, total, pos: 0, held: 0, value: 0.0 }))
}

impl Node for Prbs {
    fn process(&mut self, io: &mut Io<'_>) -> Result<(), NodeError> {
        let out = io.output(OUT);
        let live = (out.len() as u64).min(self.total - self.pos.min(self.total)) as usize;
        let (out, past_end) = out.split_at_mut(live);
        past_end.fill(0.0);
        if self.clock == 1 {
            // One chip per sample: no hold bookkeeping.
            // The sign bit is flipped without a branch: the chips are random,
            // so a branch would be mispredicted half of the time.
            let level = self.level.to_bits();
            let mut out = &mut out[..];
            if let Some(jump) = &self.jump {
                // The top eight bits, highest first, are the next eight chips.
                let shift = self.lfsr.top.trailing_zeros() - 7;
                let mut chunks = out.chunks_exact_mut(8);
                for chunk in &mut chunks {
                    let chips = u64::from(self.lfsr.reg >> shift);
                    for (k, y) in chunk.iter_mut().enumerate() {
                        *y = f64::from_bits(level ^ ((chips >> (7 - k)) & 1) << 63);
                    }
                    self.lfsr.reg = jump.apply(self.lfsr.reg);
                }
                out = chunks.into_remainder();
            }
            for y in out.iter_mut() {
                *y = f64::from_bits(level ^ (u64::from(self.lfsr.next()) << 63));
            }
            self.pos += live as u64;
            return Ok(());
        }
        for y in out.iter_mut() {
            if self.held == 0 {
                self.value = if self.lfsr.next() { -self.level } else { self.level };
            }
            *y = self.value;
            self.pos += 1;
            self.held += 1;
            if self.held == self.clock {
                self.held = 0;
            }
        }
        Ok(())
    }

    fn reset(&mut self) {
        self.lfsr = self.start;
        self.pos = 0;
        self.held = 0;
        self.value = 0.0;
    }

    fn remaining(&self) -> Option<u64> {
        Some(self.total - self.pos.min(self.total))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use evflow_engine::harness::Single;
    use evflow_engine::{run_offline, RunOptions};
    use rustfft::num_complex::Complex;

    /// MATLAB `idinput(511,'prbs',[0 1],[-1 1])`, first 32 samples.
    const MATLAB_PRBS9_START: &str = "---------++++----+---++++-+--++-";

    fn single(params: &str, ticks: u64, block: usize) -> Single<'_> {
        Single::new(&SPEC, params).output("out").ticks(ticks).block(block)
    }

    fn run(params: &str, ticks: u64, block: usize) -> Vec<f64> {
        single(params, ticks, block).run().unwrap().remove(0)
    }

    /// One period of the ±1 chip sequence of an order, straight from the register.
    fn chips(order: u32) -> Vec<f64> {
        let mut r = Lfsr::new(prbs_taps::taps(order).unwrap());
        (0..(1u64 << order) - 1).map(|_| if r.next() { -1.0 } else { 1.0 }).collect()
    }

    #[test]
    fn prbs9_starts_like_matlab() {
        for (level, params) in [(1.0, "order = 9"), (2.5, "order = 9\nlevel = 2.5")] {
            let y = run(params, 32, 7);
            let signs: String = y
                .iter()
                .map(|&v| {
                    if v == level {
                        '+'
                    } else if v == -level {
                        '-'
                    } else {
                        '?'
                    }
                })
                .collect();
            assert_eq!(signs, MATLAB_PRBS9_START, "level {level}");
        }
    }

    #[test]
    fn prbs9_period_and_balance() {
        let y = run("order = 9\nperiods = 3\nlevel = 0.7", 3 * 511, 4096);
        assert_eq!(y.len(), 1533);
        for i in 0..1533 - 511 {
            assert_eq!(y[i], y[i + 511], "not periodic at {i}");
        }
        // 511 = 7 · 73: no proper divisor is a period.
        for d in [1, 7, 73] {
            assert!((0..511).any(|i| y[i] != y[i + d]), "period {d}");
        }
        let plus = y[..511].iter().filter(|&&v| v == 0.7).count();
        let minus = y[..511].iter().filter(|&&v| v == -0.7).count();
        assert_eq!((plus, minus), (255, 256));
    }

    #[test]
    fn prbs9_autocorrelation_is_two_valued() {
        let c = 2.5;
        let y = run("order = 9\nperiods = 1\nlevel = 2.5", 511, 64);
        let n = y.len();
        for k in 0..n {
            let r: f64 = (0..n).map(|i| y[i] * y[(i + k) % n]).sum::<f64>() / (n as f64 * c * c);
            let want = if k == 0 { 1.0 } else { -1.0 / 511.0 };
            assert!((r - want).abs() < 1e-12, "R({k}) = {r}, want {want}");
        }
    }

    #[test]
    fn prbs9_spectrum_is_flat() {
        let c = 1.5;
        let y = run("order = 9\nperiods = 1\nlevel = 1.5", 511, 100);
        let mut x: Vec<Complex<f64>> = y.iter().map(|&v| Complex::new(v, 0.0)).collect();
        evflow_dsp::fft::forward(511).process(&mut x);
        // Sum of one period: 255·c − 256·c = −c. Every other bin: |X|² = (N + 1)·c².
        assert!((x[0].re + c).abs() < 1e-9 && x[0].im.abs() < 1e-9, "DC {}", x[0]);
        for (k, v) in x.iter().enumerate().skip(1) {
            assert!((v.norm_sqr() - 512.0 * c * c).abs() < 1e-8, "bin {k}: |X|² = {}", v.norm_sqr());
        }
    }

    #[test]
    fn every_order_up_to_22_walks_its_full_period() {
        for order in 2..=22u32 {
            let taps = prbs_taps::taps(order).unwrap();
            let start = Lfsr::new(taps);
            let mut r = start;
            let mut steps = 0u64;
            let mut minus = 0u64;
            loop {
                minus += r.next() as u64;
                steps += 1;
                if r == start {
                    break;
                }
                assert!(steps < 1 << order, "order {order}: no return within 2^n steps");
            }
            assert_eq!(steps, (1 << order) - 1, "order {order}: period {steps}");
            assert_eq!(minus, 1 << (order - 1), "order {order}: chips at −c");
        }
    }

    /// The register's transition as a GF(2) matrix, stored by columns.
    #[derive(Clone)]
    struct Mat(Vec<u32>);

    impl Mat {
        fn step(taps: &Taps) -> Mat {
            let n = taps.order;
            // Columns are the images of the unit states, computed by the real generator.
            Mat((0..n)
                .map(|j| {
                    let mut r = Lfsr::new(taps);
                    r.reg = 1 << j;
                    r.next();
                    r.reg
                })
                .collect())
        }
        fn apply(&self, v: u32) -> u32 {
            self.0.iter().enumerate().filter(|(j, _)| v >> j & 1 == 1).fold(0, |acc, (_, c)| acc ^ c)
        }
        fn then(&self, next: &Mat) -> Mat {
            Mat(self.0.iter().map(|&c| next.apply(c)).collect())
        }
        fn pow(&self, mut e: u64) -> Mat {
            let n = self.0.len();
            let mut acc = Mat((0..n).map(|j| 1 << j).collect());
            let mut base = self.clone();
            while e > 0 {
                if e & 1 == 1 {
                    acc = acc.then(&base);
                }
                base = base.then(&base);
                e >>= 1;
            }
            acc
        }
    }

    fn prime_factors(mut m: u64) -> Vec<u64> {
        let mut out = Vec::new();
        let mut p = 2;
        while p * p <= m {
            if m.rem_euclid(p) == 0 {
                out.push(p);
                while m.rem_euclid(p) == 0 {
                    m /= p;
                }
            }
            p += 1;
        }
        if m > 1 {
            out.push(m);
        }
        out
    }

    #[test]
    fn every_order_has_maximal_period_by_matrix_powers() {
        // The state after k steps is A^k·s0. If A^(2^n−1)·s0 = s0 and
        // A^((2^n−1)/p)·s0 ≠ s0 for every prime p | 2^n − 1, the period of s0
        // divides 2^n − 1 but no maximal proper divisor of it: it is 2^n − 1.
        for t in &prbs_taps::TABLE {
            let a = Mat::step(t);
            let s0 = Lfsr::new(t).reg;
            // The matrix agrees with the generator.
            let mut r = Lfsr::new(t);
            for k in 1..=200u64 {
                r.next();
                assert_eq!(a.pow(k).apply(s0), r.reg, "order {}: matrix ≠ generator at step {k}", t.order);
            }
            let period = (1u64 << t.order) - 1;
            assert_eq!(a.pow(period).apply(s0), s0, "order {}: no return after 2^n − 1", t.order);
            for p in prime_factors(period) {
                assert_ne!(a.pow(period / p).apply(s0), s0, "order {}: returns after (2^n−1)/{p}", t.order);
            }
        }
    }

    #[test]
    fn clock_holds_each_chip() {
        let base = chips(5);
        let y = run("order = 5\nclock = 3\nperiods = 2", 2 * 31 * 3, 50);
        assert_eq!(y.len(), 186);
        for (i, v) in y.iter().enumerate() {
            assert_eq!(*v, base[(i / 3) % 31], "sample {i}");
        }
    }

    #[test]
    fn remaining_counts_down_and_the_run_stops_at_the_end() {
        // Default: PRBS9, six periods — the dissertation's 3066 samples.
        let (mut plan, _) = single("", 0, 100).plan().unwrap();
        assert_eq!(plan.remaining_ticks(), Some(3066));
        let mut left = 3066;
        while left > 0 {
            let n = left.min(100);
            plan.step(n as usize).unwrap();
            left -= n;
            assert_eq!(plan.remaining_ticks(), Some(left));
        }
        let (mut plan, _) = single("order = 4\nclock = 2\nperiods = 3", 0, 64).plan().unwrap();
        let report = run_offline(&mut plan, RunOptions::default()).unwrap();
        assert_eq!(report.ticks, 3 * 15 * 2);
        assert_eq!(plan.remaining_ticks(), Some(0));
    }

    #[test]
    fn past_the_end_writes_zero() {
        let y = run("order = 3\nperiods = 1", 10, 4);
        assert_eq!(&y[..7], &chips(3)[..]);
        assert_eq!(&y[7..], &[0.0; 3]);
    }

    #[test]
    fn eight_steps_at_once_are_eight_single_steps() {
        for taps in &prbs_taps::TABLE {
            let mut one = Lfsr::new(taps);
            let Some(jump) = Jump8::new(&one) else {
                assert!(taps.order < 8, "order {}", taps.order);
                continue;
            };
            let mut r = one.reg;
            for _ in 0..3000 {
                let shift = one.top.trailing_zeros() - 7;
                let top = r >> shift & 0xff;
                let chips: u32 = (0..8).fold(0, |acc, _| acc << 1 | u32::from(one.next()));
                assert_eq!(top, chips, "order {}", taps.order);
                r = jump.apply(r);
                assert_eq!(r, one.reg, "order {}", taps.order);
            }
        }
    }

    #[test]
    fn block_and_per_sample_are_identical() {
        for params in
            ["order = 9", "order = 5\nclock = 3\nperiods = 4\nlevel = 0.25", "order = 2\nclock = 7", "order = 23"]
        {
            let (ticks, a) = (2000, run(params, 2000, 4096));
            let b = run(params, ticks, 1);
            assert_eq!(a, b, "{params}");
            assert_eq!(a, run(params, ticks, 13), "{params}");
        }
    }

    #[test]
    fn reset_restores_the_start() {
        let (mut plan, idx) = single("order = 7\nclock = 2", 0, 64).plan().unwrap();
        let mut first = Vec::new();
        for _ in 0..5 {
            plan.step(64).unwrap();
            first.extend_from_slice(plan.output("dut", idx[0]).unwrap());
        }
        plan.reset();
        let mut again = Vec::new();
        for _ in 0..5 {
            plan.step(64).unwrap();
            again.extend_from_slice(plan.output("dut", idx[0]).unwrap());
        }
        assert_eq!(first, again);
        assert_eq!(plan.remaining_ticks(), Some(6 * 127 * 2 - 320));
    }

    #[test]
    fn extreme_orders_and_levels() {
        // Order 30: the first 30 samples are the all −1 start, then u[30] = Π u[30 − t] = +1
        // because the taps are an even number of −1s.
        let (plan, _) = single("order = 30\nlevel = 1000000.0\nperiods = 100000", 0, 64).plan().unwrap();
        assert_eq!(plan.remaining_ticks(), Some(100_000 * ((1 << 30) - 1)));
        let y = run("order = 30\nlevel = 1000000.0", 40, 16);
        assert!(y[..30].iter().all(|&v| v == -1e6));
        assert_eq!(y[30], 1e6);
        let y = run("order = 2\nlevel = 0.000000001", 6, 1);
        assert_eq!(y, [-1e-9, -1e-9, 1e-9, -1e-9, -1e-9, 1e-9]);
        // The largest count the limits allow still fits.
        let (plan, _) = single("order = 30\nclock = 100000\nperiods = 100000", 0, 64).plan().unwrap();
        assert_eq!(plan.remaining_ticks(), Some(100_000 * 100_000 * ((1 << 30) - 1)));
    }

    #[test]
    fn doc_lists_every_row_of_the_table() {
        for t in &prbs_taps::TABLE {
            let lags: Vec<String> = t.lags.iter().map(|l| l.to_string()).collect();
            let line = format!("| {} | {} | {} |", t.order, lags.join(", "), t.source.cite());
            assert!(SPEC.doc.contains(&line), "doc lacks `{line}`");
        }
    }
}
