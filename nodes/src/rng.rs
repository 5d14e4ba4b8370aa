//! Seeded random numbers for every noisy node (sources, the simulated lab, NARX
//! initialisation): SplitMix64 (seeding),
//! xoshiro256++ (the stream) and Gaussian deviates by Marsaglia's polar method.
//!
//! References: S. Vigna, "Further scramblings of Marsaglia's xorshift
//! generators" and the public-domain reference code of xoshiro256++ and
//! SplitMix64 (prng.di.unimi.it); G. Marsaglia & T. A. Bray, "A convenient
//! method for generating normal variables", SIAM Review 6 (1964).

/// SplitMix64: a 64-bit generator used to expand one seed into a state.
#[derive(Debug, Clone)]
pub struct SplitMix64 {
    state: u64,
}

impl SplitMix64 {
    /// A generator starting from `seed`.
    pub fn new(seed: u64) -> Self {
        Self { state: seed }
    }

    /// The next 64-bit output.
    pub fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
}

/// xoshiro256++ with a Gaussian sampler; the lab's only source of randomness.
#[derive(Debug, Clone)]
pub struct Rng {
    s: [u64; 4],
    seed: u64,
    spare: Option<f64>,
}

impl Rng {
    /// A stream seeded from `seed` through SplitMix64 (as the xoshiro authors recommend).
    pub fn new(seed: u64) -> Self {
        let mut sm = SplitMix64::new(seed);
        let s = [sm.next_u64(), sm.next_u64(), sm.next_u64(), sm.next_u64()];
        Self { s, seed, spare: None }
    }

    /// A stream with the raw state `s` (must not be all zero); for reference tests.
    pub fn from_state(s: [u64; 4]) -> Self {
        Self { s, seed: 0, spare: None }
    }

    /// A second, independent stream derived from this one's seed and a label,
    /// so several noise terms of one node never share numbers.
    pub fn substream(seed: u64, label: u64) -> Self {
        let mut sm = SplitMix64::new(seed ^ label.wrapping_mul(0xD1B5_4A32_D192_ED03));
        Self::new(sm.next_u64())
    }

    /// Back to the first number of the stream.
    pub fn reset(&mut self) {
        *self = Self::new(self.seed);
    }

    /// The next 64-bit output of xoshiro256++.
    pub fn next_u64(&mut self) -> u64 {
        let s = &mut self.s;
        let result = s[0].wrapping_add(s[3]).rotate_left(23).wrapping_add(s[0]);
        let t = s[1] << 17;
        s[2] ^= s[0];
        s[3] ^= s[1];
        s[1] ^= s[2];
        s[0] ^= s[3];
        s[2] ^= t;
        s[3] = s[3].rotate_left(45);
        result
    }

    /// A uniform number in [0, 1) with 53 random bits.
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// A standard normal deviate (mean 0, variance 1), Marsaglia's polar method.
    pub fn gaussian(&mut self) -> f64 {
        if let Some(z) = self.spare.take() {
            return z;
        }
        loop {
            let a = 2.0 * self.uniform() - 1.0;
            let b = 2.0 * self.uniform() - 1.0;
            let s = a * a + b * b;
            if s > 0.0 && s < 1.0 {
                let m = (-2.0 * s.ln() / s).sqrt();
                self.spare = Some(b * m);
                return a * m;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn splitmix64_matches_the_reference_sequence() {
        // Reference outputs for seed 1234567 (the published SplitMix64 test
        // sequence, e.g. Rosetta Code "Pseudo-random numbers/Splitmix64").
        let mut g = SplitMix64::new(1_234_567);
        let want = [
            6_457_827_717_110_365_317u64,
            3_203_168_211_198_807_973,
            9_817_491_932_198_370_423,
            4_593_380_528_125_082_431,
            16_408_922_859_458_223_821,
        ];
        for w in want {
            assert_eq!(g.next_u64(), w);
        }
    }

    #[test]
    fn xoshiro256pp_matches_the_reference_code() {
        // From state [1, 2, 3, 4]: the first output is rotl(1 + 4, 23) + 1 by
        // definition; the rest are the values of Vigna's reference C code
        // (also the `rand_xoshiro` crate's reference test).
        let mut g = Rng::from_state([1, 2, 3, 4]);
        let want = [
            41_943_041u64,
            58_720_359,
            3_588_806_011_781_223,
            3_591_011_842_654_386,
            9_228_616_714_210_784_205,
            9_973_669_472_204_895_162,
            14_011_001_112_246_962_877,
            12_406_186_145_184_390_807,
            15_849_039_046_786_891_736,
            10_450_023_813_501_588_000,
        ];
        for w in want {
            assert_eq!(g.next_u64(), w);
        }
    }

    #[test]
    fn gaussian_has_unit_moments() {
        let mut g = Rng::new(42);
        let n = 200_000;
        let (mut m1, mut m2, mut m4) = (0.0, 0.0, 0.0);
        for _ in 0..n {
            let z = g.gaussian();
            m1 += z;
            m2 += z * z;
            m4 += z * z * z * z;
        }
        let n = n as f64;
        let (mean, var, kurt) = (m1 / n, m2 / n, m4 / n);
        // Standard errors: mean 1/sqrt(n) = 0.0022, var sqrt(2/n) = 0.0032, m4 sqrt(96/n) = 0.022.
        assert!(mean.abs() < 0.01, "mean {mean}");
        assert!((var - 1.0).abs() < 0.015, "variance {var}");
        assert!((kurt - 3.0).abs() < 0.1, "fourth moment {kurt}");
    }

    #[test]
    fn uniform_is_in_range_and_reset_replays() {
        let mut g = Rng::new(7);
        let first: Vec<f64> = (0..100).map(|_| g.uniform()).collect();
        assert!(first.iter().all(|u| (0.0..1.0).contains(u)));
        g.reset();
        let again: Vec<f64> = (0..100).map(|_| g.uniform()).collect();
        assert_eq!(first, again);
        let mut a = Rng::substream(7, 1);
        let mut b = Rng::substream(7, 2);
        assert_ne!(a.next_u64(), b.next_u64());
    }
}
