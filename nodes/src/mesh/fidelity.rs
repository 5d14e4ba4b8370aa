//! Fidelity of the mesh chain, measured against ground truth (the report
//! behind `evflow report mesh` and `docs/mesh.md`):
//!
//! * **Gradient against resolution.** The Gaussian scene of §4.2 is
//!   tessellated from coarse to fine; scan lines in several directions are
//!   rendered tick by tick (1 kHz, a given speed) and each tick's F^sq is
//!   compared with the analytic F^sq of the smooth surface at the finger,
//!   sgn(−∇z·d)·√|∇z·d| (RMS error, also of the slope itself), next to the
//!   build time and the run time per tick: error against run time.
//! * **Edges against dihedral ground truth.** A mesh with sharp edges is
//!   scanned; for every tick where the hit triangle changes, the path since
//!   the previous tick is re-cast at 64 sub-steps to find the mesh edges it
//!   crossed (consecutive sub-step triangles sharing an edge), and the true
//!   bend is the sum of their convex turns, 180° − Σ(180° − θ_i), with each
//!   θ_i computed from the file's winding (outward normals of a
//!   consistently oriented file) — independently of the tracker. Ticks
//!   whose bend is sharper than a threshold are the truth; the tracker's
//!   events are the detections. A tick whose sub-steps still skip a
//!   triangle, or that leaves the mesh, is unresolved.

use super::edges::{census, EdgeTracker};
use super::gradient::{signed_sqrt, Gradient, GradientSettings, SlopeMode};
use super::raycast::RayCaster;
use super::scenes::{gaussian_height, layout, scene, Shape};
use super::trimesh::{dot, raw_normal, sub, Mesh};
use std::collections::HashMap;
use std::time::Instant;

/// One scan setting of the fidelity runs (mesh units: cm).
#[derive(Debug, Clone, PartialEq)]
pub struct ScanPlan {
    /// Scan directions, degrees.
    pub directions: Vec<f64>,
    /// Offsets of the parallel lines from the scene centre, cm.
    pub offsets: Vec<f64>,
    /// Line length, cm.
    pub length: f64,
    /// Finger speed, cm/s.
    pub speed: f64,
    /// Tick rate, Hz.
    pub rate: f64,
    /// The estimator's min_step, cm.
    pub min_step: f64,
}

impl ScanPlan {
    /// The report's default: 5 directions, lines through the object
    /// centres and between them, 5 cm/s at 1 kHz, min_step 0.5 mm.
    pub fn standard() -> Self {
        ScanPlan {
            directions: vec![0.0, 30.0, 60.0, 90.0, 135.0],
            offsets: vec![-3.0, -1.5, 0.0, 1.5, 3.0],
            length: 11.0,
            speed: 5.0,
            rate: 1000.0,
            min_step: 0.05,
        }
    }

    /// Every touch point of every line, with the line's unit direction;
    /// a `None` separates lines.
    fn points(&self) -> Vec<Option<([f64; 2], [f64; 2])>> {
        let step = self.speed / self.rate;
        let n = (self.length / step).floor() as usize;
        let mut v = Vec::new();
        for deg in &self.directions {
            let a = deg.to_radians();
            let (d, q) = ([a.cos(), a.sin()], [-a.sin(), a.cos()]);
            for o in &self.offsets {
                v.push(None);
                for i in 0..=n {
                    let s = -0.5 * self.length + i as f64 * step;
                    v.push(Some(([o * q[0] + s * d[0], o * q[1] + s * d[1]], d)));
                }
            }
        }
        v
    }
}

/// One row of the gradient table.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GradientRow {
    /// Grid cells per 6 cm object side.
    pub resolution: usize,
    /// Triangles.
    pub triangles: usize,
    /// BVH build time, ms.
    pub build_ms: f64,
    /// Ray cast + estimate per tick, secant slope, µs.
    pub tick_us_secant: f64,
    /// Ray cast + estimate per tick, normal slope, µs.
    pub tick_us_normal: f64,
    /// RMS error of F^sq, secant slope, √N.
    pub rms_fsq_secant: f64,
    /// RMS error of F^sq, normal slope, √N.
    pub rms_fsq_normal: f64,
    /// RMS error of tan α, secant.
    pub rms_slope_secant: f64,
    /// RMS error of tan α, normal.
    pub rms_slope_normal: f64,
    /// Ticks compared per mode.
    pub ticks: u64,
}

