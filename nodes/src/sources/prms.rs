//! `prms`: a pseudo-random multilevel signal — a maximum-length q-level
//! sequence over GF(q), or a random q-level sequence of the same length.

use super::prms_field::{self, Recurrence};
use crate::rng::Rng;
use evflow_engine::ports::OutPort;
use evflow_engine::spec::{BoundArgs, PortBound};
use evflow_engine::typed_params::{Choice, Float, Int};
use evflow_engine::{BuildContext, Io, Node, NodeError, NodeSpec, Params, PortSpec, Role};

/// Declaration of `prms`.
pub static SPEC: NodeSpec = NodeSpec::new(
    "prms",
    "sources",
    Role::Source,
    "Pseudo-random multilevel signal: a maximum-length q-level sequence over GF(q), or random q levels.",
    build,
)
.doc(
    "The multilevel excitation the dissertation names as the next step after the binary PRBS \
(§5.4 and §7.2: *pseudo-random multilevel sequences*): a binary ±c signal has u² ≡ c², so a \
square-law display driven by it shows no amplitude response; q levels do.\n\
\n\
**Generator** (`mode = \"mls\"`). The linear recurrence s[k] = −(c₁s[k−1] + … + cₙs[k−n]) mod q \
over GF(q), q prime, with p(x) = xⁿ + c₁xⁿ⁻¹ + … + cₙ the first primitive polynomial of degree n in \
the lexicographic order of (c₁ … cₙ) — found when the node is built and proven primitive (x has \
order qⁿ − 1 modulo p). The register starts with all n symbols at 1. One period is qⁿ − 1 chips: \
every nonzero symbol appears qⁿ⁻¹ times and 0 appears qⁿ⁻¹ − 1 times.\n\
\n\
**Levels.** Symbol a ∈ GF(q) becomes c·φ(a) with φ the symmetric map onto q evenly spaced levels \
in [−1, 1]: φ(a) = a/h for a ≤ h and (a − q)/h above, h = (q − 1)/2 (q = 3: 0, 1, −1; q = 5: 0, ½, 1, \
−1, −½). For q = 2, φ(a) = (−1)ᵃ (±c, no zero level). φ is odd, so the levels sum to zero and the \
periodic autocorrelation is R(0) on the peak, exactly 0 at every lag that is not a multiple of \
(qⁿ − 1)/(q − 1), and R(0)·Σφ(a)φ(g a)/Σφ(a)² at those (g ∈ GF(q) the shift's scalar: −R(0) at \
half a period). In the complex map a ↦ e^{2πia/q} the same sequence has the classic two-valued \
autocorrelation qⁿ − 1 and −1.\n\
\n\
**Random** (`mode = \"random\"`): each chip an independent uniform draw from the same q levels \
(seeded by `seed`, or by the node's name when `seed = 0`), the same length as the MLS of that \
order — the random multilevel sequence of §5.4.\n\
\n\
Each chip is held for `clock` samples; the source ends after `periods` × (qⁿ − 1) × `clock` \
samples and writes 0 past the end.\n\
\n\
**Port** `out` at the rate set by `rate`.\n\
\n\
**Checked against:** published primitive polynomials and imprimitive ones (GF(2), GF(3), GF(5), \
GF(7)); for q = 3, 5, 7 full periods qⁿ − 1 (and no shorter one), level balance, the complex \
two-valued autocorrelation and the real one above; the random mode's level frequencies.",
)
.ports(PORTS)
.params(&[Q.spec(), ORDER.spec(), CLOCK.spec(), LEVEL.spec(), PERIODS.spec(), MODE.spec(), SEED.spec(), RATE.spec()])
.rate_param(RATE.name())
.bound(output_bound)
.example("q = 5\norder = 6\nclock = 1\nlevel = 1.0\nperiods = 1\nmode = \"mls\"\nrate = 1000.0");

/// The port: the signal out.
const PORTS: &[PortSpec] = &[PortSpec::output("out", "1", "the signal, one of q levels in [−level, level]")];
/// `out`: the signal.
const OUT: OutPort = OutPort::named(PORTS, "out");

/// How the symbols are drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Mode {
    /// The maximum-length sequence over GF(q).
    Mls,
    /// Independent uniform draws.
    Random,
}

