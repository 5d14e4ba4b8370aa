//! `mesh.gradient`: touch point → vertical ray on a mesh → surface
//! gradient → friction intensity (dissertation §4.1, Eq. 4.1–4.7).

use super::calibrate::{calibrate, CacheStatus, Range, ScanSettings};
use super::gradient::{intensity, Gradient, GradientSettings, SlopeMode};
use super::raycast::RayCaster;
use super::shared;
use super::source::{self, Fit, Placed};
use evflow_engine::ports::{InPort, OutPort};
use evflow_engine::spec::Scene;
use evflow_engine::typed_params::{Choice, Float, Floats, Int, Text};
use evflow_engine::{BuildContext, Change, Io, Node, NodeError, NodeSpec, Params, PortSpec, Refused, Role, Summary};
use std::sync::Arc;

/// Declaration of `mesh.gradient`.
pub static SPEC: NodeSpec = NodeSpec::new(
    "mesh.gradient",
    "mesh",
    Role::Filter,
    "Touch point → vertical ray cast on a 3D mesh → surface gradient → friction intensity (§4.1).",
    build,
)
.doc(
    "The generalized gradient algorithm of dissertation §4.1. Each tick the touch point (x, y) — metres \
on the screen, mapped to mesh units by `unit` and `offset_x/y` — casts a vertical ray from above the \
mesh; the highest hit is the hit point. A ray that misses lands on the screen plane (`floor`: z = 0 \
for generated scenes, the lowest vertex for a file).\n\n\
**Slope.** `slope = \"secant\"` (the dissertation's): tan α = Δz/Δr between the hit point and the \
previous one (Eq. 4.1–4.3), where \"previous\" is the last hit point at least `min_step` away — the \
output holds while the finger moves less (a stationary finger never divides by zero) and a move longer \
than `max_step` in one tick (a lift or jump) restarts without a slope. `slope = \"normal\"`: the slope of \
the hit triangle along the last direction of motion, −(n_x d_x + n_y d_y)/n_z, defined every tick even \
when the finger nearly stops. `docs/mesh.md` compares their fidelity.\n\n\
**Intensity.** F = −F_pz·tan α (Eq. 4.4–4.5, F_pz = `normal_force`), F^sq = sgn(F)√|F| (Eq. 4.6), \
I = linear map of [F_min, F_max] onto [`i_max`, `i_min`] = [1.0, 0.3] (Eq. 4.7), clamped outside. \
With `range = \"auto\"` (F_min, F_max) = (μ − 2σ, μ + 2σ) of F^sq over a simulated scan of the mesh \
(§4.1.1: `calib_directions` directions × `calib_lines` lines at the `calib_speeds`, at this node's rate), \
cached under a hash of the mesh and the settings, so the next session starts at once — in the folder \
`cache` (relative to the output folder), by default the user's cache folder ($EVFLOW_CACHE, else \
$XDG_CACHE_HOME/evflow, else ~/.cache/evflow), or nowhere with `cache = \"none\"`; `range = \"fixed\"` takes `f_min`/`f_max` \
(the formative study's ±1). A flat mesh has F_min = F_max = 0 and renders I = `i_max`.\n\n\
**Mesh.** `file`: OBJ, STL (ASCII or binary), PLY (ASCII or binary) or glTF/GLB, by extension \
(docs/mesh.md, Formats; quads and n-gons triangulated; normals recomputed; vertices welded \
so neighbouring triangles share edges, within `weld`; zero-area and repeated triangles dropped), or a generated §4.2 scene (`shape`, `config`, \
`resolution`; cm). **Orientation and fit:** `up` names the mesh axis that points out of the screen \
(default `auto`: +y for OBJ and glTF/GLB, as OBJ models conventionally are and as glTF's spec says; \
+z for STL, PLY — CAD and scanners — and generated scenes); the mesh \
is turned so that it becomes height z. `fit = \"footprint\"` centres the mesh's x–y bounds on \
(`offset_x`, `offset_y`) and scales the mesh uniformly (heights too, so slopes keep their values) so that \
the larger side spans `fit_size` metres — whatever its units (mm, m) or however far from the origin it \
was modelled — and reports heights `z` from its lowest point; the default `fit = \"none\"` keeps `unit` and the origin at `offset_x/y`. Each entry of \
`scenes` is turned and fitted on its own. The BVH (obvhs CWBVH) is built when the node is constructed — never for a pruned \
node. The hit test is f64 and watertight: rays through vertices and edges hit whatever the winding; \
where the mesh overhangs (a teapot's handle or spout), the highest hit is the one felt, never the surface beneath.\n\n\
**Scenes.** `scenes` lists several meshes (generated-scene configs such as \"4B0H\", or mesh files of any of the formats above); all \
are loaded, ray-cast structures built and calibrated when the node is built, and the live parameter \
`scene` (0-based index) picks the one felt. On a change the slope estimate continues on the new mesh from the finger's last point and \
direction (its held slope: the new mesh's slope there), and \
the intensity crossfades from the old mesh's to the new one's over `switch_fade` (10 ms) — no click. \
Change `mesh.gradient` and `mesh.edges` together through a graph variable bound to both (`scene=4` in \
`graphs/mesh-live.toml`, `docs/live.md`).\n\n\
**Ports** (all at the node's rate): inputs `x`, `y` (m); outputs `intensity`, `fsq` (√N), `slope`, `z` \
(height under the finger, m), `tri` (index of the triangle hit, −1 off the mesh; feeds `mesh.edges`).\n\n\
**Checked against:** planes and ramps scanned in many directions (exact slope), the Eq. 4.7 closed form, \
a brute-force loop over all triangles on grid meshes hit exactly at vertices and edges, the analytic \
gradient of the Gaussian scene (fidelity report), and the robustness cases of `docs/mesh.md`.",
)
.ports(PORTS)
.params(source::with_scene_params![
    unit: UNIT.spec();
    SWITCH_FADE.spec(),
    SLOPE.spec(),
    MIN_STEP.spec(),
    MAX_STEP.spec(),
    NORMAL_FORCE.spec(),
    RANGE.spec(),
    F_MIN.spec(),
    F_MAX.spec(),
    I_MAX.spec(),
    I_MIN.spec(),
    CALIB_SPEEDS.spec(),
    CALIB_DIRECTIONS.spec(),
    CALIB_LINES.spec(),
    CACHE.spec(),
])
.scene(Scene::Mesh)
.example("shape = \"gaussian\"\nconfig = \"bump\"\nresolution = 12\ncalib_directions = 4\ncalib_lines = 8");

