//! Where a mesh node's mesh comes from — a mesh file (OBJ, STL, PLY,
//! glTF/GLB: [`super::formats`]) or a generated §4.2 scene — which of its axes is up, and how touch coordinates (metres on
//! the screen) map to mesh units (`unit` and `offset_x/y`, or `fit`). The
//! parameters are declared here once and shared by `mesh.gradient` and
//! `mesh.edges`, so both see the same triangles in the same order at the
//! same place.

use super::formats::{Format, EXTENSIONS};
use super::place::{self, Up};
use super::scenes::{Shape, CONFIGS};
use super::shared;
use super::trimesh::Mesh;
use evflow_engine::typed_params::{Choice, Float, Int, Text, Words};
use evflow_engine::{BuildContext, NodeError, Params};
use std::sync::Arc;

/// The parameters of a node that loads its scenes here (`file`, `shape`,
/// `config`, `resolution`, `unit`, `offset_x`, `offset_y`, `up`, `fit`,
/// `fit_size`, `weld`, `scenes`, `scene`), then the node's own: the one
/// list `mesh.gradient` and `mesh.edges` both declare. A node whose cost
/// grows with `unit` (a calibration scan) declares its own costly `unit`
/// first: `with_scene_params![unit: UNIT.spec(); …]`.
macro_rules! with_scene_params {
    (unit: $unit:expr; $($own:expr),* $(,)?) => {
        &[
            $crate::mesh::source::FILE.spec(),
            $crate::mesh::source::SHAPE.spec(),
            $crate::mesh::source::CONFIG.spec(),
            $crate::mesh::source::RESOLUTION.spec(),
            $unit,
            $crate::mesh::source::OFFSET_X.spec(),
            $crate::mesh::source::OFFSET_Y.spec(),
            $crate::mesh::source::UP.spec(),
            $crate::mesh::source::FIT.spec(),
            $crate::mesh::source::FIT_SIZE.spec(),
            $crate::mesh::source::WELD.spec(),
            $crate::mesh::source::SCENES.spec(),
            $crate::mesh::source::SCENE.spec(),
            $($own),*
        ]
    };
    ($($own:expr),* $(,)?) => {
        $crate::mesh::source::with_scene_params![unit: $crate::mesh::source::UNIT.spec(); $($own),*]
    };
}
pub(crate) use with_scene_params;

/// `file`: a mesh file; empty for a generated scene.
pub const FILE: Text = Text::new(
    "file",
    "",
    "mesh file (relative to the graph file), by extension: .obj, .stl (ASCII or binary), .ply (ASCII or binary), \
     .gltf or .glb; empty: the generated scene below",
);
/// `shape` of a generated scene.
pub const SHAPE: Choice<Shape> = Choice::new(
    "shape",
    &["gaussian", "frustum"],
    &[Shape::Gaussian, Shape::Frustum],
    "gaussian",
    "generated scene: object profile (Fig. 4.5)",
);
/// `config` of a generated scene, read as its word (the same words name
/// scenes in a `scenes` list).
pub const CONFIG: Choice<&str> =
    Choice::new("config", CONFIGS, CONFIGS, "2B2H", "generated scene: bumps and holes (Fig. 4.6), or one bump/hole");
/// `resolution` of a generated Gaussian scene.
pub const RESOLUTION: Int =
    Int::new("resolution", 2, 4096, 48, "1", "generated Gaussian scene: grid cells per 6 cm object side")
        .costly(512.0, "4096² cells: 34 M triangles, minutes to build");
