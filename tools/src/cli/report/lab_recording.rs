//! Texture recordings made on the spot for the reports: one condition of
//! `graphs/record-textures.toml` run on the simulated lab, reduced to its
//! constant-speed segments (§5.1.1).

use crate::cli::graph_args::run_with;
use anyhow::{anyhow, Context, Result};
use evflow_nodes::recording::format::Recording;
use std::path::Path;

/// One recording condition.
#[derive(Debug, Clone, Copy)]
pub struct Condition<'a> {
    /// Texture sample.
    pub sample: &'a str,
    /// Stylus mass, g.
    pub mass: f64,
    /// Speed, cm/s.
    pub speed: f64,
    /// Tribometer passes.
    pub passes: u32,
    /// Repetition (the force sensor's seed).
    pub rep: u32,
}

impl Condition<'_> {
    /// The name graphs/record-textures.toml gives its recording.
    pub fn name(&self) -> String {
        format!("{}-{}g-{}cms-r{}", self.sample, self.mass, self.speed, self.rep)
    }

    /// The `--set` values that make graphs/record-textures.toml record it.
    pub fn sets(&self) -> [String; 5] {
        [
            format!("sample=\"{}\"", self.sample),
            format!("speed={}", self.speed),
            format!("mass={}", self.mass),
            format!("passes={}", self.passes),
            format!("rep={}", self.rep),
        ]
    }
}

/// Records `c` with `graph` into a folder under `dir` and returns the rate
/// and the constant-speed force: runs within 2 % of the set speed, less
/// their first 100 ms (the high-pass filter's response to the reversal),
/// each less its mean (the friction's sign flips between passes) and faded
/// in and out over 50 ms so that the joins add no steps, concatenated.
pub fn record(graph: &Path, c: &Condition<'_>, dir: &Path) -> Result<(f64, Vec<f64>)> {
    let out = dir.join(c.name());
    std::fs::create_dir_all(&out).with_context(|| format!("{}: cannot create", out.display()))?;
    run_with(graph, &c.sets(), &out)?;
    constant_speed_force(&recording_in(&out)?, c.speed, &out)
}

/// The rate and the constant-speed force (see [`record`]) of `rec`, a
/// recording of graphs/record-textures.toml at `speed_cm_s` read from `what`.
pub fn constant_speed_force(rec: &Recording, speed_cm_s: f64, what: &Path) -> Result<(f64, Vec<f64>)> {
    let (force, velocity) = (
        rec.channel("force").ok_or_else(|| anyhow!("{}: no `force` channel", what.display()))?,
        rec.channel("velocity").ok_or_else(|| anyhow!("{}: no `velocity` channel", what.display()))?,
    );
    Ok((rec.rate(), constant_speed(force, velocity, speed_cm_s, rec.rate())))
}

/// The only recording a graph run wrote into `dir`.
pub fn recording_in(dir: &Path) -> Result<Recording> {
    let wav = std::fs::read_dir(dir)
        .with_context(|| format!("{}: cannot read", dir.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .find(|p| p.extension().is_some_and(|x| x == "wav"))
        .ok_or_else(|| anyhow!("{}: the graph wrote no recording", dir.display()))?;
    Recording::open(&wav).map_err(|e| anyhow!("{e}"))
}

/// The constant-speed segments of `force` (see [`record`]).
pub fn constant_speed(force: &[f64], velocity: &[f64], speed_cm_s: f64, rate: f64) -> Vec<f64> {
    let settle = (0.1 * rate) as usize;
    let fade = settle / 2;
    let mut kept = Vec::new();
    let mut run: Vec<f64> = Vec::new();
    let flush = |run: &mut Vec<f64>, kept: &mut Vec<f64>| {
        if run.len() > 2 * settle {
            let seg = &run[settle..];
            let mean = seg.iter().sum::<f64>() / seg.len() as f64;
            let n = seg.len();
            kept.extend(seg.iter().enumerate().map(|(i, f)| {
                let edge = i.min(n - 1 - i);
                let w = if edge < fade {
                    0.5 - 0.5 * (std::f64::consts::PI * edge as f64 / fade as f64).cos()
                } else {
                    1.0
                };
                w * (f - mean)
            }));
        }
        run.clear();
    };
    for (f, v) in force.iter().zip(velocity) {
        if (v.abs() * 100.0 - speed_cm_s).abs() <= 0.02 * speed_cm_s {
            run.push(*f);
        } else {
            flush(&mut run, &mut kept);
        }
    }
    flush(&mut run, &mut kept);
    kept
}

#[cfg(test)]
mod tests {
    use super::constant_speed;

    #[test]
    fn keeps_the_constant_speed_runs_settled_centred_and_faded() {
        // Two 1 s runs at 5 cm/s in opposite directions with offsets ±0.1 N,
        // separated by a reversal: 2 × 900 samples kept, each with mean ~0,
        // starting and ending at 0.
        let rate = 1000.0;
        let mut f = Vec::new();
        let mut v = Vec::new();
        for (dir, off) in [(1.0, 0.1), (-1.0, -0.1)] {
            for k in 0..1000 {
                f.push(off + 0.01 * (k as f64 * 0.3).sin());
                v.push(dir * 0.05);
            }
            for _ in 0..50 {
                f.push(0.0);
                v.push(0.0);
            }
        }
        let kept = constant_speed(&f, &v, 5.0, rate);
        assert_eq!(kept.len(), 1800);
        for seg in kept.chunks(900) {
            assert!(seg[0].abs() < 1e-12 && seg[899].abs() < 1e-3);
            assert!(seg.iter().sum::<f64>().abs() / 900.0 < 1e-3);
        }
    }
}
