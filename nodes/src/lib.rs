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
pub mod families;
pub mod filters;
#[cfg(feature = "lab")]
pub mod lab;
pub mod math;
#[cfg(feature = "mesh")]
pub mod mesh;
pub mod metric;
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

/// Every node declaration, family by family.
pub fn all_specs() -> Vec<&'static NodeSpec> {
    let mut v = Vec::new();
    v.extend_from_slice(sources::SPECS);
    v.extend_from_slice(filters::SPECS);
    v.extend_from_slice(output::SPECS);
    v.extend_from_slice(safety::SPECS);
    v.extend_from_slice(recording::SPECS);
    v.extend_from_slice(metric::SPECS);
    v.extend_from_slice(math::SPECS);
    #[cfg(feature = "mesh")]
    v.extend_from_slice(mesh::SPECS);
    v.extend_from_slice(analysis::SPECS);
    #[cfg(feature = "lab")]
    v.extend_from_slice(lab::SPECS);
    v.extend_from_slice(rate::SPECS);
    #[cfg(feature = "texture")]
    v.extend_from_slice(texture::SPECS);
    v.extend_from_slice(serial::SPECS);
    #[cfg(feature = "narx")]
    v.extend_from_slice(narx::SPECS);
    #[cfg(feature = "synth")]
    v.extend_from_slice(synth::SPECS);
    v
}