/// `unit`: metres per mesh unit.
pub const UNIT: Float = Float::new(
    "unit",
    1e-9,
    1e3,
    0.01,
    "m",
    "length of one mesh unit (0.01: the mesh is in cm); with fit = \"footprint\" the fit's scale replaces it",
);
/// `offset_x`: screen position of the mesh origin (or, fitted, of its footprint's centre).
pub const OFFSET_X: Float = Float::new(
    "offset_x",
    -1e6,
    1e6,
    0.0,
    "m",
    "touch x of the mesh's origin; with fit = \"footprint\", of the footprint's centre",
);
/// `offset_y`: screen position of the mesh origin (or, fitted, of its footprint's centre).
pub const OFFSET_Y: Float = Float::new(
    "offset_y",
    -1e6,
    1e6,
    0.0,
    "m",
    "touch y of the mesh's origin; with fit = \"footprint\", of the footprint's centre",
);
/// `up`: the mesh axis that points out of the screen; `None` for `auto`
/// (the convention of the mesh's format).
pub const UP: Choice<Option<Up>> = Choice::new(
    "up",
    &["auto", "+x", "-x", "+y", "-y", "+z", "-z"],
    &[None, Some(Up::PlusX), Some(Up::MinusX), Some(Up::PlusY), Some(Up::MinusY), Some(Up::PlusZ), Some(Up::MinusZ)],
    "auto",
    "mesh axis pointing up, out of the screen (turned to height z by a rotation, never a mirror); \
     auto: +y for OBJ (convention) and glTF/GLB (specification), +z for STL and PLY (CAD and scanners) and for \
     generated scenes",
);
/// How a mesh is placed on the screen (`fit`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Fit {
    /// Mesh units × `unit`, the mesh origin at `offset_x/y`.
    None,
    /// The footprint centred at `offset_x/y`, its larger side `fit_size`.
    Footprint,
}

/// `fit`: how the mesh's footprint is placed on the screen.
pub const FIT: Choice<Fit> = Choice::new(
    "fit",
    &["none", "footprint"],
    &[Fit::None, Fit::Footprint],
    "none",
    "none: mesh units × `unit`, mesh origin at `offset_x/y`; footprint: the x–y bounds (after `up`) centred \
     at `offset_x/y` and scaled uniformly, heights too, so the larger side is `fit_size`, the lowest point at \
     height 0",
);
/// `fit_size`: the fitted footprint's larger side.
pub const FIT_SIZE: Float = Float::new(
    "fit_size",
    1e-6,
    1e3,
    0.1,
    "m",
    "with fit = \"footprint\": length on the screen of the footprint's larger side",
);
/// `scenes`: the meshes a session can switch between.
pub const SCENES: Words = Words::new(
    "scenes",
    "meshes to switch between live: each a generated-scene config (with `shape`, e.g. \"4B0H\") or a mesh file \
     (*.obj, *.stl, *.ply, *.gltf, *.glb); empty: the one mesh of `file` or `config`",
);
/// `scene`: which of `scenes` is felt (live).
pub const SCENE: Int = Int::new("scene", 0, 255, 0, "1", "index into `scenes` of the mesh felt (changes live)").live();
/// `weld`: vertex weld tolerance.
pub const WELD: Float = Float::new(
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
    /// The mesh, turned so that `up` is +z; a generated scene shared with
    /// the other nodes that hold it ([`shared`]).
    pub mesh: Arc<Mesh>,
    /// The file's axis that was turned to +z.
    pub up: Up,
    /// Height of the screen plane in mesh units: 0 for scenes (objects
    /// stand on the screen), the lowest vertex for a file.
    pub floor: f64,
    /// Height (mesh units) at the screen surface, subtracted from the
    /// hit's z before it is reported in metres: 0 (the mesh's own z) with
    /// fit = "none", the floor with fit = "footprint" (the fitted mesh
    /// stands on the screen, so its heights stay small whatever its
    /// coordinates).
    pub z0: f64,
    /// Metres per mesh unit.
    pub unit: f64,
    /// Touch coordinates of the mesh origin, m.
    pub offset: [f64; 2],
    /// File name or scene description, for reports.
    pub name: String,
    /// What looks wrong with the placement ([`placement_warnings`]), each a
    /// line starting `warning:`; shown by `evflow check` and in the run's
    /// summary.
    pub warnings: Vec<String>,
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
    let file = FILE.get(p);
    if !file.is_empty() {
        return load_entry(p, ctx, file);
    }
    load_entry(p, ctx, CONFIG.get(p))
}

/// Loads every mesh a node can switch between: the `scenes` list, or the
/// one mesh of [`load`]. Also checks `scene` against the list.
pub fn load_scenes(p: &Params, ctx: &BuildContext) -> Result<Vec<Placed>, NodeError> {
    let list = SCENES.get(p);
    let scene = SCENE.count(p);
    if list.is_empty() {
        if scene != 0 {
            return Err(NodeError::param(
                SCENE.name(),
                format!("{scene}: without a `scenes` list the only scene is 0"),
            ));
        }
        return Ok(vec![load(p, ctx)?]);
    }
    if !FILE.get(p).is_empty() {
        return Err(NodeError::param(SCENES.name(), "give `file` or `scenes` (which may list mesh files), not both"));
    }
    if scene >= list.len() {
        return Err(NodeError::param(
            SCENE.name(),
            format!("{scene} is not an index into the {} scenes given (0 … {})", list.len(), list.len() - 1),
        ));
    }
    list.iter()
        .enumerate()
        .map(|(k, e)| {
            load_entry(p, ctx, e).map_err(|err| NodeError::param(SCENES.name(), format!("entry {k} `{e}`: {err}")))
        })
        .collect()
}

