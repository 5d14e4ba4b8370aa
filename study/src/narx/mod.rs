//! Error against training time of the inverse NARX model over network
//! settings (issue 6, point 10; `evflow report narx`).
//!
//! For each network setting — hidden layers, tap delays, trainer — models
//! are trained for one condition with `graphs/model-build.toml` (one per
//! seed); every texture's force at that condition is synthesized with each
//! and played on the virtual display over the gain sweep
//! (`graphs/synthesize.toml`, every method in one run, as the texture
//! study does), the gain chosen by Table 5.1's rule (and, as a second
//! reading, the best E_s). The optimized synthesis the graph also plays is
//! computed once per texture (through the condition's forward model) and
//! reused.
//!
//! **Items and shards.** The items are the (setting, seed) pairs, settings
//! in the order given, seeds 1 … N within each; a shard (`K/N`) trains and
//! scores its contiguous slice of them. The condition's default models
//! (`models/base`) and the textures' recordings and optimized syntheses are
//! shared by every item and are computed by every shard: they are
//! deterministic, so each shard computes the same ones. Only shard 1 (or a
//! run without shards) keeps the default models in the output folder; the
//! others build them in the work folder, so that the shards' folders merge
//! without two versions of one file.
//!
//! **Failures.** One failing item does not lose the others: a failed
//! (setting, seed) is left out of its setting's means ([`run::Scored::seeds`]
//! says over how many seeds a row is), a setting whose every seed failed has
//! no scores, and a texture whose recording or optimized synthesis failed is
//! left out of every setting's scores; every failure is listed with its
//! reason ([`run::NarxStudy::failures`]).
//!
//! [`setting`] parses the network settings, [`scope`] says what a study
//! covers (its config's, its shard record's and its merge's one
//! description), [`run`] runs it and [`saved`] is a shard's record.

pub mod run;
pub mod saved;
pub mod scope;
pub mod setting;
