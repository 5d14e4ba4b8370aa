//! What a NARX study covers ([`NarxScope`]): the one description its
//! config ([`super::run::NarxConfig`]), its shard record
//! ([`super::saved::NarxRecord`]) and the merge of shards share.

use super::setting::Setting;
use crate::setup::Cond;
use crate::StudyError;
use serde::{Deserialize, Serialize};

/// What a NARX study covers and how; every shard of one study has the same.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NarxScope {
    /// The condition the models are trained and scored at.
    pub condition: Cond,
    /// The network settings, in the table's order.
    pub settings: Vec<Setting>,
    /// The texture samples scored.
    pub samples: Vec<String>,
    /// The gain sweep (§5.3.2).
    pub gains: Vec<f64>,
    /// Models per setting, from seeds 1 … `seeds`.
    pub seeds: u32,
    /// Epochs at most per model.
    pub epochs: u32,
    /// Iterations at most of the optimized synthesis.
    pub iterations: usize,
    /// Whether training times are measured and shown (off: the model files
    /// and every score are the same on every run).
    pub times: bool,
}

impl NarxScope {
    /// Every item of the whole study, in order: (setting index, seed).
    pub fn items(&self) -> Vec<(usize, u32)> {
        let seeds = self.seeds;
        (0..self.settings.len()).flat_map(|i| (1..=seeds).map(move |seed| (i, seed))).collect()
    }

    /// Items in the whole study.
    pub fn total(&self) -> usize {
        self.settings.len() * self.seeds as usize
    }

    /// Checks what can be checked before anything runs.
    pub fn check(&self) -> Result<(), StudyError> {
        let bad = |m: String| Err(StudyError::Config(m));
        if self.seeds == 0 {
            return bad("seeds: at least 1".into());
        }
        if self.settings.is_empty() {
            return bad("settings: at least one".into());
        }
        for (i, s) in self.settings.iter().enumerate() {
            if self.settings[..i].iter().any(|t| t.name == s.name) {
                return bad(format!("settings: the name `{}` is given twice", s.name));
            }
        }
        if self.samples.is_empty() {
            return bad("samples: at least one".into());
        }
        for (i, s) in self.samples.iter().enumerate() {
            evflow_nodes::lab::texture::samples::lookup(s).map_err(|e| StudyError::Config(format!("samples: {e}")))?;
            if self.samples[..i].contains(s) {
                return bad(format!("samples: `{s}` is given twice"));
            }
        }
        if self.gains.is_empty() || !self.gains.iter().all(|g| g.is_finite() && *g > 0.0) {
            return bad("gains: positive numbers".into());
        }
        Ok(())
    }
}