/// One mesh: a mesh file (a name with a mesh extension) or a generated scene's
/// config word, turned by `up` and placed by `unit`/`offset_x/y` or `fit`.
fn load_entry(p: &Params, ctx: &BuildContext, entry: &str) -> Result<Placed, NodeError> {
    let (mesh, floor, name, up) = load_mesh(p, ctx, entry)?;
    let mut placed = Placed {
        mesh,
        up,
        floor,
        z0: 0.0,
        unit: UNIT.get(p),
        offset: [OFFSET_X.get(p), OFFSET_Y.get(p)],
        name,
        warnings: Vec::new(),
    };
    let fitted = FIT.get(p) == Fit::Footprint;
    if fitted {
        let footprint = place::footprint(&placed.mesh)
            .ok_or_else(|| NodeError::param(FIT.name(), format!("{}: the mesh has no triangles", placed.name)))?;
        let fitted = place::fit(footprint, FIT_SIZE.get(p), placed.offset)
            .map_err(|e| NodeError::param(FIT.name(), format!("{}: {e}", placed.name)))?;
        placed.unit = fitted.unit;
        placed.offset = fitted.offset;
        placed.z0 = placed.floor;
    }
    let auto = UP.get(p).is_none().then(|| Format::of(entry)).flatten();
    placed.warnings = placement_warnings(&placed, auto, fitted);
    Ok(placed)
}

/// The largest footprint side, m, that fits a display evflow drives
/// without `fit` (tablet-sized electrostatic displays are 10–25 cm).
pub const MAX_SCREEN_SIDE_M: f64 = 0.3;
/// The smallest footprint side, m, a finger can explore.
pub const MIN_SCREEN_SIDE_M: f64 = 0.002;

/// Warnings about a placed mesh: a file whose `up` was taken by
/// convention (`auto`, the file's `format`) but that stands taller than it
/// is thin across — a relief lying on its side, e.g. a z-up OBJ — with the
/// file axis to set instead; and, without `fit`, a footprint larger than a
/// display or smaller than a fingertip explores.
pub fn placement_warnings(placed: &Placed, auto: Option<Format>, fitted: bool) -> Vec<String> {
    let mut out = Vec::new();
    let b = placed.mesh.bounds();
    let ext = [b.max[0] - b.min[0], b.max[1] - b.min[1], b.max[2] - b.min[2]];
    if !ext.iter().all(|e| e.is_finite()) {
        return out;
    }
    if let Some(format) = auto {
        let thin = if ext[0] <= ext[1] { 0 } else { 1 };
        if ext[thin] < 0.5 * ext[2] {
            // The file axis that was turned to the thin horizontal one.
            let mut unit = [0.0; 3];
            let file_axis = (0..3)
                .find(|&k| {
                    unit = [0.0; 3];
                    unit[k] = 1.0;
                    placed.up.to_z_up(unit)[thin].abs() > 0.5
                })
                .unwrap_or(2);
            let g = |x: f64| format!("{:.4}", x);
            out.push(format!(
                "warning: {}: up {} (auto: the {} convention) stands the mesh {} units tall on a {} × {} footprint; \
                 a relief is thinnest along its up axis — if it lies on its side, set up = \"+{}\" (or \"-{}\")",
                placed.name,
                placed.up.word(),
                format.name(),
                g(ext[2]),
                g(ext[0]),
                g(ext[1]),
                ["x", "y", "z"][file_axis],
                ["x", "y", "z"][file_axis],
            ));
        }
    }
    let side = ext[0].max(ext[1]) * placed.unit;
    if !fitted && !(MIN_SCREEN_SIDE_M..=MAX_SCREEN_SIDE_M).contains(&side) {
        out.push(format!(
            "warning: {}: its footprint is {:.1} cm × {:.1} cm on the screen ({} m per mesh unit), {} than a display \
             shows ({} … {} cm); set fit = \"footprint\" (its larger side becomes fit_size) or `unit`",
            placed.name,
            ext[0] * placed.unit * 100.0,
            ext[1] * placed.unit * 100.0,
            placed.unit,
            if side > MAX_SCREEN_SIDE_M { "larger" } else { "smaller" },
            MIN_SCREEN_SIDE_M * 100.0,
            MAX_SCREEN_SIDE_M * 100.0,
        ));
    }
    out
}