/// `q`: the number of levels, a prime.
const Q: Int = Int::new("q", 2, 13, 3, "1", "number of levels, a prime (2, 3, 5, 7, 11, 13)");
/// `order`: the register's order n.
const ORDER: Int = Int::new("order", 1, 40, 6, "1", "register order n: the period is q^n − 1 chips");
/// `clock`: samples each chip is held.
const CLOCK: Int = Int::new("clock", 1, 100_000, 1, "samples", "samples each chip is held");
/// `level`: the largest level c.
const LEVEL: Float = Float::new("level", 1e-9, 1e6, 1.0, "1", "largest level c: the levels lie in [−c, c]");
/// `periods`: full periods before the source ends.
const PERIODS: Int = Int::new("periods", 1, 100_000, 1, "1", "full periods to play before the source ends");
/// `mode`: maximum-length or random sequence.
const MODE: Choice<Mode> = Choice::new(
    "mode",
    &["mls", "random"],
    &[Mode::Mls, Mode::Random],
    "mls",
    "maximum-length sequence, or independent random levels",
);
/// `seed`: the random mode's seed.
const SEED: Int = Int::new("seed", 0, i64::MAX, 0, "1", "random mode's seed (0: derived from the node's name)");
/// `rate`: the node's sample rate.
const RATE: Float = Float::new("rate", 1e-3, 1e7, 1000.0, "Hz", "sample rate");

/// The symmetric level map φ of the node's doc, for every symbol of GF(q).
pub fn levels(q: u32) -> Vec<f64> {
    if q == 2 {
        return vec![1.0, -1.0];
    }
    let h = f64::from(q - 1) / 2.0;
    (0..q).map(|a| if f64::from(a) <= h { f64::from(a) / h } else { (f64::from(a) - f64::from(q)) / h }).collect()
}

/// Where the symbols come from.
enum Symbols {
    Mls { start: Recurrence, rec: Recurrence },
    Random { rng: Rng, q: u64 },
}

impl Symbols {
    #[inline]
    fn next(&mut self) -> usize {
        match self {
            Symbols::Mls { rec, .. } => rec.step() as usize,
            // Multiply-shift: uniform enough for q ≤ 13 (bias < 2⁻⁶⁰).
            Symbols::Random { rng, q } => ((u128::from(rng.next_u64()) * u128::from(*q)) >> 64) as usize,
        }
    }

    fn reset(&mut self) {
        match self {
            Symbols::Mls { start, rec } => *rec = start.clone(),
            Symbols::Random { rng, .. } => rng.reset(),
        }
    }
}

