//! One row of the live study: one lab profile, texture sample and virtual
//! user, every live chain and the floors beside them.

use crate::exact;
use crate::gains::{AtGain, Chosen};
use crate::row::Reading;
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

/// A live chain (graphs/texture-live-quality.toml).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Chain {
    /// Record-and-playback cells, normalized per recording (§6.5.2).
    Playback,
    /// The inverse NARX models' cells (§5.2, chapter 6).
    Narx,
    /// The optimized synthesis' cells on their carrier.
    Optimized,
    /// Forces first: the forces interpolated, the nearest inverse model.
    ForcesFirst,
    /// The live synthesis (`synth.live`).
    Live,
}

impl Chain {
    /// Every chain, in report order.
    pub const ALL: [Chain; 5] = [Chain::Playback, Chain::Narx, Chain::Optimized, Chain::ForcesFirst, Chain::Live];

    /// The chain's prefix in graphs/texture-live-quality.toml (its nodes
    /// `PREFIX_es`, `PREFIX_welch`; its channel in the actuations' recording).
    pub fn prefix(&self) -> &'static str {
        match self {
            Chain::Playback => "playback",
            Chain::Narx => "narx",
            Chain::Optimized => "optimized",
            Chain::ForcesFirst => "ff",
            Chain::Live => "live",
        }
    }

    /// A label for tables.
    pub fn label(&self) -> &'static str {
        match self {
            Chain::Playback => "record-and-playback cells",
            Chain::Narx => "NARX cells",
            Chain::Optimized => "optimized cells",
            Chain::ForcesFirst => "forces first (NARX)",
            Chain::Live => "live synthesis",
        }
    }
}

/// One chain's scores over the gain sweep.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ChainResult {
    /// The chain.
    pub chain: Chain,
    /// Every gain.
    pub sweep: Vec<AtGain>,
    /// The gains chosen by Table 5.1's rule and by the lowest E_s.
    pub chosen: Chosen,
    /// The chain's synthesis node's mean objective reduction and iterations
    /// per tick at gain 1 (the live synthesis only; else 0).
    #[serde(with = "exact")]
    pub iterations_per_tick: f64,
}

/// The stroke's achievable floor as played.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StrokeFloor {
    /// The best start's scores over the gain sweep.
    pub sweep: Vec<AtGain>,
    /// The best of each reading over the sweep, over every start.
    pub reached: Reading,
    /// The start whose optimum played best (Welch, best gain).
    pub start: String,
    /// Its objective through the twin, noise off (E_s²).
    #[serde(with = "exact")]
    pub objective: f64,
    /// The same actuation with nothing played within [`super::floor::REVERSAL_MS`]
    /// of every reversal of the finger, played alike: how much of the
    /// floor lies in the sliding alone (a live chain knows neither when a
    /// reversal comes nor how the display behaves through one).
    pub sliding_only: Reading,
    /// Seconds the optimizations took: both floors' starts run in one
    /// queue, so the joint run's seconds times this floor's share of the
    /// evaluations.
    #[serde(with = "exact")]
    pub seconds: f64,
}

/// The target's floor as played: the whole stroke's actuation optimized
/// through the display's twin towards the live synthesis' own target (the
/// force the chain computed, tick by tick, from the IR frame and the load
/// cell, in the direction of motion, high-passed — in the stroke's floor's
/// objective, in place of the real force), played like every chain and
/// scored against the real force. It splits the live synthesis' distance
/// from the stroke's floor into what its target lacks (target's floor /
/// stroke's floor) and what the synthesis loses (live / target's floor).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TargetFloor {
    /// The best start's scores over the gain sweep.
    pub sweep: Vec<AtGain>,
    /// The best of each reading over the sweep, over every start.
    pub reached: Reading,
    /// The start whose optimum played best (Welch, best gain).
    pub start: String,
    /// Its objective through the twin towards the target, noise off (E_s²).
    #[serde(with = "exact")]
    pub objective: f64,
    /// Seconds the optimizations took: both floors' starts run in one
    /// queue, so the joint run's seconds times this floor's share of the
    /// evaluations.
    #[serde(with = "exact")]
    pub seconds: f64,
}

/// One row.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LiveRow {
    /// Lab profile.
    pub profile: String,
    /// Texture sample.
    pub sample: String,
    /// Virtual user's name.
    pub user: String,
    /// The display with no actuation.
    pub nothing: Reading,
    /// The display floor: no actuation plus the texture's own force
    /// modulation added — a display rendering the texture perfectly on top
    /// of its own friction.
    pub display_floor: Reading,
    /// Every chain.
    pub chains: Vec<ChainResult>,
    /// The stroke's achievable floor (None: not computed).
    pub achievable: Option<StrokeFloor>,
    /// The target's floor (None: not computed, or the live synthesis not played).
    #[serde(default)]
    pub target_floor: Option<TargetFloor>,
    /// The folder of the row's runs.
    pub dir: PathBuf,
}

impl LiveRow {
    /// A chain's result.
    pub fn chain(&self, c: Chain) -> Option<&ChainResult> {
        self.chains.iter().find(|r| r.chain == c)
    }

    /// The stroke's floor as defined: the best that optimizing through the
    /// display reached, or a chain's best-gain value where one did better
    /// (the optimization then was not optimal there), per reading.
    pub fn floor(&self) -> Option<Reading> {
        let mut f = self.achievable.as_ref()?.reached;
        for c in &self.chains {
            f = f.min(Reading { rect: c.chosen.best_rect.rect, welch: c.chosen.best_welch.welch });
        }
        Some(f)
    }

    /// The target's floor as defined: the best that optimizing towards the
    /// live synthesis' target reached, or the live synthesis' own best-gain
    /// value where it did better (the optimization then was not optimal
    /// there), per reading.
    pub fn target_floor(&self) -> Option<Reading> {
        let mut f = self.target_floor.as_ref()?.reached;
        if let Some(c) = self.chain(Chain::Live) {
            f = f.min(Reading { rect: c.chosen.best_rect.rect, welch: c.chosen.best_welch.welch });
        }
        Some(f)
    }

    /// The best chain by the Welch reading at its best gain.
    pub fn best(&self) -> Option<&ChainResult> {
        self.chains.iter().min_by(|a, b| a.chosen.best_welch.welch.total_cmp(&b.chosen.best_welch.welch))
    }
}
