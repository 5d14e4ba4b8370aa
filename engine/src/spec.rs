//! Node declarations as data.
//!
//! Every node type declares its ports, its parameters and its constructor once,
//! in a [`NodeSpec`]. The loader, the validator, `evflow nodes` and the
//! generated node reference (`docs/nodes.md`) all read that one declaration.

use crate::node::{BuildContext, Constant, Node, NodeError};
use crate::params::{Params, Value};

pub use crate::ports::{Direction, PortSpec, RateSpec};

/// The type and limits of a parameter.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ParamKind {
    /// A real number within `[min, max]` (inclusive).
    Float {
        /// Smallest accepted value.
        min: f64,
        /// Largest accepted value.
        max: f64,
    },
    /// An integer within `[min, max]` (inclusive).
    Int {
        /// Smallest accepted value.
        min: i64,
        /// Largest accepted value.
        max: i64,
    },
    /// `true` or `false`.
    Bool,
    /// Free text (e.g. a file path; relative paths are taken from the graph file's folder).
    Text,
    /// One of a fixed set of words.
    Choice(&'static [&'static str]),
    /// A list of words (e.g. channel names).
    TextList,
    /// A list of real numbers, each within `[min, max]`.
    FloatList {
        /// Smallest accepted element.
        min: f64,
        /// Largest accepted element.
        max: f64,
    },
}

impl ParamKind {
    /// A short human name of the type, used in errors and docs.
    pub fn type_name(&self) -> &'static str {
        match self {
            ParamKind::Float { .. } => "number",
            ParamKind::Int { .. } => "integer",
            ParamKind::Bool => "boolean",
            ParamKind::Text => "text",
            ParamKind::Choice(_) => "choice",
            ParamKind::TextList => "list of text",
            ParamKind::FloatList { .. } => "list of numbers",
        }
    }

    /// The limits written for people, e.g. `0.001 ..= 1e6` or `lowpass | highpass`.
    pub fn limits(&self) -> String {
        match self {
            ParamKind::Float { min, max } | ParamKind::FloatList { min, max } => {
                format!("{} ..= {}", fmt_num(*min), fmt_num(*max))
            }
            ParamKind::Int { min, max } => format!("{min} ..= {max}"),
            ParamKind::Choice(c) => c.join(" \\| "),
            _ => String::new(),
        }
    }
}

fn fmt_num(x: f64) -> String {
    if x == f64::INFINITY {
        "inf".into()
    } else if x == f64::NEG_INFINITY {
        "-inf".into()
    } else {
        format!("{x}")
    }
}

/// A parameter's default value (`Required` when the user must give it).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ParamDefault {
    /// No default: the graph file must set it.
    Required,
    /// Default real number.
    Float(f64),
    /// Default integer.
    Int(i64),
    /// Default boolean.
    Bool(bool),
    /// Default text or choice.
    Text(&'static str),
    /// Default empty list.
    EmptyList,
}