/// The mesh of one entry turned so that its up axis is +z, with its floor
/// (mesh units), name and the axis turned.
fn load_mesh(p: &Params, ctx: &BuildContext, entry: &str) -> Result<(Arc<Mesh>, f64, String, Up), NodeError> {
    let format = Format::of(entry);
    let up = match (UP.get(p), format) {
        (Some(up), _) => up,
        (None, Some(f)) => f.default_up(),
        (None, None) => Up::PlusZ,
    };
    if let Some(format) = format {
        let path = ctx.path(entry);
        let mesh = format.load(&path, WELD.get(p)).map_err(|e| NodeError::Other(e.to_string()))?;
        let mesh = place::reorient(mesh, up);
        let floor = mesh.bounds().min[2];
        return Ok((Arc::new(mesh), floor, path.display().to_string(), up));
    }
    let shape = SHAPE.get(p);
    if !CONFIGS.contains(&entry) && (entry.contains('.') || entry.contains('/')) {
        let known: Vec<String> = EXTENSIONS.iter().map(|(e, _)| format!(".{e}")).collect();
        return Err(NodeError::param(
            FILE.name(),
            format!("`{entry}`: unknown mesh format (one of {})", known.join(", ")),
        ));
    }
    if !CONFIGS.contains(&entry) {
        let help = evflow_engine::suggest::help(entry, CONFIGS.iter().copied());
        return Err(NodeError::param(
            CONFIG.name(),
            format!("unknown scene `{entry}` (one of {}, or a mesh file); {help}", CONFIGS.join(", ")),
        ));
    }
    let mesh =
        shared::scene(shape, entry, RESOLUTION.count(p)).map_err(|e| NodeError::param(CONFIG.name(), e.to_string()))?;
    // Scenes stand on the screen plane z = 0; turned, on their lowest point
    // (a turned scene is a copy of its own).
    let (mesh, floor) = match up {
        Up::PlusZ => (mesh, 0.0),
        _ => {
            let mesh = place::reorient(Arc::unwrap_or_clone(mesh), up);
            let floor = mesh.bounds().min[2];
            (Arc::new(mesh), floor)
        }
    };
    Ok((mesh, floor, format!("{} {entry}", shape.word()), up))
}

#[cfg(test)]
mod tests {
    use crate::mesh::gradient_node;
    use crate::mesh::place::{Up, UP_WORDS};
    use evflow_engine::harness::Single;
    use std::fmt::Write;
    use std::path::Path;

