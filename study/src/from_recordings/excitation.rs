//! An excitation recording → the 1 kHz recording the models are trained
//! on, with the actuation `u` kept exact.
//!
//! The shipped graphs (graphs/forward-build-recordings.toml,
//! graphs/model-build-recordings.toml) take every channel through
//! `resample` to 1 kHz — a 1 kHz recording too, whose sinc then cuts u's
//! band from 448 to 500 Hz. That band is where the Nyquist-rate carrier
//! lives: without it the forward model's carrier gain κ, which `synth.live`
//! renders with, is not identified (a stepped multilevel excitation at 60 g,
//! 5 cm/s, 20 passes: κ = 2.67 N through the resampler, against 0.168 N
//! from the same recording unresampled — what graphs/forward-build.toml
//! gives on the lab — and 12.2 N from a 10 kHz recording). So the route
//! takes the recordings to 1 kHz itself and runs those graphs with their
//! resamplers set to `quality = "fast"`, which at 1 kHz → 1 kHz passes the
//! samples through (a cubic at whole-sample positions), 5 samples late on
//! every channel:
//!
//! - at 1 kHz, the recording is used as it is;
//! - at k kHz, `u` (a 1 kHz sequence held for k samples, docs/rig.md) is
//!   taken back sample for sample — the sample at each millisecond, as
//!   `hold` takes it — and the force and velocity go through the
//!   `resample` node's own stream (`balanced`: nothing aliases), late by
//!   its latency D; the resampled channels are moved D samples earlier
//!   (D rounded: 65 for 10 kHz, 0.004 samples off), so all three stay
//!   aligned. The last D samples are dropped.

use super::survey::{Excitation, CHAIN_RATE};
use crate::StudyError;
use evflow_nodes::rate::resampler::{Quality, Stream};
use evflow_nodes::recording::format::{Channel, Recording, RecordingMeta, RecordingWriter};
use std::path::{Path, PathBuf};

/// The sets that make the shipped recordings graphs pass a 1 kHz recording through unfiltered.
pub fn passthrough() -> crate::graphs::Sets {
    crate::graphs::Sets::new()
        .text("u_rate.quality", "fast")
        .text("force_rate.quality", "fast")
        .text("velocity_rate.quality", "fast")
}

