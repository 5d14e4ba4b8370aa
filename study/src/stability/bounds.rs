//! The output bounds and cost caps the stability suite reads from each
//! node type's declaration: an output bound tighter than "finite" is the
//! node's own [`NodeSpec::bound`] (derived from its parameters and
//! inputs), and a parameter whose largest value is a cost, not a numerical
//! extreme, is declared [`ParamSpec::costly`](evflow_engine::ParamSpec::costly)
//! where the parameter is. A new node type needs no entry here to be
//! covered (its cases are generated from its declaration); declaring a
//! bound makes its check tighter.

use evflow_engine::NodeSpec;
use toml::Table;

/// A bound on one output port: `(port, bound, where it comes from)`.
pub use evflow_engine::spec::PortBound;

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

/// The bound on the output of a node of type `spec` given its parameters
/// `p` (as the case sets them; the declared default where absent) and the
/// largest |input| `input_max` (0 for sources); `None`: only "finite" is
/// known.
pub fn bound(spec: &NodeSpec, p: Get<'_>, input_max: f64) -> Option<PortBound> {
    spec.output_bound(p, input_max)
}

/// The value a case sets `param` of a node of type `spec` to instead of
/// `value`, and why, when `value` is above the parameter's declared cost
/// cap.
pub fn capped(spec: &NodeSpec, param: &str, value: f64) -> Option<(f64, &'static str)> {
    spec.param(param)?.capped(value)
}

#[cfg(test)]
mod tests {
    use super::*;
    use evflow_engine::spec::{BoundArgs, PortBound};
    use evflow_engine::{BuildContext, Node, NodeError, ParamSpec, Params, PortSpec, Role};

    fn spec(name: &str) -> &'static NodeSpec {
        evflow_nodes::registry().get(name).unwrap()
    }

    #[test]
    fn bounds_read_the_parameters() {
        let t = |s: &str| -> Table { s.parse().unwrap() };
        let (p, empty, g, unclamped) = (t("amplitude = 0.5"), Table::new(), t("gain = -3"), t("clamp = false"));
        assert_eq!(bound(spec("limit"), &from_table(&p), 9.0).unwrap().1, 0.5);
        assert_eq!(bound(spec("limit"), &from_table(&empty), 9.0).unwrap().1, 1.0);
        assert_eq!(bound(spec("gain"), &from_table(&g), 2.0).unwrap().1, 6.0);
        assert!(bound(spec("gain"), &from_table(&g), f64::MAX).is_none(), "an overflowing product gives no bound");
        assert!(bound(spec("normalize"), &from_table(&unclamped), 1.0).is_none());
        assert!(bound(spec("butterworth"), &from_table(&empty), 1.0).is_none());
    }

    fn never(_: &Params, _: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
        Err(NodeError::Other("test only".into()))
    }

    const LEVEL: ParamSpec = ParamSpec::float("level", 0.0, 1e6, 2.0, "1", "level").costly(10.0, "slow above 10");

    fn three_levels(b: &BoundArgs<'_>) -> Option<PortBound> {
        Some(("out", 3.0 * b.num(&LEVEL), "three levels".into()))
    }

    /// A node type known to no list: what it declares is all the suite knows.
    static DECLARED: NodeSpec = NodeSpec::new("test.declared", "test", Role::Source, "test only", never)
        .ports(&[PortSpec::output("out", "1", "level")])
        .params(&[LEVEL])
        .bound(three_levels);

    #[test]
    fn a_new_node_types_declared_bound_and_cost_cap_are_the_suites() {
        let t: Table = "level = 0.5".parse().unwrap();
        assert_eq!(bound(&DECLARED, &from_table(&t), 0.0), Some(("out", 1.5, "three levels".into())));
        assert_eq!(bound(&DECLARED, &from_table(&Table::new()), 0.0).unwrap().1, 6.0, "the declared default");
        assert_eq!(capped(&DECLARED, "level", 1e6), Some((10.0, "slow above 10")));
        assert_eq!(capped(&DECLARED, "level", 10.0), None, "at the cap: not capped");
        assert_eq!(capped(&DECLARED, "other", 1e6), None);
    }

    /// The node types that had a bound, and the parameters that had a cost
    /// cap, in the suite's own lists before they moved onto the
    /// declarations (issue 35): the declarations hold the same.
    #[cfg(all(feature = "mesh", feature = "synth"))]
    #[test]
    fn the_declarations_hold_the_suites_former_lists() {
        let specs = evflow_nodes::all_specs();
        let mut bounded: Vec<&str> = specs.iter().filter(|s| s.bound.is_some()).map(|s| s.name).collect();
        bounded.sort();
        let mut former = [
            "limit",
            "normalize",
            "delay",
            "hold",
            "gain",
            "sine",
            "pulse",
            "prbs",
            "prms",
            "profile1d",
            "synth.optimize",
            "synth.live",
            "grain",
        ];
        former.sort();
        assert_eq!(bounded, former);
        let caps: Vec<(&str, &str, f64, &str)> = specs
            .iter()
            .flat_map(|s| s.params.iter().filter_map(move |p| p.cost_cap.map(|(c, why)| (s.name, p.name, c, why))))
            .collect();
        let scan = "calibration scan time grows with directions × lines";
        let cells = "4096² cells: 34 M triangles, minutes to build";
        let unit =
            "the calibration scan crosses the mesh at finger speed: at 1000 m a unit, 162 s (found by this suite)";
        assert_eq!(
            caps,
            [
                ("mesh.gradient", "resolution", 512.0, cells),
                ("mesh.gradient", "unit", 0.1, unit),
                ("mesh.gradient", "calib_directions", 36.0, scan),
                ("mesh.gradient", "calib_lines", 48.0, scan),
                ("mesh.edges", "resolution", 512.0, cells),
            ]
        );
    }
}
