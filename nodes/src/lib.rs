//! # evflow-nodes
//!
//! The node library of evflow, one module per family. Each node type lives
//! in its own file and declares itself once as a [`NodeSpec`]; [`registry`]
//! gathers them for the loader, the validator, `evflow nodes` and the docs.
#![deny(missing_docs)]

pub mod analysis;
pub mod filters;
pub mod lab;
pub mod math;
pub mod mesh;
pub mod metric;
pub mod narx;
pub mod output;
pub mod rate;
pub mod recording;
pub mod safety;
pub mod serial;
pub mod sources;
pub mod sum;
pub mod synth;
pub mod texture;

use evflow_engine::{NodeSpec, Registry};

/// Every node type of the library.
pub fn registry() -> Registry {
    let mut reg = Registry::new();
    for spec in all_specs() {
        reg.add(spec);
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
    v.extend_from_slice(mesh::SPECS);
    v.extend_from_slice(analysis::SPECS);
    v.extend_from_slice(lab::SPECS);
    v.extend_from_slice(rate::SPECS);
    v.extend_from_slice(texture::SPECS);
    v.extend_from_slice(serial::SPECS);
    v.extend_from_slice(narx::SPECS);
    v.extend_from_slice(synth::SPECS);
    v
}