/// One parameter of a node type.
#[derive(Debug, Clone, Copy)]
pub struct ParamSpec {
    /// Parameter name, as written in the node's table.
    pub name: &'static str,
    /// Type and limits.
    pub kind: ParamKind,
    /// Default value, or [`ParamDefault::Required`].
    pub default: ParamDefault,
    /// Unit (e.g. `Hz`, `s`, `g`, `1`); empty for words and flags.
    pub unit: &'static str,
    /// One-line description.
    pub doc: &'static str,
    /// True when the node takes changes of this parameter while it runs
    /// ([`crate::node::Node::set`], the live runner's parameter queue).
    pub live: bool,
    /// When its largest values buy run time or memory rather than a
    /// numerical extreme: the value the stability suite runs instead of any
    /// larger one, and why (see [`ParamSpec::costly`]).
    pub cost_cap: Option<(f64, &'static str)>,
}

impl ParamSpec {
    /// A real-number parameter.
    pub const fn float(
        name: &'static str,
        min: f64,
        max: f64,
        default: f64,
        unit: &'static str,
        doc: &'static str,
    ) -> Self {
        Self {
            name,
            kind: ParamKind::Float { min, max },
            default: ParamDefault::Float(default),
            unit,
            doc,
            live: false,
            cost_cap: None,
        }
    }
    /// An integer parameter.
    pub const fn int(
        name: &'static str,
        min: i64,
        max: i64,
        default: i64,
        unit: &'static str,
        doc: &'static str,
    ) -> Self {
        Self {
            name,
            kind: ParamKind::Int { min, max },
            default: ParamDefault::Int(default),
            unit,
            doc,
            live: false,
            cost_cap: None,
        }
    }
    /// A boolean parameter.
    pub const fn flag(name: &'static str, default: bool, doc: &'static str) -> Self {
        Self {
            name,
            kind: ParamKind::Bool,
            default: ParamDefault::Bool(default),
            unit: "",
            doc,
            live: false,
            cost_cap: None,
        }
    }
    /// A choice among fixed words.
    pub const fn choice(
        name: &'static str,
        words: &'static [&'static str],
        default: &'static str,
        doc: &'static str,
    ) -> Self {
        Self {
            name,
            kind: ParamKind::Choice(words),
            default: ParamDefault::Text(default),
            unit: "",
            doc,
            live: false,
            cost_cap: None,
        }
    }
    /// A text parameter with a default.
    pub const fn text(name: &'static str, default: &'static str, doc: &'static str) -> Self {
        Self {
            name,
            kind: ParamKind::Text,
            default: ParamDefault::Text(default),
            unit: "",
            doc,
            live: false,
            cost_cap: None,
        }
    }
    /// A list of words, empty by default.
    pub const fn text_list(name: &'static str, doc: &'static str) -> Self {
        Self {
            name,
            kind: ParamKind::TextList,
            default: ParamDefault::EmptyList,
            unit: "",
            doc,
            live: false,
            cost_cap: None,
        }
    }
    /// A list of real numbers, empty by default.
    pub const fn float_list(name: &'static str, min: f64, max: f64, unit: &'static str, doc: &'static str) -> Self {
        Self {
            name,
            kind: ParamKind::FloatList { min, max },
            default: ParamDefault::EmptyList,
            unit,
            doc,
            live: false,
            cost_cap: None,
        }
    }
    /// The same parameter without a default: the graph file must set it.
    pub const fn required(mut self) -> Self {
        self.default = ParamDefault::Required;
        self
    }
    /// The same parameter, changeable while the graph runs live: the node's
    /// [`crate::node::Node::set`] takes it (numbers, flags as 0/1, choices
    /// as the index of the word) and applies it without a click.
    pub const fn live(mut self) -> Self {
        self.live = true;
        self
    }
    /// The same parameter, whose values above `cap` only cost run time or
    /// memory (a finer mesh, a longer calibration scan), saying `why`: the
    /// stability suite (`evflow report stability`) tries it at `cap`
    /// instead of its declared maximum, and says so.
    pub const fn costly(mut self, cap: f64, why: &'static str) -> Self {
        self.cost_cap = Some((cap, why));
        self
    }
    /// The value to try instead of `value` when `value` is above the
    /// parameter's cost cap, and why (see [`ParamSpec::costly`]).
    pub fn capped(&self, value: f64) -> Option<(f64, &'static str)> {
        self.cost_cap.filter(|(cap, _)| value > *cap)
    }
    /// Its default as a number (flags as 0/1); `None` for text, lists and
    /// a required parameter.
    pub fn default_f64(&self) -> Option<f64> {
        match self.default {
            ParamDefault::Float(x) => Some(x),
            ParamDefault::Int(i) => Some(i as f64),
            ParamDefault::Bool(b) => Some(f64::from(u8::from(b))),
            _ => None,
        }
    }
}

/// What part a node plays in a graph.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Role {
    /// Produces samples (no inputs).
    Source,
    /// Transforms samples.
    Filter,
    /// Consumes samples and has an effect outside the graph (file, device,
    /// report). Only nodes from which a sink is reachable enter a plan.
    Sink,
}

/// The constructor of a node type: validated parameters in, a node out.
/// Called only for nodes that survive pruning.
pub type Constructor = fn(&Params, &BuildContext) -> Result<Box<dyn Node>, NodeError>;

/// What a node type's [`Fold`] sees: its parameters and which of its inputs
/// are constant, before anything is built.
#[derive(Debug, Clone, Copy)]
pub struct FoldArgs<'a> {
    spec: &'static NodeSpec,
    params: &'a Params,
    inputs: &'a [Option<f64>],
    outputs: usize,
    settled: bool,
}

