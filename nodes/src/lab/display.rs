//! `sim.display`: the virtual electrovibration display.

use super::display_model::DisplayModel;
use super::{profile_of, seed_of, INTEGRATOR, NOISE, PROFILE, SEED, SUBSTEPS};
use evflow_engine::ports::{InPort, OutPort};
use evflow_engine::{BuildContext, Io, Node, NodeError, NodeSpec, Params, PortSpec, Role, Summary};

/// Declaration of `sim.display`.
pub static SPEC: NodeSpec = NodeSpec::new(
    "sim.display",
    "lab",
    Role::Filter,
    "Virtual electrovibration display: actuation, load and sliding velocity → lateral friction force.",
    build,
)
.doc(
    "Stands in for a friction display (3M MicroTouch panel + piezo amplifier, dissertation §5.1.2) \
     touched by a pen on a tribometer. Per sample (inputs held over the sample, output at its end): \
     the amplifier (gain 50 V per unit, so ±1 is 100 Vpp; offset; ±`max_v` limit; first-order bandwidth) \
     drives the series circuit coating → air gap → pen tip → return (Shultz, Peshkin & Colgate 2018, with \
     the leaky-coating Johnsen–Rahbek path of Shultz et al. 2015); the gap voltage v_g gives the \
     electrostatic normal force F_e = k_e·v_g², k_e = ε0·A/(2d²) (square law, Meyer, Peshkin & Colgate 2013), \
     which reaches the contact through a first-order lag whose cutoff rises with sliding speed \
     (Balasubramanian, Pool & Vardar 2025); friction μ(v)·(F_n + F_e) (Stribeck, with coloured noise and \
     drift of μ) acts on the pen tip, a mass on a lateral spring and damper to the holder; the output is the \
     force the contact transmits to the holder. Because the coating blocks DC while the gap leaks, a ±c PRBS \
     gives a force spike at each transition that decays between transitions (the force depends on the \
     recent history of u, not only on u²); the amplifier offset reaching the gap through the leaky coating \
     adds a small term linear in u, which makes the sign of u weakly observable. Static friction increase \
     and vibratory force are both quadratic in the actuation amplitude (§3.1.2). \n\n\
     Rates: all ports at the node's rate (1 kHz or 10 kHz). Integration: `exact` advances the circuit and \
     the contact by their zero-order-hold matrix exponentials and treats Coulomb friction as a set-valued \
     law solved implicitly (stable and passive at any stiffness); `rk4`/`euler` are explicit and only for \
     work-precision comparisons — they diverge on the stiff profiles at 1 kHz, where the node resets its \
     state and reports it at the end. Every physical constant comes from the lab profile (`profile`); see \
     docs/simulated-lab.md for the physics, the values and their sources. Checked against: the complex \
     impedance of the circuit, analytic steady sliding, passivity (energy never rises), the quadratic law \
     (R² > 0.99) and the u → −u symmetry without offset. `seed` (default: from the graph's seed and the \
     node's name) lets several copies of the display in one graph draw the same noise (common random \
     numbers), e.g. to compare integrators or actuations on one noise realization.",
)
.ports(PORTS)
.params(&[PROFILE.spec(), INTEGRATOR.spec(), SUBSTEPS.spec(), NOISE.spec(), SEED.spec()])
.example("profile = \"\"\nintegrator = \"exact\"\nsubsteps = 4\nnoise = 1.0");

/// The ports: actuation, load and sliding velocity in, the friction force out.
const PORTS: &[PortSpec] = &[
    PortSpec::input("u", "1", "actuation (1.0 = 50 V at the amplifier output; ±1 = 100 Vpp)"),
    PortSpec::input("load", "N", "normal force pressing the pen (or finger) on the display"),
    PortSpec::input("velocity", "m/s", "sliding velocity of the holder along the display"),
    PortSpec::output("force", "N", "lateral friction force transmitted to the holder (positive opposes +x motion)")
        .view(),
];
/// `u`: the actuation.
const U: InPort = InPort::named(PORTS, "u");
/// `load`: the normal force.
const LOAD: InPort = InPort::named(PORTS, "load");
/// `velocity`: the sliding velocity.
const VELOCITY: InPort = InPort::named(PORTS, "velocity");
/// `force`: the lateral friction force.
const FORCE: OutPort = OutPort::named(PORTS, "force");

struct SimDisplay {
    model: DisplayModel,
}

fn build(p: &Params, ctx: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
    let profile = profile_of(p, ctx)?;
    let method = INTEGRATOR.get(p);
    let seed = seed_of(p, ctx);
    let model = DisplayModel::new(&profile, ctx.rate, method, SUBSTEPS.count(p), NOISE.get(p), seed)
        .map_err(|m| NodeError::param(PROFILE.name(), m))?;
    Ok(Box::new(SimDisplay { model }))
}

impl Node for SimDisplay {
    fn process(&mut self, io: &mut Io<'_>) -> Result<(), NodeError> {
        for i in 0..io.len() {
            let (u, load, v) = (io.input(U)[i], io.input(LOAD)[i], io.input(VELOCITY)[i]);
            io.output(FORCE)[i] = self.model.step(u, load, v);
        }
        Ok(())
    }

    fn reset(&mut self) {
        self.model.reset();
    }

