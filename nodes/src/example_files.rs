//! The files the node examples (`NodeSpec::example`) read, and the stiff
//! mesh of the stability suite, written into a folder: a force recording,
//! a 2 × 2 grid of actuation cells, small NARX and forward models (with the
//! families that read them), a mesh of slivers. The generic node tests
//! (`nodes/tests/every_node.rs`) and `evflow report stability` write them
//! through this one module.

use crate::recording::format::{Channel, RecordingMeta, RecordingWriter};
use std::path::Path;

/// Samples of each fixture recording (at 1 kHz).
pub const RECORDING_SAMPLES: usize = 5000;

/// Deterministic test input: a chirp plus pseudo-random noise.
pub fn signal(len: usize, salt: u64) -> Vec<f64> {
    let mut state = 0x9E37_79B9_7F4A_7C15u64 ^ salt;
    (0..len)
        .map(|i| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let noise = (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
            let t = i as f64 / 1000.0;
            0.5 * (2.0 * std::f64::consts::PI * (5.0 + 40.0 * t) * t).sin() + 0.3 * noise
        })
        .collect()
}

/// Writes a one-channel recording of `values` at `rate`.
pub fn write_recording(path: &Path, channel: &str, rate: f64, values: &[f64]) -> Result<(), String> {
    let meta = RecordingMeta::new(rate, vec![Channel::new(channel, "N")]);
    let mut w = RecordingWriter::create(path, meta).map_err(|e| e.to_string())?;
    for x in values {
        w.write_frame(&[*x]).map_err(|e| e.to_string())?;
    }
    w.finish().map_err(|e| e.to_string())?;
    Ok(())
}

/// Writes every fixture into `dir`.
pub fn write(dir: &Path) -> Result<(), String> {
    let mkdir = |p: &Path| std::fs::create_dir_all(p).map_err(|e| format!("{}: {e}", p.display()));
    mkdir(&dir.join("recordings/grid"))?;
    mkdir(&dir.join("models"))?;
    mkdir(&dir.join("meshes"))?;
    let felt: Vec<f64> = signal(RECORDING_SAMPLES, 99).iter().map(|x| 0.2 + 0.05 * x).collect();
    write_recording(&dir.join("recordings/felt.wav"), "force", 1000.0, &felt)?;
    // A 2 × 2 grid of actuation signals for `interp` (loads 60/110 g, velocities 3/7 cm/s).
    for (k, (load, velocity)) in [(60.0, 3.0), (60.0, 7.0), (110.0, 3.0), (110.0, 7.0)].into_iter().enumerate() {
        let mut meta = RecordingMeta::new(1000.0, vec![Channel::new("u", "1")]);
        meta.condition.load_g = Some(load);
        meta.condition.velocity_cm_s = Some(velocity);
        let path = dir.join(format!("recordings/grid/cell{k}.wav"));
        let mut w = RecordingWriter::create(&path, meta).map_err(|e| e.to_string())?;
        for x in signal(4000, 7 + k as u64) {
            w.write_frame(&[x]).map_err(|e| e.to_string())?;
        }
        w.finish().map_err(|e| e.to_string())?;
    }
    std::fs::write(dir.join("meshes/slivers.obj"), sliver_obj()).map_err(|e| e.to_string())?;
    #[cfg(feature = "narx")]
    narx_models(dir)?;
    #[cfg(feature = "synth")]
    forward_models(dir)?;
    Ok(())
}

