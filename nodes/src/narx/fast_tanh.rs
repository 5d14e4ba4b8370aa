//! A fast hyperbolic tangent for the NARX network's hidden layers, with a
//! stated error bound: |[`tanh`]`(x)` − tanh(x)| ≤ [`MAX_ABS_ERROR`]
//! (1.0e-15, about 4.5 ulp of 1) for every real x.
//!
//! # Method
//!
//! tanh is odd, so the work is done on a = min(|x|, 20) and the sign of x is
//! copied back at the end (odd symmetry holds exactly; beyond 20,
//! 1 − tanh(a) < 2e-17 and the rounded result is ±1 either way). With
//! E = e^{2a} = 2^k·e^r, k = round(2a·log₂e), r = 2a − k·ln 2 (ln 2 split in
//! two parts, Cody–Waite, so k·ln2_hi is exact),
//!
//! ```text
//! tanh(a) = (E − 1)/(E + 1) = 1 − 2/(E + 1),   E − 1 = 2^k·q + (2^k − 1),   q = e^r − 1
//! ```
//!
//! and q is the Taylor polynomial of e^r − 1 of degree [`DEGREE`],
//! evaluated in Estrin's scheme (short dependency chains, no branch: the
//! compiler vectorizes it over lanes). Writing E − 1 through q keeps the
//! relative accuracy near 0, where (E − 1) would cancel; the first form is
//! used for a ≤ 1/2, the second beyond (the quotient of two large rounded
//! numbers is not monotone near saturation, 1 − 2/(E + 1) is), both through
//! one division. 2^k is built from
//! its bits; nothing here allocates, branches on data or calls libm.
//!
//! # Error bound
//!
//! |r| ≤ ρ = ln2/2 (+ rounding). Lagrange's remainder of the Taylor
//! polynomial of degree N = 12 gives |q − (e^r − 1)| ≤ ρ^13/13!·e^ρ, so the
//! relative error of E is at most ε = ρ^13/13!·e^{2ρ} = 3.4e-16. Since
//! d/dE (E − 1)/(E + 1) = 2/(E + 1)², a relative error ε of E moves tanh by
//! at most 2Eε/(E + 1)² ≤ ε/2 = 1.7e-16. Rounding adds a few ulp: the
//! polynomial (|r| < 0.35, terms decreasing) ≲ 2 ulp of q, 2^k·q exact,
//! the sum with 2^k − 1, the denominator, the quotient and the last
//! difference ½ ulp each; in all well under 4 ulp of a result in
//! [½, 1) (2^-53 each) and less below. The stated bound,
//! 1.0e-15, covers both with margin, and the tests check it against the
//! standard library's tanh (itself within 1 ulp) on a dense sweep of the
//! real line (every binade from 1e-300 to 1e300, steps of 1e-5 over
//! [−25, 25], ±0, ±∞): the largest difference seen is 2.2e-16 (3.3e-16 on a 1e-6 grid of
//! [0, 25]).
//!
//! # Properties
//!
//! For every x: tanh(−x) = −tanh(x) exactly; |tanh(x)| ≤ 1; tanh(±∞) = ±1;
//! the result is finite for every non-NaN x; NaN in gives NaN out (never a
//! silent ±1); non-decreasing on the 1e-5 grid of [−30, 30]. At the scale
//! of single ulps rounding makes it wiggle: from one float argument to the
//! next the result may step back by one ulp (≤ 1.1e-16 — the std tanh is
//! not proven monotone at that scale either). The tests walk ulp by ulp
//! across every point where k changes (a = (k + ½)·ln2/2), the switch of
//! form and 200 other points, and check that no step back exceeds one ulp.

/// Degree of the Taylor polynomial of e^r − 1.
pub const DEGREE: usize = 12;

/// Largest absolute error against the exact tanh, for every real x.
pub const MAX_ABS_ERROR: f64 = 1.0e-15;