/// Renders the Gaussian scene `config` at each resolution along `plan`'s
/// lines and compares with the analytic surface.
pub fn gradient_fidelity(config: &str, resolutions: &[usize], plan: &ScanPlan) -> Vec<GradientRow> {
    let l = layout(Shape::Gaussian, config).expect("a valid configuration");
    let pts = plan.points();
    let mut rows = Vec::new();
    for &res in resolutions {
        let Ok(mesh) = scene(Shape::Gaussian, config, res) else { continue };
        let t0 = Instant::now();
        let rc = RayCaster::new(&mesh);
        let build_ms = t0.elapsed().as_secs_f64() * 1e3;
        let mut errs = [[0.0f64; 2]; 2];
        let mut ticks = 0u64;
        let mut tick_s = [0.0; 2];
        for (m, mode) in [SlopeMode::Secant, SlopeMode::Normal].into_iter().enumerate() {
            let gs = GradientSettings { mode, min_step: plan.min_step, max_step: 1.0, normal_force: 1.0, floor: 0.0 };
            let mut g = Gradient::new(gs);
            let mut started = false;
            let mut n = 0u64;
            let t0 = Instant::now();
            for p in &pts {
                let Some((xy, d)) = p else {
                    g.reset();
                    started = false;
                    continue;
                };
                let e = g.step(&mesh, &rc, xy[0], xy[1]);
                started |= e.fresh;
                if !started {
                    continue;
                }
                let (_, zx, zy) = gaussian_height(&l, xy[0], xy[1]);
                let slope = zx * d[0] + zy * d[1];
                let (ds, df) = (e.slope - slope, e.fsq - signed_sqrt(-slope));
                errs[m][0] += ds * ds;
                errs[m][1] += df * df;
                n += 1;
            }
            tick_s[m] = t0.elapsed().as_secs_f64() / pts.len().max(1) as f64;
            ticks = n;
        }
        let rms = |s: f64| (s / ticks.max(1) as f64).sqrt();
        rows.push(GradientRow {
            resolution: res,
            triangles: mesh.triangles.len(),
            build_ms,
            tick_us_secant: tick_s[0] * 1e6,
            tick_us_normal: tick_s[1] * 1e6,
            rms_fsq_secant: rms(errs[0][1]),
            rms_fsq_normal: rms(errs[1][1]),
            rms_slope_secant: rms(errs[0][0]),
            rms_slope_normal: rms(errs[1][0]),
            ticks,
        });
    }
    rows
}

/// One line of the Gaussian scene rendered at `resolution`: per tick the
/// position along the line (cm), the analytic F^sq, and the rendered F^sq
/// with the secant and the normal slope.
pub fn line_trace(config: &str, resolution: usize, deg: f64, offset: f64, plan: &ScanPlan) -> Vec<[f64; 4]> {
    let l = layout(Shape::Gaussian, config).expect("a valid configuration");
    let Ok(mesh) = scene(Shape::Gaussian, config, resolution) else { return Vec::new() };
    let rc = RayCaster::new(&mesh);
    let one = ScanPlan { directions: vec![deg], offsets: vec![offset], ..plan.clone() };
    let gs = |mode| GradientSettings { mode, min_step: plan.min_step, max_step: 1.0, normal_force: 1.0, floor: 0.0 };
    let (mut a, mut b) = (Gradient::new(gs(SlopeMode::Secant)), Gradient::new(gs(SlopeMode::Normal)));
    let mut out = Vec::new();
    for (i, (xy, d)) in one.points().into_iter().flatten().enumerate() {
        let (_, zx, zy) = gaussian_height(&l, xy[0], xy[1]);
        let s = -0.5 * plan.length + i as f64 * plan.speed / plan.rate;
        let fs = a.step(&mesh, &rc, xy[0], xy[1]).fsq;
        let fn_ = b.step(&mesh, &rc, xy[0], xy[1]).fsq;
        out.push([s, signed_sqrt(-(zx * d[0] + zy * d[1])), fs, fn_]);
    }
    out
}