    fn finish(&mut self) -> Result<Summary, NodeError> {
        Ok(super::health(
            "sim.display",
            self.model.diverged,
            "; use integrator = \"exact\" or more substeps",
            self.model.bad_inputs,
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lab::testutil::prbs;
    use evflow_engine::harness::Single;
    use std::path::{Path, PathBuf};

    fn lab_dir() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../graphs/lab")
    }

    fn single<'a>(params: &'a str, dir: &'a Path, block: usize, n: usize) -> Single<'a> {
        let v: Vec<f64> = (0..n).map(|i| if (i / 300) % 2 == 0 { 0.05 } else { -0.03 }).collect();
        Single::new(&SPEC, params)
            .input("u", prbs(n, 1.0), 1000.0)
            .input("load", vec![0.85; n], 1000.0)
            .input("velocity", v, 1000.0)
            .output("force")
            .ticks(n as u64)
            .block(block)
            .base_dir(dir)
    }

    #[test]
    fn block_and_per_sample_processing_agree() {
        let dir = lab_dir();
        for params in [
            "",
            "profile = \"stiff.toml\"\nnoise = 3.0",
            "profile = \"display-b.toml\"\nintegrator = \"rk4\"\nsubsteps = 50",
        ] {
            let a = single(params, &dir, 1, 1000).run().unwrap();
            let b = single(params, &dir, 64, 1000).run().unwrap();
            assert_eq!(a, b, "{params}");
            assert!(a[0].iter().all(|x| x.is_finite()));
        }
    }

    #[test]
    fn reset_restores_the_initial_state() {
        let dir = lab_dir();
        let s = single("noise = 2.0", &dir, 50, 600);
        let (mut plan, idx) = s.plan().unwrap();
        let mut first = Vec::new();
        for _ in 0..12 {
            plan.step(50).unwrap();
            first.extend_from_slice(plan.output("dut", idx[0]).unwrap());
        }
        plan.reset();
        let mut again = Vec::new();
        for _ in 0..12 {
            plan.step(50).unwrap();
            again.extend_from_slice(plan.output("dut", idx[0]).unwrap());
        }
        assert_eq!(first, again);
    }

    #[test]
    fn profile_errors_name_the_file_line_and_key() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("mine.toml"), "[display.contact]\nstifness_n_per_m = 5.0\n").unwrap();
        let e = single("profile = \"mine.toml\"", dir.path(), 10, 10).run().unwrap_err();
        assert!(e.contains("mine.toml"), "{e}");
        assert!(e.contains("line 2"), "{e}");
        assert!(e.contains("did you mean `stiffness_n_per_m`?"), "{e}");
        let e = single("profile = \"missing.toml\"", dir.path(), 10, 10).run().unwrap_err();
        assert!(e.contains("missing.toml") && e.contains("cannot read"), "{e}");
    }

    /// Two displays `a` and `b` in one graph on the same inputs; their forces.
    fn twins(params_a: &str, params_b: &str) -> (Vec<f64>, Vec<f64>) {
        use evflow_engine::{check, graph::parse_graph, Plan, PlanOptions, RunMode};
        let doc = format!(
            "[graph]\nformat = 1\nname = \"crn\"\nrate = 1000.0\nseed = 3\nconnections = [\n\
             \"x.out -> a.u\", \"t.load -> a.load\", \"t.velocity -> a.velocity\",\n\
             \"x.out -> b.u\", \"t.load -> b.load\", \"t.velocity -> b.velocity\",\n\
             \"a.force -> e.test\", \"b.force -> e.reference\"]\n\
             [nodes.x]\ntype = \"prbs\"\norder = 7\n\
             [nodes.t]\ntype = \"sim.tribometer\"\npasses = 1\n\
             [nodes.a]\ntype = \"sim.display\"\n{params_a}\n\
             [nodes.b]\ntype = \"sim.display\"\n{params_b}\n\
             [nodes.e]\ntype = \"error\"\n"
        );
        let graph = parse_graph(Path::new("crn.toml"), &doc).unwrap();
        let checked = check(&graph, &crate::registry(), &[]).unwrap_or_else(|e| panic!("{e}"));
        let opts = PlanOptions {
            max_block: 100,
            seed: None,
            base_dir: Some(lab_dir()),
            out_dir: Some(lab_dir()),
            timing: false,
            mode: RunMode::Offline,
            check_only: false,
        };
        let mut plan = Plan::build(&checked, &opts).unwrap();
        let (mut fa, mut fb) = (Vec::new(), Vec::new());
        for _ in 0..20 {
            plan.step(100).unwrap();
            fa.extend_from_slice(plan.output("a", 0).unwrap());
            fb.extend_from_slice(plan.output("b", 0).unwrap());
        }
        (fa, fb)
    }

    #[test]
    fn copies_with_one_seed_draw_the_same_noise_and_without_differ() {
        let (a, b) = twins("noise = 1.0\nseed = 42", "noise = 1.0\nseed = 42");
        assert!(a.iter().any(|x| x.abs() > 0.1), "the displays are driven");
        assert_eq!(a, b, "same seed, same inputs: same output");
        let (a, b) = twins("noise = 1.0", "noise = 1.0");
        assert_ne!(a, b, "default seeds differ per node");
        let (a, b) = twins("noise = 1.0\nseed = 42", "noise = 1.0\nseed = 43");
        assert_ne!(a, b, "different seeds differ");
        let (a, b) = twins("noise = 0.0\nseed = 1", "noise = 0.0\nseed = 2");
        assert_eq!(a, b, "without noise the seed does not matter");
    }

    #[test]
    fn the_example_and_the_defaults_are_the_nominal_lab() {
        let dir = lab_dir();
        let a = single(SPEC.example, &dir, 16, 400).run().unwrap();
        let b = single("profile = \"nominal.toml\"", &dir, 16, 400).run().unwrap();
        assert_eq!(a, b);
    }
}
