//! F_min and F_max (dissertation §4.1.1): the mesh is scanned in simulation
//! with the same estimator the node runs — straight lines across its
//! bounds in several directions, at several speeds, sampled at the node's
//! rate — and (F_min, F_max) = (μ − 2σ, μ + 2σ) of the F^sq values. Ticks
//! where neither the current nor the previous point is on the mesh are
//! left out (they would count the empty screen as flat surface).
//!
//! At a speed v and rate f_s the finger moves δ = v/f_s per tick; the
//! estimator's anchor then advances every k = ⌈min_step/δ⌉ ticks and holds
//! its value in between, so each scan line is simulated at the spacing k·δ
//! with one sample per anchor step (the held copies have equal weight and
//! change neither μ nor σ).
//!
//! The result is cached per mesh, keyed by a hash of the welded mesh and
//! every setting that affects it, as a small JSON file written atomically
//! (temporary file + rename), so a live session starts at once.

use super::error::MeshError;
use super::gradient::{Gradient, GradientSettings, SlopeMode};
use super::raycast::RayCaster;
use super::trimesh::{Fnv, Mesh};
use std::path::{Path, PathBuf};

/// How the mesh is scanned.
#[derive(Debug, Clone, PartialEq)]
pub struct ScanSettings {
    /// Finger speeds, mesh units per second.
    pub speeds: Vec<f64>,
    /// Tick rate, Hz.
    pub rate: f64,
    /// Directions, evenly spaced over 360°.
    pub directions: usize,
    /// Parallel lines per direction across the mesh's bounds.
    pub lines: usize,
}

/// The calibrated range and the statistics behind it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Range {
    /// μ − 2σ of F^sq, √N.
    pub f_min: f64,
    /// μ + 2σ of F^sq, √N.
    pub f_max: f64,
    /// μ.
    pub mean: f64,
    /// σ (population).
    pub std: f64,
    /// Number of F^sq values.
    pub samples: u64,
}

/// Whether the range came from the cache.
#[derive(Debug, Clone, PartialEq)]
pub enum CacheStatus {
    /// No cache folder given.
    Disabled,
    /// Read from this file.
    Hit(PathBuf),
    /// Computed and written to this file.
    Written(PathBuf),
    /// Computed; the cache could not be written (the error).
    Failed(String),
}

/// Scans the mesh and returns the range.
pub fn scan(mesh: &Mesh, rc: &RayCaster, gs: GradientSettings, ss: &ScanSettings) -> Range {
    let b = rc.bounds;
    let c = b.center();
    let radius = 0.5 * (b.max[0] - b.min[0]).hypot(b.max[1] - b.min[1]) * 1.05 + gs.min_step;
    let (mut n, mut mean, mut m2) = (0u64, 0.0f64, 0.0f64);
    for &v in &ss.speeds {
        let delta = v / ss.rate;
        if delta.is_nan() || delta <= 0.0 || delta > gs.max_step {
            continue;
        }
        let h = if delta >= gs.min_step { delta } else { delta * (gs.min_step / delta).ceil() } * (1.0 + 1e-9);
        let count = ((2.0 * radius) / h).floor() as usize;
        for k in 0..ss.directions.max(1) {
            let a = std::f64::consts::TAU * k as f64 / ss.directions.max(1) as f64;
            let (d, q) = ([a.cos(), a.sin()], [-a.sin(), a.cos()]);
            for j in 0..ss.lines.max(1) {
                let o = -radius + (j as f64 + 0.5) * 2.0 * radius / ss.lines.max(1) as f64;
                let mut g = Gradient::new(gs);
                let mut prev_on = false;
                for i in 0..=count {
                    let s = -radius + i as f64 * h;
                    let (x, y) = (c[0] + o * q[0] + s * d[0], c[1] + o * q[1] + s * d[1]);
                    let e = g.step(mesh, rc, x, y);
                    let on = e.hit.is_some();
                    let counted = match gs.mode {
                        SlopeMode::Secant => on || prev_on,
                        SlopeMode::Normal => on,
                    };
                    if e.fresh && counted {
                        n += 1;
                        let dlt = e.fsq - mean;
                        mean += dlt / n as f64;
                        m2 += dlt * (e.fsq - mean);
                    }
                    prev_on = on;
                }
            }
        }
    }
    let std = if n > 0 { (m2 / n as f64).max(0.0).sqrt() } else { 0.0 };
    Range { f_min: mean - 2.0 * std, f_max: mean + 2.0 * std, mean, std, samples: n }
}

