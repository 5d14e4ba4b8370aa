//! Parameter values after validation.

use std::collections::BTreeMap;
use std::fmt;

/// A parameter value as written in a graph file.
#[derive(Debug, Clone, PartialEq)]
pub enum Value {
    /// A real number.
    Float(f64),
    /// An integer.
    Int(i64),
    /// A boolean.
    Bool(bool),
    /// Text, a choice, or a `$variable` reference before substitution.
    Text(String),
    /// A list of words.
    TextList(Vec<String>),
    /// A list of numbers.
    FloatList(Vec<f64>),
}

impl Value {
    /// The number, if this is a number (integers widen to real).
    pub fn as_f64(&self) -> Option<f64> {
        match self {
            Value::Float(x) => Some(*x),
            Value::Int(i) => Some(*i as f64),
            _ => None,
        }
    }

    /// The variable name when this value is a `$name` reference.
    pub fn var_ref(&self) -> Option<&str> {
        match self {
            Value::Text(s) => s
                .strip_prefix('$')
                .filter(|n| !n.is_empty() && n.chars().all(|c| c.is_alphanumeric() || c == '_' || c == '-')),
            _ => None,
        }
    }
}

impl fmt::Display for Value {
    /// Writes the value as TOML.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Value::Float(x) => write!(f, "{}", toml_float(*x)),
            Value::Int(i) => write!(f, "{i}"),
            Value::Bool(b) => write!(f, "{b}"),
            Value::Text(s) => write!(f, "{}", toml_string(s)),
            Value::TextList(v) => {
                let items: Vec<String> = v.iter().map(|s| toml_string(s)).collect();
                write!(f, "[{}]", items.join(", "))
            }
            Value::FloatList(v) => {
                let items: Vec<String> = v.iter().map(|x| toml_float(*x)).collect();
                write!(f, "[{}]", items.join(", "))
            }
        }
    }
}

/// A float written so TOML reads back the same bits (always with a `.` or exponent).
pub fn toml_float(x: f64) -> String {
    if x.is_nan() {
        "nan".into()
    } else if x.is_infinite() {
        if x > 0.0 {
            "inf".into()
        } else {
            "-inf".into()
        }
    } else {
        let s = format!("{x:?}");
        if s.contains('.') || s.contains('e') || s.contains('E') {
            s
        } else {
            format!("{s}.0")
        }
    }
}

/// A TOML basic string with escapes.
pub fn toml_string(s: &str) -> String {
    let mut out = String::with_capacity(s.len() + 2);
    out.push('"');
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            '\n' => out.push_str("\\n"),
            '\t' => out.push_str("\\t"),
            '\r' => out.push_str("\\r"),
            c if (c as u32) < 0x20 || c as u32 == 0x7f => out.push_str(&format!("\\u{:04X}", c as u32)),
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

/// The validated parameters of one node: every declared parameter present,
/// of its declared type and within its limits, variables substituted.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Params {
    values: BTreeMap<String, Value>,
}

impl Params {
    /// Parameters from already validated values (used by the validator and tests).
    pub fn from_map(values: BTreeMap<String, Value>) -> Self {
        Self { values }
    }

    /// The raw value.
    pub fn get(&self, name: &str) -> Option<&Value> {
        self.values.get(name)
    }

    /// A real-number parameter (integers widen). Panics only if the node's
    /// own declaration disagrees with its constructor — a programming error
    /// caught by the generic node tests, never by user input.
    pub fn f64(&self, name: &str) -> f64 {
        match self.values.get(name) {
            Some(v) => v.as_f64().unwrap_or_else(|| declared_wrong(name, "number")),
            None => declared_wrong(name, "number"),
        }
    }

    /// An integer parameter.
    pub fn i64(&self, name: &str) -> i64 {
        match self.values.get(name) {
            Some(Value::Int(i)) => *i,
            _ => declared_wrong(name, "integer"),
        }
    }

    /// A non-negative integer parameter as `usize`.
    pub fn usize(&self, name: &str) -> usize {
        usize::try_from(self.i64(name)).unwrap_or_else(|_| declared_wrong(name, "non-negative integer"))
    }

    /// A boolean parameter.
    pub fn bool(&self, name: &str) -> bool {
        match self.values.get(name) {
            Some(Value::Bool(b)) => *b,
            _ => declared_wrong(name, "boolean"),
        }
    }

    /// A text or choice parameter.
    pub fn str(&self, name: &str) -> &str {
        match self.values.get(name) {
            Some(Value::Text(s)) => s,
            _ => declared_wrong(name, "text"),
        }
    }

    /// A list-of-words parameter.
    pub fn text_list(&self, name: &str) -> &[String] {
        match self.values.get(name) {
            Some(Value::TextList(v)) => v,
            _ => declared_wrong(name, "list of text"),
        }
    }

    /// A list-of-numbers parameter.
    pub fn float_list(&self, name: &str) -> &[f64] {
        match self.values.get(name) {
            Some(Value::FloatList(v)) => v,
            _ => declared_wrong(name, "list of numbers"),
        }
    }

    /// All values, by name.
    pub fn iter(&self) -> impl Iterator<Item = (&str, &Value)> {
        self.values.iter().map(|(k, v)| (k.as_str(), v))
    }
}

#[cold]
fn declared_wrong(name: &str, what: &str) -> ! {
    panic!("node constructor asked for parameter `{name}` as {what}, which its declaration does not provide")
}
