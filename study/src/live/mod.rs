//! The live study (docs/texture.md §9): what a finger feels under each
//! live texture chain, held to what the display could have done on the
//! same stroke. Per lab profile × texture sample × virtual user, every
//! chain of graphs/texture-live-quality.toml — nothing, record-and-playback
//! cells, NARX cells, optimized cells, forces first, the live synthesis —
//! is scored by E_s (Welch headline, rect beside it) against the force the
//! finger meets on the real sample, at Table 5.1's gain rule and at its
//! best gain, beside the display floor and the stroke's achievable floor.
//!
//! * [`scope`] — what a study covers (one serializable scope);
//! * [`stroke`] — a user's true strokes and the real force;
//! * [`chains`] — every chain over the gain sweep;
//! * [`floor`] — the stroke's achievable floor and the target's floor, through the display's twin;
//! * [`library`] — the live synthesis' own library (forward models and forces);
//! * [`play`] — actuations played and scored like every chain;
//! * [`row`] — one row's results; [`run`] — the driver;
//! * [`saved`] — a shard's record, read back by `evflow merge`.

pub mod chains;
pub mod floor;
pub mod library;
pub mod play;
pub mod row;
pub mod run;
pub mod saved;
pub mod scope;
pub mod stroke;