struct Prms {
    symbols: Symbols,
    /// c·φ(a) per symbol.
    values: Vec<f64>,
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

fn build(p: &Params, ctx: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
    let q = Q.get(p);
    let q = u32::try_from(q)
        .ok()
        .filter(|q| prms_field::PRIMES.contains(q))
        .ok_or_else(|| NodeError::param(Q.name(), format!("{q} is not one of the primes {:?}", prms_field::PRIMES)))?;
    let n = u32::try_from(ORDER.get(p)).ok().filter(|&n| n >= 1);
    let n = n.ok_or_else(|| NodeError::param(ORDER.name(), "the order must be at least 1"))?;
    let chips = prms_field::period(q, n).ok_or_else(|| {
        NodeError::param(ORDER.name(), format!("{q}^{n} − 1 chips is longer than the largest period, 2^40"))
    })?;
    let clock = u64::try_from(CLOCK.get(p)).ok().filter(|&b| b >= 1);
    let clock = clock.ok_or_else(|| NodeError::param(CLOCK.name(), "the clock period must be at least 1 sample"))?;
    let periods = u64::try_from(PERIODS.get(p)).ok().filter(|&m| m >= 1);
    let periods = periods.ok_or_else(|| NodeError::param(PERIODS.name(), "at least one period is needed"))?;
    let level = LEVEL.get(p);
    if !(level.is_finite() && level > 0.0) {
        return Err(NodeError::param(LEVEL.name(), format!("the level must be a positive number, not {level}")));
    }
    let total = periods.checked_mul(chips).and_then(|x| x.checked_mul(clock)).ok_or_else(|| {
        NodeError::param(PERIODS.name(), "periods × (q^order − 1) × clock is too many samples to count")
    })?;
    let symbols = match MODE.get(p) {
        Mode::Random => {
            let seed = u64::try_from(SEED.get(p)).unwrap_or(0);
            let seed = if seed == 0 { ctx.node_seed() } else { seed };
            Symbols::Random { rng: Rng::new(seed), q: u64::from(q) }
        }
        Mode::Mls => {
            let c = prms_field::primitive(q, n).ok_or_else(|| {
                NodeError::param(ORDER.name(), format!("no primitive polynomial of degree {n} over GF({q})"))
            })?;
            let start = Recurrence::new(&c, q);
            Symbols::Mls { rec: start.clone(), start }
        }
    };
    let values = levels(q).into_iter().map(|v| v * level).collect();
    Ok(Box::new(Prms { symbols, values, clock, total, pos: 0, held: 0, value: 0.0 }))
}

impl Node for Prms {
    fn process(&mut self, io: &mut Io<'_>) -> Result<(), NodeError> {
        let out = io.output(OUT);
        let live = (out.len() as u64).min(self.total - self.pos.min(self.total)) as usize;
        let (out, past_end) = out.split_at_mut(live);
        past_end.fill(0.0);
        for y in out.iter_mut() {
            if self.held == 0 {
                self.value = self.values[self.symbols.next()];
            }
            *y = self.value;
            self.held += 1;
            if self.held == self.clock {
                self.held = 0;
            }
        }
        self.pos += live as u64;
        Ok(())
    }

    fn reset(&mut self) {
        self.symbols.reset();
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

    fn single(params: &str, ticks: u64, block: usize) -> Single<'_> {
        Single::new(&SPEC, params).output("out").ticks(ticks).block(block)
    }

    fn run(params: &str, ticks: u64, block: usize) -> Vec<f64> {
        single(params, ticks, block).run().unwrap().remove(0)
    }

    /// One period of symbols straight from the recurrence.
    fn symbols(q: u32, n: u32) -> Vec<u32> {
        let mut r = Recurrence::new(&prms_field::primitive(q, n).unwrap(), q);
        (0..prms_field::period(q, n).unwrap()).map(|_| r.step()).collect()
    }

    #[test]
    fn the_period_is_q_to_the_n_minus_one_and_no_shorter() {
        for (q, n) in [(3, 2), (3, 5), (3, 9), (5, 3), (5, 6), (7, 2), (7, 5), (2, 10)] {
            let s = symbols(q, n);
            let p = s.len();
            let mut r = Recurrence::new(&prms_field::primitive(q, n).unwrap(), q);
            let twice: Vec<u32> = (0..2 * p).map(|_| r.step()).collect();
            assert_eq!(&twice[..p], &twice[p..], "q {q} n {n}: repeats after q^n − 1");
            // The window of n symbols visits every nonzero state once: no shorter period.
            let mut seen = std::collections::HashSet::new();
            for k in 0..p {
                let w: Vec<u32> = (0..n as usize).map(|i| twice[k + i]).collect();
                assert!(w.iter().any(|&v| v != 0), "q {q} n {n}: the zero state");
                assert!(seen.insert(w), "q {q} n {n}: a state repeats within the period at {k}");
            }
        }
    }

    #[test]
    fn every_level_is_balanced() {
        for (q, n) in [(3, 6), (5, 4), (7, 3)] {
            let s = symbols(q, n);
            let mut count = vec![0u64; q as usize];
            for &a in &s {
                count[a as usize] += 1;
            }
            let each = u64::from(q).pow(n - 1);
            assert_eq!(count[0], each - 1, "q {q}: zeros");
            assert!(count[1..].iter().all(|&c| c == each), "q {q}: {count:?}");
        }
    }