impl<'a> FoldArgs<'a> {
    /// The arguments of one fold: `inputs[i]` is `Some(v)` when input `i`
    /// (in the order of the node's resolved inputs) holds `v` at every
    /// sample; `outputs` is the number of output ports; `settled` is true
    /// when the plan takes no live parameter changes (an offline run).
    pub fn new(
        spec: &'static NodeSpec,
        params: &'a Params,
        inputs: &'a [Option<f64>],
        outputs: usize,
        settled: bool,
    ) -> Self {
        Self { spec, params, inputs, outputs, settled }
    }
    /// The constant value of input `i`, if it is constant.
    pub fn input(&self, i: usize) -> Option<f64> {
        self.inputs.get(i).copied().flatten()
    }
    /// Every input's constant value (`None`: not constant).
    pub fn inputs(&self) -> &[Option<f64>] {
        self.inputs
    }
    /// The number of output ports.
    pub fn outputs(&self) -> usize {
        self.outputs
    }
    /// A parameter's value — `None` when it is declared live and the plan
    /// may change it while it runs (a live session or its replay), so no
    /// fold can rely on it there.
    pub fn value(&self, name: &str) -> Option<&'a Value> {
        let live = self.spec.param(name).is_some_and(|p| p.live);
        if live && !self.settled {
            return None;
        }
        self.params.get(name)
    }
    /// A number parameter (see [`FoldArgs::value`]).
    pub fn f64(&self, name: &str) -> Option<f64> {
        self.value(name).and_then(Value::as_f64)
    }
}