/// The ports: the touch point in; intensity, F^sq, slope, height and the
/// triangle hit out, in the order of a [`TickOut`].
const PORTS: &[PortSpec] = &[
    PortSpec::input("x", "m", "touch x on the screen"),
    PortSpec::input("y", "m", "touch y on the screen"),
    PortSpec::output("intensity", "1", "AREA-EVEN intensity I (Eq. 4.7), 0.3 … 1.0").view(),
    PortSpec::output("fsq", "sqrt(N)", "signed square root of the lateral force, F^sq (Eq. 4.6)"),
    PortSpec::output("slope", "1", "tan α, the surface slope along the motion"),
    PortSpec::output("z", "m", "height of the surface under the finger"),
    PortSpec::output("tri", "1", "index of the triangle hit, −1 off the mesh"),
];
/// `x`: touch x.
const X: InPort = InPort::named(PORTS, "x");
/// `y`: touch y.
const Y: InPort = InPort::named(PORTS, "y");
/// `intensity`: the AREA-EVEN intensity.
const INTENSITY: OutPort = OutPort::named(PORTS, "intensity");
/// `fsq`: F^sq.
const FSQ: OutPort = OutPort::named(PORTS, "fsq");
/// `slope` (the port): tan α.
const SLOPE_OUT: OutPort = OutPort::named(PORTS, "slope");
/// `z`: the height under the finger.
const Z: OutPort = OutPort::named(PORTS, "z");
/// `tri`: the triangle hit.
const TRI: OutPort = OutPort::named(PORTS, "tri");
/// The output each entry of a [`TickOut`] goes to.
const TICK_PORTS: [OutPort; 5] = [INTENSITY, FSQ, SLOPE_OUT, Z, TRI];

