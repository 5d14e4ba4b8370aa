//! The extreme input signals every node input is fed (issue 26: ±1e300,
//! ±f64::MAX, subnormals, steps and impulses of full scale, long constant
//! runs).

/// One kind of extreme input.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Extreme {
    /// Steps 0 → +1e300 → −1e300 → 0, a quarter of the run each.
    Steps1e300,
    /// Steps 0 → +f64::MAX → −f64::MAX → 0.
    StepsMax,
    /// Impulses of full scale: one sample of +f64::MAX, later one of
    /// −f64::MAX, zeros elsewhere.
    ImpulsesMax,
    /// Subnormal numbers of both signs (and the smallest normal).
    Subnormals,
    /// A long run of one constant (1.0).
    LongConstant,
}

impl Extreme {
    /// Every kind, in table order.
    pub const ALL: [Extreme; 5] =
        [Extreme::Steps1e300, Extreme::StepsMax, Extreme::ImpulsesMax, Extreme::Subnormals, Extreme::LongConstant];

    /// A short name for the case's name.
    pub fn name(self) -> &'static str {
        match self {
            Extreme::Steps1e300 => "steps ±1e300",
            Extreme::StepsMax => "steps ±f64::MAX",
            Extreme::ImpulsesMax => "impulses ±f64::MAX",
            Extreme::Subnormals => "subnormals",
            Extreme::LongConstant => "long constant",
        }
    }

    /// What is extreme about it, for the table.
    pub fn describe(self, len: usize) -> String {
        match self {
            Extreme::Steps1e300 => format!("every input steps 0 → +1e300 → −1e300 → 0 over {len} samples"),
            Extreme::StepsMax => format!("every input steps 0 → +f64::MAX → −f64::MAX → 0 over {len} samples"),
            Extreme::ImpulsesMax => format!("one-sample impulses of ±f64::MAX on every input ({len} samples)"),
            Extreme::Subnormals => format!("subnormal inputs of both signs ({len} samples)"),
            Extreme::LongConstant => format!("every input held at 1.0 for {len} samples"),
        }
    }

    /// The samples, `len` of them; `salt` shifts the pattern between inputs
    /// of one node so that they are not all equal.
    pub fn samples(self, len: usize, salt: usize) -> Vec<f64> {
        let q = (len / 4).max(1);
        let step = |big: f64| -> Vec<f64> {
            (0..len)
                .map(|i| match (i + salt) / q {
                    1 => big,
                    2 => -big,
                    _ => 0.0,
                })
                .collect()
        };
        match self {
            Extreme::Steps1e300 => step(1e300),
            Extreme::StepsMax => step(f64::MAX),
            Extreme::ImpulsesMax => {
                let mut v = vec![0.0; len];
                if len > 0 {
                    v[(q + salt) % len] = f64::MAX;
                    v[(3 * q + salt) % len] = -f64::MAX;
                }
                v
            }
            Extreme::Subnormals => {
                let tiny = [5e-324, -5e-324, f64::MIN_POSITIVE / 3.0, -f64::MIN_POSITIVE / 7.0, f64::MIN_POSITIVE];
                (0..len).map(|i| tiny[(i + salt) % tiny.len()]).collect()
            }
            Extreme::LongConstant => vec![1.0; len],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn signals_hold_what_they_say() {
        let s = Extreme::StepsMax.samples(8, 0);
        assert_eq!(s, vec![0.0, 0.0, f64::MAX, f64::MAX, -f64::MAX, -f64::MAX, 0.0, 0.0]);
        let i = Extreme::ImpulsesMax.samples(8, 0);
        assert_eq!(i.iter().filter(|x| **x != 0.0).count(), 2);
        let sub = Extreme::Subnormals.samples(10, 1);
        assert!(sub.iter().all(|x| x.abs() <= f64::MIN_POSITIVE && *x != 0.0));
        assert!(sub.iter().any(|x| x.is_subnormal()));
        assert!(Extreme::LongConstant.samples(5, 3).iter().all(|x| *x == 1.0));
    }
}
