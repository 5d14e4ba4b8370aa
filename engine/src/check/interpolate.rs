//! `${name}` in text parameters: graph variables spliced into text, so one
//! graph can name its outputs after its condition
//! (`path = "recordings/${material}-${mass}g"`).

use crate::graph::Var;
use crate::params::Value;

/// A variable named in `${…}` that the graph does not declare, or a `${`
/// without its `}`.
#[derive(Debug, Clone, PartialEq)]
pub enum InterpolateError {
    /// `${name}` names no variable.
    Unknown(String),
    /// `${` is not closed.
    Unclosed,
}

/// How a variable's value reads inside text: integral numbers without a
/// decimal point (`60`, not `60.0`), others in their shortest exact form.
pub fn text_of(v: &Value) -> String {
    match v {
        Value::Float(x) if x.fract() == 0.0 && x.abs() < 1e15 => format!("{x:.0}"),
        Value::Float(x) => format!("{x}"),
        Value::Int(i) => i.to_string(),
        Value::Bool(b) => b.to_string(),
        Value::Text(t) => t.clone(),
        Value::TextList(l) => l.join(","),
        Value::FloatList(l) => l.iter().map(|x| text_of(&Value::Float(*x))).collect::<Vec<_>>().join(","),
    }
}

/// Replaces every `${name}` in `text` by the value of variable `name`.
pub fn interpolate(text: &str, vars: &[Var]) -> Result<String, InterpolateError> {
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(at) = rest.find("${") {
        out.push_str(&rest[..at]);
        let after = &rest[at + 2..];
        let end = after.find('}').ok_or(InterpolateError::Unclosed)?;
        let name = &after[..end];
        let var = vars.iter().find(|v| v.name == name).ok_or_else(|| InterpolateError::Unknown(name.to_string()))?;
        out.push_str(&text_of(&var.value));
        rest = &after[end + 1..];
    }
    out.push_str(rest);
    Ok(out)
}

/// Interpolates a text or text-list value; other values pass unchanged.
pub fn interpolate_value(v: &Value, vars: &[Var]) -> Result<Value, InterpolateError> {
    Ok(match v {
        Value::Text(t) if t.contains("${") => Value::Text(interpolate(t, vars)?),
        Value::TextList(l) if l.iter().any(|t| t.contains("${")) => {
            Value::TextList(l.iter().map(|t| interpolate(t, vars)).collect::<Result<_, _>>()?)
        }
        other => other.clone(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diag::Loc;

    fn vars() -> Vec<Var> {
        [
            ("mass", Value::Float(60.0)),
            ("speed", Value::Float(3.5)),
            ("material", Value::Text("felt".into())),
            ("rep", Value::Int(2)),
        ]
        .into_iter()
        .map(|(n, v)| Var { name: n.into(), value: v, loc: Loc::default() })
        .collect()
    }

    #[test]
    fn splices_variables_into_text() {
        assert_eq!(
            interpolate("rec/${material}-${mass}g-${speed}cms-r${rep}", &vars()).unwrap(),
            "rec/felt-60g-3.5cms-r2"
        );
        assert_eq!(interpolate("no variables", &vars()).unwrap(), "no variables");
        assert_eq!(interpolate("${mass}${mass}", &vars()).unwrap(), "6060");
        assert_eq!(interpolate("$mass stays", &vars()).unwrap(), "$mass stays");
    }

    #[test]
    fn names_the_unknown_variable() {
        assert_eq!(interpolate("a-${mas}", &vars()), Err(InterpolateError::Unknown("mas".into())));
        assert_eq!(interpolate("a-${mass", &vars()), Err(InterpolateError::Unclosed));
    }

    #[test]
    fn numbers_read_as_people_write_them() {
        assert_eq!(text_of(&Value::Float(110.0)), "110");
        assert_eq!(text_of(&Value::Float(0.1)), "0.1");
        assert_eq!(text_of(&Value::Float(-2.0)), "-2");
    }

    #[test]
    fn lists_interpolate_each_entry() {
        let v = Value::TextList(vec!["${material}".into(), "x".into()]);
        assert_eq!(interpolate_value(&v, &vars()).unwrap(), Value::TextList(vec!["felt".into(), "x".into()]));
    }
}