/// Where F_min and F_max come from (`range`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum RangeMode {
    /// A simulated scan of the mesh (§4.1.1).
    Auto,
    /// `f_min` and `f_max`.
    Fixed,
}

/// `switch_fade`: the crossfade of a scene change.
const SWITCH_FADE: Float =
    Float::new("switch_fade", 0.0, 1000.0, 10.0, "ms", "intensity crossfade when `scene` changes");
/// `slope`: how the slope is estimated.
const SLOPE: Choice<SlopeMode> = Choice::new(
    "slope",
    &["secant", "normal"],
    &[SlopeMode::Secant, SlopeMode::Normal],
    "secant",
    "slope estimate: Eq. 4.1 secant or triangle normal",
);
/// `min_step`: the smallest move that updates the previous hit point.
const MIN_STEP: Float =
    Float::new("min_step", 0.0, 1.0, 0.0005, "m", "smallest move that updates the previous hit point");
/// `max_step`: the largest move per tick taken as motion.
const MAX_STEP: Float =
    Float::new("max_step", 1e-6, 1e3, 0.01, "m", "largest move per tick taken as motion (longer: a jump)");
/// `normal_force`: F_pz.
const NORMAL_FORCE: Float = Float::new("normal_force", 0.0, 100.0, 1.0, "N", "F_pz of Eq. 4.4");
/// `range`: where F_min and F_max come from.
const RANGE: Choice<RangeMode> = Choice::new(
    "range",
    &["auto", "fixed"],
    &[RangeMode::Auto, RangeMode::Fixed],
    "auto",
    "F_min/F_max: simulated scan (§4.1.1) or fixed",
);
/// `f_min`: F_min when fixed.
const F_MIN: Float = Float::new("f_min", -1e3, 1e3, -1.0, "sqrt(N)", "F_min when range = fixed");
/// `f_max`: F_max when fixed.
const F_MAX: Float = Float::new("f_max", -1e3, 1e3, 1.0, "sqrt(N)", "F_max when range = fixed");
/// `i_max`: the intensity at F_min.
const I_MAX: Float = Float::new("i_max", 0.0, 1.0, 1.0, "1", "intensity at F_min (most friction)");
/// `i_min`: the intensity at F_max.
const I_MIN: Float = Float::new("i_min", 0.0, 1.0, 0.3, "1", "intensity at F_max (least perceivable friction)");
/// `calib_speeds`: the calibration scan's finger speeds.
const CALIB_SPEEDS: Floats =
    Floats::new("calib_speeds", 1e-6, 100.0, "m/s", "finger speeds of the calibration scan; empty: 0.02, 0.05, 0.1");
/// `calib_directions`: the calibration scan's directions.
const CALIB_DIRECTIONS: Int =
    Int::new("calib_directions", 1, 360, 12, "1", "directions of the calibration scan (over 360°)")
        .costly(36.0, SCAN_COST);
/// `calib_lines`: parallel lines per direction in the calibration scan.
const CALIB_LINES: Int =
    Int::new("calib_lines", 1, 1000, 24, "1", "parallel lines per direction in the calibration scan")
        .costly(48.0, SCAN_COST);
/// Why the calibration scan's size is capped in the stability suite.
const SCAN_COST: &str = "calibration scan time grows with directions × lines";
/// `unit` (the shared mesh parameter), capped in the stability suite: the
/// calibration scan crosses the mesh at finger speed.
const UNIT: Float = source::UNIT.costly(
    0.1,
    "the calibration scan crosses the mesh at finger speed: at 1000 m a unit, 162 s (found by this suite)",
);
/// `cache`: the calibration cache folder, or `none`.
const CACHE: Text = Text::new(
    "cache",
    "",
    "calibration cache folder (relative to the output folder); empty: the user's cache folder; \"none\": no cache",
);

