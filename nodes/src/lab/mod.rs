//! The simulated lab: a virtual electrovibration display, the linear
//! tribometer of dissertation §5.1.1 and its force sensor, standing in for
//! the hardware so every graph runs on a fresh machine. Physics, parameter
//! values and their sources: `docs/simulated-lab.md`. Every physical
//! parameter lives in a lab profile (`graphs/lab/*.toml`, [`LabProfile`]).

pub mod display;
pub mod display_model;
pub mod electrical;
pub mod expm;
pub mod family;
pub mod forcesensor;
pub mod integrator;
pub mod noise;
pub mod profile;
pub mod profile_load;
pub mod sensor_model;
pub mod texture;
pub mod tribometer;
pub mod tribometer_model;
pub mod user;

#[cfg(test)]
mod chain_tests;
#[cfg(test)]
mod convergence_tests;
#[cfg(test)]
mod display_tests;
#[cfg(test)]
mod reference;
#[cfg(test)]
mod testutil;
#[cfg(test)]
mod tribometer_tests;

pub use profile::LabProfile;
pub use profile_load::ProfileError;

use evflow_engine::typed_params::{Choice, Float, Int, Text};
use evflow_engine::{BuildContext, NodeError, NodeSpec, Params, Summary};
use integrator::Method;

/// The node types of this family.
pub static SPECS: &[&NodeSpec] = &[&display::SPEC, &tribometer::SPEC, &forcesensor::SPEC, &texture::SPEC, &user::SPEC];

/// The seed a node's [`SEED`] parameter asks for: its value when ≥ 0, else
/// the graph's seed mixed with the node's name.
pub fn seed_of(p: &Params, ctx: &BuildContext) -> u64 {
    seed_or_node(SEED.get(p), ctx)
}

/// The seed a `seed` value asks for: itself when ≥ 0, else the graph's seed
/// mixed with the node's name.
pub fn seed_or_node(seed: i64, ctx: &BuildContext) -> u64 {
    match seed {
        s if s >= 0 => s as u64,
        _ => ctx.node_seed(),
    }
}

/// The `seed` parameter of the lab's noisy nodes: copies of a node given the
/// same seed draw the same noise (common random numbers).
pub const SEED: Int = Int::new(
    "seed",
    -1,
    i64::MAX,
    -1,
    "1",
    "noise seed (−1: from the graph's seed and the node name; equal seeds give copies the same noise stream)",
);

/// The `profile` parameter shared by the lab's nodes.
pub const PROFILE: Text = Text::new(
    "profile",
    "",
    "lab profile file (TOML, relative to the graph file); empty = the built-in nominal lab (graphs/lab/nominal.toml)",
);
/// The `integrator` parameter shared by the lab's nodes.
pub const INTEGRATOR: Choice<Method> = Choice::new(
    "integrator",
    Method::WORDS,
    &[Method::Exact, Method::Rk4, Method::Euler],
    "exact",
    "exact (zero-order-hold matrix exponential + implicit Coulomb), rk4 or euler (explicit, for comparison only)",
);
/// The `substeps` parameter shared by the lab's nodes.
pub const SUBSTEPS: Int = Int::new("substeps", 1, 10_000, 4, "1", "integration steps per sample");
/// The `noise` parameter shared by the lab's nodes.
pub const NOISE: Float =
    Float::new("noise", 0.0, 100.0, 1.0, "1", "scale of every random term of the profile (0 = noiseless)");

/// The profile named by the `profile` parameter (nominal when empty).
pub fn profile_of(p: &Params, ctx: &BuildContext) -> Result<LabProfile, NodeError> {
    let name = PROFILE.get(p);
    if name.is_empty() {
        return Ok(LabProfile::default());
    }
    let path = ctx.path(name);
    LabProfile::load(&path).map_err(|e| NodeError::file(&path, e.issues_text()))
}

/// What a simulated device's run reports when it ends: how often its
/// integrator diverged (and `hint`, what to change) and how many input
/// samples were NaN or infinite and read as 0; nothing when neither.
pub(crate) fn health(node: &str, diverged: u64, hint: &str, bad_inputs: u64) -> Summary {
    let mut s = Summary::default();
    if diverged > 0 {
        s = s.line(format!("{node}: the integrator diverged {diverged} times (state reset each time){hint}"));
    }
    if bad_inputs > 0 {
        s = s.line(format!("{node}: {bad_inputs} NaN or infinite input samples were read as 0"));
    }
    s
}
