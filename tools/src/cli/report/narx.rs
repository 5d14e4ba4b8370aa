//! `evflow report narx`: error against run time of the inverse NARX model
//! (issue 6, point 10), on the texture study (`evflow_nodes::synth::study`).
//! For each network setting — hidden layers, tap delays, trainer — models
//! are trained for one condition with `graphs/model-build.toml` (one per
//! seed); every texture's force at that condition is synthesized with each
//! and played on the virtual display over the gain sweep
//! (`graphs/synthesize.toml`, every method in one run, as `report
//! textures` does), the gain chosen by Table 5.1's rule (and, as a second
//! reading, the best E_s), and the mean E_s is set against the training
//! time. The optimized synthesis the graph also plays is computed once per
//! texture (through the condition's forward model) and reused. A setting is
//! on the Pareto front when no other trains faster *and* renders with a
//! lower E_s.

use anyhow::{anyhow, ensure, Context, Result};
use evflow_engine::batch::for_each_ordered;
use evflow_nodes::lab::texture::samples::{self, NAMES};
use evflow_nodes::narx::model::Model;
use evflow_nodes::synth::study::models::{self, Models};
use evflow_nodes::synth::study::recordings::record_pair;
use evflow_nodes::synth::study::row::{self, Method, RowInputs};
use evflow_nodes::synth::study::setup::{Cond, Profile};
use evflow_tools::batch::{progress_bar, JobsArg};
use evflow_tools::plot::{Plot, Series};
use std::fmt::Write as _;
use std::path::PathBuf;

/// Arguments of `evflow report narx`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Folder for the Markdown table (narx.md), the models (the condition's
    /// default inverse and forward models under `models/base`, each
    /// setting's under `models/SETTING/seed-N`) and the PNG.
    #[arg(long, default_value = ".")]
    out: PathBuf,
    /// The condition the models are trained and scored at, MASS:SPEED (g, cm/s).
    #[arg(long, default_value = "60:5")]
    condition: String,
    /// Network settings as NAME=HIDDEN/FEEDBACK/INPUT/TRAINER, hidden layers
    /// joined by `-` (e.g. `small=5/1/10/lm`). Default: eight settings around
    /// the default network (15-10-5, taps 1/10, LM).
    #[arg(long, value_delimiter = ',')]
    settings: Vec<String>,
    /// Texture samples scored (default: the six of §5.3; `generated-<seed>` for a generated one).
    #[arg(long, value_delimiter = ',')]
    samples: Vec<String>,
    /// Gains of the sweep (§5.3.2).
    #[arg(long, value_delimiter = ',', default_value = "0.6,0.8,1.0,1.2,1.4")]
    gains: Vec<f64>,
    /// Models per setting, trained from different initial weights (seeds
    /// 1 … N); E_s and time are their means, so one lucky start does not
    /// decide the comparison.
    #[arg(long, default_value_t = 5)]
    seeds: u32,
    /// Epochs at most per model.
    #[arg(long, default_value_t = 200)]
    epochs: u32,
    /// Iterations at most of the optimized synthesis (computed once per
    /// texture, played beside the NARX chain).
    #[arg(long, default_value_t = 100)]
    iterations: usize,
    /// The folder of the shipped graphs.
    #[arg(long, default_value = "graphs")]
    graphs: PathBuf,
    #[command(flatten)]
    jobs: JobsArg,
}

/// The settings compared by default; the first is evflow's default network.
const DEFAULT_SETTINGS: &[&str] = &[
    "default=15-10-5/1/10/lm",
    "one-layer-5=5/1/10/lm",
    "one-layer-15=15/1/10/lm",
    "wide=30-20-10/1/10/lm",
    "input-5=15-10-5/1/5/lm",
    "input-20=15-10-5/1/20/lm",
    "feedback-2=15-10-5/2/10/lm",
    "adam=15-10-5/1/10/adam",
    "adam-one-layer-5=5/1/10/adam",
];

/// One network setting.
#[derive(Debug, Clone, PartialEq)]
struct Setting {
    name: String,
    hidden: Vec<usize>,
    feedback: usize,
    input: usize,
    algorithm: String,
}

