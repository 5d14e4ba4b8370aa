//! # evflow-nodes
//!
//! The node library of evflow, one module per family. Each node type lives
//! in its own file and declares itself once as a [`NodeSpec`]; [`registry`]
//! gathers them for the loader, the validator, `evflow nodes` and the docs.
//!
//! Families a build can leave out sit behind cargo features, all on by
//! default: `lab`, `mesh`, `narx`, `texture`, `synth` (which needs the
//! first three) and `serial`. `docs/features.md` lists what each
//! brings in.
#![deny(missing_docs)]

pub mod analysis;
pub mod cpu;
pub mod exact_exp;
pub mod example_files;
pub mod families;
pub mod filters;
#[cfg(test)]
mod glibc_check;
#[cfg(feature = "lab")]
pub mod lab;
#[cfg(feature = "narx")]
pub mod linalg;
pub mod math;
#[cfg(feature = "mesh")]
pub mod mesh;
pub mod metric;
pub mod model_file_error;
#[cfg(feature = "narx")]
pub mod narx;
pub mod output;
pub mod rate;
pub mod recording;
pub mod rng;
pub mod safety;
pub mod serial;
pub mod sources;
pub mod sum;
#[cfg(feature = "synth")]
pub mod synth;
#[cfg(feature = "texture")]
pub mod texture;
pub mod wide_sum;

use evflow_engine::{NodeSpec, Registry};

/// Every node type of the library.
pub fn registry() -> Registry {
    let mut reg = Registry::new();
    for spec in all_specs() {
        reg.add(spec);
    }
    for (feature, types) in families::OPTIONAL {
        if !families::enabled(feature) {
            for t in *types {
                reg.add_absent(t, feature);
            }
        }
    }
    reg
}

/// `(folder, declarations)` of the family module `$m`: its name is its folder.
macro_rules! family {
    ($m:ident) => {
        (stringify!($m), $m::SPECS)
    };
}

/// Every family of this build, as `(its folder under nodes/src, its node
/// declarations)`: each declaration names that folder as its family
/// (`nodes/tests/families.rs` checks it).
pub fn families() -> Vec<(&'static str, &'static [&'static NodeSpec])> {
    let mut v = vec![
        family!(sources),
        family!(filters),
        family!(output),
        family!(safety),
        family!(recording),
        family!(metric),
        family!(math),
    ];
    #[cfg(feature = "mesh")]
    v.push(family!(mesh));
    v.push(family!(analysis));
    #[cfg(feature = "lab")]
    v.push(family!(lab));
    v.push(family!(rate));
    #[cfg(feature = "texture")]
    v.push(family!(texture));
    v.push(family!(serial));
    #[cfg(feature = "narx")]
    v.push(family!(narx));
    #[cfg(feature = "synth")]
    v.push(family!(synth));
    v
}

/// Every node declaration, family by family.
pub fn all_specs() -> Vec<&'static NodeSpec> {
    families().into_iter().flat_map(|(_, specs)| specs.iter().copied()).collect()
}
