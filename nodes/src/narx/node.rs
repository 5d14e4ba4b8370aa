//! `narx`: runs a trained inverse NARX model closed loop, force in,
//! actuation out, one sample per tick.

use super::closed_loop::ClosedLoop;
use super::model::Model;
use super::packed::Tanh;
use evflow_engine::ports::{InPort, OutPort};
use evflow_engine::typed_params::{Choice, Text};
use evflow_engine::{BuildContext, Io, Node, NodeError, NodeSpec, Params, PortSpec, Role, Summary};

/// Declaration of `narx`.
pub static SPEC: NodeSpec = NodeSpec::new(
    "narx",
    "narx",
    Role::Filter,
    "Inverse NARX model run closed loop: a desired lateral force in, the actuation that produces it out.",
    build,
)
.doc(
    "Dissertation §5.2.1–5.2.2 (Eq. 5.1, Fig. 5.3(b)): synthesizes a PRBS-like actuation signal from a \
     force recording (e.g. a real texture's force, normalized as the display's training force) with a \
     model written by `narx.train`. The network's own estimates are fed back in place of the reference \
     (closed loop); each sample costs one forward pass and nothing is allocated while running.\n\n\
     **Ports.** `force` (N) in, `u` (1 = 50 V, ±1 = 100 Vpp) out, both at the node's rate, which must be \
     the model's `rate_hz`.\n\n\
     **Look-ahead and latency.** A model with look-ahead d > 0 reads the force up to d samples *after* \
     the actuation sample it estimates (the display's force follows the actuation). Streaming, the \
     node therefore outputs at tick t the estimate of u[t − d]: its output is the synthesized actuation \
     delayed by d samples (the model's `delays.lookahead`; `evflow nodes` cannot know it before the \
     file is read). For offline synthesis, drop the first d output samples (or delay the force \
     reference by d) to realign; live, d ms of latency at 1 kHz. Before the histories fill, missing \
     force samples count as 0 N and missing past estimates as u = 0.\n\n\
     **Bounds.** The output is clamped to the actuation range the model was trained on (its \
     `normalization.y`), so it stays bounded whatever the force does (×10 amplitude, steps, silence, \
     noise); a non-finite force sample is read as 0 N. Samples clamped, outputs that left the range by \
     more than its width (divergence), and bad inputs are counted and reported when the run ends.\n\n\
     **Parameter** `model`: the model file (relative to the graph file). A missing, corrupt or newer-\
     version file is refused when the graph is built, naming the file and the field.\n\n\
     Checked against: the open-loop regressor (every tap reads the same samples closed loop), hand-built \
     linear networks (feedback echo, unstable loops clamped), and the simulated lab (nodes/tests/narx_lab.rs, \
     nodes/tests/narx_node.rs).\n\n\
     **Parameter** `tanh`: `exact` (the default: glibc's tanh written out, `nodes/src/narx/exact_tanh.rs` — \
     the standard library's tanh bit for bit on Linux x86-64 with FMA, the same bits on every platform, four \
     neurons at a time on AVX2) or \
     `fast` (`nodes/src/narx/fast_tanh.rs`: within 1e-15 of tanh for every x, about 1.9× the closed-loop \
     throughput of the exact tanh offline; on 60 s of lab force a shipped model's output moves by at most 2.5e-11 of its \
     range). At 1 kHz either costs well under 1 % of a tick.",
)
.ports(PORTS)
.params(&[MODEL.spec(), TANH.spec()])
.example("model = \"models/narx.json\"");

/// The ports: the desired force in, the actuation out.
const PORTS: &[PortSpec] = &[
    PortSpec::input("force", "N", "desired lateral force (the network's input)"),
    PortSpec::output("u", "1", "estimated actuation, delayed by the model's look-ahead d"),
];
/// The desired force.
const FORCE: InPort = InPort::named(PORTS, "force");
/// The estimated actuation.
const U: OutPort = OutPort::named(PORTS, "u");

/// `model`: the model file (also `narx.score`'s).
pub(super) const MODEL: Text =
    Text::new("model", "", "model file written by narx.train (JSON), relative to the graph file").required();
/// `tanh`: which tanh the hidden layers use (also `narx.grid`'s).
pub(super) const TANH: Choice<Tanh> = Choice::new(
    "tanh",
    &["exact", "fast"],
    &[Tanh::Exact, Tanh::Fast],
    "exact",
    "hidden-layer tanh: exact (glibc's, written out) or fast (|error| ≤ 1e-15)",
);

struct Narx {
    cl: ClosedLoop,
    shown: String,
}

fn build(p: &Params, ctx: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
    let shown = MODEL.get(p).to_string();
    if shown.is_empty() {
        return Err(NodeError::param(MODEL.name(), "name the model file (written by narx.train)"));
    }
    let path = ctx.path(&shown);
    let model = Model::load(&path)?;
    if (model.rate_hz - ctx.rate).abs() > 1e-9 * ctx.rate {
        return Err(NodeError::file(
            &path,
            format!(
                "field `rate_hz`: the model was trained at {} Hz but the node runs at {} Hz (its taps count samples)",
                model.rate_hz, ctx.rate
            ),
        ));
    }
    Ok(Box::new(Narx { cl: model.closed_loop_with(TANH.get(p))?, shown }))
}

impl Node for Narx {
    fn process(&mut self, io: &mut Io<'_>) -> Result<(), NodeError> {
        let (x, u) = io.io(FORCE, U);
        for (o, &f) in u.iter_mut().zip(x) {
            *o = self.cl.step(f);
        }
        Ok(())
    }

    fn reset(&mut self) {
        self.cl.reset();
    }

    fn finish(&mut self) -> Result<Summary, NodeError> {
        let cl = &self.cl;
        let mut s = Summary::default().value("clamped", cl.clamped as f64, "samples").value(
            "diverged",
            cl.diverged as f64,
            "samples",
        );
        if cl.diverged > 0 || cl.bad_inputs > 0 {
            s = s.line(format!(
                "narx ({}): {} outputs left the trained range by more than its width and were clamped; {} non-finite force samples were read as 0",
                self.shown, cl.diverged, cl.bad_inputs
            ));
        }
        Ok(s)
    }
}