impl Setting {
    fn parse(s: &str) -> Result<Self> {
        let (name, rest) =
            s.split_once('=').ok_or_else(|| anyhow!("--settings: `{s}` is not NAME=HIDDEN/FEEDBACK/INPUT/TRAINER"))?;
        let parts: Vec<&str> = rest.split('/').collect();
        ensure!(parts.len() == 4, "--settings: `{s}`: give HIDDEN/FEEDBACK/INPUT/TRAINER, e.g. 15-10-5/1/10/lm");
        let hidden = parts[0]
            .split('-')
            .map(|h| h.trim().parse::<usize>().ok().filter(|&h| h > 0))
            .collect::<Option<Vec<_>>>()
            .ok_or_else(|| anyhow!("--settings: `{s}`: hidden layers are sizes ≥ 1 joined by `-`"))?;
        let num = |x: &str, what: &str| {
            x.trim().parse::<usize>().map_err(|_| anyhow!("--settings: `{s}`: {what} `{x}` is not a whole number"))
        };
        let algorithm = parts[3].trim().to_string();
        ensure!(algorithm == "lm" || algorithm == "adam", "--settings: `{s}`: the trainer is lm or adam");
        Ok(Self {
            name: name.trim().into(),
            hidden,
            feedback: num(parts[1], "feedback")?,
            input: num(parts[2], "input")?,
            algorithm,
        })
    }

    fn overrides(&self) -> Vec<String> {
        let hidden: Vec<String> = self.hidden.iter().map(|h| h.to_string()).collect();
        vec![
            format!("train.hidden=[{}]", hidden.join(", ")),
            format!("train.feedback={}", self.feedback),
            format!("train.input={}", self.input),
            format!("train.algorithm=\"{}\"", self.algorithm),
        ]
    }

    fn describe(&self) -> String {
        let h: Vec<String> = self.hidden.iter().map(|h| h.to_string()).collect();
        format!("{}, k_y {}, k_x {}, {}", h.join("-"), self.feedback, self.input, self.algorithm.to_uppercase())
    }
}

/// A trained and scored setting.
struct Scored {
    setting: Setting,
    weights: usize,
    seconds: f64,
    epochs: f64,
    transitions: f64,
    /// Mean E_s at the Table 5.1 gain.
    es: f64,
    /// Mean E_s at the best gain of the sweep.
    best: f64,
    /// Smallest and largest mean E_s (Table 5.1 gain) of one seed.
    spread: (f64, f64),
}

/// Indices of the points no other point beats in both coordinates.
fn pareto(points: &[(f64, f64)]) -> Vec<bool> {
    points.iter().map(|&(t, e)| !points.iter().any(|&(t2, e2)| t2 <= t && e2 <= e && (t2 < t || e2 < e))).collect()
}