/// An OBJ of slivers and near-degenerate triangles over a 4 × 4 cm square:
/// a fan of needles from one corner (each 1e-9 of a radian wide), a
/// triangle of area ~1e-24 m², a collinear (zero-area) triangle, two
/// triangles meeting at a knife edge 1e-12 cm high, vertices 1e-15 apart.
pub fn sliver_obj() -> String {
    let mut v: Vec<[f64; 3]> = Vec::new();
    let mut f: Vec<[usize; 3]> = Vec::new();
    // The base: two triangles over [0, 4]² at height 0.
    v.extend([[0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [4.0, 4.0, 0.0], [0.0, 4.0, 0.0]]);
    f.extend([[0, 1, 2], [0, 2, 3]]);
    // A fan of needles rising from (1, 1) towards x = 3: each triangle
    // spans 1e-9 in y at its far end.
    let c = v.len();
    v.push([1.0, 1.0, 0.5]);
    for k in 0..40 {
        let y = 1.0 + k as f64 * 1e-9;
        v.push([3.0, y, 0.5 + 1e-3 * k as f64]);
    }
    for k in 0..39 {
        f.push([c, c + 1 + k, c + 2 + k]);
    }
    // A near-zero-area triangle, a collinear one, a knife edge.
    let d = v.len();
    v.extend([
        [2.0, 3.0, 0.2],
        [2.0 + 1e-12, 3.0, 0.2],
        [2.0, 3.0 + 1e-12, 0.2 + 1e-15],
        [1.0, 2.0, 0.1],
        [2.0, 2.0, 0.1],
        [3.0, 2.0, 0.1],
        [0.5, 3.5, 0.3],
        [1.5, 3.5, 0.3 + 1e-12],
        [1.0, 3.6, 0.3],
        [1.0, 3.4, 0.3],
    ]);
    f.extend([[d, d + 1, d + 2], [d + 3, d + 4, d + 5], [d + 6, d + 7, d + 8], [d + 7, d + 6, d + 9]]);
    let mut s = String::from("# slivers and near-degenerate triangles (evflow report stability)\n");
    for p in &v {
        s += &format!("v {:?} {:?} {:?}\n", p[0], p[1], p[2]);
    }
    for t in &f {
        s += &format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    s
}

#[cfg(feature = "narx")]
fn narx_models(dir: &Path) -> Result<(), String> {
    use crate::narx::fit::{fit, FitConfig};
    let x = signal(2000, 7);
    let u: Vec<f64> = x.iter().map(|v| if *v > 0.0 { 1.0 } else { -1.0 }).collect();
    let cfg = FitConfig {
        hidden: vec![4],
        feedback: 1,
        input: 3,
        lookahead: Some(1),
        options: crate::narx::train::Options { max_epochs: 3, ..Default::default() },
        ..FitConfig::default()
    };
    let model = fit(&x, &u, &cfg, &mut |_| {}).map_err(|e| e.to_string())?;
    model.save(&dir.join("models/narx.json")).map_err(|e| e.to_string())?;
    for (m, v) in [(60.0, 3.0), (110.0, 7.0)] {
        let mut at = model.clone();
        at.condition.mass_g = Some(m);
        at.condition.speed_cm_s = Some(v);
        at.save(&dir.join(format!("models/narx-{m}g-{v}cms.json"))).map_err(|e| e.to_string())?;
    }
    Ok(())
}

#[cfg(feature = "synth")]
fn forward_models(dir: &Path) -> Result<(), String> {
    use crate::synth::model_file::{ForwardModel, Training};
    use crate::synth::volterra_fit::{fit, FitConfig};
    // A square law behind a short filter, trained on actuations within ±1.
    let u: Vec<f64> = signal(3000, 5).iter().map(|v| 2.0 * v).collect();
    let y: Vec<f64> = (0..u.len()).map(|n| (0.8 * u[n] - 0.3 * if n > 0 { u[n - 1] } else { 0.0 }).powi(2)).collect();
    let cfg = FitConfig { memory: 4, ..FitConfig::default() };
    let fitted = fit(&u, &y, &vec![true; u.len()], &cfg).map_err(|e| e.to_string())?;
    let training = Training {
        scores: fitted.scores,
        actuation_rms: 0.5,
        actuation_peak: 1.0,
        data_hash: String::new(),
        seconds: 0.0,
    };
    let forward = ForwardModel::new(
        &fitted.model,
        1000.0,
        &cfg.filter,
        Default::default(),
        fitted.noise,
        fitted.spectrum,
        training,
    );
    forward.save(&dir.join("models/forward.json")).map_err(|e| e.to_string())?;
    for (m, v) in [(60.0, 3.0), (60.0, 7.0), (110.0, 3.0), (110.0, 7.0)] {
        let mut at = forward.clone();
        at.condition.mass_g = Some(m);
        at.condition.speed_cm_s = Some(v);
        at.save(&dir.join(format!("models/forward-{m}g-{v}cms.json"))).map_err(|e| e.to_string())?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_sliver_mesh_has_its_degenerate_triangles() {
        let obj = super::sliver_obj();
        assert_eq!(obj.lines().filter(|l| l.starts_with("f ")).count(), 2 + 39 + 4);
        // The near-zero-area triangle's vertices, 1e-12 cm apart.
        assert!(obj.contains("v 2.000000000001 3.0 0.2"), "{obj}");
    }
}
