//! The mesh file formats, told apart by extension (case-insensitive), each
//! with its reader and its `up = "auto"` axis: OBJ (`.obj`) and glTF
//! (`.gltf`, `.glb`) are y-up — OBJ by the convention of the tools that
//! write it, glTF by its specification —, STL (`.stl`) and PLY (`.ply`)
//! z-up, as CAD tools and scanners usually write them. Every reader welds
//! the vertices ([`Mesh::new`]) and refuses a malformed file naming it and
//! the line (text) or byte offset (binary). Docs: docs/mesh.md, "Formats".

use super::error::MeshError;
use super::place::Up;
use super::trimesh::Mesh;
use std::path::Path;

/// A mesh file format.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// Wavefront OBJ (tobj).
    Obj,
    /// STL, ASCII or binary.
    Stl,
    /// PLY, ASCII or binary (ply-rs-bw).
    Ply,
    /// glTF 2.0 JSON (`.gltf`).
    Gltf,
    /// glTF 2.0 binary container.
    Glb,
}

/// Every format with its extension.
pub const EXTENSIONS: [(&str, Format); 5] =
    [("obj", Format::Obj), ("stl", Format::Stl), ("ply", Format::Ply), ("gltf", Format::Gltf), ("glb", Format::Glb)];

impl Format {
    /// The format a file name's extension names, if any.
    pub fn of(name: &str) -> Option<Format> {
        let ext = Path::new(name).extension()?.to_str()?;
        EXTENSIONS.iter().find(|(e, _)| e.eq_ignore_ascii_case(ext)).map(|(_, f)| *f)
    }

    /// The format's name for people: `OBJ`, `STL`, `PLY`, `glTF`, `GLB`.
    pub fn name(self) -> &'static str {
        match self {
            Format::Obj => "OBJ",
            Format::Stl => "STL",
            Format::Ply => "PLY",
            Format::Gltf => "glTF",
            Format::Glb => "GLB",
        }
    }

    /// The up axis `up = "auto"` takes for this format.
    pub fn default_up(self) -> Up {
        match self {
            Format::Obj | Format::Gltf | Format::Glb => Up::PlusY,
            Format::Stl | Format::Ply => Up::PlusZ,
        }
    }

    /// Reads a file of this format; `weld` in file units (0: bit-identical
    /// positions only).
    pub fn load(self, path: &Path, weld: f64) -> Result<Mesh, MeshError> {
        match self {
            Format::Obj => super::obj::load_obj(path, weld),
            Format::Stl => super::stl::load_stl(path, weld),
            Format::Ply => super::ply::load_ply(path, weld),
            Format::Gltf | Format::Glb => super::gltf::load_gltf(path, weld),
        }
    }
}

/// Reads a mesh file of any format, told by its extension.
pub fn load_file(path: &Path, weld: f64) -> Result<Mesh, MeshError> {
    let format = Format::of(&path.to_string_lossy()).ok_or_else(|| MeshError::Format { path: path.into() })?;
    format.load(path, weld)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn extensions_and_defaults() {
        assert_eq!(Format::of("a/b.OBJ"), Some(Format::Obj));
        assert_eq!(Format::of("scan.Ply"), Some(Format::Ply));
        assert_eq!(Format::of("x.glb").map(Format::default_up), Some(Up::PlusY));
        assert_eq!(Format::of("part.stl").map(Format::default_up), Some(Up::PlusZ));
        assert_eq!(Format::of("2B2H"), None);
        assert_eq!(Format::of("m.off"), None);
        let e = load_file(Path::new("m.off"), 0.0).unwrap_err().to_string();
        assert!(e.starts_with("m.off: unknown mesh format"), "{e}");
    }
}
