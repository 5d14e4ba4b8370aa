//! Typed parameter handles: a parameter declared once, as a constant that
//! gives both its [`ParamSpec`] (for the node's declaration) and a typed
//! read of its validated value (for the node's constructor), so that the
//! name is written in one place and a choice arrives as the node's own
//! enum, parsed by the loader's word list and no second `match` on text.
//!
//! ```
//! use evflow_engine::typed_params::{Choice, Float};
//! use evflow_engine::{ParamSpec, Params, Value};
//!
//! #[derive(Debug, Clone, Copy, PartialEq)]
//! enum Band { Low, High }
//!
//! const CUTOFF: Float = Float::new("cutoff", 0.001, f64::INFINITY, 10.0, "Hz", "−3 dB frequency");
//! const KIND: Choice<Band> = Choice::new("kind", &["lowpass", "highpass"], &[Band::Low, Band::High], "lowpass", "which band passes");
//! static PARAMS: &[ParamSpec] = &[KIND.spec(), CUTOFF.spec()];
//!
//! let p = Params::from_map([("kind".to_string(), Value::Text("highpass".into())), ("cutoff".to_string(), Value::Float(50.0))].into());
//! assert_eq!((KIND.get(&p), CUTOFF.get(&p)), (Band::High, 50.0));
//! assert_eq!(PARAMS[0].name, "kind");
//! ```

use crate::params::Params;
use crate::spec::{ParamKind, ParamSpec};

/// A real-number parameter.
#[derive(Debug, Clone, Copy)]
pub struct Float(ParamSpec);

impl Float {
    /// Declares it: name, limits, default, unit, one-line description.
    pub const fn new(
        name: &'static str,
        min: f64,
        max: f64,
        default: f64,
        unit: &'static str,
        doc: &'static str,
    ) -> Self {
        Self(ParamSpec::float(name, min, max, default, unit, doc))
    }

    /// The same parameter, changeable while the graph runs live.
    pub const fn live(self) -> Self {
        Self(self.0.live())
    }

    /// The same parameter without a default: the graph file must set it.
    pub const fn required(self) -> Self {
        Self(self.0.required())
    }

    /// Its declaration.
    pub const fn spec(&self) -> ParamSpec {
        self.0
    }

    /// Its name, as written in the node's table (and as a live change names it).
    pub const fn name(&self) -> &'static str {
        self.0.name
    }

    /// Its validated value.
    pub fn get(&self, p: &Params) -> f64 {
        p.f64(self.0.name)
    }
}

/// An integer parameter.
#[derive(Debug, Clone, Copy)]
pub struct Int(ParamSpec);

impl Int {
    /// Declares it: name, limits, default, unit, one-line description.
    pub const fn new(
        name: &'static str,
        min: i64,
        max: i64,
        default: i64,
        unit: &'static str,
        doc: &'static str,
    ) -> Self {
        Self(ParamSpec::int(name, min, max, default, unit, doc))
    }

    /// Its declaration.
    pub const fn spec(&self) -> ParamSpec {
        self.0
    }

    /// Its validated value.
    pub fn get(&self, p: &Params) -> i64 {
        p.i64(self.0.name)
    }

    /// Its validated value as a count (the declaration's minimum is ≥ 0).
    pub fn count(&self, p: &Params) -> usize {
        p.usize(self.0.name)
    }
}

/// A choice among fixed words, read as the node's enum `E`: `values[i]`
/// stands for `words[i]`.
#[derive(Debug, Clone, Copy)]
pub struct Choice<E: 'static> {
    spec: ParamSpec,
    values: &'static [E],
}

impl<E: Copy> Choice<E> {
    /// Declares it: name, the words a graph file writes and the values they
    /// stand for (as many, in the same order), the default word, one-line
    /// description.
    pub const fn new(
        name: &'static str,
        words: &'static [&'static str],
        values: &'static [E],
        default: &'static str,
        doc: &'static str,
    ) -> Self {
        assert!(words.len() == values.len(), "a choice needs one value per word");
        Self { spec: ParamSpec::choice(name, words, default, doc), values }
    }

    /// Its declaration.
    pub const fn spec(&self) -> ParamSpec {
        self.spec
    }

    /// The value of the word the loader accepted. The loader refuses any
    /// other word, naming the ones it takes, so a word outside the list is
    /// a node whose declaration is not the one it was loaded with.
    pub fn get(&self, p: &Params) -> E {
        let word = p.str(self.spec.name);
        let ParamKind::Choice(words) = self.spec.kind else { unreachable!("a Choice is declared as a choice") };
        match words.iter().position(|w| *w == word) {
            Some(i) => self.values[i],
            None => panic!("parameter `{}`: `{word}` is not one of {words:?}, which the loader checks", self.spec.name),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::Value;

    #[derive(Debug, Clone, Copy, PartialEq)]
    enum Mode {
        A,
        B,
    }

    const MODE: Choice<Mode> = Choice::new("mode", &["a", "b"], &[Mode::A, Mode::B], "a", "which");
    const GAIN: Float = Float::new("gain", -1.0, 1.0, 0.5, "1", "multiplier").live();
    const ORDER: Int = Int::new("order", 1, 16, 4, "1", "order");

    fn params(v: &[(&str, Value)]) -> Params {
        Params::from_map(v.iter().map(|(k, v)| (k.to_string(), v.clone())).collect())
    }

    #[test]
    fn handles_declare_and_read_one_parameter() {
        let p = params(&[("mode", Value::Text("b".into())), ("gain", Value::Int(1)), ("order", Value::Int(7))]);
        assert_eq!((MODE.get(&p), GAIN.get(&p), ORDER.get(&p), ORDER.count(&p)), (Mode::B, 1.0, 7, 7));
        let s = GAIN.spec();
        assert_eq!((s.name, s.unit, s.live), ("gain", "1", true));
        assert!(matches!(MODE.spec().kind, ParamKind::Choice(&["a", "b"])));
    }

    #[test]
    #[should_panic(expected = "`c` is not one of")]
    fn a_word_the_loader_would_refuse_is_a_declaration_error() {
        MODE.get(&params(&[("mode", Value::Text("c".into()))]));
    }
}
