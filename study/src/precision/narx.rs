//! The inverse NARX model's sizes and trainers: the NARX settings study
//! (`evflow report narx`, [`crate::narx::run::run`]) at the report's size,
//! each setting's mean E_s (Table 5.1's gain rule, rectangular segments)
//! against its mean training time.
//!
//! E_s is measured against the real texture's force (repetition 1), an
//! exact reference — but no setting comes near it: the display's noise and
//! the inverse model's structure keep every E_s far above 0, and no
//! reference 10× more precise than the best setting exists. The curve says
//! so (its reference error is not a number), and the 10 % column is read
//! against the best setting.

use super::curve::{Curve, WorkPoint};
use super::{PrecisionError, Scratch, Size};
use crate::narx::run::{run, NarxConfig};
use crate::narx::scope::NarxScope;
use crate::narx::setting::{Setting, DEFAULT_SETTINGS};
use crate::setup::Cond;
use evflow_engine::batch::Shard;
use std::path::Path;

/// The name of evflow's default network among the settings.
pub const DEFAULT: &str = "default";

/// The scope at `size`: CI, the default network and a one-layer Adam
/// network, one seed, one texture, 30 epochs, gain 1; full, `report narx`'s
/// nine default settings, one seed, two textures, its epochs and gains.
pub fn scope(size: Size) -> Result<NarxScope, PrecisionError> {
    let parse = |s: &&str| Setting::parse(s).map_err(|e| PrecisionError::Study(e.to_string()));
    let (settings, samples, gains, epochs, iterations): (Vec<&str>, &[&str], &[f64], u32, usize) = match size {
        Size::Ci => (vec![DEFAULT_SETTINGS[0], "adam-one-layer-5=5/1/10/adam"], &["plastic-sheet"], &[1.0], 30, 10),
        Size::Full => {
            (DEFAULT_SETTINGS.to_vec(), &["plastic-sheet", "felt-fabric"], &[0.6, 0.8, 1.0, 1.2, 1.4], 200, 100)
        }
    };
    Ok(NarxScope {
        condition: Cond { mass: 60.0, speed: 5.0 },
        settings: settings.iter().map(parse).collect::<Result<_, _>>()?,
        samples: samples.iter().map(|s| s.to_string()).collect(),
        gains: gains.to_vec(),
        seeds: 1,
        epochs,
        iterations,
        times: true,
    })
}

/// The curve.
pub fn curve(graphs: &Path, size: Size) -> Result<Curve, PrecisionError> {
    let scope = scope(size)?;
    let scratch = Scratch::new("narx")?;
    let jobs = match size {
        Size::Ci => 1,
        Size::Full => std::thread::available_parallelism().map_or(1, |n| n.get()),
    };
    let cfg = NarxConfig {
        scope: scope.clone(),
        graphs: graphs.to_path_buf(),
        out: scratch.path().join("out"),
        work: scratch.path().join("work"),
        jobs,
        shard: Shard::ALL,
    };
    let study = run(&cfg, &mut |_| {}).map_err(|e| PrecisionError::Study(format!("the NARX study: {e}")))?;
    if let Some((what, why)) = study.failures.first() {
        return Err(PrecisionError::Study(format!("the NARX study: {what}: {why}")));
    }
    let points = study
        .scored
        .iter()
        .map(|s| WorkPoint {
            setting: s.setting.name.clone(),
            series: s.setting.algorithm.to_uppercase(),
            error: s.es,
            cost: s.seconds,
            // Weights × epochs: the training's counted work.
            work: s.weights as f64 * s.epochs,
        })
        .collect();
    Ok(Curve {
        name: "narx-settings".into(),
        computation: format!(
            "inverse NARX model ({} at {}, {} seed)",
            scope.samples.join(", "),
            scope.condition.label(),
            scope.seeds
        ),
        knob: "network, taps, trainer".into(),
        error_unit: "mean E_s, Table 5.1 gain".into(),
        cost_unit: "model trained".into(),
        reference: "the real texture's force (exact); none 10× better than the best setting: the 10 % column is \
                    against the best setting"
            .into(),
        reference_error: f64::NAN,
        baseline: None,
        default: DEFAULT.into(),
        points,
    })
}