/// The 1 kHz recording to train on for `e`: its own sidecar at 1 kHz, else
/// one written into `dir` (`excitation-TAG`).
pub fn at_1khz(e: &Excitation, dir: &Path) -> Result<PathBuf, StudyError> {
    let k = (e.rate / CHAIN_RATE).round() as usize;
    if k <= 1 {
        return Ok(e.path.clone());
    }
    let bad = |m: String| StudyError::Recording(format!("{}: {m}", e.path.display()));
    let rec = Recording::open_channels(&e.path, &["u", "force", "velocity"]).map_err(|x| bad(x.to_string()))?;
    let ch = |n: &str| rec.channel(n).unwrap_or_default();
    let count = rec.frames() / k;
    let mut stream = Stream::new(1.0 / k as f64, Quality::Balanced).map_err(|x| bad(x.to_string()))?;
    let d = stream.latency().round() as usize;
    if count <= d + 1 {
        return Err(bad(format!("too short to take to 1 kHz ({count} samples at 1 kHz, {d} of resampler latency)")));
    }
    let mut late = |x: &[f64]| stream.run(x, count).map_err(|x| bad(x.to_string()));
    let force = late(ch("force"))?;
    let velocity = late(ch("velocity"))?;
    let u: Vec<f64> = ch("u").iter().step_by(k).take(count).copied().collect();
    let n = count - d;
    let mut frames = Vec::with_capacity(3 * n);
    for l in 0..n {
        frames.extend([u[l], force[l + d], velocity[l + d]]);
    }
    let mut meta = RecordingMeta::new(
        CHAIN_RATE,
        vec![Channel::new("u", "1"), Channel::new("force", "N"), Channel::new("velocity", "m/s")],
    );
    meta.condition = rec.meta().condition.clone();
    meta.source = format!(
        "evflow library from-recordings: {} at 1 kHz (u taken every {k} samples; force and velocity resampled, \
         {d} samples earlier)",
        e.path.display()
    );
    std::fs::create_dir_all(dir).map_err(|x| StudyError::Io { path: dir.to_path_buf(), message: x.to_string() })?;
    let path = dir.join(format!("excitation-{}", e.cond.tag()));
    let io = |x: evflow_nodes::recording::format::RecordingError| StudyError::Io {
        path: path.clone(),
        message: x.to_string(),
    };
    let mut w = RecordingWriter::create(&path, meta).map_err(io)?;
    w.write_interleaved(&frames).map_err(io)?;
    w.finish().map_err(io)?;
    Ok(path.with_extension("json"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::setup::Cond;

    #[test]
    fn a_10_khz_excitation_comes_to_1_khz_with_u_exact_and_the_channels_aligned() {
        // u: a 1 kHz ±1 sequence held for 10 samples; force and velocity
        // smooth and known at every instant, so that at 1 kHz sample l they
        // must read their values at l ms — the instant of u[l].
        let dir = tempfile::tempdir().unwrap();
        let n1 = 3000;
        let seq: Vec<f64> = (0..n1).map(|l| if (l * 7919 + l / 3) % 5 < 2 { 1.0 } else { -1.0 }).collect();
        let tau = std::f64::consts::TAU;
        let force = |t: f64| 0.1 * (tau * 37.0 * t).sin() + 0.3;
        let velocity = |t: f64| 0.05 + 0.001 * (tau * 11.0 * t).sin();
        let frames: Vec<f64> =
            (0..n1 * 10).flat_map(|i| [seq[i / 10], force(i as f64 / 1e4), velocity(i as f64 / 1e4)]).collect();
        let mut meta = RecordingMeta::new(
            10_000.0,
            vec![Channel::new("u", "1"), Channel::new("force", "N"), Channel::new("velocity", "m/s")],
        );
        meta.condition.load_g = Some(85.0);
        meta.condition.velocity_cm_s = Some(5.0);
        let src = dir.path().join("x-85g-5cms");
        let mut w = RecordingWriter::create(&src, meta).unwrap();
        w.write_interleaved(&frames).unwrap();
        w.finish().unwrap();
        let e = Excitation {
            path: src.with_extension("json"),
            cond: Cond { mass: 85.0, speed: 5.0 },
            rate: 10_000.0,
            display: None,
            binary: true,
        };
        let out = at_1khz(&e, &dir.path().join("out")).unwrap();
        let rec = Recording::open(&out).unwrap();
        assert_eq!(rec.rate(), 1000.0);
        assert_eq!(rec.frames(), n1 - 65);
        assert_eq!(rec.meta().condition.load_g, Some(85.0));
        let (u, f, v) = (rec.channel("u").unwrap(), rec.channel("force").unwrap(), rec.channel("velocity").unwrap());
        assert_eq!(u, &seq[..n1 - 65], "u is the 1 kHz sequence itself");
        // Past the resampler's start-up, each at its instant: one sample
        // off would be 0.023 N and 7e-5 m/s off.
        let worst = |x: &[f64], g: &dyn Fn(f64) -> f64| {
            (100..n1 - 165).map(|l| (x[l] - g(l as f64 / 1e3)).abs()).fold(0.0, f64::max)
        };
        let (ef, ev) = (worst(f, &force), worst(v, &velocity));
        assert!(ef < 2e-4 && ev < 1e-6, "force off by {ef} N, velocity by {ev} m/s");
        // A 1 kHz recording is used as it is.
        let one = Excitation { rate: 1000.0, ..e };
        assert_eq!(at_1khz(&one, dir.path()).unwrap(), one.path);
    }
}