/// Edge detection against dihedral ground truth.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct EdgeFidelity {
    /// Ticks changing triangle whose crossed edges were all found.
    pub resolved_crossings: u64,
    /// Resolved ticks that crossed more than one edge.
    pub multi_edge_crossings: u64,
    /// Ticks changing triangle that could not be resolved into edges.
    pub unresolved_crossings: u64,
    /// Resolved ticks whose true bend is sharper than the threshold.
    pub sharp_truth: u64,
    /// Sharp truth detected with θ below the threshold.
    pub true_positives: u64,
    /// Detections on resolved ticks whose true bend is not that sharp.
    pub false_positives: u64,
    /// Sharp truth not detected.
    pub false_negatives: u64,
    /// Detections on unresolved ticks.
    pub unverified_detections: u64,
    /// RMS of θ_detected − θ_true over true positives, degrees.
    pub theta_rms_error: f64,
    /// Largest |θ_detected − θ_true| over true positives, degrees.
    pub theta_max_error: f64,
    /// Interior edges whose two triangles run them in opposite directions
    /// (a consistently oriented mesh has all of them).
    pub oriented_fraction: f64,
    /// θ_min of the mesh (census).
    pub theta_min: f64,
}

/// The true dihedral angle of every interior manifold edge, from the
/// file's winding (outward normals): 180° − ∠ when convex, 180° + ∠ when
/// concave; keyed by the sorted vertex pair. Also the oriented fraction.
pub fn true_dihedrals(m: &Mesh) -> (HashMap<(u32, u32), f64>, f64) {
    let mut faces: HashMap<(u32, u32), Vec<(u32, bool)>> = HashMap::new();
    for (t, tri) in m.triangles.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            faces.entry((a.min(b), a.max(b))).or_default().push((t as u32, a < b));
        }
    }
    let mut out = HashMap::new();
    let (mut interior, mut oriented) = (0u64, 0u64);
    for (&(v0, v1), f) in &faces {
        if f.len() != 2 {
            continue;
        }
        interior += 1;
        if f[0].1 != f[1].1 {
            oriented += 1;
        }
        let (a, b) = (f[0].0 as usize, f[1].0 as usize);
        let [p, q, r] = m.corners(a);
        let na = raw_normal(p, q, r);
        let [p2, q2, r2] = m.corners(b);
        let nb = raw_normal(p2, q2, r2);
        let ob = m.triangles[b].into_iter().find(|&k| k != v0 && k != v1).unwrap_or(v0);
        let phi = dot(na, nb).clamp(-1.0, 1.0).acos().to_degrees();
        let behind = dot(na, sub(m.vertices[ob as usize], m.vertices[v0 as usize])) < 0.0;
        out.insert((v0, v1), if behind { 180.0 - phi } else { 180.0 + phi });
    }
    (out, oriented as f64 / interior.max(1) as f64)
}

/// The edge shared by two triangles, if any.
fn shared_edge(m: &Mesh, a: u32, b: u32) -> Option<(u32, u32)> {
    let (ta, tb) = (m.triangles[a as usize], m.triangles[b as usize]);
    let common: Vec<u32> = ta.into_iter().filter(|v| tb.contains(v)).collect();
    (common.len() == 2).then(|| (common[0].min(common[1]), common[0].max(common[1])))
}

