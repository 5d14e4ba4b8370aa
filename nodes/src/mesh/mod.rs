//! The mesh family: live mesh-gradient rendering (dissertation §3.2.1 and
//! chapter 4). A touch point becomes a vertical ray on a 3D mesh; the
//! surface gradient between consecutive hits becomes a friction intensity
//! (Eq. 4.1–4.7), sharp convex edges an EDGE-TICK intensity (Eq. 4.8–4.9),
//! and `grain` turns both into an actuation waveform. Design and figures:
//! `docs/mesh.md`.

pub mod calibrate;
pub mod edges;
pub mod error;
pub mod formats;
pub mod gltf;
pub mod gltf_doc;
mod gltf_json;
pub mod gradient;
pub mod obj;
pub mod ply;
pub mod raycast;
pub mod scenes;
pub mod shared;
pub mod trimesh;

pub use error::MeshError;
pub use trimesh::Mesh;
pub mod edges_node;
pub mod gradient_node;
pub mod grain;
pub mod path;
pub mod place;
pub mod profile1d;
pub mod source;
pub mod stl;

use evflow_engine::NodeSpec;

/// The node types of this family.
pub static SPECS: &[&NodeSpec] =
    &[&profile1d::SPEC, &gradient_node::SPEC, &edges_node::SPEC, &grain::SPEC, &path::SPEC];
pub mod fidelity;