    #[test]
    fn the_complex_autocorrelation_is_two_valued() {
        for (q, n) in [(3, 5), (5, 3), (7, 3)] {
            let s = symbols(q, n);
            let p = s.len();
            let w = 2.0 * std::f64::consts::PI / f64::from(q);
            for tau in 0..p {
                let (mut re, mut im) = (0.0, 0.0);
                for k in 0..p {
                    let d = f64::from((s[k] + q - s[(k + tau) % p]) % q);
                    re += (w * d).cos();
                    im += (w * d).sin();
                }
                let want = if tau == 0 { p as f64 } else { -1.0 };
                assert!((re - want).abs() < 1e-6 && im.abs() < 1e-6, "q {q} τ {tau}: {re} {im}");
            }
        }
    }

    #[test]
    fn the_real_autocorrelation_vanishes_off_the_scalar_shifts() {
        for (q, n) in [(3, 5), (5, 4), (7, 3)] {
            let level = 0.8;
            let p = prms_field::period(q, n).unwrap() as usize;
            let y = run(&format!("q = {q}\norder = {n}\nlevel = {level}"), p as u64, 333);
            let phi = levels(q);
            let r0: f64 = y.iter().map(|v| v * v).sum();
            let expect_r0 = level * level * f64::from(q).powi(n as i32 - 1) * phi.iter().map(|v| v * v).sum::<f64>();
            assert!((r0 - expect_r0).abs() < 1e-9 * expect_r0, "q {q}: R(0) {r0} vs {expect_r0}");
            let step = p / (q as usize - 1);
            let s = symbols(q, n);
            for tau in 1..p {
                let r: f64 = (0..p).map(|k| y[k] * y[(k + tau) % p]).sum();
                if tau % step == 0 {
                    // s[k+τ] = g·s[k] for a fixed g ∈ GF(q)*; R = c² qⁿ⁻¹ Σ φ(a)φ(ga).
                    let k0 = s.iter().position(|&a| a != 0).unwrap();
                    let g = (0..q).find(|&g| (g * s[k0]) % q == s[(k0 + tau) % p]).unwrap();
                    let want: f64 = level
                        * level
                        * f64::from(q).powi(n as i32 - 1)
                        * (0..q).map(|a| phi[a as usize] * phi[((g * a) % q) as usize]).sum::<f64>();
                    assert!((r - want).abs() < 1e-9 * r0, "q {q} τ {tau}: {r} vs {want}");
                    if tau == p / 2 {
                        assert!((r + r0).abs() < 1e-9 * r0, "q {q}: half a period is −R(0)");
                    }
                } else {
                    assert!(r.abs() < 1e-9 * r0, "q {q} τ {tau}: R = {r}");
                }
            }
        }
    }

    #[test]
    fn chips_are_held_and_the_source_ends() {
        let y = run("q = 3\norder = 2\nclock = 3\nperiods = 2", 60, 7);
        let s = symbols(3, 2);
        let phi = levels(3);
        for (k, v) in y.iter().enumerate().take(48) {
            assert_eq!(*v, phi[s[(k / 3) % 8] as usize], "sample {k}");
        }
        assert!(y[48..].iter().all(|&v| v == 0.0), "zero past the end");
    }

    #[test]
    fn random_levels_are_uniform_reproducible_and_seeded() {
        let a = run("q = 5\norder = 6\nmode = \"random\"\nseed = 7", 15_624, 512);
        let b = run("q = 5\norder = 6\nmode = \"random\"\nseed = 7", 15_624, 100);
        let c = run("q = 5\norder = 6\nmode = \"random\"\nseed = 8", 15_624, 512);
        assert_eq!(a, b, "same seed, same signal, whatever the block size");
        assert_ne!(a, c);
        let phi = levels(5);
        for l in &phi {
            let n = a.iter().filter(|&&v| v == *l).count() as f64;
            // Binomial(15624, 1/5): sd ≈ 50; 5 sd.
            assert!((n - 3124.8).abs() < 250.0, "level {l}: {n}");
        }
        assert_eq!(a.iter().filter(|v| !phi.contains(v)).count(), 0);
    }

    #[test]
    fn bad_parameters_are_refused_by_name() {
        for (params, name) in [("q = 4", "q"), ("q = 13\norder = 40", "order"), ("level = -1", "level")] {
            let err = single(params, 1, 1).run().err().unwrap_or_else(|| panic!("{params} accepted"));
            assert!(err.to_string().contains(name), "{params}: {err}");
        }
    }
}
