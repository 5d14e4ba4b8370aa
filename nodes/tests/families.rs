//! The optional families' lists (`evflow_nodes::families::OPTIONAL`, which a
//! build without a family still has) against the families' own
//! declarations, in a build with every feature.
#![cfg(all(
    feature = "lab",
    feature = "mesh",
    feature = "narx",
    feature = "texture",
    feature = "synth",
    feature = "serial"
))]

use evflow_nodes::families::{enabled, OPTIONAL};

fn names(specs: &[&evflow_engine::NodeSpec]) -> Vec<&'static str> {
    specs.iter().map(|s| s.name).collect()
}

#[test]
fn the_lists_match_the_families_declarations() {
    let families = [
        ("lab", names(evflow_nodes::lab::SPECS)),
        ("mesh", names(evflow_nodes::mesh::SPECS)),
        ("narx", names(evflow_nodes::narx::SPECS)),
        ("texture", names(evflow_nodes::texture::SPECS)),
        ("synth", names(evflow_nodes::synth::SPECS)),
        ("serial", names(evflow_nodes::serial::SPECS)),
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
    let reg = evflow_nodes::registry();
    for (_, types) in OPTIONAL {
        for t in *types {
            assert!(reg.get(t).is_some() && reg.absent(t).is_none(), "{t}");
        }
    }
}

#[test]
fn every_family_is_a_folder_and_every_node_names_its_folder() {
    let src = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let families = evflow_nodes::families();
    for (folder, specs) in &families {
        assert!(src.join(folder).join("mod.rs").is_file(), "family `{folder}` is not a folder of nodes/src");
        for s in *specs {
            assert_eq!(s.family, *folder, "`{}` names family `{}` but lives in nodes/src/{folder}", s.name, s.family);
        }
    }
    // Every folder that declares nodes is a family.
    for entry in std::fs::read_dir(&src).unwrap() {
        let dir = entry.unwrap().path();
        let declares = std::fs::read_to_string(dir.join("mod.rs")).is_ok_and(|t| t.contains("pub static SPECS"));
        let name = dir.file_name().unwrap().to_string_lossy().into_owned();
        assert!(
            !declares || families.iter().any(|(f, _)| *f == name),
            "nodes/src/{name} declares nodes but is no family"
        );
    }
}
