//! Every live chain under one user on one sample: graphs/texture-live-quality.toml
//! run over the gain sweep (as one shared sweep: each chain computed once,
//! its gain, limiter, display and metrics once per gain), each chain's
//! scores read per gain, and every
//! chain's actuation as played at gain 1 (the stroke's floor starts from
//! them).

use super::play::Stage;
use super::row::{Chain, ChainResult};
use crate::gains::{choose, AtGain};
use crate::graphs::{run_sweep_for, value, Sets};
use crate::row::Reading;
use crate::StudyError;
use evflow_nodes::recording::format::Recording;
use std::path::Path;

/// The quality graph's file name.
pub const GRAPH: &str = "texture-live-quality.toml";

/// What the chains did under one user.
#[derive(Debug, Clone)]
pub struct ChainsRun {
    /// The display with no actuation.
    pub nothing: Reading,
    /// Every chain over the sweep.
    pub chains: Vec<ChainResult>,
    /// Every chain's actuation as played at gain 1 (or at the sweep's
    /// first gain when 1 is not in it), by chain.
    pub actuations: Vec<(Chain, Vec<f64>)>,
    /// The force the live synthesis aimed at, tick by tick, at that gain
    /// (N; empty when the live synthesis was left out).
    pub live_target: Vec<f64>,
}

/// Runs the chains on `at`, the grids and models read from `library`.
pub fn run(at: &Stage<'_>, library: &Path) -> Result<ChainsRun, StudyError> {
    let (scope, profile, sample, user, dir) = (at.scope, at.profile, at.sample, at.user, at.dir);
    let graph = at.graphs.join(GRAPH);
    let record_gain = if scope.gains.contains(&1.0) { 1.0 } else { scope.gains[0] };
    let mut points = Vec::new();
    for &gain in &scope.gains {
        // A chain left out plays nothing: its gain is 0, and what fed only it is pruned (never built).
        let out = Chain::ALL.iter().filter(|c| !scope.chains.contains(c));
        let sets = out
            .fold(Sets::new(), |s, c| s.num(&format!("{}_gain.gain", c.prefix()), 0.0))
            .path("library", library)
            .text("sample", sample)
            .and(profile.sets())
            .num("gain", gain)
            .int("lookahead", scope.live.lookahead as i64)
            .int("iterations", scope.live.iterations as i64)
            .num("offset", scope.live.offset)
            .text("record", &format!("actuations-g{gain:?}"))
            .and(user.sets());
        points.push(sets);
    }
    // One run for the whole sweep: what comes before each chain's gain is the same at every gain.
    let reports = run_sweep_for(&graph, &points, dir, Some(scope.seconds))?;
    let runs: Vec<(f64, _)> = scope.gains.iter().copied().zip(reports).collect();
    let first = &runs[0].1;
    let nothing = Reading {
        rect: value(first, &graph, "nothing_es", "E_s")?,
        welch: value(first, &graph, "nothing_welch", "E_s")?,
    };
    let mut chains = Vec::new();
    for c in Chain::ALL.into_iter().filter(|c| scope.chains.contains(c)) {
        let p = c.prefix();
        let mut sweep = Vec::new();
        for (gain, r) in &runs {
            sweep.push(AtGain {
                gain: *gain,
                rect: value(r, &graph, &format!("{p}_es"), "E_s")?,
                welch: value(r, &graph, &format!("{p}_welch"), "E_s")?,
                peak_ratio: value(r, &graph, &format!("{p}_es"), "peak_psd_ratio")?,
            });
        }
        let chosen = choose(&sweep).ok_or_else(|| StudyError::Config("an empty gain sweep".into()))?;
        let at_record = runs.iter().find(|(g, _)| *g == record_gain).map(|(_, r)| r).unwrap_or(first);
        let iterations_per_tick =
            if c == Chain::Live { value(at_record, &graph, "live_synth", "iterations_per_tick")? } else { 0.0 };
        chains.push(ChainResult { chain: c, sweep, chosen, iterations_per_tick });
    }
    // The actuations as played at the recorded gain; the other gains' recordings are not kept.
    let mut actuations = Vec::new();
    let mut live_target = Vec::new();
    for &gain in &scope.gains {
        let file = dir.join(format!("actuations-g{gain:?}"));
        if gain == record_gain {
            let rec = Recording::open(&file).map_err(|e| StudyError::Recording(e.to_string()))?;
            for c in Chain::ALL.into_iter().filter(|c| scope.chains.contains(c)) {
                actuations.push((c, rec.channel(c.prefix()).unwrap_or_default().to_vec()));
            }
            if scope.chains.contains(&Chain::Live) {
                live_target = rec.channel("live_target").unwrap_or_default().to_vec();
            }
        } else {
            for ext in ["wav", "json"] {
                let _ = std::fs::remove_file(file.with_extension(ext));
            }
        }
    }
    Ok(ChainsRun { nothing, chains, actuations, live_target })
}