/// Default calibration speeds, m/s (3–7 cm/s is the study's range; slower and faster included).
pub const DEFAULT_SPEEDS: [f64; 3] = [0.02, 0.05, 0.1];

/// One mesh's gradient state: the mesh, its ray caster, estimator and
/// calibrated range.
pub struct MeshGradient {
    /// The mesh and its placement.
    pub placed: Placed,
    /// The ray caster (BVH), shared with the other holders of the mesh.
    pub rc: Arc<RayCaster>,
    /// The estimator.
    pub est: Gradient,
    /// The F^sq range.
    pub range: Range,
    /// Intensity at F_min and at F_max.
    pub i_hi: f64,
    /// Intensity at F_max.
    pub i_lo: f64,
    cache: CacheStatus,
    /// Ticks on the mesh and off it.
    hits: u64,
    misses: u64,
}

/// Builds one mesh's state from the node's parameters.
pub fn build_state(p: &Params, ctx: &BuildContext, placed: Placed) -> Result<MeshGradient, NodeError> {
    let rc = shared::ray_caster(&placed.mesh);
    let unit = placed.unit;
    let gs = GradientSettings {
        mode: SLOPE.get(p),
        min_step: MIN_STEP.get(p) / unit,
        max_step: MAX_STEP.get(p) / unit,
        normal_force: NORMAL_FORCE.get(p),
        floor: placed.floor,
    };
    if gs.max_step < gs.min_step {
        return Err(NodeError::param(MAX_STEP.name(), "must not be smaller than min_step"));
    }
    let (range, cache) = if RANGE.get(p) == RangeMode::Fixed {
        let (f_min, f_max) = (F_MIN.get(p), F_MAX.get(p));
        if f_min > f_max {
            return Err(NodeError::param(F_MIN.name(), format!("{f_min} exceeds f_max = {f_max}")));
        }
        (
            Range { f_min, f_max, mean: 0.5 * (f_min + f_max), std: 0.25 * (f_max - f_min), samples: 0 },
            CacheStatus::Disabled,
        )
    } else {
        let speeds = CALIB_SPEEDS.get(p);
        let speeds = if speeds.is_empty() { DEFAULT_SPEEDS.to_vec() } else { speeds.to_vec() };
        let ss = ScanSettings {
            speeds: speeds.iter().map(|v| v / unit).collect(),
            rate: ctx.rate,
            directions: CALIB_DIRECTIONS.count(p),
            lines: CALIB_LINES.count(p),
        };
        let dir = match CACHE.get(p) {
            "none" => None,
            "" => user_cache_dir(),
            d => Some(ctx.out_path(d)),
        };
        calibrate(&placed.mesh, &rc, gs, &ss, dir.as_deref())
    };
    Ok(MeshGradient {
        placed,
        rc,
        est: Gradient::new(gs),
        range,
        i_hi: I_MAX.get(p),
        i_lo: I_MIN.get(p),
        cache,
        hits: 0,
        misses: 0,
    })
}

/// The user's cache folder for evflow: `$EVFLOW_CACHE`, else
/// `$XDG_CACHE_HOME/evflow`, else `$HOME/.cache/evflow`.
pub fn user_cache_dir() -> Option<std::path::PathBuf> {
    let var = |k: &str| std::env::var_os(k).filter(|v| !v.is_empty()).map(std::path::PathBuf::from);
    var("EVFLOW_CACHE")
        .or_else(|| var("XDG_CACHE_HOME").map(|d| d.join("evflow")))
        .or_else(|| var("HOME").map(|d| d.join(".cache").join("evflow")))
}

