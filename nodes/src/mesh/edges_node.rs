//! `mesh.edges`: EDGE-TICK intensity when the finger crosses a sharp convex
//! edge (dissertation §4.1.2, Eq. 4.8–4.9).

use super::edges::{census, EdgeCensus, EdgeTracker};
use super::source::{self, Placed};
use evflow_engine::{BuildContext, Io, Node, NodeError, NodeSpec, ParamSpec, Params, PortSpec, Refused, Role, Summary};

/// Declaration of `mesh.edges`.
pub static SPEC: NodeSpec = NodeSpec::new(
    "mesh.edges",
    "mesh",
    Role::Filter,
    "Edge emphasis: dihedral angle between the triangles hit in consecutive ticks → EDGE-TICK intensity (§4.1.2).",
    build,
)
.doc(
    "Dissertation §4.1.2. Takes the touch point and the triangle `mesh.gradient` hit (`tri`, −1 off the \
mesh) and, when the triangle changes, the dihedral angle θ between the previous and the current one: \
convex only (normals face the ray; convex when each hit point lies below the other face's plane), \
θ = 180° − ∠(n_a, n_b); when the chord between the two hit points is steeper than both faces (a \
vertical wall, which a vertical ray never hits, lies between them) the convex turn at the wall's \
top gives θ instead, if sharper. Convex bends flatter than `max_angle` are the facets \
of a smooth surface and are ignored. Sharpness S = −(θ − 180°)/(180° − θ_min) (Eq. 4.8), θ_min the \
sharpest convex edge of the whole mesh, computed once when the node is built over every edge of the \
welded mesh (pairs of faces around non-manifold edges, walls, and open boundaries above the screen \
plane as cliffs); a mesh without one has θ_min = 180° and never ticks. Output I_e = 0.7·S + 0.3 \
(Eq. 4.9) on the tick of the crossing, 0 otherwise — feed it to a `grain` edge input.\n\n\
The mesh parameters (with `up` and `fit`) must name the same mesh as the `mesh.gradient` node that feeds `tri` (a graph \
variable keeps them together); only the triangles and normals are loaded, no BVH. A scene without \
sharp edges leaves this node out, and pruning never constructs it. A `tri` that is not an index of \
this mesh, or whose triangle does not hold the point, counts as off the mesh.\n\n\
**Scenes.** With a `scenes` list (as `mesh.gradient`'s) every mesh's edges are found when the node is \
built, and the live `scene` index picks the one felt; a change restarts the crossing tracker on the new \
mesh (no edge is counted between two meshes). Switch it at the same tick as `mesh.gradient`'s through \
one graph variable.\n\n\
**Ports** (all at the node's rate): inputs `x`, `y` (m), `tri`; outputs `intensity` (I_e), \
`sharpness` (S), `angle` (θ of the bend crossed this tick, degrees; 180 when none). **Checked \
against:** a cube standing on an edge (90°, either winding), an axis-aligned cube stepped off (90° \
wall), frustum top/side and hip angles (180° − atan 2, 180° − acos(1/5)), a valley (no convex edge), \
boundary and non-manifold cases (unit tests); fandisk's dihedral angles in the fidelity report.",
)
.ports(&[
    PortSpec::input("x", "m", "touch x on the screen"),
    PortSpec::input("y", "m", "touch y on the screen"),
    PortSpec::input("tri", "1", "triangle hit (mesh.gradient's `tri`), −1 off the mesh"),
    PortSpec::output("intensity", "1", "EDGE-TICK intensity I_e (Eq. 4.9) on the crossing tick, else 0"),
    PortSpec::output("sharpness", "1", "sharpness S (Eq. 4.8) on the crossing tick, else 0"),
    PortSpec::output("angle", "deg", "dihedral angle θ crossed this tick (180: none)"),
])
.params(&[
    source::FILE,
    source::SHAPE,
    source::CONFIG,
    source::RESOLUTION,
    source::UNIT,
    source::OFFSET_X,
    source::OFFSET_Y,
    source::UP,
    source::FIT,
    source::FIT_SIZE,
    source::WELD,
    source::SCENES,
    source::SCENE,
    ParamSpec::float("max_angle", 1.0, 180.0, 160.0, "deg", "convex bends flatter than this are not edges"),
    ParamSpec::float("max_step", 1e-6, 1e3, 0.01, "m", "largest move per tick taken as motion (longer: a jump)"),
])
.example("shape = \"frustum\"\nconfig = \"1B3H\"");