/// Runs `evflow report narx`.
pub fn main(a: Args) -> Result<()> {
    ensure!(a.seeds >= 1, "--seeds: at least 1");
    let cond = Cond::parse(&a.condition).map_err(|e| anyhow!("--condition: {e}"))?;
    let settings: Vec<Setting> = if a.settings.is_empty() {
        DEFAULT_SETTINGS.iter().map(|s| Setting::parse(s)).collect::<Result<_>>()?
    } else {
        a.settings.iter().map(|s| Setting::parse(s)).collect::<Result<_>>()?
    };
    let samples: Vec<String> = if a.samples.is_empty() {
        NAMES.iter().filter(|s| **s != "rippled-paper").map(|s| s.to_string()).collect()
    } else {
        a.samples.clone()
    };
    for s in &samples {
        samples::lookup(s).map_err(|e| anyhow::anyhow!("--samples: {e}"))?;
    }
    ensure!(!a.gains.is_empty() && a.gains.iter().all(|g| g.is_finite() && *g > 0.0), "--gains: positive numbers");
    std::fs::create_dir_all(&a.out).with_context(|| format!("{}: cannot create", a.out.display()))?;
    let out = std::fs::canonicalize(&a.out).with_context(|| format!("{}: cannot open", a.out.display()))?;
    let graphs = std::fs::canonicalize(&a.graphs).with_context(|| format!("--graphs {}", a.graphs.display()))?;
    let tmp = tempfile::tempdir().context("cannot create a temporary folder")?;
    let textures = tmp.path().join("textures");
    let profile = Profile::nominal();
    eprintln!("building the default inverse model and the forward model at {} …", cond.label());
    let base = models::build(&graphs, &profile, &cond, a.epochs, false, &out.join("models").join("base"))?;
    // Each texture recorded, and its optimized actuation synthesized, once
    // (the samples on --jobs threads).
    let jobs = a.jobs.jobs();
    let never = Default::default();
    let mut optimized = Vec::new();
    let mut first_error = None;
    let prepare = |_: usize, s: &String| -> Result<_> {
        record_pair(&graphs, &profile, s, &cond, &textures)?;
        let inputs = inputs(&a, &graphs, &profile, s, &cond, &base, &textures, tmp.path().join("optimized").join(s));
        Ok(row::optimize(&inputs)?)
    };
    for_each_ordered(samples.iter().collect(), jobs, &never, prepare, |_, r| {
        match r.map_err(|p| anyhow!(p)).and_then(|r| r) {
            Ok(o) => optimized.push(o),
            Err(e) => {
                first_error.get_or_insert(e);
            }
        }
    });
    if let Some(e) = first_error {
        return Err(e);
    }
    // Every setting × seed: a model trained, every texture synthesized with
    // it (on --jobs threads; summed in setting and seed order, as on one).
    let pairs: Vec<(usize, u32)> = (0..settings.len()).flat_map(|i| (1..=a.seeds).map(move |seed| (i, seed))).collect();
    let bar = progress_bar(pairs.len(), "models", false);
    let one = |_: usize, (i, seed): (usize, u32)| -> Result<(f64, f64, Model)> {
        let st = &settings[i];
        let dir = out.join("models").join(&st.name).join(format!("seed-{seed}"));
        let mut sets = st.overrides();
        sets.push(format!("train.seed={seed}"));
        let path = models::inverse(&graphs, &profile, &cond, a.epochs, &sets, &dir)?;
        let model = Model::load(&path).map_err(|e| anyhow!("{e}"))?;
        let m = Models { narx: path, narx_multilevel: None, forward: base.forward.clone(), seconds: [0.0; 3] };
        let (mut this, mut this_best) = (0.0, 0.0);
        for (s, opt) in samples.iter().zip(&optimized) {
            let work = tmp.path().join(&st.name).join(format!("seed-{seed}")).join(s);
            let mut inputs = inputs(&a, &graphs, &profile, s, &cond, &m, &textures, work);
            inputs.optimized = Some(opt.clone());
            let r = row::run(&inputs)?;
            let narx = r.method(Method::NarxBinary).ok_or_else(|| anyhow!("the study scored no NARX chain"))?;
            this += narx.chosen.table51.rect / samples.len() as f64;
            this_best += narx.chosen.best_rect.rect / samples.len() as f64;
        }
        bar.inc(1);
        Ok((this, this_best, model))
    };
    let mut results: Vec<Result<(f64, f64, Model)>> = Vec::with_capacity(pairs.len());
    for_each_ordered(pairs.clone(), jobs, &never, one, |_, r| results.push(r.map_err(|p| anyhow!(p)).and_then(|r| r)));
    bar.finish_and_clear();
    let mut results = results.into_iter();
    let mut scored = Vec::new();
    for st in settings.iter() {
        eprintln!(
            "{} ({}): trained at {}, {} textures synthesized",
            st.name,
            st.describe(),
            cond.label(),
            samples.len()
        );
        let (mut es, mut best, mut seconds, mut epochs, mut transitions, mut weights) = (0.0, 0.0, 0.0, 0.0, 0.0, 0);
        let mut spread = (f64::INFINITY, f64::NEG_INFINITY);
        for _ in 1..=a.seeds {
            let (this, this_best, model) = results.next().expect("one result per setting and seed")?;
            es += this;
            best += this_best;
            spread = (spread.0.min(this), spread.1.max(this));
            let t = &model.training;
            seconds += t.seconds;
            epochs += t.epochs as f64;
            transitions += t.closed_loop.as_ref().map_or(f64::NAN, |c| c.transition_agreement);
            weights = model.weights.len();
        }
        let n = a.seeds as f64;
        scored.push(Scored {
            setting: st.clone(),
            weights,
            seconds: seconds / n,
            epochs: epochs / n,
            transitions: transitions / n,
            es: es / n,
            best: best / n,
            spread,
        });
    }
    let front = pareto(&scored.iter().map(|s| (s.seconds, s.es)).collect::<Vec<_>>());
    let mut md = String::new();
    let _ = writeln!(
        md,
        "Error against run time of the inverse NARX model at {} ({} textures, gain sweep {:?}): mean E_s (Eq. 5.2, 2–200 Hz, rectangular segments as the `metric` node takes it) of the virtual against the real force at the gain Table 5.1's rule chooses, and at the best gain of the sweep, as `report textures` scores every method; training time of graphs/model-build.toml (3066 samples); each the mean over {} models trained from seeds 1–{}.\n",
        cond.label(),
        samples.len(),
        a.gains,
        a.seeds,
        a.seeds
    );
    let _ = writeln!(md, "| setting | network, taps, trainer | weights | epochs | training time (s) | closed-loop transition agreement | mean E_s | E_s range over seeds | mean E_s, best gain | Pareto front |");
    let _ = writeln!(md, "|---|---|---:|---:|---:|---:|---:|---|---:|---|");
    for (s, on) in scored.iter().zip(&front) {
        let _ = writeln!(
            md,
            "| {} | {} | {} | {:.0} | {:.2} | {:.3} | {:.3} | {:.2}–{:.2} | {:.3} | {} |",
            s.setting.name,
            s.setting.describe(),
            s.weights,
            s.epochs,
            s.seconds,
            s.transitions,
            s.es,
            s.spread.0,
            s.spread.1,
            s.best,
            if *on { "yes" } else { "" }
        );
    }
    if let Some(i) = scored.iter().position(|s| s.setting.name == "default") {
        let _ = writeln!(md, "\nThe default network is {}on the Pareto front.", if front[i] { "" } else { "**not** " });
    }
    print!("{md}");
    super::save_markdown(&out.join("narx.md"), &md)?;
    let plot = Plot {
        title: format!("Inverse NARX: E_s against training time at {}", cond.label()),
        x_label: "training time (s)".into(),
        y_label: "mean E_s".into(),
        log_x: true,
        log_y: false,
        series: scored
            .iter()
            .map(|s| Series::points(format!("{} ({})", s.setting.name, s.setting.describe()), vec![(s.seconds, s.es)]))
            .collect(),
    };
    super::save_png(&plot, &out.join("narx-work-precision.png"));
    Ok(())
}