/// Version of the cache file and of the scan; bump when either changes.
const CACHE_VERSION: u64 = 1;

/// The cache key of a scan.
pub fn cache_key(mesh: &Mesh, gs: &GradientSettings, ss: &ScanSettings) -> u64 {
    let mut h = Fnv::new();
    h.u64(CACHE_VERSION);
    h.u64(mesh.content_hash());
    h.u64(match gs.mode {
        SlopeMode::Secant => 0,
        SlopeMode::Normal => 1,
    });
    for x in [gs.min_step, gs.max_step, gs.normal_force, gs.floor, ss.rate] {
        h.u64(x.to_bits());
    }
    h.u64(ss.directions as u64);
    h.u64(ss.lines as u64);
    h.u64(ss.speeds.len() as u64);
    for v in &ss.speeds {
        h.u64(v.to_bits());
    }
    h.finish()
}

/// The range, from `dir`'s cache when it holds this key, else scanned and
/// written there (unless `dir` is `None`).
pub fn calibrate(
    mesh: &Mesh,
    rc: &RayCaster,
    gs: GradientSettings,
    ss: &ScanSettings,
    dir: Option<&Path>,
) -> (Range, CacheStatus) {
    let Some(dir) = dir else {
        return (scan(mesh, rc, gs, ss), CacheStatus::Disabled);
    };
    let key = cache_key(mesh, &gs, ss);
    let path = dir.join(format!("mesh-range-{key:016x}.json"));
    if let Some(r) = read_cache(&path, key) {
        return (r, CacheStatus::Hit(path));
    }
    let r = scan(mesh, rc, gs, ss);
    match write_cache(&path, key, &r, mesh.triangles.len()) {
        Ok(()) => (r, CacheStatus::Written(path)),
        Err(e) => (r, CacheStatus::Failed(e.to_string())),
    }
}

fn read_cache(path: &Path, key: u64) -> Option<Range> {
    let text = evflow_engine::files::read_regular_to_string(path).ok()?;
    let v: serde_json::Value = serde_json::from_str(&text).ok()?;
    if v.get("version")?.as_u64()? != CACHE_VERSION || v.get("key")?.as_str()? != format!("{key:016x}") {
        return None;
    }
    // Exact values travel as the hex of their bits (decimal is for people).
    let f = |k: &str| {
        let bits = u64::from_str_radix(v.get("bits")?.get(k)?.as_str()?, 16).ok()?;
        Some(f64::from_bits(bits)).filter(|x| x.is_finite())
    };
    Some(Range {
        f_min: f("f_min")?,
        f_max: f("f_max")?,
        mean: f("mean")?,
        std: f("std")?,
        samples: v.get("samples")?.as_u64()?,
    })
}