/// One mesh's edges and the tracker of the finger on it.
struct MeshEdges {
    placed: Placed,
    census: EdgeCensus,
    tracker: EdgeTracker,
    crossings: u64,
}

/// The node: the meshes it can switch between (`scenes`), one felt.
struct EdgesNode {
    scenes: Vec<MeshEdges>,
    current: usize,
    initial: usize,
}

fn build(p: &Params, ctx: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
    let max_angle = p.f64("max_angle");
    let scenes = source::load_scenes(p, ctx)?
        .into_iter()
        .map(|placed| {
            let census = census(&placed.mesh, placed.floor, max_angle);
            let tracker = EdgeTracker::new(census.theta_min, max_angle, p.f64("max_step") / placed.unit, placed.floor);
            MeshEdges { placed, census, tracker, crossings: 0 }
        })
        .collect();
    let initial = p.usize("scene");
    Ok(Box::new(EdgesNode { scenes, current: initial, initial }))
}

impl Node for EdgesNode {
    fn process(&mut self, io: &mut Io<'_>) -> Result<(), NodeError> {
        let s = &mut self.scenes[self.current];
        s.process(io);
        Ok(())
    }

    fn reset(&mut self) {
        for s in &mut self.scenes {
            s.tracker.reset();
            s.crossings = 0;
        }
        self.current = self.initial;
    }

    fn finish(&mut self) -> Result<Summary, NodeError> {
        let first = &self.scenes[self.initial];
        if self.scenes.len() == 1 {
            return Ok(first.summary(Summary::default(), true));
        }
        let c = &first.census;
        let mut s = Summary::default()
            .value("theta_min", c.theta_min, "deg")
            .value("convex_edges", c.convex as f64, "1")
            .value("crossings", self.scenes.iter().map(|s| s.crossings).sum::<u64>() as f64, "1");
        for (k, sc) in self.scenes.iter().enumerate() {
            s = s.line(format!("scene {k}: {}", sc.summary(Summary::default(), false).lines.concat()));
        }
        Ok(s)
    }

    fn set(&mut self, param: &'static str, value: f64) -> Result<(), Refused> {
        match param {
            "scene" if (value as usize) < self.scenes.len() => {
                let next = value as usize;
                if next != self.current {
                    // No crossing is counted between two meshes.
                    self.scenes[next].tracker.reset();
                    self.current = next;
                }
                Ok(())
            }
            _ => Err(Refused(param)),
        }
    }
}

impl MeshEdges {
    fn process(&mut self, io: &mut Io<'_>) {
        for i in 0..io.len() {
            let (x, y) = self.placed.to_mesh(io.input(0)[i], io.input(1)[i]);
            let t = io.input(2)[i];
            let tri = (t >= 0.0 && t.fract() == 0.0 && t < u32::MAX as f64).then_some(t as u32);
            let (p, tri) = self.tracker.locate(&self.placed.mesh, x, y, tri);
            let e = self.tracker.step(&self.placed.mesh, p, tri);
            if e.intensity > 0.0 {
                self.crossings += 1;
            }
            io.output(0)[i] = e.intensity;
            io.output(1)[i] = e.sharpness;
            io.output(2)[i] = e.theta;
        }
    }

    /// Adds this mesh's figures: as named values (`values`) or as a line.
    fn summary(&self, s: Summary, values: bool) -> Summary {
        let c = &self.census;
        let line = format!(
            "{}: {} edges, {} boundary, {} non-manifold, {} convex edges (θ_min {:.1}°), {} crossings",
            self.placed.name, c.edges, c.boundary, c.non_manifold, c.convex, c.theta_min, self.crossings
        );
        if values {
            s.value("theta_min", c.theta_min, "deg")
                .value("convex_edges", c.convex as f64, "1")
                .value("crossings", self.crossings as f64, "1")
                .line(format!(
                    "{}: {} edges, {} boundary, {} non-manifold",
                    self.placed.name, c.edges, c.boundary, c.non_manifold
                ))
        } else {
            s.line(line)
        }
    }
}