/// The node: the meshes it can switch between and the crossfade of a switch.
struct GradientNode {
    scenes: Vec<MeshGradient>,
    current: usize,
    initial: usize,
    /// (scene faded out, samples of the fade done).
    fade: Option<(usize, usize)>,
    fade_len: usize,
    /// Build notes: where each mesh lands ([`placement_note`]).
    notes: Vec<String>,
    /// Ticks on the mesh felt and off it (the `tri` output ≥ 0 or −1).
    on: u64,
    off: u64,
}

fn build(p: &Params, ctx: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
    let scenes = source::load_scenes(p, ctx)?
        .into_iter()
        .map(|placed| build_state(p, ctx, placed))
        .collect::<Result<Vec<_>, _>>()?;
    let notes = scenes
        .iter()
        .flat_map(|s| std::iter::once(placement_note(&s.placed, p)).chain(s.placed.warnings.iter().cloned()))
        .collect();
    let initial = source::SCENE.count(p);
    let fade_len = (SWITCH_FADE.get(p) * 1e-3 * ctx.rate).round() as usize;
    Ok(Box::new(GradientNode { scenes, current: initial, initial, fade: None, fade_len, notes, on: 0, off: 0 }))
}

/// What `evflow check` says about a loaded mesh (the build note of
/// every node that loads one): its size, its bounds in its own units after
/// `up` was turned to height, the axis taken as up and why, the scale, and
/// where it lands on the screen in metres.
pub fn placement_note(placed: &Placed, p: &Params) -> String {
    let b = placed.mesh.bounds();
    let up = format!("{} ({})", placed.up.word(), if source::UP.get(p).is_none() { "auto" } else { "set" });
    let how = if source::FIT.get(p) == Fit::Footprint { "fit = footprint" } else { "unit" };
    let (u, o) = (placed.unit, placed.offset);
    let g = |x: f64| format!("{:.4}", x + 0.0);
    format!(
        "{}: {} triangles; bounds x {} … {}, y {} … {}, z {} … {} (mesh units, up turned to z); up {up}; \
         scale {} m per unit ({how}); on the screen x {} … {} m, y {} … {} m, heights {} … {} m",
        placed.name,
        placed.mesh.triangles.len(),
        g(b.min[0]),
        g(b.max[0]),
        g(b.min[1]),
        g(b.max[1]),
        g(b.min[2]),
        g(b.max[2]),
        u,
        g(o[0] + b.min[0] * u),
        g(o[0] + b.max[0] * u),
        g(o[1] + b.min[1] * u),
        g(o[1] + b.max[1] * u),
        g((b.min[2] - placed.z0) * u),
        g((b.max[2] - placed.z0) * u),
    )
}

/// One tick's outputs: intensity, F^sq, slope, z (m), triangle (−1: none).
pub type TickOut = [f64; 5];

impl MeshGradient {
    /// One tick at the touch point (m).
    #[inline]
    pub fn tick(&mut self, x: f64, y: f64) -> TickOut {
        let (mx, my) = self.placed.to_mesh(x, y);
        let e = self.est.step(&self.placed.mesh, &self.rc, mx, my);
        match e.hit {
            Some(_) => self.hits += 1,
            None => self.misses += 1,
        }
        let i = intensity(e.fsq, self.range.f_min, self.range.f_max, self.i_hi, self.i_lo);
        let z = (e.z - self.placed.z0) * self.placed.unit;
        [i, e.fsq, e.slope, if z.is_finite() { z } else { 0.0 }, e.hit.map_or(-1.0, |h| h.tri as f64)]
    }
}