    /// A height field h(x, y) on an n × m grid of unit cells, each point
    /// `(x·scale + off, y·scale + off, h·scale + off)` written through `write`
    /// (which puts the three coordinates in the file's axis order).
    fn grid_obj(n: usize, m: usize, scale: f64, off: f64, write: impl Fn([f64; 3]) -> [f64; 3]) -> String {
        let h = |x: f64, y: f64| 0.5 * (0.8 * x).sin() + 0.1 * y + 1.0;
        let mut s = String::new();
        for j in 0..=m {
            for i in 0..=n {
                let (x, y) = (i as f64, j as f64);
                let p = write([x * scale + off, y * scale + off, h(x, y) * scale + off]);
                writeln!(s, "v {} {} {}", p[0], p[1], p[2]).unwrap();
            }
        }
        let id = |i: usize, j: usize| j * (n + 1) + i + 1;
        for j in 0..m {
            for i in 0..n {
                writeln!(s, "f {} {} {} {}", id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)).unwrap();
            }
        }
        s
    }

    /// `mesh.gradient` (fixed range, every tick's secant) over the touch
    /// points: outputs intensity, fsq, slope, z, tri.
    fn run(dir: &Path, params: &str, x: Vec<f64>, y: Vec<f64>) -> Vec<Vec<f64>> {
        let n = x.len() as u64;
        let params = format!("{params}\nrange = \"fixed\"\nmin_step = 0.0");
        Single::new(&gradient_node::SPEC, &params)
            .input("x", x, 1000.0)
            .input("y", y, 1000.0)
            .outputs(["intensity", "fsq", "slope", "z", "tri"])
            .ticks(n)
            .base_dir(dir)
            .run()
            .unwrap()
    }

    /// A diagonal scan from a to b (m), 1 kHz.
    fn scan(a: [f64; 2], b: [f64; 2], n: usize) -> (Vec<f64>, Vec<f64>) {
        let at = |k: usize, i: usize| a[k] + (b[k] - a[k]) * i as f64 / n as f64;
        ((0..n).map(|i| at(0, i)).collect(), (0..n).map(|i| at(1, i)).collect())
    }

    #[test]
    fn a_file_written_with_any_up_axis_renders_like_z_up_once_up_is_set() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("z.obj"), grid_obj(8, 8, 1.0, 0.0, |p| p)).unwrap();
        let (x, y) = scan([0.001, 0.002], [0.079, 0.071], 1500);
        let reference = run(dir.path(), "file = \"z.obj\"\nup = \"+z\"", x.clone(), y.clone());
        assert!(reference[4].iter().all(|&t| t >= 0.0));
        for (word, up) in UP_WORDS {
            // The file's coordinates: the inverse rotation (its transpose) of the z-up point.
            let cols = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]].map(|e| up.to_z_up(e));
            let file = |q: [f64; 3]| cols.map(|c| c[0] * q[0] + c[1] * q[1] + c[2] * q[2]);
            let name = format!("up-{}{}.obj", if word.starts_with('+') { "plus" } else { "minus" }, &word[1..]);
            std::fs::write(dir.path().join(&name), grid_obj(8, 8, 1.0, 0.0, file)).unwrap();
            let out = run(dir.path(), &format!("file = \"{name}\"\nup = \"{word}\""), x.clone(), y.clone());
            assert_eq!(out, reference, "up = {word}");
            if up == Up::PlusY {
                // OBJ's convention is the default.
                assert_eq!(run(dir.path(), &format!("file = \"{name}\""), x.clone(), y.clone()), reference);
            }
        }
        // A z-up file read with the OBJ default (+y) stands on its side: another surface.
        assert_ne!(run(dir.path(), "file = \"z.obj\"", x.clone(), y.clone())[3], reference[3]);
    }

    /// The warning lines of `mesh.gradient`'s summary after a short scan.
    fn warnings(dir: &Path, params: &str) -> Vec<String> {
        let params = format!("{params}\nrange = \"fixed\"");
        let s = Single::new(&gradient_node::SPEC, &params)
            .input("x", vec![0.001; 4], 1000.0)
            .input("y", vec![0.001; 4], 1000.0)
            .output("tri")
            .ticks(4)
            .block(4)
            .base_dir(dir)
            .summary()
            .unwrap();
        s.lines.into_iter().filter(|l| l.starts_with("warning:") && !l.contains("off the mesh")).collect()
    }

    #[test]
    fn a_relief_on_its_side_or_a_footprint_no_display_shows_is_warned_of() {
        let dir = tempfile::tempdir().unwrap();
        // A z-up relief, 8 × 6 units, read with the OBJ default (+y up):
        // it stands 8 units tall on a 8 × 1 footprint.
        std::fs::write(dir.path().join("z.obj"), grid_obj(8, 6, 1.0, 0.0, |p| p)).unwrap();
        let w = warnings(dir.path(), "file = \"z.obj\"");
        assert_eq!(w.len(), 1, "{w:?}");
        assert!(w[0].contains("up +y (auto: the OBJ convention)") && w[0].contains("set up = \"+z\""), "{w:?}");
        assert!(warnings(dir.path(), "file = \"z.obj\"\nup = \"+z\"").is_empty());
        // 60 units at 1 cm per unit: 60 cm wide, wider than any display.
        std::fs::write(dir.path().join("wide.obj"), grid_obj(60, 40, 1.0, 0.0, |p| p)).unwrap();
        let w = warnings(dir.path(), "file = \"wide.obj\"\nup = \"+z\"");
        assert_eq!(w.len(), 1, "{w:?}");
        assert!(w[0].contains("60.0 cm × 40.0 cm") && w[0].contains("larger") && w[0].contains("fit"), "{w:?}");
        assert!(warnings(dir.path(), "file = \"wide.obj\"\nup = \"+z\"\nfit = \"footprint\"").is_empty());
        assert!(warnings(dir.path(), "file = \"wide.obj\"\nup = \"+z\"\nunit = 0.002").is_empty());
        // A millimetre-sized mesh in metres: too small to feel.
        let w = warnings(dir.path(), "file = \"z.obj\"\nup = \"+z\"\nunit = 0.0001");
        assert!(w.len() == 1 && w[0].contains("smaller"), "{w:?}");
        // Generated scenes never warn.
        assert!(warnings(dir.path(), "config = \"4B0H\"").is_empty());
    }

    #[test]
    fn fit_centres_the_footprint_and_scales_its_larger_side() {
        let dir = tempfile::tempdir().unwrap();
        // A ramp from z = 1 to 3 over x ∈ [10, 14], y ∈ [−3, −1]: 4 × 2 units.
        let plate = "v 10 -3 1\nv 14 -3 3\nv 14 -1 3\nv 10 -1 1\nf 1 2 3 4\n";
        std::fs::write(dir.path().join("plate.obj"), plate).unwrap();
        let p =
            "file = \"plate.obj\"\nup = \"+z\"\nfit = \"footprint\"\nfit_size = 0.1\noffset_x = 0.02\noffset_y = -0.01";
        // 0.1 m / 4 units: 0.025 m per unit, so 0.1 × 0.05 m centred at (0.02, −0.01).
        let (e, d) = (1e-6, [0.05, 0.025]);
        let mut x = vec![0.02];
        let mut y = vec![-0.01];
        for (sx, sy) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
            x.extend([0.02 + sx * (d[0] - e), 0.02 + sx * (d[0] + e), 0.02]);
            y.extend([-0.01 + sy * (d[1] - e), -0.01, -0.01 + sy * (d[1] + e)]);
        }
        let out = run(dir.path(), p, x, y);
        let on: Vec<bool> = out[4].iter().map(|&t| t >= 0.0).collect();
        let expect = [true, true, false, false, true, false, false, true, false, false, true, false, false];
        assert_eq!(on, expect);
        // Heights scale with the footprint, from the lowest point: 1 unit (at the centre) = 0.025 m.
        assert!((out[3][0] - 0.025).abs() < 1e-15, "{}", out[3][0]);
    }

    #[test]
    fn meshes_far_away_or_in_mm_or_m_fit_to_the_same_surface() {
        let dir = tempfile::tempdir().unwrap();
        // One surface, 8 × 6 cells: in cm at the origin, in mm 10⁶ mm away (up too), in m.
        let files = [("cm.obj", 1.0, 0.0), ("mm-far.obj", 10.0, 1e6), ("m.obj", 0.01, 0.0)];
        for (name, scale, off) in files {
            std::fs::write(dir.path().join(name), grid_obj(8, 6, scale, off, |p| p)).unwrap();
        }
        let (x, y) = scan([-0.049, -0.036], [0.049, 0.036], 2000);
        let fitted = |name: &str| {
            let p = format!("file = \"{name}\"\nup = \"+z\"\nfit = \"footprint\"\nfit_size = 0.1");
            run(dir.path(), &p, x.clone(), y.clone())
        };
        let cm = fitted("cm.obj");
        for out in [&cm, &fitted("mm-far.obj"), &fitted("m.obj")] {
            assert!(out.iter().flatten().all(|v| v.is_finite()));
            // Inside the footprint (0.1 × 0.075 m, centred on the origin) every tick hits.
            assert!(out[4].iter().all(|&t| t >= 0.0));
            for (a, b) in cm[2].iter().zip(&out[2]) {
                assert!((a - b).abs() < 1e-6, "slope {a} vs {b}");
            }
            // Heights in m from the lowest point: 1 cm of the grid is 0.1/8 m on the screen.
            assert!(out[3].iter().all(|z| (0.0..0.03).contains(z)));
            for (a, b) in cm[3].iter().zip(&out[3]) {
                assert!((a - b).abs() < 1e-12, "height {a} vs {b}");
            }
        }
        // Unfitted, the millimetre mesh would lie 10 km away and the finger would miss it.
        let far = run(dir.path(), "file = \"mm-far.obj\"\nup = \"+z\"", x.clone(), y.clone());
        assert!(far[4].iter().all(|&t| t < 0.0) && far.iter().flatten().all(|v| v.is_finite()));
    }
}