/// A node type's constant folding: given its parameters and its constant
/// inputs, `Some` when its output is a constant for this plan (e.g. `gain`
/// with gain 0, `add` of two constants). Asked in the plan's order before
/// any node is built, so nodes that only fed a constant are never built
/// and never open their files (`docs/pruning.md`). It must be exact: the
/// constant equals, sample for sample from t = 0, what the node would
/// output given finite inputs.
pub type Fold = fn(&FoldArgs<'_>) -> Option<Constant>;

/// A bound on one output port: `(port, bound, where it comes from)`.
pub type PortBound = (&'static str, f64, String);

/// What a node type's [`OutputBound`] sees: its parameters as numbers and
/// the largest |input| it is fed.
#[derive(Clone, Copy)]
pub struct BoundArgs<'a> {
    get: &'a dyn Fn(&str) -> Option<f64>,
    input_max: f64,
}

impl<'a> BoundArgs<'a> {
    /// The arguments of one bound: `get(name)` is the parameter's value as
    /// a number (flags as 0/1; `None`: not set, so the declared default);
    /// `input_max` is the largest |input| (0 for a source).
    pub fn new(get: &'a dyn Fn(&str) -> Option<f64>, input_max: f64) -> Self {
        Self { get, input_max }
    }
    /// The largest |input|.
    pub fn input_max(&self) -> f64 {
        self.input_max
    }
    /// A number parameter's value, else its declared default (NaN when it
    /// has none, so no bound from it holds).
    pub fn num(&self, p: &ParamSpec) -> f64 {
        (self.get)(p.name).or_else(|| p.default_f64()).unwrap_or(f64::NAN)
    }
    /// A flag parameter's value, else its declared default.
    pub fn flag(&self, p: &ParamSpec) -> bool {
        (self.get)(p.name).map(|x| x != 0.0).unwrap_or(p.default == ParamDefault::Bool(true))
    }
}

/// A node type's output bound, tighter than "finite": given its
/// parameters and the largest |input|, the port, the bound on its |value|
/// and where the bound comes from; `None` when only "finite" is known
/// (e.g. `gain` when |gain|·max|in| overflows). The stability suite
/// (`evflow report stability`, docs/numerics.md) checks it in every case
/// that runs the node.
pub type OutputBound = fn(&BoundArgs<'_>) -> Option<PortBound>;

/// What the studio's finger view draws under the finger for a node of
/// this type (the first such node of a graph, in the plan's order).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scene {
    /// The height maps of the meshes the node can switch between
    /// (`mesh.gradient`).
    Mesh,
    /// The (load, velocity) axes of the texture grids the node can switch
    /// between (`interp`).
    TextureGrid,
}

/// The one declaration of a node type.
#[derive(Debug, Clone, Copy)]
pub struct NodeSpec {
    /// Type name as written in graph files (e.g. `butterworth`, `sim.display`).
    pub name: &'static str,
    /// Family, for grouping in `evflow nodes` and the docs.
    pub family: &'static str,
    /// One-line summary.
    pub summary: &'static str,
    /// Longer description: behaviour, rates, the dissertation section it
    /// implements and the references it was checked against (Markdown).
    pub doc: &'static str,
    /// Source, filter or sink.
    pub role: Role,
    /// Ports.
    pub ports: &'static [PortSpec],
    /// Parameters.
    pub params: &'static [ParamSpec],
    /// For nodes whose rate is set by a parameter (sources): its name.
    pub rate_param: Option<&'static str>,
    /// True for nodes whose output depends only on past input (`delay`):
    /// the only nodes a feedback cycle may pass through.
    pub breaks_cycles: bool,
    /// True for nodes that drive hardware: each of their inputs must come
    /// straight from a node with `safety_guard` (the `limit` node).
    pub hardware: bool,
    /// For the safety limiter, the only node allowed to feed hardware, and
    /// only from its first output: the name of its live flag parameter that
    /// keeps the gate open (`true`) or fades the output to zero (`false`),
    /// which a live session sets to `false` on stop. `None` for other nodes.
    pub safety_guard: Option<&'static str>,
    /// Why the node cannot run in a live session (e.g. it does blocking file
    /// I/O while processing); `None` for nodes that can.
    pub offline_only: Option<&'static str>,
    /// A node table that works as-is (TOML body without the header), used by
    /// the docs and by the generic tests that run every node type.
    pub example: &'static str,
    /// The constructor.
    pub build: Constructor,
    /// How the node folds to a constant (see [`Fold`]); `None`: never.
    pub fold: Option<Fold>,
    /// The bound on one of its outputs (see [`OutputBound`]); `None`: only
    /// "finite" is checked.
    pub bound: Option<OutputBound>,
    /// What the studio draws under the finger for it (see [`Scene`]).
    pub scene: Option<Scene>,
}

impl NodeSpec {
    /// A declaration with no ports or parameters yet; chain the setters below.
    pub const fn new(
        name: &'static str,
        family: &'static str,
        role: Role,
        summary: &'static str,
        build: Constructor,
    ) -> Self {
        Self {
            name,
            family,
            summary,
            doc: "",
            role,
            ports: &[],
            params: &[],
            rate_param: None,
            breaks_cycles: false,
            hardware: false,
            safety_guard: None,
            offline_only: None,
            example: "",
            build,
            fold: None,
            bound: None,
            scene: None,
        }
    }
    /// Sets the long description.
    pub const fn doc(mut self, doc: &'static str) -> Self {
        self.doc = doc;
        self
    }
    /// Sets the ports.
    pub const fn ports(mut self, ports: &'static [PortSpec]) -> Self {
        self.ports = ports;
        self
    }
    /// Sets the parameters.
    pub const fn params(mut self, params: &'static [ParamSpec]) -> Self {
        self.params = params;
        self
    }
    /// Names the parameter that sets the node's rate (sources).
    pub const fn rate_param(mut self, p: &'static str) -> Self {
        self.rate_param = Some(p);
        self
    }
    /// Marks a node whose output depends only on past input.
    pub const fn breaks_cycles(mut self) -> Self {
        self.breaks_cycles = true;
        self
    }
    /// Marks a hardware output.
    pub const fn hardware(mut self) -> Self {
        self.hardware = true;
        self
    }
    /// Marks the safety limiter, naming its live flag that opens the gate
    /// (see [`NodeSpec::safety_guard`](struct.NodeSpec.html#structfield.safety_guard)).
    pub const fn safety_guard(mut self, gate: &'static str) -> Self {
        self.safety_guard = Some(gate);
        self
    }
    /// True for the safety limiter.
    pub const fn is_guard(&self) -> bool {
        self.safety_guard.is_some()
    }
    /// Marks a node that cannot run live, saying why (the live runner
    /// refuses a graph that contains it).
    pub const fn offline_only(mut self, reason: &'static str) -> Self {
        self.offline_only = Some(reason);
        self
    }
    /// Sets the working example node table.
    pub const fn example(mut self, example: &'static str) -> Self {
        self.example = example;
        self
    }
    /// Declares how the node folds to a constant (see [`Fold`]).
    pub const fn fold(mut self, fold: Fold) -> Self {
        self.fold = Some(fold);
        self
    }
    /// Declares the bound on one of its outputs (see [`OutputBound`]).
    pub const fn bound(mut self, bound: OutputBound) -> Self {
        self.bound = Some(bound);
        self
    }
    /// Declares what the studio draws under the finger for it (see [`Scene`]).
    pub const fn scene(mut self, scene: Scene) -> Self {
        self.scene = Some(scene);
        self
    }
    /// Its output bound for the parameters `get` gives and inputs up to
    /// `input_max` (see [`OutputBound`]).
    pub fn output_bound(&self, get: &dyn Fn(&str) -> Option<f64>, input_max: f64) -> Option<PortBound> {
        self.bound.and_then(|f| f(&BoundArgs::new(get, input_max)))
    }
    /// The ports the studio shows by default (see [`PortSpec::view`]) in
    /// direction `dir`, in their declared order.
    pub fn viewed(&self, dir: Direction) -> impl Iterator<Item = &'static str> + '_ {
        self.ports.iter().filter(move |p| p.view && p.multi.is_none() && p.dir == dir).map(|p| p.name)
    }
    /// The declared parameter of that name.
    pub fn param(&self, name: &str) -> Option<&ParamSpec> {
        self.params.iter().find(|p| p.name == name)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn never(_: &Params, _: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
        Err(NodeError::Other("test only".into()))
    }

    const LEVEL: ParamSpec = ParamSpec::float("level", 0.0, 1e6, 2.0, "1", "level").costly(10.0, "slow above 10");
    const CLAMP: ParamSpec = ParamSpec::flag("clamp", true, "clamp");

    fn clamped_level(b: &BoundArgs<'_>) -> Option<PortBound> {
        b.flag(&CLAMP).then(|| ("out", b.num(&LEVEL) + b.input_max(), "level + max|in|".into()))
    }

    static SPEC: NodeSpec = NodeSpec::new("test.spec", "test", Role::Filter, "test only", never)
        .ports(&[
            PortSpec::input("in", "1", "in").view(),
            PortSpec::input("more", "1", "more").per("names").view(),
            PortSpec::output("out", "1", "out"),
            PortSpec::output("seen", "1", "seen").view(),
        ])
        .params(&[LEVEL, CLAMP])
        .bound(clamped_level)
        .scene(Scene::Mesh);

    #[test]
    fn a_bound_reads_the_parameters_their_defaults_and_the_input() {
        let set = |name: &str| match name {
            "level" => Some(0.5),
            _ => None,
        };
        assert_eq!(SPEC.output_bound(&set, 2.0), Some(("out", 2.5, "level + max|in|".to_string())));
        assert_eq!(SPEC.output_bound(&|_| None, 0.0).unwrap().1, 2.0, "the declared default");
        assert_eq!(SPEC.output_bound(&|n| (n == "clamp").then_some(0.0), 0.0), None, "a flag off");
        let plain = NodeSpec::new("test.plain", "test", Role::Filter, "test only", never);
        assert_eq!(plain.output_bound(&|_| None, 1.0), None);
    }

    #[test]
    fn a_costly_parameter_is_capped_above_its_cap_only() {
        assert_eq!(LEVEL.capped(1e6), Some((10.0, "slow above 10")));
        assert_eq!(LEVEL.capped(10.0), None);
        assert_eq!(CLAMP.capped(1e6), None);
    }

    #[test]
    fn the_viewed_ports_are_the_declared_ones_but_a_repeated_port() {
        assert_eq!(SPEC.viewed(Direction::In).collect::<Vec<_>>(), ["in"]);
        assert_eq!(SPEC.viewed(Direction::Out).collect::<Vec<_>>(), ["seen"]);
        assert_eq!(SPEC.scene, Some(Scene::Mesh));
    }
}
