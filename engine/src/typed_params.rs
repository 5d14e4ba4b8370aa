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

use crate::node::Change;
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

    /// Its validated value.
    pub fn get(&self, p: &Params) -> f64 {
        p.f64(self.0.name)
    }

    /// The new value when `c` changes this parameter.
    pub fn changed(&self, c: &Change) -> Option<f64> {
        (c.param == self.0.name).then_some(c.value)
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

    /// Its validated value.
    pub fn get(&self, p: &Params) -> i64 {
        p.i64(self.0.name)
    }

    /// Its validated value as a count (the declaration's minimum is ≥ 0).
    pub fn count(&self, p: &Params) -> usize {
        p.usize(self.0.name)
    }

    /// The new value when `c` changes this parameter (checked against the
    /// declared limits, so a whole number), as a count.
    pub fn changed(&self, c: &Change) -> Option<usize> {
        (c.param == self.0.name && c.value >= 0.0).then_some(c.value as usize)
    }
}

/// A true/false parameter.
#[derive(Debug, Clone, Copy)]
pub struct Flag(ParamSpec);

impl Flag {
    /// Declares it: name, default, one-line description.
    pub const fn new(name: &'static str, default: bool, doc: &'static str) -> Self {
        Self(ParamSpec::flag(name, default, doc))
    }

    /// Its validated value.
    pub fn get(&self, p: &Params) -> bool {
        p.bool(self.0.name)
    }

    /// The new value when `c` changes this parameter.
    pub fn changed(&self, c: &Change) -> Option<bool> {
        (c.param == self.0.name).then_some(c.value != 0.0)
    }
}

/// A free-text parameter (a file path, a name).
#[derive(Debug, Clone, Copy)]
pub struct Text(ParamSpec);

impl Text {
    /// Declares it: name, default, one-line description.
    pub const fn new(name: &'static str, default: &'static str, doc: &'static str) -> Self {
        Self(ParamSpec::text(name, default, doc))
    }

    /// Its validated value.
    pub fn get<'p>(&self, p: &'p Params) -> &'p str {
        p.str(self.0.name)
    }
}

/// A list-of-words parameter (channel names, gate ports), empty by default.
#[derive(Debug, Clone, Copy)]
pub struct Words(ParamSpec);

impl Words {
    /// Declares it: name, one-line description.
    pub const fn new(name: &'static str, doc: &'static str) -> Self {
        Self(ParamSpec::text_list(name, doc))
    }

    /// Its validated value.
    pub fn get<'p>(&self, p: &'p Params) -> &'p [String] {
        p.text_list(self.0.name)
    }
}

/// A list-of-numbers parameter, empty by default.
#[derive(Debug, Clone, Copy)]
pub struct Floats(ParamSpec);

impl Floats {
    /// Declares it: name, limits of each element, unit, one-line description.
    pub const fn new(name: &'static str, min: f64, max: f64, unit: &'static str, doc: &'static str) -> Self {
        Self(ParamSpec::float_list(name, min, max, unit, doc))
    }

    /// Its validated value.
    pub fn get<'p>(&self, p: &'p Params) -> &'p [f64] {
        p.float_list(self.0.name)
    }
}

/// What every one-spec handle has: its declaration, its name, and the
/// same parameter made live, required or costly.
macro_rules! handle_basics {
    ($($handle:ident),*) => {$(
        impl $handle {
            /// Its declaration.
            pub const fn spec(&self) -> ParamSpec {
                self.0
            }

            /// Its name, as written in the node's table (and in errors about it).
            pub const fn name(&self) -> &'static str {
                self.0.name
            }

            /// The same parameter, changeable while the graph runs live.
            pub const fn live(self) -> Self {
                Self(self.0.live())
            }

            /// The same parameter without a default: the graph file must set it.
            pub const fn required(self) -> Self {
                Self(self.0.required())
            }

            /// The same parameter, whose values above `cap` only cost run
            /// time or memory (see [`ParamSpec::costly`]).
            pub const fn costly(self, cap: f64, why: &'static str) -> Self {
                Self(self.0.costly(cap, why))
            }
        }
    )*};
}

handle_basics!(Float, Int, Flag, Text, Words, Floats);

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

    /// Its name, as written in the node's table.
    pub const fn name(&self) -> &'static str {
        self.spec.name
    }

    /// The same parameter, changeable while the graph runs live (the node's
    /// `set` receives the index of the word).
    pub const fn live(mut self) -> Self {
        self.spec = self.spec.live();
        self
    }

    /// The new value when `c` changes this parameter (`c` carries the index
    /// of the word, checked against the list).
    pub fn changed(&self, c: &Change) -> Option<E> {
        if c.param != self.spec.name || c.value < 0.0 {
            return None;
        }
        self.values.get(c.value as usize).copied()
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
    fn a_live_change_is_read_only_by_its_own_handle() {
        let c = Change { param: "gain", value: 0.25 };
        assert_eq!((GAIN.changed(&c), ORDER.changed(&c), MODE.changed(&c)), (Some(0.25), None, None));
        assert_eq!(MODE.changed(&Change { param: "mode", value: 1.0 }), Some(Mode::B));
        assert_eq!(MODE.changed(&Change { param: "mode", value: 2.0 }), None);
        assert_eq!(ORDER.changed(&Change { param: "order", value: 3.0 }), Some(3));
        let on = Flag::new("on", false, "switch").live();
        assert_eq!((on.changed(&Change { param: "on", value: 1.0 }), on.spec().live), (Some(true), true));
    }

    #[test]
    #[should_panic(expected = "`c` is not one of")]
    fn a_word_the_loader_would_refuse_is_a_declaration_error() {
        MODE.get(&params(&[("mode", Value::Text("c".into()))]));
    }
}