impl MeshGradient {
    fn summary(&self, s: Summary, prefix: &str) -> Summary {
        let on = self.hits as f64 / (self.hits + self.misses).max(1) as f64;
        let s = if prefix.is_empty() {
            s.value("f_min", self.range.f_min, "sqrt(N)").value("f_max", self.range.f_max, "sqrt(N)").value(
                "triangles",
                self.placed.mesh.triangles.len() as f64,
                "1",
            )
        } else {
            s.line(format!(
                "{prefix}{}: F^sq range [{:.4}, {:.4}] √N, {} triangles, on the mesh {:.3} of its ticks",
                self.placed.name,
                self.range.f_min,
                self.range.f_max,
                self.placed.mesh.triangles.len(),
                on
            ))
        };
        let s = self.placed.warnings.iter().fold(s, |s, w| s.line(format!("{prefix}{w}")));
        match &self.cache {
            CacheStatus::Hit(p) => s.line(format!("{prefix}F^sq range from the cache {}", p.display())),
            CacheStatus::Written(p) => s.line(format!("{prefix}F^sq range calibrated, cached in {}", p.display())),
            CacheStatus::Failed(e) => s.line(format!("{prefix}F^sq range calibrated; not cached: {e}")),
            CacheStatus::Disabled => s,
        }
    }
}

impl Node for GradientNode {
    fn process(&mut self, io: &mut Io<'_>) -> Result<(), NodeError> {
        for i in 0..io.len() {
            let (x, y) = (io.input(X)[i], io.input(Y)[i]);
            let mut out = self.scenes[self.current].tick(x, y);
            if let Some((from, done)) = self.fade {
                // The old mesh keeps being felt, fading out, while the new one fades in.
                let old = self.scenes[from].tick(x, y);
                let w = (done + 1) as f64 / (self.fade_len + 1) as f64;
                out[0] = (1.0 - w) * old[0] + w * out[0];
                self.fade = (done + 1 < self.fade_len).then_some((from, done + 1));
            }
            if out[4] >= 0.0 {
                self.on += 1;
            } else {
                self.off += 1;
            }
            for (port, v) in TICK_PORTS.into_iter().zip(out) {
                io.output(port)[i] = v;
            }
        }
        Ok(())
    }

    fn reset(&mut self) {
        for s in &mut self.scenes {
            s.est.reset();
            s.hits = 0;
            s.misses = 0;
        }
        self.current = self.initial;
        self.fade = None;
        self.on = 0;
        self.off = 0;
    }

    fn finish(&mut self) -> Result<Summary, NodeError> {
        let s = self.scene_summary();
        Ok(off_mesh_warning(s, self.on, self.off))
    }

    fn notes(&self) -> Vec<String> {
        self.notes.clone()
    }

    fn set(&mut self, c: Change) -> Result<(), Refused> {
        match source::SCENE.changed(&c) {
            Some(next) if next < self.scenes.len() => {
                if next != self.current {
                    // The estimate continues on the new mesh from where the finger is.
                    let from = self.scenes[self.current].est;
                    let sc = &mut self.scenes[next];
                    sc.est.rebase(&from, &sc.placed.mesh, &sc.rc);
                    // Mid-fade, fade from whichever mesh dominates the output now.
                    let from = match self.fade {
                        Some((f, done)) if 2 * (done + 1) < self.fade_len + 1 => f,
                        _ => self.current,
                    };
                    self.fade = (self.fade_len > 0 && from != next).then_some((from, 0));
                    self.current = next;
                }
                Ok(())
            }
            _ => Err(c.refused()),
        }
    }
}

/// The unit of `on_mesh` and `off_mesh`, printed after them.
const SHARE_OF_TICKS: &str = "of the ticks (a share)";

/// The fractions of the session's ticks the finger was on and off the mesh
/// felt (whichever scene that was), as the values `on_mesh` and
/// `off_mesh`, and a warning line when it was off for most of them (more
/// than half): the mesh is probably not where the finger goes.
fn off_mesh_warning(s: Summary, on: u64, off: u64) -> Summary {
    let total = on + off;
    if total == 0 {
        return s;
    }
    let fraction = off as f64 / total as f64;
    // Shares, not counts: say of what.
    let s = s.value("on_mesh", on as f64 / total as f64, SHARE_OF_TICKS).value("off_mesh", fraction, SHARE_OF_TICKS);
    if 2 * off <= total {
        return s;
    }
    s.line(format!(
        "warning: the finger was off the mesh on {:.1} % of the ticks ({off} of {total}); check where the mesh \
         lies (offset_x/y, unit or fit; `evflow check` prints its place on the screen)",
        100.0 * fraction
    ))
}

