//! What a texture study covers ([`Scope`]): the one description its
//! config ([`crate::run::StudyConfig`]), its shard record
//! ([`crate::saved::SavedStudy`]) and the merge of shards share.

use super::setup::Cond;
use serde::{Deserialize, Serialize};

/// What a texture study covers and how: its config's part that every
/// shard saves ([`crate::saved`]) and a merge checks agrees.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Scope {
    /// Lab profiles, by name.
    pub profiles: Vec<String>,
    /// Texture samples.
    pub samples: Vec<String>,
    /// Trained conditions.
    pub conds: Vec<Cond>,
    /// The gain sweep (finite positive numbers, exact in JSON).
    pub gains: Vec<f64>,
    /// NARX training epochs at most.
    pub epochs: u32,
    /// The optimized synthesis' iteration budget.
    pub iterations: usize,
    /// Whether the multilevel inverse model was built.
    pub multilevel: bool,
    /// Whether the achievable floor was computed.
    pub floor: bool,
    /// The optimized synthesis' objective.
    pub objective: String,
    /// Whether run times are measured and shown: the tables' times and each
    /// model's training time in its file (`--no-times` leaves them out, so
    /// that the files are the same on every run).
    pub times: bool,
}
