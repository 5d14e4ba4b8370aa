//! Node types whose outputs have a bound tighter than "finite", derived
//! from their parameters and inputs; and the parameters whose largest
//! value is a cost, not a numerical extreme. A new node type needs no
//! entry here to be covered (its cases are generated from its
//! declaration); an entry makes its check tighter.

use toml::Table;

/// A bound on one output port: `(port, bound, where it comes from)`.
pub type PortBound = (&'static str, f64, String);

/// A node's parameters as numbers (flags as 0/1; `None`: not set, so the
/// declared default).
pub type Get<'a> = &'a dyn Fn(&str) -> Option<f64>;

/// The getter of a node table (as written in a graph file).
pub fn from_table(t: &Table) -> impl Fn(&str) -> Option<f64> + '_ {
    move |name| match t.get(name) {
        Some(toml::Value::Float(x)) => Some(*x),
        Some(toml::Value::Integer(i)) => Some(*i as f64),
        Some(toml::Value::Boolean(b)) => Some(f64::from(u8::from(*b))),
        _ => None,
    }
}

/// The getter of a checked node's parameters (defaults filled in).
pub fn from_params(p: &evflow_engine::Params) -> impl Fn(&str) -> Option<f64> + '_ {
    move |name| match p.get(name) {
        Some(evflow_engine::Value::Bool(b)) => Some(f64::from(u8::from(*b))),
        Some(v) => v.as_f64(),
        None => None,
    }
}

fn num(p: Get<'_>, name: &str, default: f64) -> f64 {
    p(name).unwrap_or(default)
}

fn flag(p: Get<'_>, name: &str, default: bool) -> bool {
    p(name).map(|x| x != 0.0).unwrap_or(default)
}

/// The bound on `node`'s output given its parameters `p` (as the case
/// sets them; the declared default where absent) and the largest |input|
/// `input_max` (0 for sources); `None`: only "finite" is known.
pub fn bound(node: &str, p: Get<'_>, input_max: f64) -> Option<PortBound> {
    let b = match node {
        "limit" => ("out", num(p, "amplitude", 1.0), "|out| ≤ amplitude".to_string()),
        "normalize" if flag(p, "clamp", true) => ("out", 1.0, "clamped to [−1, 1]".into()),
        "delay" => ("out", input_max, "a delayed input".into()),
        "hold" => ("out", input_max, "a held input".into()),
        "gain" if (num(p, "gain", 1.0) * input_max).is_finite() => {
            ("out", num(p, "gain", 1.0).abs() * input_max, "|gain|·max|in|".into())
        }
        "sine" => ("out", num(p, "offset", 0.0).abs() + num(p, "amplitude", 1.0), "|offset| + amplitude".into()),
        "pulse" => ("out", num(p, "high", 1.0).abs().max(num(p, "low", 0.0).abs()), "max(|high|, |low|)".into()),
        "prbs" | "prms" => ("out", num(p, "level", 1.0), "the level c".into()),
        "profile1d" => ("intensity", 1.0, "an intensity in [0, 1]".into()),
        "synth.optimize" => ("u", num(p, "bound", 1.0), "|u| ≤ bound".into()),
        "synth.live" => ("u", num(p, "bound", 1.0), "|u| ≤ bound".into()),
        "grain" => ("out", 1.0 + 1e-12, "actuation full scale".into()),
        _ => return None,
    };
    Some(b)
}

/// Parameters whose declared largest value buys run time or memory, not
/// a numerical extreme: the cases run them at `cap` instead (and say so).
/// `(node, parameter, cap, why)`.
pub const COSTLY: &[(&str, &str, f64, &str)] = &[
    ("mesh.gradient", "resolution", 512.0, "4096² cells: 34 M triangles, minutes to build"),
    ("mesh.edges", "resolution", 512.0, "4096² cells: 34 M triangles, minutes to build"),
    (
        "mesh.gradient",
        "unit",
        0.1,
        "the calibration scan crosses the mesh at finger speed: at 1000 m a unit, 162 s (found by this suite)",
    ),
    ("mesh.gradient", "calib_directions", 36.0, "calibration scan time grows with directions × lines"),
    ("mesh.gradient", "calib_lines", 48.0, "calibration scan time grows with directions × lines"),
];

/// The value a case sets `param` of `node` to instead of `value`, and
/// why, when `value` is above its cost cap.
pub fn capped(node: &str, param: &str, value: f64) -> Option<(f64, &'static str)> {
    COSTLY.iter().find(|(n, p, cap, _)| *n == node && *p == param && value > *cap).map(|(_, _, cap, why)| (*cap, *why))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bounds_read_the_parameters() {
        let t = |s: &str| -> Table { s.parse().unwrap() };
        let (p, empty, g, unclamped) = (t("amplitude = 0.5"), Table::new(), t("gain = -3"), t("clamp = false"));
        assert_eq!(bound("limit", &from_table(&p), 9.0).unwrap().1, 0.5);
        assert_eq!(bound("limit", &from_table(&empty), 9.0).unwrap().1, 1.0);
        assert_eq!(bound("gain", &from_table(&g), 2.0).unwrap().1, 6.0);
        assert!(bound("gain", &from_table(&g), f64::MAX).is_none(), "an overflowing product gives no bound");
        assert!(bound("normalize", &from_table(&unclamped), 1.0).is_none());
        assert!(bound("butterworth", &from_table(&empty), 1.0).is_none());
    }
}
