//! What a stability case saw ([`Observed`]), what must hold
//! ([`Invariant`]) and the verdict ([`Verdict`]).

/// What one case saw.
#[derive(Debug, Clone, PartialEq)]
pub struct Observed {
    /// The largest finite |output| over every output the case watched.
    pub max_abs: f64,
    /// The largest finite |output| of each watched port, by name.
    pub ports: Vec<(String, f64)>,
    /// Output samples that were NaN or infinite.
    pub non_finite: u64,
    /// Output samples watched.
    pub samples: u64,
    /// The ports (or reported values) that were NaN or infinite.
    pub bad_ports: Vec<String>,
    /// The error that stopped the run (a clean refusal, not a panic).
    pub error: Option<String>,
    /// The panic's message, if the case panicked.
    pub panic: Option<String>,
    /// A measured value, for [`Invariant::Reference`].
    pub measured: Option<f64>,
    /// A series, for [`Invariant::Monotone`] (e.g. an objective per iteration).
    pub series: Vec<f64>,
    /// Input and output energy (Σx², Σy²), for [`Invariant::Energy`].
    pub energy: Option<(f64, f64)>,
    /// Bounds seen broken while running (each fails the case, whatever
    /// the invariant).
    pub violations: Vec<String>,
    /// Anything else worth a word in the table.
    pub notes: Vec<String>,
    /// Set by a piece of a case run in pieces ([`super::Work::Pieces`])
    /// that ends the case: its error is the case's, and what it and the
    /// pieces after it saw is left out ([`super::join`]).
    pub ends_case: bool,
}

impl Default for Observed {
    fn default() -> Self {
        Self {
            max_abs: 0.0,
            ports: Vec::new(),
            non_finite: 0,
            samples: 0,
            bad_ports: Vec::new(),
            error: None,
            panic: None,
            measured: None,
            series: Vec::new(),
            energy: None,
            violations: Vec::new(),
            notes: Vec::new(),
            ends_case: false,
        }
    }
}

/// The largest |x| over the finite samples (0 if none) and how many are
/// not finite. Eight running maxima side by side: the largest of a set is
/// the same whatever the order it is taken in, and these loops vectorize.
fn finite_max_abs(samples: &[f64]) -> (f64, u64) {
    let mut lanes = [0.0f64; 8];
    let mut bad = [0u64; 8];
    let mut chunks = samples.chunks_exact(8);
    for c in &mut chunks {
        for i in 0..8 {
            let x = c[i];
            let finite = x.is_finite();
            let a = if finite { x.abs() } else { 0.0 };
            lanes[i] = if a > lanes[i] { a } else { lanes[i] };
            bad[i] += u64::from(!finite);
        }
    }
    let mut m = lanes.iter().fold(0.0f64, |m, &a| if a > m { a } else { m });
    let mut b: u64 = bad.iter().sum();
    for &x in chunks.remainder() {
        if x.is_finite() {
            m = m.max(x.abs());
        } else {
            b += 1;
        }
    }
    (m, b)
}

impl Observed {
    /// Counts one watched output port's samples into the totals.
    pub fn watch(&mut self, port: &str, samples: &[f64]) {
        let (m, bad) = finite_max_abs(samples);
        let before = self.non_finite;
        self.non_finite += bad;
        if self.non_finite > before && !self.bad_ports.iter().any(|p| p == port) {
            self.bad_ports.push(port.to_string());
        }
        self.samples += samples.len() as u64;
        self.max_abs = self.max_abs.max(m);
        match self.ports.iter_mut().find(|(n, _)| n == port) {
            Some((_, v)) => *v = v.max(m),
            None => self.ports.push((port.to_string(), m)),
        }
    }