/// |x| beyond which tanh(x) is ±1 in f64 (1 − tanh(20) < 2e-17).
pub(super) const SATURATE: f64 = 20.0;
/// Where the last step switches from (E − 1)/(E + 1) to 1 − 2/(E + 1).
pub(super) const SWITCH: f64 = 0.5;
/// 1.5·2^52: adding it rounds a value below 2^51 to an integer, which then
/// sits in the low bits of the sum.
pub(super) const MAGIC: f64 = 6_755_399_441_055_744.0;
/// ln 2 in two parts: the high part has 21 trailing zero bits, so k·LN2_HI
/// is exact for every k used here (k ≤ 58); fdlibm's split.
pub(super) const LN2_HI: f64 = f64::from_bits(0x3fe6_2e42_fee0_0000); // 6.93147180369123816490e-01
pub(super) const LN2_LO: f64 = f64::from_bits(0x3dea_39ef_3579_3c76); // 1.90821492927058770002e-10

/// 1/n! for n = 1 … 12: the coefficients of e^r − 1 = Σ rⁿ/n!.
pub(super) const C: [f64; DEGREE] = [
    1.0,
    1.0 / 2.0,
    1.0 / 6.0,
    1.0 / 24.0,
    1.0 / 120.0,
    1.0 / 720.0,
    1.0 / 5040.0,
    1.0 / 40320.0,
    1.0 / 362_880.0,
    1.0 / 3_628_800.0,
    1.0 / 39_916_800.0,
    1.0 / 479_001_600.0,
];

/// tanh(x) within [`MAX_ABS_ERROR`] (see the module documentation).
#[inline]
pub fn tanh(x: f64) -> f64 {
    tanh_lanes([x])[0]
}

/// [`tanh`] of every lane, written lane by lane so that the compiler turns
/// each step into one vector instruction (the same operations as the
/// scalar version: equal results, bit for bit).
#[inline(always)]
pub fn tanh_lanes<const N: usize>(x: [f64; N]) -> [f64; N] {
    tanh_impl::<N, false>(x)
}

/// [`tanh_lanes`] with fused multiply-adds in the range reduction and the
/// polynomial: fewer instructions and fewer roundings (the bound holds with
/// room to spare), for code compiled with FMA enabled — without hardware
/// FMA each `mul_add` is a library call, far slower.
#[inline(always)]
pub fn tanh_lanes_fused<const N: usize>(x: [f64; N]) -> [f64; N] {
    tanh_impl::<N, true>(x)
}

/// a·b + c, fused or not.
#[inline(always)]
fn madd<const FUSED: bool>(a: f64, b: f64, c: f64) -> f64 {
    if FUSED {
        a.mul_add(b, c)
    } else {
        a * b + c
    }
}