fn write_cache(path: &Path, key: u64, r: &Range, triangles: usize) -> Result<(), MeshError> {
    let err = |e: std::io::Error| MeshError::Cache { path: path.into(), message: e.to_string() };
    if let Some(parent) = path.parent() {
        std::fs::create_dir_all(parent).map_err(err)?;
    }
    let body = serde_json::json!({
        "version": CACHE_VERSION,
        "key": format!("{key:016x}"),
        "what": "F^sq range of a mesh (dissertation §4.1.1): f_min = mean - 2 std, f_max = mean + 2 std",
        "triangles": triangles,
        "f_min": r.f_min, "f_max": r.f_max, "mean": r.mean, "std": r.std, "samples": r.samples,
        "bits": {
            "f_min": format!("{:016x}", r.f_min.to_bits()),
            "f_max": format!("{:016x}", r.f_max.to_bits()),
            "mean": format!("{:016x}", r.mean.to_bits()),
            "std": format!("{:016x}", r.std.to_bits()),
        },
    });
    evflow_engine::atomic_file::write_atomically(path, serde_json::to_string_pretty(&body).unwrap_or_default())
        .map_err(err)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::scenes::{grid, scene, Shape};

    fn gs(mode: SlopeMode) -> GradientSettings {
        GradientSettings { mode, min_step: 0.05, max_step: 1.0, normal_force: 1.0, floor: 0.0 }
    }

    fn ss() -> ScanSettings {
        ScanSettings { speeds: vec![2.0, 5.0, 10.0], rate: 1000.0, directions: 8, lines: 12 }
    }

    #[test]
    fn a_flat_mesh_has_an_empty_range() {
        let m = grid(4, 4, [0.0, 4.0], [0.0, 4.0], |_, _| 1.5);
        let rc = RayCaster::new(&m);
        let r = scan(&m, &rc, GradientSettings { floor: 1.5, ..gs(SlopeMode::Secant) }, &ss());
        assert!(r.samples > 1000);
        assert_eq!((r.f_min, r.f_max), (0.0, 0.0));
    }

    #[test]
    fn a_plane_scanned_in_all_directions_matches_its_analytic_distribution() {
        // z = a·x scanned along direction φ: F^sq = sgn(−a cos φ)·√|a cos φ|;
        // over directions evenly spread the mean is 0 and the variance is
        // the mean of |a cos φ| = 2a/π.
        let a = 0.4;
        let m = grid(8, 8, [-20.0, 20.0], [-20.0, 20.0], |x, _| a * x);
        let rc = RayCaster::new(&m);
        let s = ScanSettings { speeds: vec![5.0], rate: 1000.0, directions: 64, lines: 32 };
        for mode in [SlopeMode::Secant, SlopeMode::Normal] {
            // The floor is far below: only on-mesh samples matter for the normal mode;
            // for the secant the lines are clipped to the mesh by keeping them inside.
            let g = GradientSettings { floor: -1e3, min_step: 0.5, ..gs(mode) };
            let r = scan(&m, &rc, g, &s);
            let want_var = 2.0 * a / std::f64::consts::PI;
            if mode == SlopeMode::Normal {
                assert!(r.mean.abs() < 1e-9, "{mode:?} {r:?}");
                // Lines sample the square with direction-dependent counts: 5 %.
                assert!((r.std * r.std - want_var).abs() < 0.05 * want_var, "{mode:?} {r:?}");
            } else {
                // Secant samples at the mesh boundary see the cliff to the floor.
                assert!(r.std > 0.5, "{r:?}");
            }
        }
    }

    #[test]
    fn cache_round_trips_and_is_keyed_by_content() {
        let dir = tempfile::tempdir().unwrap();
        let m = scene(Shape::Gaussian, "bump", 8).unwrap();
        let rc = RayCaster::new(&m);
        let (r1, s1) = calibrate(&m, &rc, gs(SlopeMode::Secant), &ss(), Some(dir.path()));
        assert!(matches!(s1, CacheStatus::Written(_)));
        let (r2, s2) = calibrate(&m, &rc, gs(SlopeMode::Secant), &ss(), Some(dir.path()));
        assert!(matches!(s2, CacheStatus::Hit(_)));
        assert_eq!(r1, r2);
        assert!(r1.f_min < 0.0 && r1.f_max > 0.0 && r1.samples > 1000);
        // Another mesh or setting is another key.
        let m2 = scene(Shape::Gaussian, "hole", 8).unwrap();
        assert_ne!(cache_key(&m, &gs(SlopeMode::Secant), &ss()), cache_key(&m2, &gs(SlopeMode::Secant), &ss()));
        assert_ne!(cache_key(&m, &gs(SlopeMode::Secant), &ss()), cache_key(&m, &gs(SlopeMode::Normal), &ss()));
        // A corrupt cache file is recomputed, not trusted.
        let CacheStatus::Hit(p) = s2 else { unreachable!() };
        std::fs::write(&p, "{ not json").unwrap();
        let (r3, s3) = calibrate(&m, &rc, gs(SlopeMode::Secant), &ss(), Some(dir.path()));
        assert_eq!(r3, r1);
        assert!(matches!(s3, CacheStatus::Written(_)));
        // No temporary files are left behind.
        let names: Vec<_> = std::fs::read_dir(dir.path()).unwrap().map(|e| e.unwrap().file_name()).collect();
        assert_eq!(names.len(), 1, "{names:?}");
    }
}