    /// Adds what `other` saw (a variant of the same case) to this.
    pub fn merge(&mut self, other: Observed) {
        self.max_abs = self.max_abs.max(other.max_abs);
        for (p, m) in other.ports {
            match self.ports.iter_mut().find(|(n, _)| *n == p) {
                Some((_, v)) => *v = v.max(m),
                None => self.ports.push((p, m)),
            }
        }
        self.non_finite += other.non_finite;
        for p in other.bad_ports {
            if !self.bad_ports.contains(&p) {
                self.bad_ports.push(p);
            }
        }
        self.samples += other.samples;
        if self.panic.is_none() {
            self.panic = other.panic;
        }
        self.notes.extend(other.notes);
        self.violations.extend(other.violations);
        if let Some(e) = other.error {
            self.notes.push(e);
        }
    }

    /// The detail column: panic, error, measured value, notes.
    pub fn detail(&self) -> String {
        let mut parts = Vec::new();
        if let Some(p) = &self.panic {
            parts.push(format!("panicked: {p}"));
        }
        if let Some(e) = &self.error {
            parts.push(format!("error: {e}"));
        }
        if !self.bad_ports.is_empty() {
            parts.push(format!("NaN/Inf in: {}", self.bad_ports.join(", ")));
        }
        if let Some(m) = self.measured {
            parts.push(format!("measured {m:.6e}"));
        }
        if let Some((i, o)) = self.energy {
            parts.push(format!("Σy²/Σx² = {:.6}", if i > 0.0 { o / i } else { 0.0 }));
        }
        if let (Some(a), Some(b)) = (self.series.first(), self.series.last()) {
            parts.push(format!("{} values, {a:.4e} → {b:.4e}", self.series.len()));
        }
        parts.extend(self.notes.iter().cloned());
        parts.join("; ").replace(['\n', '|'], " ")
    }
}

/// What must hold for a case to pass. Every invariant also demands that
/// nothing panicked and that no output was NaN or infinite.
#[derive(Debug, Clone, PartialEq)]
pub enum Invariant {
    /// Outputs finite; the run may be refused with an error (a clean
    /// refusal of a value the node cannot take) when `refusal_ok`.
    Finite {
        /// Whether an error that stops the run passes.
        refusal_ok: bool,
    },
    /// |output| ≤ `bound` (on port `port`, or every port), no error.
    Bound {
        /// The bound.
        bound: f64,
        /// The port it applies to (`None`: all watched ports).
        port: Option<String>,
        /// Where the bound comes from.
        why: String,
    },
    /// Σy² ≤ Σx² (a filter whose gain is at most 1 at every frequency,
    /// over a finite causal run), within a relative `1e-9`.
    Energy,
    /// The series never rises (an objective per iteration), and it has at
    /// least one value (an optimizer that stops at its start, stationary,
    /// reports one).
    Monotone,
    /// The measured value is within `tol` of `value`.
    Reference {
        /// The reference value.
        value: f64,
        /// Absolute tolerance.
        tol: f64,
        /// What it is.
        what: String,
    },
    /// The run must stop with an error whose message contains `naming`
    /// (e.g. the frame of a NaN sample), and no NaN or Inf may come out
    /// before it.
    Refused {
        /// Text the error must contain.
        naming: String,
    },
}

/// The verdict on one case.
#[derive(Debug, Clone, PartialEq)]
pub enum Verdict {
    /// The invariant held.
    Pass,
    /// It did not, and why.
    Fail(String),
}

impl Verdict {
    /// True for [`Verdict::Pass`].
    pub fn passed(&self) -> bool {
        matches!(self, Verdict::Pass)
    }
    /// `pass` or `FAIL: why`.
    pub fn text(&self) -> String {
        match self {
            Verdict::Pass => "pass".into(),
            Verdict::Fail(w) => format!("FAIL: {w}"),
        }
    }
}

impl Invariant {
    /// The invariant for people (the table's column).
    pub fn describe(&self) -> String {
        match self {
            Invariant::Finite { refusal_ok: true } => "finite (or refused)".into(),
            Invariant::Finite { refusal_ok: false } => "finite".into(),
            Invariant::Bound { bound, port, why } => match port {
                Some(p) => format!("bound |{p}| ≤ {bound:.6} ({why})"),
                None => format!("bound |out| ≤ {bound:.6e} ({why})"),
            },
            Invariant::Energy => "energy Σy² ≤ Σx²".into(),
            Invariant::Monotone => "monotone objective".into(),
            Invariant::Reference { value, tol, what } => format!("reference {what} = {value} ± {tol:e}"),
            Invariant::Refused { naming } => format!("error naming `{naming}`"),
        }
    }

