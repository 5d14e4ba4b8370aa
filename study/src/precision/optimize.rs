//! `synth.optimize`'s iterations on every lab profile: the texture study's
//! optimized synthesis ([`crate::row::optimize_run`], graphs/synthesize-optimized.toml
//! as shipped: objective `expected`, start `best`) of one texture at one
//! condition, over its iteration budget. The error is how far the
//! optimizer's objective (the expected E_s²) still is above what the same
//! synthesis reaches with 10× the largest budget; the cost is the
//! synthesis' time (both starts) for the whole target recording.
//!
//! The reference is the node's own final answer, not the true optimum:
//! `synth.optimize` stops at 1000 objective evaluations per start (its
//! optimizer's limit), which the reference budget reaches, so a larger
//! budget changes nothing. The reference's own error is 0 when its run
//! stopped before its budget (then more iterations give the same answer),
//! else measured against a run with twice its budget.

use super::curve::{Curve, WorkPoint};
use super::{PrecisionError, Scratch, Size};
use crate::graphs::value;
use crate::models::{self, Models};
use crate::recordings::record_pair;
use crate::row::{optimize_graph, optimize_run, RowInputs};
use crate::setup::{Cond, Profile};
use std::path::Path;

/// graphs/synthesize-optimized.toml's `iterations`.
pub const DEFAULT_ITERATIONS: usize = 100;
/// The texture synthesized.
pub const SAMPLE: &str = "plastic-sheet";
/// The condition: the shipped nominal models' (graphs/data/models).
pub const COND: Cond = Cond { mass: 85.0, speed: 5.0 };

/// The lab profiles measured: the nominal lab (its shipped models and
/// recordings), and at the full size every profile file of `graphs/lab/`
/// but nominal.toml (the nominal lab again).
pub fn profiles(graphs: &Path, size: Size) -> Result<Vec<String>, PrecisionError> {
    let mut v = vec!["nominal".to_string()];
    if size == Size::Full {
        let dir = graphs.join("lab");
        let read = std::fs::read_dir(&dir).map_err(|e| PrecisionError::Study(format!("{}: {e}", dir.display())))?;
        let mut files: Vec<String> = read
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|x| x == "toml"))
            .filter_map(|p| p.file_stem().map(|s| s.to_string_lossy().into_owned()))
            .filter(|n| n != "nominal")
            .collect();
        files.sort();
        v.extend(files);
    }
    Ok(v)
}

/// One curve per profile of [`profiles`].
pub fn curves(graphs: &Path, size: Size) -> Result<Vec<Curve>, PrecisionError> {
    profiles(graphs, size)?.iter().map(|p| curve(graphs, p, size)).collect()
}

/// What one run of the optimized synthesis reported.
struct Opt {
    objective: f64,
    iterations: f64,
    evaluations: f64,
    seconds: f64,
}

/// The curve of profile `name`.
pub fn curve(graphs: &Path, name: &str, size: Size) -> Result<Curve, PrecisionError> {
    let study = |e: crate::StudyError| PrecisionError::Study(format!("synth.optimize on {name}: {e}"));
    let profile = Profile::resolve(name, graphs).map_err(study)?;
    let scratch = Scratch::new("optimize")?;
    let (recordings, models): (std::path::PathBuf, Models) = if profile.path.is_none() {
        let data = graphs.join("data");
        (data.join("textures"), models::given(&data.join("models"), &COND).map_err(study)?)
    } else {
        let rec = scratch.path().join("textures");
        record_pair(graphs, &profile, SAMPLE, &COND, &rec).map_err(study)?;
        let m =
            models::build(graphs, &profile, &COND, 200, false, true, &scratch.path().join("models")).map_err(study)?;
        (rec, m)
    };
    let budgets: &[usize] = match size {
        Size::Ci => &[1, 10, DEFAULT_ITERATIONS],
        Size::Full => &[1, 2, 5, 10, 20, 50, DEFAULT_ITERATIONS, 200],
    };
    let reference_budget = 10 * budgets.iter().max().copied().unwrap_or(DEFAULT_ITERATIONS);
    let graph = optimize_graph(graphs);
    let run = |iterations: usize| -> Result<Opt, PrecisionError> {
        let inputs = RowInputs {
            graphs,
            profile: &profile,
            sample: SAMPLE,
            cond: COND,
            models: &models,
            recordings: &recordings,
            gains: &[1.0],
            iterations,
            objective: "expected",
            optimized: None,
            dir: scratch.path().join(format!("run-{iterations}")),
        };
        let (_, r) = optimize_run(&inputs).map_err(study)?;
        let v = |n: &str| value(&r, &graph, "opt", n);
        Ok(Opt {
            objective: v("objective_end")?,
            iterations: v("iterations")?,
            evaluations: v("evaluations")?,
            seconds: v("seconds")?,
        })
    };
    let reference = run(reference_budget)?;
    // Stopped before its budget (the evaluation limit, or converged): more
    // iterations give the same answer. Else: against twice its budget.
    let reference_error = if reference.iterations < reference_budget as f64 {
        0.0
    } else {
        (reference.objective / run(2 * reference_budget)?.objective - 1.0).abs()
    };
    let mut points = Vec::new();
    for &k in budgets {
        let o = run(k)?;
        points.push(WorkPoint {
            setting: format!("{k} iterations"),
            series: "start = best (carrier and inverse NARX)".into(),
            error: (o.objective / reference.objective - 1.0).abs(),
            cost: o.seconds,
            work: o.evaluations,
        });
    }
    Ok(Curve {
        name: format!("optimize-{}", profile.name),
        computation: format!("synth.optimize ({}, {SAMPLE} at {})", profile.name, COND.label()),
        knob: "iterations".into(),
        error_unit: "objective above the reference's, relative".into(),
        cost_unit: "synthesis (both starts)".into(),
        reference: format!(
            "the same synthesis with a budget of {reference_budget} iterations (ran {:.0}, objective {:.4})",
            reference.iterations, reference.objective
        ),
        reference_error,
        baseline: None,
        default: format!("{DEFAULT_ITERATIONS} iterations"),
        points,
    })
}
