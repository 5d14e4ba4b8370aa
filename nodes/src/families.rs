//! The node families a build can leave out, by cargo feature, with the node
//! types each one holds — so that a graph naming a type of a family this
//! build left out is told which feature brings it back, instead of
//! "unknown node type". The lists are checked against the families' own
//! declarations by `nodes/tests/families.rs` (in a build with every feature).

/// `(cargo feature, node types)` for each optional family.
pub const OPTIONAL: &[(&str, &[&str])] = &[
    ("lab", &["sim.display", "sim.tribometer", "sim.forcesensor", "sim.texture", "sim.user"]),
    ("mesh", &["profile1d", "mesh.gradient", "mesh.edges", "grain", "mesh.path"]),
    ("narx", &["narx.train", "narx.score", "narx", "narx.grid"]),
    ("texture", &["interp", "playback"]),
    ("synth", &["forward.train", "synth.optimize", "synth.live"]),
    ("serial", &["serial.in", "serial.out"]),
];

/// Whether this build has the cargo feature `name` of the nodes crate.
// Each arm's value depends on the build, so the match is not a `matches!`.
#[allow(clippy::match_like_matches_macro)]
pub fn enabled(name: &str) -> bool {
    match name {
        "lab" => cfg!(feature = "lab"),
        "mesh" => cfg!(feature = "mesh"),
        "narx" => cfg!(feature = "narx"),
        "texture" => cfg!(feature = "texture"),
        "synth" => cfg!(feature = "synth"),
        "serial" => cfg!(feature = "serial"),
        _ => false,
    }
}