    /// Judges what a case saw.
    pub fn judge(&self, o: &Observed) -> Verdict {
        if let Some(p) = &o.panic {
            return Verdict::Fail(format!("panicked: {p}"));
        }
        if o.non_finite > 0 {
            return Verdict::Fail(format!("{} NaN/Inf output samples", o.non_finite));
        }
        if let Some(v) = o.violations.first() {
            return Verdict::Fail(format!("{v} ({} breaches)", o.violations.len()));
        }
        let no_error = || match &o.error {
            Some(e) => Verdict::Fail(format!("stopped: {e}")),
            None => Verdict::Pass,
        };
        match self {
            Invariant::Finite { refusal_ok } => {
                if *refusal_ok {
                    Verdict::Pass
                } else {
                    no_error()
                }
            }
            Invariant::Bound { bound, port, .. } => {
                if o.error.is_some() {
                    return no_error();
                }
                let seen = match port {
                    Some(p) => match o.ports.iter().find(|(n, _)| n == p) {
                        Some((_, m)) => *m,
                        None => return Verdict::Fail(format!("port `{p}` was not watched")),
                    },
                    None => o.max_abs,
                };
                if seen <= *bound {
                    Verdict::Pass
                } else {
                    Verdict::Fail(format!("|out| = {seen:e} > {bound:e}"))
                }
            }
            Invariant::Energy => {
                if o.error.is_some() {
                    return no_error();
                }
                match o.energy {
                    Some((i, out)) if out.is_finite() && i.is_finite() && out <= i * (1.0 + 1e-9) => Verdict::Pass,
                    Some((i, out)) => Verdict::Fail(format!("Σy² = {out:e} > Σx² = {i:e}")),
                    None => Verdict::Fail("no energy measured".into()),
                }
            }
            Invariant::Monotone => {
                if o.error.is_some() {
                    return no_error();
                }
                if o.series.is_empty() {
                    return Verdict::Fail("no objective value reported".into());
                }
                if let Some(i) = o.series.iter().position(|v| !v.is_finite()) {
                    return Verdict::Fail(format!("value {i} is not finite"));
                }
                match o.series.windows(2).position(|w| w[1] > w[0]) {
                    Some(i) => {
                        Verdict::Fail(format!("rose at step {}: {:e} → {:e}", i + 1, o.series[i], o.series[i + 1]))
                    }
                    None => Verdict::Pass,
                }
            }
            Invariant::Reference { value, tol, what } => {
                if o.error.is_some() {
                    return no_error();
                }
                match o.measured {
                    Some(m) if (m - value).abs() <= *tol => Verdict::Pass,
                    Some(m) => Verdict::Fail(format!("{what} = {m:e}, off {value} by {:e}", (m - value).abs())),
                    None => Verdict::Fail(format!("{what} was not measured")),
                }
            }
            Invariant::Refused { naming } => match &o.error {
                Some(e) if e.contains(naming.as_str()) => Verdict::Pass,
                Some(e) => Verdict::Fail(format!("the error does not name `{naming}`: {e}")),
                None => Verdict::Fail(format!("ran without an error (expected one naming `{naming}`)")),
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn seen(values: &[f64]) -> Observed {
        let mut o = Observed::default();
        o.watch("out", values);
        o
    }

    #[test]
    fn the_eight_lane_maximum_is_the_sample_by_sample_one() {
        let mut r = evflow_nodes::rng::Rng::new(3);
        for len in 0..40 {
            let mut v: Vec<f64> = (0..len).map(|_| r.gaussian() * 10f64.powi((r.uniform() * 8.0) as i32 - 4)).collect();
            for (k, x) in v.iter_mut().enumerate() {
                match (k * 7 + len) % 11 {
                    0 => *x = f64::NAN,
                    1 => *x = -f64::INFINITY,
                    2 => *x = -0.0,
                    _ => {}
                }
            }
            let (mut want, mut bad) = (0.0f64, 0u64);
            for &x in &v {
                if x.is_finite() {
                    want = want.max(x.abs());
                } else {
                    bad += 1;
                }
            }
            let (got, got_bad) = finite_max_abs(&v);
            assert_eq!((got.to_bits(), got_bad), (want.to_bits(), bad), "length {len}");
        }
    }

    #[test]
    fn a_broken_bound_fails() {
        let inv = Invariant::Bound { bound: 1.0, port: None, why: "test".into() };
        assert!(inv.judge(&seen(&[0.5, -1.0])).passed());
        let v = inv.judge(&seen(&[0.5, -1.5]));
        assert!(!v.passed(), "{v:?}");
        assert!(v.text().contains("1.5e0"), "{}", v.text());
        let port = Invariant::Bound { bound: 1.0, port: Some("u".into()), why: "test".into() };
        assert!(!port.judge(&seen(&[0.5])).passed(), "an unwatched port fails");
    }

    #[test]
    fn nan_inf_and_panics_fail_every_invariant() {
        let all = [
            Invariant::Finite { refusal_ok: true },
            Invariant::Bound { bound: f64::INFINITY, port: None, why: String::new() },
            Invariant::Energy,
            Invariant::Monotone,
            Invariant::Reference { value: 0.0, tol: f64::INFINITY, what: "x".into() },
            Invariant::Refused { naming: String::new() },
        ];
        let mut nan = seen(&[1.0, f64::NAN, f64::INFINITY]);
        assert_eq!(nan.non_finite, 2);
        assert_eq!(nan.max_abs, 1.0);
        nan.error = Some(String::new());
        let panicked = Observed { panic: Some("boom".into()), ..Observed::default() };
        let breached = Observed { violations: vec!["l.out above 1".into()], ..Observed::default() };
        for inv in &all {
            assert!(!inv.judge(&nan).passed(), "{inv:?}");
            assert!(!inv.judge(&panicked).passed(), "{inv:?}");
            assert!(!inv.judge(&breached).passed(), "{inv:?}");
        }
    }

    #[test]
    fn a_rising_objective_fails() {
        let inv = Invariant::Monotone;
        let ok = Observed { series: vec![3.0, 2.0, 2.0, 1.0], ..Observed::default() };
        assert!(inv.judge(&ok).passed());
        let bad = Observed { series: vec![3.0, 2.0, 2.5], ..Observed::default() };
        assert_eq!(inv.judge(&bad), Verdict::Fail("rose at step 2: 2e0 → 2.5e0".into()));
        assert!(inv.judge(&Observed { series: vec![1.0], ..Observed::default() }).passed());
        assert!(!inv.judge(&Observed::default()).passed(), "no value at all fails");
    }

    #[test]
    fn energy_reference_and_refusal_fail_when_broken() {
        let gain = |i: f64, o: f64| Observed { energy: Some((i, o)), ..Observed::default() };
        assert!(Invariant::Energy.judge(&gain(2.0, 1.0)).passed());
        assert!(!Invariant::Energy.judge(&gain(1.0, 2.0)).passed());
        assert!(!Invariant::Energy.judge(&Observed::default()).passed());
        let r = Invariant::Reference { value: 1.0, tol: 1e-6, what: "DC gain".into() };
        assert!(r.judge(&Observed { measured: Some(1.0 + 1e-7), ..Observed::default() }).passed());
        assert!(!r.judge(&Observed { measured: Some(1.0 + 1e-5), ..Observed::default() }).passed());
        let e = Invariant::Refused { naming: "frame 17".into() };
        assert!(e.judge(&Observed { error: Some("x: NaN at frame 17".into()), ..Observed::default() }).passed());
        assert!(!e.judge(&Observed { error: Some("x: NaN".into()), ..Observed::default() }).passed());
        assert!(!e.judge(&Observed::default()).passed(), "no error is a failure");
        let strict = Invariant::Finite { refusal_ok: false };
        assert!(!strict.judge(&Observed { error: Some("no".into()), ..Observed::default() }).passed());
    }
}