/// Scans `mesh` along `plan`'s lines (around the mesh's centre) with the
/// edge tracker and scores its detections sharper than `sharp` degrees
/// against the true dihedral angles.
pub fn edge_fidelity(mesh: &Mesh, floor: f64, plan: &ScanPlan, sharp: f64, max_angle: f64) -> EdgeFidelity {
    let rc = RayCaster::new(mesh);
    let c = census(mesh, floor, max_angle);
    let (truth, oriented) = true_dihedrals(mesh);
    let centre = rc.bounds.center();
    let mut tr = EdgeTracker::new(c.theta_min, max_angle, 1.0, floor);
    let mut f = EdgeFidelity { oriented_fraction: oriented, theta_min: c.theta_min, ..Default::default() };
    let mut prev: Option<([f64; 2], Option<u32>)> = None;
    let mut sq = 0.0;
    let mut seq = Vec::with_capacity(64);
    for p in plan.points() {
        let Some((xy, _)) = p else {
            tr.reset();
            prev = None;
            continue;
        };
        let (x, y) = (xy[0] + centre[0], xy[1] + centre[1]);
        let hit = rc.cast(x, y);
        let (pt, tri) = tr.locate(mesh, x, y, hit.map(|h| h.tri));
        let e = tr.step(mesh, pt, tri);
        let detected = e.intensity > 0.0 && e.theta < sharp;
        let last = prev.replace(([x, y], tri));
        let Some((q, qt)) = last else { continue };
        if qt == tri {
            continue;
        }
        // The edges crossed since the previous tick, from sub-step ray casts.
        seq.clear();
        seq.push(qt);
        for k in 1..=64 {
            let s = k as f64 / 64.0;
            let t = rc.cast(q[0] + s * (x - q[0]), q[1] + s * (y - q[1])).map(|h| h.tri);
            if seq.last() != Some(&t) {
                seq.push(t);
            }
        }
        let mut bend = 0.0;
        let mut resolved = true;
        for w in seq.windows(2) {
            match (w[0], w[1]) {
                (Some(a), Some(b)) => match shared_edge(mesh, a, b).and_then(|k| truth.get(&k)) {
                    Some(&t) => bend += (180.0 - t).max(0.0),
                    None => resolved = false,
                },
                _ => resolved = false,
            }
        }
        if !resolved {
            f.unresolved_crossings += 1;
            f.unverified_detections += detected as u64;
            continue;
        }
        f.resolved_crossings += 1;
        f.multi_edge_crossings += (seq.len() > 2) as u64;
        let t = (180.0 - bend).max(0.0);
        let is_sharp = t < sharp;
        f.sharp_truth += is_sharp as u64;
        match (is_sharp, detected) {
            (true, true) => {
                f.true_positives += 1;
                let err = e.theta - t;
                sq += err * err;
                f.theta_max_error = f.theta_max_error.max(err.abs());
            }
            (true, false) => f.false_negatives += 1,
            (false, true) => f.false_positives += 1,
            (false, false) => {}
        }
    }
    f.theta_rms_error = (sq / f.true_positives.max(1) as f64).sqrt();
    f
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quick() -> ScanPlan {
        ScanPlan { directions: vec![0.0, 60.0, 90.0], offsets: vec![-3.0, 0.0, 3.0], ..ScanPlan::standard() }
    }

    #[test]
    fn gradient_error_falls_with_resolution_and_is_small_when_fine() {
        let rows = gradient_fidelity("2B2H", &[4, 16, 64], &quick());
        assert_eq!(rows.len(), 3);
        for r in &rows {
            assert!(r.ticks > 5000 && r.rms_fsq_secant.is_finite() && r.rms_fsq_normal.is_finite());
        }
        // The normal slope converges with the facet size; the secant to the
        // error of its 0.5 mm chord.
        assert!(rows[2].rms_slope_normal < 0.5 * rows[0].rms_slope_normal, "{rows:?}");
        assert!(rows[2].rms_slope_secant < rows[0].rms_slope_secant, "{rows:?}");
        assert!(rows[2].rms_slope_normal < 0.05 && rows[2].rms_slope_secant < 0.05, "{rows:?}");
        assert!(rows[2].triangles == 2 * 128 * 128);
        // Along one line through a bump's centre the rendered F^sq follows the analytic one.
        let t = line_trace("4B0H", 64, 0.0, 3.0, &quick());
        assert!(t.len() > 2000);
        let err = (t[100..].iter().map(|r| (r[3] - r[1]).powi(2)).sum::<f64>() / (t.len() - 100) as f64).sqrt();
        assert!(err < 0.1, "{err}");
    }

    #[test]
    fn frustum_edges_are_found_at_their_true_angles() {
        // The frustum scene is oriented consistently (outward = up for the
        // ground and bumps' outsides); its sharp edges are the bump's hips
        // (101.5°), its top rim (116.6°) and the holes' rims (116.6°).
        let m = scene(Shape::Frustum, "2B2H", 0).unwrap();
        let f = edge_fidelity(&m, 0.0, &quick(), 135.0, 160.0);
        assert_eq!(f.oriented_fraction, 1.0);
        assert!(f.sharp_truth >= 8, "{f:?}");
        assert_eq!(f.false_negatives, 0, "{f:?}");
        assert_eq!(f.false_positives, 0, "{f:?}");
        assert!(f.theta_max_error < 1e-6, "{f:?}");
    }
}
