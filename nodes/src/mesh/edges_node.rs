//! `mesh.edges`: EDGE-TICK intensity when the finger crosses a sharp convex
//! edge (dissertation §4.1.2, Eq. 4.8–4.9).

use super::edges::{census, EdgeCensus, EdgeTracker};
use super::gradient_node::placement_note;
use super::source::{self, Placed};
use evflow_engine::node::Constant;
use evflow_engine::ports::{InPort, OutPort};
use evflow_engine::typed_params::Float;
use evflow_engine::{BuildContext, Change, Io, Node, NodeError, NodeSpec, Params, PortSpec, Refused, Role, Summary};

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
plane as cliffs — when higher than the face beside them is wide × tan(180° − `max_angle`)); a mesh without one has θ_min = 180° and never ticks. Output I_e = 0.7·S + 0.3 \
(Eq. 4.9) on the tick of the crossing, 0 otherwise — feed it to a `grain` edge input.\n\n\
The mesh parameters (with `up` and `fit`) must name the same mesh as the `mesh.gradient` node that feeds `tri` (a graph \
variable keeps them together); only the triangles and normals are loaded, no BVH. A `tri` that is not an index of \
this mesh, or whose triangle does not hold the point, counts as off the mesh.\n\n\
**Scenes.** With a `scenes` list (as `mesh.gradient`'s) every mesh's edges are found when the node is \
built, and the live `scene` index picks the one felt; a change restarts the crossing tracker on the new \
mesh (no edge is counted between two meshes). Switch it at the same tick as `mesh.gradient`'s through \
one graph variable.\n\n\
**Pruning** (docs/pruning.md): when no mesh it can switch to has a convex edge sharper than `max_angle` \
(θ_min = 180°, e.g. the Gaussian scenes), `intensity` and `sharpness` are 0 at every tick whatever the \
finger does; the node says so when built, and unless something reads its `angle` (which still reports \
the bends of the facets crossed) the planner replaces it by those constants — it is never stepped — and \
leaves out what fed only it. Its summary is then not reported; `evflow check` lists it.\n\n\
**Ports** (all at the node's rate): inputs `x`, `y` (m), `tri`; outputs `intensity` (I_e), \
`sharpness` (S), `angle` (θ of the bend crossed this tick, degrees; 180 when none). **Checked \
against:** a cube standing on an edge (90°, either winding), an axis-aligned cube stepped off (90° \
wall), frustum top/side and hip angles (180° − atan 2, 180° − acos(1/5)), a valley (no convex edge), \
boundary and non-manifold cases (unit tests); fandisk's dihedral angles in the fidelity report.",
)
.ports(PORTS)
.params(source::with_scene_params![MAX_ANGLE.spec(), MAX_STEP.spec()])
.example("shape = \"frustum\"\nconfig = \"1B3H\"");

/// The ports: the touch point and the triangle hit in; EDGE-TICK
/// intensity, sharpness and the angle crossed out.
const PORTS: &[PortSpec] = &[
    PortSpec::input("x", "m", "touch x on the screen"),
    PortSpec::input("y", "m", "touch y on the screen"),
    PortSpec::input("tri", "1", "triangle hit (mesh.gradient's `tri`), −1 off the mesh"),
    PortSpec::output("intensity", "1", "EDGE-TICK intensity I_e (Eq. 4.9) on the crossing tick, else 0").view(),
    PortSpec::output("sharpness", "1", "sharpness S (Eq. 4.8) on the crossing tick, else 0"),
    PortSpec::output("angle", "deg", "dihedral angle θ crossed this tick (180: none)"),
];
/// `x`: touch x.
const X: InPort = InPort::named(PORTS, "x");
/// `y`: touch y.
const Y: InPort = InPort::named(PORTS, "y");
/// `tri`: the triangle hit.
const TRI: InPort = InPort::named(PORTS, "tri");
/// `intensity`: I_e.
const INTENSITY: OutPort = OutPort::named(PORTS, "intensity");
/// `sharpness`: S.
const SHARPNESS: OutPort = OutPort::named(PORTS, "sharpness");
/// `angle`: θ crossed this tick.
const ANGLE: OutPort = OutPort::named(PORTS, "angle");

/// `max_angle`: convex bends flatter than this are not edges.
const MAX_ANGLE: Float =
    Float::new("max_angle", 1.0, 180.0, 160.0, "deg", "convex bends flatter than this are not edges");
/// `max_step`: the largest move per tick taken as motion.
const MAX_STEP: Float =
    Float::new("max_step", 1e-6, 1e3, 0.01, "m", "largest move per tick taken as motion (longer: a jump)");

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
    max_angle: f64,
    notes: Vec<String>,
}