impl GradientNode {
    /// The meshes' figures: the starting one's as values, and with several
    /// scenes every scene's as a line.
    fn scene_summary(&self) -> Summary {
        let first = &self.scenes[self.initial];
        if self.scenes.len() == 1 {
            return first.summary(Summary::default(), "");
        }
        // The starting scene's figures as values, every scene's as a line
        // (the session's on/off the mesh: `off_mesh_warning`).
        let mut s = Summary::default()
            .value("f_min", first.range.f_min, "sqrt(N)")
            .value("f_max", first.range.f_max, "sqrt(N)")
            .value("triangles", first.placed.mesh.triangles.len() as f64, "1");
        for (k, sc) in self.scenes.iter().enumerate() {
            s = sc.summary(s, &format!("scene {k}: "));
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::SPEC;
    use evflow_engine::harness::Single;
    use evflow_engine::Summary;

    /// `on` ticks on a 1 cm plate, then `off` ticks beside it.
    fn summary(dir: &std::path::Path, on: usize, off: usize) -> Summary {
        summary_with(dir, on, off, "file = \"plate.obj\"")
    }

    /// [`summary`] with the mesh chosen by `mesh` (`file = …` or `scenes = […]`).
    fn summary_with(dir: &std::path::Path, on: usize, off: usize, mesh: &str) -> Summary {
        let n = on + off;
        let x: Vec<f64> = (0..n).map(|i| if i < on { 0.002 + 0.001 * i as f64 % 0.006 } else { 0.05 }).collect();
        Single::new(&SPEC, &format!("{mesh}\nup = \"+z\"\nrange = \"fixed\""))
            .input("x", x, 1000.0)
            .input("y", vec![0.005; n], 1000.0)
            .output("tri")
            .ticks(n as u64)
            .block(4)
            .base_dir(dir)
            .summary()
            .unwrap()
    }

    #[test]
    fn a_finger_off_the_mesh_for_most_ticks_is_reported_with_the_exact_fraction() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("plate.obj"), "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n").unwrap();
        let s = summary(dir.path(), 3, 7);
        assert_eq!(s.get("off_mesh"), Some(0.7));
        let warning: Vec<&String> = s.lines.iter().filter(|l| l.starts_with("warning:")).collect();
        assert_eq!(warning.len(), 1, "{:?}", s.lines);
        assert!(warning[0].starts_with("warning: the finger was off the mesh on 70.0 % of the ticks (7 of 10)"));
        // Off for exactly half the ticks is not most of them: no warning.
        let s = summary(dir.path(), 500, 500);
        assert_eq!(s.get("off_mesh"), Some(0.5));
        assert!(!s.lines.iter().any(|l| l.starts_with("warning:")), "{:?}", s.lines);
        // 1 tick on, 2 off: 66.7 %.
        let s = summary(dir.path(), 1, 2);
        assert!(s.lines.iter().any(|l| l.contains("66.7 % of the ticks (2 of 3)")), "{:?}", s.lines);
    }

    #[test]
    fn on_and_off_the_mesh_are_the_session_s_figures_with_several_scenes() {
        // Before: `on_mesh` was scene 0's own figure beside the session's
        // `off_mesh` (issue 27, point 9).
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("plate.obj"), "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n").unwrap();
        for mesh in ["file = \"plate.obj\"", "scenes = [\"plate.obj\", \"plate.obj\"]"] {
            let s = summary_with(dir.path(), 3, 7, mesh);
            assert_eq!((s.get("on_mesh"), s.get("off_mesh")), (Some(0.3), Some(0.7)), "{mesh}");
            assert!(s.values.iter().all(|(k, _, u)| !k.ends_with("_mesh") || u == super::SHARE_OF_TICKS), "{mesh}");
        }
    }
}