#[inline(always)]
fn tanh_impl<const N: usize, const FUSED: bool>(x: [f64; N]) -> [f64; N] {
    let mut out = [0.0; N];
    for i in 0..N {
        // NaN stays NaN: the comparison is false and the NaN flows through.
        let a = x[i].abs();
        let a = if a > SATURATE { SATURATE } else { a };
        let t = 2.0 * a;
        let m = madd::<FUSED>(t, std::f64::consts::LOG2_E, MAGIC);
        let k = m - MAGIC;
        let r = madd::<FUSED>(-k, LN2_LO, madd::<FUSED>(-k, LN2_HI, t));
        // Estrin's scheme for q = r·Σ_{n=1}^{12} rⁿ⁻¹/n!.
        let r2 = r * r;
        let r4 = r2 * r2;
        let r8 = r4 * r4;
        let p01 = madd::<FUSED>(C[1], r, C[0]);
        let p23 = madd::<FUSED>(C[3], r, C[2]);
        let p45 = madd::<FUSED>(C[5], r, C[4]);
        let p67 = madd::<FUSED>(C[7], r, C[6]);
        let p89 = madd::<FUSED>(C[9], r, C[8]);
        let pab = madd::<FUSED>(C[11], r, C[10]);
        let p0 = madd::<FUSED>(p23, r2, p01);
        let p1 = madd::<FUSED>(p67, r2, p45);
        let p2 = madd::<FUSED>(pab, r2, p89);
        let q = r * madd::<FUSED>(p2, r8, madd::<FUSED>(p1, r4, p0));
        // 2^k from its bits: the low bits of m hold k (0 ≤ k ≤ 58).
        let kb = m.to_bits().wrapping_sub(MAGIC.to_bits());
        let s = f64::from_bits(kb.wrapping_add(1023) << 52);
        let em1 = madd::<FUSED>(s, q, s - 1.0);
        // One division: (E − 1)/(E + 1) near 0 (relative accuracy), the
        // equal 1 − 2/(E + 1) beyond SWITCH (monotone up to saturation,
        // where the quotient of two rounded large numbers wiggles by an ulp).
        // The numerator is chosen by its bits, so that the compiler keeps
        // one division rather than dividing in both branches and selecting.
        let big = a > SWITCH;
        let mask = (big as u64).wrapping_neg();
        let num = f64::from_bits((2.0f64.to_bits() & mask) | (em1.to_bits() & !mask));
        let quot = num / (em1 + 2.0);
        let v = if big { 1.0 - quot } else { quot };
        out[i] = v.copysign(x[i]);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Largest |fast − std| over a set of points, and where.
    fn worst(xs: impl Iterator<Item = f64>) -> (f64, f64) {
        xs.map(|x| ((tanh(x) - x.tanh()).abs(), x)).fold((0.0, 0.0), |a, b| if b.0 > a.0 { b } else { a })
    }

    /// The dense sweep of the module documentation.
    fn sweep() -> impl Iterator<Item = f64> {
        let fine = (-2_500_000..=2_500_000).map(|i| i as f64 * 1e-5);
        // 64 points per binade from 2^-1000 to 2^1000, both signs.
        let binades = (-1000 * 64..1000 * 64).flat_map(|i| {
            let v = (i as f64 / 64.0).exp2();
            [v, -v]
        });
        // The points where k = round(2a·log₂e) changes, and their neighbours.
        let steps = (0..60).flat_map(|k| {
            let a = (k as f64 + 0.5) * std::f64::consts::LN_2 / 2.0;
            (-50..=50).map(move |j| a + j as f64 * a.max(1.0) * f64::EPSILON)
        });
        fine.chain(binades).chain(steps)
    }

    #[test]
    fn error_is_within_the_stated_bound_on_the_whole_real_line() {
        let (e, at) = worst(sweep());
        assert!(e <= MAX_ABS_ERROR, "error {e:e} at x = {at}");
        // The bound is not loose by orders of magnitude either: the sweep
        // sees errors of a few ulp (3.3e-16 when this was written).
        assert!(e > 1e-17, "{e:e}");
        println!("largest |fast − std| on the sweep: {e:e} at x = {at}");
    }

    #[test]
    fn ln2_split_is_exact_enough() {
        // LN2_HI has 21 trailing zero bits (k·LN2_HI exact for k < 2^21) and
        // the two parts add up to ln 2.
        assert_eq!(LN2_HI.to_bits() & ((1 << 21) - 1), 0);
        assert!((LN2_HI + LN2_LO - std::f64::consts::LN_2).abs() <= f64::EPSILON * 0.5);
        assert!((LN2_HI - 0.693_147_180_369_123_8).abs() < 1e-16);
    }

    #[test]
    fn stated_bound_follows_from_the_remainder_term() {
        // ε = ρ^13/13!·e^{2ρ}, ρ = ln2/2 (module documentation).
        let rho = std::f64::consts::LN_2 / 2.0;
        let fact13: f64 = (1..=13).map(|n| n as f64).product();
        let eps = rho.powi(13) / fact13 * (2.0 * rho).exp();
        assert!(eps / 2.0 < 2e-16, "{eps:e}");
        // Plus 4 ulp of a result below 1 (2^-53 each).
        assert!(eps / 2.0 + 4.0 * f64::EPSILON / 2.0 < MAX_ABS_ERROR);
    }

    #[test]
    fn odd_bounded_monotone_and_finite() {
        let mut prev = -1.0f64;
        let mut x = -30.0f64;
        while x <= 30.0 {
            let y = tanh(x);
            assert_eq!(tanh(-x), -y, "x = {x}");
            assert!(y.abs() <= 1.0 && y.is_finite(), "x = {x}: {y}");
            assert!(y >= prev, "not monotone at x = {x}: {y} < {prev}");
            prev = y;
            x += 1e-5;
        }
        // Ulp by ulp across each step of k, the switch of form and a spread
        // of other points: a step back is never more than one ulp.
        let edges = (0..60)
            .map(|k| (k as f64 + 0.5) * std::f64::consts::LN_2 / 2.0)
            .chain([SWITCH])
            .chain((1..200).map(|i| i as f64 * 0.0917));
        let (mut back, mut steps) = (0, 0);
        for edge in edges {
            let mut a = edge * (1.0 - 64.0 * f64::EPSILON);
            let mut prev = tanh(a);
            for _ in 0..128 {
                a = a.next_up();
                let y = tanh(a);
                steps += 1;
                if y < prev {
                    back += 1;
                    assert_eq!(y.next_up(), prev, "more than one ulp back at {a}: {y} < {prev}");
                }
                prev = y;
            }
        }
        println!("{back} one-ulp steps back in {steps} ulp steps");
    }

    #[test]
    fn extremes_saturate_and_nan_propagates() {
        assert_eq!(tanh(f64::INFINITY), 1.0);
        assert_eq!(tanh(f64::NEG_INFINITY), -1.0);
        assert_eq!(tanh(f64::MAX), 1.0);
        assert_eq!(tanh(-f64::MAX), -1.0);
        assert_eq!(tanh(20.0), 1.0);
        assert_eq!(tanh(0.0).to_bits(), 0.0f64.to_bits());
        assert_eq!(tanh(-0.0).to_bits(), (-0.0f64).to_bits());
        // Tiny arguments: tanh(x) = x to full relative precision.
        for x in [1e-300, 5e-324, 1e-100, 1e-20, 1e-9] {
            assert!((tanh(x) - x).abs() <= x * 4.0 * f64::EPSILON, "{x}: {}", tanh(x));
        }
        assert!(tanh(f64::NAN).is_nan());
    }

    #[test]
    fn fused_variant_is_within_the_bound_too() {
        // Fewer points: without hardware FMA each mul_add is a library call.
        let xs = (-200_000..=200_000)
            .map(|i| i as f64 * 1.25e-4)
            .chain((-64 * 60..64 * 60).map(|i| (i as f64 / 64.0).exp2()));
        let mut e = 0.0f64;
        for x in xs {
            let y = tanh_lanes_fused([x])[0];
            assert!(y.abs() <= 1.0 && tanh_lanes_fused([-x])[0] == -y, "{x}");
            e = e.max((y - x.tanh()).abs());
        }
        assert!(e <= MAX_ABS_ERROR, "{e:e}");
        assert_eq!(tanh_lanes_fused([f64::INFINITY])[0], 1.0);
        assert!(tanh_lanes_fused([f64::NAN])[0].is_nan());
    }

    #[test]
    fn lanes_equal_the_scalar_bit_for_bit() {
        let xs = [-3.7, -0.2, 1e-12, 0.9, 5.5, 19.99, -40.0, 0.3466];
        let v = tanh_lanes(xs);
        for (x, y) in xs.iter().zip(v) {
            assert_eq!(tanh(*x).to_bits(), y.to_bits(), "{x}");
        }
    }
}