fn build(p: &Params, ctx: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
    let max_angle = MAX_ANGLE.get(p);
    let scenes = source::load_scenes(p, ctx)?
        .into_iter()
        .map(|placed| {
            let census = census(&placed.mesh, placed.floor, max_angle);
            let tracker = EdgeTracker::new(census.theta_min, max_angle, MAX_STEP.get(p) / placed.unit, placed.floor);
            MeshEdges { placed, census, tracker, crossings: 0 }
        })
        .collect();
    let initial = source::SCENE.count(p);
    let scenes: Vec<MeshEdges> = scenes;
    let notes = scenes
        .iter()
        .flat_map(|s| {
            let c = &s.census;
            let note = format!(
                "{}; {} convex edges sharper than {max_angle}° (θ_min {:.1}°){}",
                placement_note(&s.placed, p),
                c.convex,
                c.theta_min,
                cliffs_note(c)
            );
            std::iter::once(note).chain(s.placed.warnings.iter().cloned())
        })
        .collect();
    Ok(Box::new(EdgesNode { scenes, current: initial, initial, max_angle, notes }))
}

/// What part of the convex edges is the open boundary, when any: an open
/// mesh standing above the floor ends in cliffs, which count as edges.
fn cliffs_note(c: &EdgeCensus) -> String {
    match c.cliffs {
        0 => String::new(),
        n => format!(
            ", {n} of them on the open mesh's boundary, read as cliffs down to the floor (close the mesh or lower it \
             to the floor if its border is not a cliff)"
        ),
    }
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

    /// Constant `intensity` and `sharpness` (0) when no mesh the node can
    /// switch to has a convex edge sharper than `max_angle`: with θ_min =
    /// 180° no crossing ticks (Eq. 4.8 gives S = 0). `angle` still varies.
    fn constant_output(&self) -> Option<Constant> {
        if !self.scenes.iter().all(|s| s.census.theta_min >= 180.0) {
            return None;
        }
        let which = match self.scenes.as_slice() {
            [one] => one.placed.name.clone(),
            all => format!("any of its {} meshes", all.len()),
        };
        let reason = format!("no convex edge sharper than max_angle = {}° in {which}", self.max_angle);
        Some(Constant::new(vec![Some(0.0), Some(0.0), None], reason))
    }

    fn notes(&self) -> Vec<String> {
        self.notes.clone()
    }

    fn set(&mut self, c: Change) -> Result<(), Refused> {
        match source::SCENE.changed(&c) {
            Some(next) if next < self.scenes.len() => {
                if next != self.current {
                    // No crossing is counted between two meshes.
                    self.scenes[next].tracker.reset();
                    self.current = next;
                }
                Ok(())
            }
            _ => Err(c.refused()),
        }
    }
}

impl MeshEdges {
    fn process(&mut self, io: &mut Io<'_>) {
        for i in 0..io.len() {
            let (x, y) = self.placed.to_mesh(io.input(X)[i], io.input(Y)[i]);
            let t = io.input(TRI)[i];
            let tri = (t >= 0.0 && t.fract() == 0.0 && t < u32::MAX as f64).then_some(t as u32);
            let (p, tri) = self.tracker.locate(&self.placed.mesh, x, y, tri);
            let e = self.tracker.step(&self.placed.mesh, p, tri);
            if e.intensity > 0.0 {
                self.crossings += 1;
            }
            io.output(INTENSITY)[i] = e.intensity;
            io.output(SHARPNESS)[i] = e.sharpness;
            io.output(ANGLE)[i] = e.theta;
        }
    }