/// The study's inputs for `sample` at `c` with `models` (the optimized
/// actuation to be filled in by the caller when it has one).
#[allow(clippy::too_many_arguments)]
fn inputs<'a>(
    a: &'a Args,
    graphs: &'a std::path::Path,
    profile: &'a Profile,
    sample: &'a str,
    c: &Cond,
    models: &'a Models,
    recordings: &'a std::path::Path,
    dir: PathBuf,
) -> RowInputs<'a> {
    RowInputs {
        graphs,
        profile,
        sample,
        cond: *c,
        models,
        recordings,
        gains: &a.gains,
        iterations: a.iterations,
        objective: "expected",
        optimized: None,
        dir,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn settings_parse_into_model_build_overrides() {
        let s = Setting::parse("wide=30-20-10/2/15/adam").unwrap();
        assert_eq!((s.hidden.clone(), s.feedback, s.input, s.algorithm.as_str()), (vec![30, 20, 10], 2, 15, "adam"));
        assert_eq!(
            s.overrides(),
            ["train.hidden=[30, 20, 10]", "train.feedback=2", "train.input=15", "train.algorithm=\"adam\""]
        );
        for bad in ["x", "x=15/1/10", "x=15-0/1/10/lm", "x=15/a/10/lm", "x=15/1/10/sgd"] {
            assert!(Setting::parse(bad).is_err(), "{bad}");
        }
        for d in DEFAULT_SETTINGS {
            Setting::parse(d).unwrap();
        }
    }

    #[test]
    fn the_pareto_front_keeps_what_nothing_beats_in_both() {
        // (1, 0.5) and (2, 0.4) and (0.5, 0.9) trade off; (3, 0.6) is beaten
        // by both of the first; a duplicate of a front point stays on it.
        let p = [(1.0, 0.5), (2.0, 0.4), (3.0, 0.6), (0.5, 0.9), (1.0, 0.5)];
        assert_eq!(pareto(&p), vec![true, true, false, true, true]);
    }
}
