//! The node families a build can leave out, by cargo feature, with the node
//! types each one holds — so that a graph naming a type of a family this
//! build left out is told which feature brings it back, instead of
//! "unknown node type". The lists are checked against the families' own
//! declarations by this module's test (in a build with every feature).

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

#[cfg(all(
    test,
    feature = "lab",
    feature = "mesh",
    feature = "narx",
    feature = "texture",
    feature = "synth",
    feature = "serial"
))]
mod tests {
    use super::*;

    fn names(specs: &[&evflow_engine::NodeSpec]) -> Vec<&'static str> {
        specs.iter().map(|s| s.name).collect()
    }

    #[test]
    fn the_lists_match_the_families_declarations() {
        let families = [
            ("lab", names(crate::lab::SPECS)),
            ("mesh", names(crate::mesh::SPECS)),
            ("narx", names(crate::narx::SPECS)),
            ("texture", names(crate::texture::SPECS)),
            ("synth", names(crate::synth::SPECS)),
            ("serial", names(crate::serial::SPECS)),
        ];
        assert_eq!(families.len(), OPTIONAL.len());
        for ((feature, declared), (listed_feature, listed)) in families.iter().zip(OPTIONAL) {
            assert_eq!(feature, listed_feature);
            assert_eq!(declared, &listed.to_vec(), "family `{feature}`");
            assert!(enabled(feature));
        }
        assert!(!enabled("studio"));
    }

    #[test]
    fn a_full_build_marks_nothing_absent() {
        let reg = crate::registry();
        for (_, types) in OPTIONAL {
            for t in *types {
                assert!(reg.get(t).is_some() && reg.absent(t).is_none(), "{t}");
            }
        }
    }
}