    /// Adds this mesh's figures: as named values (`values`) or as a line.
    fn summary(&self, s: Summary, values: bool) -> Summary {
        let c = &self.census;
        let line = format!(
            "{}: {} edges, {} boundary, {} non-manifold, {} convex edges (θ_min {:.1}°){}, {} crossings",
            self.placed.name,
            c.edges,
            c.boundary,
            c.non_manifold,
            c.convex,
            c.theta_min,
            cliffs_note(c),
            self.crossings
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

#[cfg(test)]
mod tests {
    use evflow_engine::plan::Folding;
    use evflow_engine::{check, graph::parse_graph, Plan, PlanOptions};
    use std::path::Path;

    /// A stroke across the 2B2H scene's top row (x from −6 to 6 cm at
    /// y = 3 cm, 5 cm/s) through `mesh.gradient` into `mesh.edges` with
    /// the given mesh parameters; `reads` are the edges outputs sinks read.
    /// Returns each read output, and the nodes folded, with pruning `folding`.
    fn run(mesh: &str, reads: &[&str], folding: Folding) -> (Vec<Vec<f64>>, Vec<String>) {
        // Parameters after a `|` are the edges node's alone.
        let (mesh, own) = mesh.split_once('|').unwrap_or((mesh, ""));
        let n = 2400;
        let xs: Vec<String> = (0..n).map(|i| format!("{}", -0.06 + 0.12 * i as f64 / n as f64)).collect();
        let mut doc = format!(
            "[graph]\nformat = 1\nname = \"e\"\nrate = 1000\nconnections = [\"x.out -> surface.x\", \"y.out -> surface.y\", \
             \"x.out -> edges.x\", \"y.out -> edges.y\", \"surface.tri -> edges.tri\", \"surface.intensity -> s.in\"{}]\n\
             [nodes.x]\ntype = \"harness.feed\"\nvalues = [{}]\n[nodes.y]\ntype = \"harness.feed\"\nvalues = [{}]\n\
             [nodes.surface]\ntype = \"mesh.gradient\"\nrange = \"fixed\"\n{mesh}\n[nodes.edges]\ntype = \"mesh.edges\"\n{mesh}\n{own}\n\
             [nodes.s]\ntype = \"harness.tap\"\n",
            reads.iter().map(|r| format!(", \"edges.{r} -> t_{r}.in\"")).collect::<String>(),
            xs.join(","),
            vec!["0.03"; n].join(",")
        );
        for r in reads {
            doc += &format!("[nodes.t_{r}]\ntype = \"harness.tap\"\n");
        }
        let mut reg = crate::registry();
        reg.add(&evflow_engine::harness::FEED).add(&evflow_engine::harness::TAP);
        let c = check(&parse_graph(Path::new("e.toml"), &doc).unwrap(), &reg, &[]).unwrap();
        let opts = PlanOptions { max_block: 64, timing: false, ..PlanOptions::default() };
        let mut plan = Plan::build_with(&c, &opts, folding).unwrap();
        let folded = plan.folded().iter().map(|f| format!("{}: {}", f.node, f.reason)).collect();
        let k = plan.index("edges").unwrap();
        let ports: Vec<usize> =
            reads.iter().map(|r| plan.output_names(k).iter().position(|p| p == r).unwrap()).collect();
        let mut out = vec![Vec::new(); reads.len()];
        for _ in 0..n / 64 {
            plan.step(64).unwrap();
            for (o, &j) in out.iter_mut().zip(&ports) {
                o.extend_from_slice(plan.output_at(k, j));
            }
        }
        (out, folded)
    }

    #[test]
    fn the_open_boundarys_cliffs_are_said_to_be_such() {
        use super::{cliffs_note, EdgeCensus};
        let open = EdgeCensus { edges: 5, boundary: 4, convex: 4, cliffs: 4, theta_min: 90.0, ..Default::default() };
        let note = cliffs_note(&open);
        assert!(note.contains("4 of them on the open mesh's boundary, read as cliffs"), "{note}");
        assert_eq!(cliffs_note(&EdgeCensus { cliffs: 0, ..open }), "");
    }

    #[test]
    fn a_smooth_scene_makes_the_intensity_a_constant_an_edgy_one_does_not() {
        // Gaussian bumps and holes at the default resolution: every convex
        // bend is a facet (flatter than 160°), and the 30 µm where the scene
        // ends is no cliff.
        let gauss = "shape = \"gaussian\"\nconfig = \"2B2H\"";
        let reads = ["intensity", "sharpness"];
        let (out, folded) = run(gauss, &reads, Folding::On);
        assert_eq!(folded, ["edges: no convex edge sharper than max_angle = 160° in gaussian 2B2H"]);
        assert!(out.iter().flatten().all(|&v| v == 0.0));
        // Without pruning the node runs and gives the same, and it does
        // cross the facets' bends (which its `angle` reports).
        let (unpruned, folded) = run(gauss, &reads, Folding::Off);
        assert!(folded.is_empty());
        assert_eq!(unpruned, out);
        let (kept, folded) = run(gauss, &["intensity", "angle"], Folding::On);
        assert!(folded.is_empty(), "a read `angle` keeps the node");
        assert!(kept[0].iter().all(|&v| v == 0.0));
        assert!(kept[1].iter().any(|&a| a < 180.0), "the facets' bends are reported");
        // Frustums have sharp edges: the node stays and ticks on them.
        let (out, folded) = run("shape = \"frustum\"\nconfig = \"2B2H\"", &reads, Folding::On);
        assert!(folded.is_empty());
        assert!(out[0].iter().filter(|&&v| v > 0.0).count() >= 4, "crossings on the frustums' edges");
        // With several scenes the constant must hold for every one the
        // finger can switch to.
        let mixed = "shape = \"gaussian\"\nscenes = [\"0B4H\", \"4B0H\"]";
        let expect = "edges: no convex edge sharper than max_angle = 160° in any of its 2 meshes";
        assert_eq!(run(mixed, &reads, Folding::On).1, [expect]);
        let sharp = format!("{mixed}|max_angle = 179.9");
        assert!(run(&sharp, &reads, Folding::On).1.is_empty(), "facet bends count as edges below 179.9°");
        // Coarser, the Gaussian's facets bend by more than 20°: edges.
        assert!(run("shape = \"gaussian\"\nconfig = \"bump\"\nresolution = 12", &reads, Folding::On).1.is_empty());
    }
}
