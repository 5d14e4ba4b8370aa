//! Where a mesh node's mesh comes from — an OBJ file or a generated §4.2
//! scene — and how touch coordinates (metres on the screen) map to mesh
//! units. The parameters are shared by `mesh.gradient` and `mesh.edges` so
//! both see the same triangles in the same order.

use super::obj::load_obj;
use super::scenes::{scene, Shape, CONFIGS};
use super::trimesh::Mesh;
use evflow_engine::{BuildContext, NodeError, ParamSpec, Params};

/// `file`: an OBJ file; empty for a generated scene.
pub const FILE: ParamSpec =
    ParamSpec::text("file", "", "OBJ mesh (relative to the graph file); empty: the generated scene below");
/// `shape` of a generated scene.
pub const SHAPE: ParamSpec =
    ParamSpec::choice("shape", &["gaussian", "frustum"], "gaussian", "generated scene: object profile (Fig. 4.5)");
/// `config` of a generated scene.
pub const CONFIG: ParamSpec =
    ParamSpec::choice("config", CONFIGS, "2B2H", "generated scene: bumps and holes (Fig. 4.6), or one bump/hole");
/// `resolution` of a generated Gaussian scene.
pub const RESOLUTION: ParamSpec =
    ParamSpec::int("resolution", 2, 4096, 48, "1", "generated Gaussian scene: grid cells per 6 cm object side");
/// `unit`: metres per mesh unit.
pub const UNIT: ParamSpec =
    ParamSpec::float("unit", 1e-9, 1e3, 0.01, "m", "length of one mesh unit (0.01: the mesh is in cm)");
/// `offset_x`: screen position of the mesh origin.
pub const OFFSET_X: ParamSpec = ParamSpec::float("offset_x", -1e6, 1e6, 0.0, "m", "touch x of the mesh's origin");
/// `offset_y`: screen position of the mesh origin.
pub const OFFSET_Y: ParamSpec = ParamSpec::float("offset_y", -1e6, 1e6, 0.0, "m", "touch y of the mesh's origin");
/// `scenes`: the meshes a session can switch between.
pub const SCENES: ParamSpec = ParamSpec::text_list(
    "scenes",
    "meshes to switch between live: each a generated-scene config (with `shape`, e.g. \"4B0H\") or an OBJ file \
     (*.obj); empty: the one mesh of `file` or `config`",
);
/// `scene`: which of `scenes` is felt (live).
pub const SCENE: ParamSpec =
    ParamSpec::int("scene", 0, 255, 0, "1", "index into `scenes` of the mesh felt (changes live)").live();
/// `weld`: vertex weld tolerance.
pub const WELD: ParamSpec = ParamSpec::float(
    "weld",
    0.0,
    1e3,
    0.0,
    "1",
    "vertex weld distance in mesh units (0: merge bit-identical positions only)",
);

/// A loaded mesh with its placement.
#[derive(Debug, Clone)]
pub struct Placed {
    /// The mesh.
    pub mesh: Mesh,
    /// Height of the screen plane in mesh units: 0 for scenes (objects
    /// stand on the screen), the lowest vertex for a file.
    pub floor: f64,
    /// Metres per mesh unit.
    pub unit: f64,
    /// Touch coordinates of the mesh origin, m.
    pub offset: [f64; 2],
    /// File name or scene description, for reports.
    pub name: String,
}

impl Placed {
    /// A touch point (m) in mesh units.
    #[inline]
    pub fn to_mesh(&self, x: f64, y: f64) -> (f64, f64) {
        ((x - self.offset[0]) / self.unit, (y - self.offset[1]) / self.unit)
    }
}

/// Loads the mesh the parameters name (`file`, else the generated scene
/// `shape` × `config`).
pub fn load(p: &Params, ctx: &BuildContext) -> Result<Placed, NodeError> {
    let file = p.str("file");
    if !file.is_empty() {
        return load_entry(p, ctx, file);
    }
    load_entry(p, ctx, p.str("config"))
}

/// Loads every mesh a node can switch between: the `scenes` list, or the
/// one mesh of [`load`]. Also checks `scene` against the list.
pub fn load_scenes(p: &Params, ctx: &BuildContext) -> Result<Vec<Placed>, NodeError> {
    let list = p.text_list("scenes");
    let scene = p.usize("scene");
    if list.is_empty() {
        if scene != 0 {
            return Err(NodeError::param("scene", format!("{scene}: without a `scenes` list the only scene is 0")));
        }
        return Ok(vec![load(p, ctx)?]);
    }
    if !p.str("file").is_empty() {
        return Err(NodeError::param("scenes", "give `file` or `scenes` (which may list OBJ files), not both"));
    }
    if scene >= list.len() {
        return Err(NodeError::param(
            "scene",
            format!("{scene} is not an index into the {} scenes given (0 … {})", list.len(), list.len() - 1),
        ));
    }
    list.iter()
        .enumerate()
        .map(|(k, e)| {
            load_entry(p, ctx, e).map_err(|err| NodeError::param("scenes", format!("entry {k} `{e}`: {err}")))
        })
        .collect()
}

/// One mesh: an OBJ file (a name ending in `.obj`) or a generated scene's
/// config word.
fn load_entry(p: &Params, ctx: &BuildContext, entry: &str) -> Result<Placed, NodeError> {
    let unit = p.f64("unit");
    let offset = [p.f64("offset_x"), p.f64("offset_y")];
    if entry.to_ascii_lowercase().ends_with(".obj") {
        let path = ctx.path(entry);
        let mesh = load_obj(&path, p.f64("weld")).map_err(|e| NodeError::Other(e.to_string()))?;
        let floor = mesh.bounds().min[2];
        return Ok(Placed { mesh, floor, unit, offset, name: path.display().to_string() });
    }
    let shape = if p.str("shape") == "frustum" { Shape::Frustum } else { Shape::Gaussian };
    if !CONFIGS.contains(&entry) {
        let help = evflow_engine::suggest::help(entry, CONFIGS.iter().copied());
        return Err(NodeError::param(
            "config",
            format!("unknown scene `{entry}` (one of {}, or an OBJ file); {help}", CONFIGS.join(", ")),
        ));
    }
    let mesh = scene(shape, entry, p.usize("resolution")).map_err(|e| NodeError::param("config", e.to_string()))?;
    Ok(Placed { mesh, floor: 0.0, unit, offset, name: format!("{} {entry}", p.str("shape")) })
}
