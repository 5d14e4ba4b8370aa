//! From a recording to a trained model: checks the data, normalizes it
//! (mapminmax), aligns force and actuation (look-ahead), builds open-loop
//! regressors, splits off a contiguous validation block (the last 15 % by
//! default), trains, and scores the closed loop on the validation block.

use super::error::NarxError;
use super::eval;
use super::mapminmax::MapMinMax;
use super::model::{self, Architecture, ClosedLoopScore, Condition, Model, Normalization, Training};
use super::net::Mlp;
use super::taps::{self, Taps};
use super::train::{self, Data, Epoch, Options};
use crate::rng::Rng;
use crate::wide_sum::SumSq;
use serde::{Deserialize, Serialize};

/// The training algorithm.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Algorithm {
    /// Levenberg–Marquardt (MATLAB `trainlm`).
    Lm,
    /// Adam.
    Adam,
}

impl Algorithm {
    /// The word used in parameters and files.
    pub fn word(&self) -> &'static str {
        match self {
            Algorithm::Lm => "lm",
            Algorithm::Adam => "adam",
        }
    }
}

/// Everything that decides how a model is trained.
#[derive(Debug, Clone, PartialEq)]
pub struct FitConfig {
    /// Hidden layer sizes.
    pub hidden: Vec<usize>,
    /// Feedback taps k_y.
    pub feedback: usize,
    /// Input taps k_x behind the output sample.
    pub input: usize,
    /// Look-ahead d; `None` chooses it by cross-correlation up to `max_lookahead`.
    pub lookahead: Option<i64>,
    /// Largest look-ahead the automatic choice may take.
    pub max_lookahead: usize,
    /// Fraction of the usable samples, at the end, kept for validation (0 = none).
    pub validation: f64,
    /// Algorithm.
    pub algorithm: Algorithm,
    /// Algorithm options.
    pub options: Options,
    /// Seed of the initial weights.
    pub seed: u64,
    /// Condition written into the model.
    pub condition: Condition,
    /// Sample rate of the data, Hz (written into the model).
    pub rate_hz: f64,
}

impl Default for FitConfig {
    fn default() -> Self {
        Self {
            hidden: vec![15, 10, 5],
            feedback: 2,
            input: 10,
            lookahead: None,
            max_lookahead: 10,
            validation: 0.15,
            algorithm: Algorithm::Lm,
            options: Options::default(),
            seed: 1,
            condition: Condition::default(),
            rate_hz: 1000.0,
        }
    }
}

/// Checks that a series can be trained on.
fn check_series(name: &str, s: &[f64]) -> Result<MapMinMax, NarxError> {
    if let Some(i) = s.iter().position(|v| !v.is_finite()) {
        return Err(NarxError::Data(format!("{name}[{i}] is {} (every sample must be finite)", s[i])));
    }
    let m = MapMinMax::fit(s).ok_or_else(|| NarxError::Data(format!("{name} has no samples")))?;
    if m.is_constant() {
        return Err(NarxError::Data(format!(
            "{name} is constant ({}) over all {} samples: there is nothing to learn (was the display off, or the sensor disconnected?)",
            m.min,
            s.len()
        )));
    }
    Ok(m)
}

/// Trains a model on force `x` (network input) and actuation `u` (network
/// output, the reference), sample-aligned and of equal length.
pub fn fit(x: &[f64], u: &[f64], cfg: &FitConfig, progress: &mut dyn FnMut(&Epoch)) -> Result<Model, NarxError> {
    if x.len() != u.len() {
        return Err(NarxError::Data(format!("{} force samples but {} actuation samples", x.len(), u.len())));
    }
    if !(0.0..0.9).contains(&cfg.validation) {
        return Err(NarxError::Config(format!("validation fraction {} is not in [0, 0.9)", cfg.validation)));
    }
    let xmap = check_series("the force x", x)?;
    let ymap = check_series("the actuation y", u)?;
    let lookahead = match cfg.lookahead {
        Some(d) => d,
        None => match taps::choose_lookahead(u, x, cfg.max_lookahead) {
            Some(a) => a.lookahead as i64,
            None => 0,
        },
    };
    let taps = Taps { feedback: cfg.feedback, input: cfg.input, lookahead };
    taps.validate().map_err(NarxError::Config)?;
    let mut net = Mlp::new(taps.n_inputs(), &cfg.hidden)?;
    let xn: Vec<f64> = x.iter().map(|&v| xmap.apply(v)).collect();
    let yn: Vec<f64> = u.iter().map(|&v| ymap.apply(v)).collect();
    let (m, t) = taps.regressors(&xn, &yn);
    let rows = t.len();
    let n_val = (rows as f64 * cfg.validation).round() as usize;
    let n_train = rows - n_val;
    let p = net.n_params();
    let min_val = if cfg.validation > 0.0 { 10 } else { 0 };
    if n_train < p || n_val < min_val {
        let per_row = 1.0 / (1.0 - cfg.validation);
        return Err(NarxError::Data(format!(
            "the recording is too short: {} samples give {n_train} training rows{} for a network of {p} weights; \
             record at least {} samples (or use a smaller network)",
            x.len(),
            if min_val > 0 { format!(" and {n_val} validation rows") } else { String::new() },
            (p.max(min_val) as f64 * per_row).ceil() as usize + taps.first() + taps.latency() + min_val,
        )));
    }
    let data = Data::new(m.view(), t.view()).ok_or_else(|| NarxError::Config("regressor shape".into()))?;
    let (tr, va) = (data.slice(0..n_train), data.slice(n_train..rows));
    net.init_nguyen_widrow(&mut Rng::new(cfg.seed));
    let opts = Options { seed: cfg.seed, ..cfg.options };
    let report = match cfg.algorithm {
        Algorithm::Lm => train::lm::train(&mut net, &tr, &va, &opts, progress),
        Algorithm::Adam => train::adam::train(&mut net, &tr, &va, &opts, progress),
    };
    let finite = |v: f64| v.is_finite().then_some(v);
    let mut model = Model {
        format: model::FORMAT.into(),
        version: model::VERSION,
        rate_hz: cfg.rate_hz,
        architecture: Architecture {
            inputs: taps.n_inputs(),
            hidden: cfg.hidden.clone(),
            hidden_activation: "tanh".into(),
            output_activation: "linear".into(),
        },
        delays: taps,
        normalization: Normalization { x: xmap, y: ymap },
        condition: cfg.condition,
        training: Training {
            algorithm: cfg.algorithm.word().into(),
            data_hash: model::data_hash(&[x, u]),
            samples: x.len(),
            train_rows: n_train,
            validation_rows: n_val,
            epochs: report.epochs,
            best_epoch: report.best_epoch,
            stop: report.stop,
            train_mse: report.train_mse,
            validation_mse: finite(report.val_mse),
            closed_loop: None,
            closed_loop_noise_force: None,
            seconds: report.seconds,
            seed: cfg.seed,
        },
        weights: net.weights().to_vec(),
    };
    if n_val > 0 {
        let from = taps.first() + n_train;
        model.training.closed_loop = closed_loop_score(&model, x, u, from, None)?;
        model.training.closed_loop_noise_force = closed_loop_score(&model, x, u, from, Some(cfg.seed))?;
    }
    Ok(model)
}

/// Scores the model closed loop from sample `from` on against `u`. The
/// loop is started from known states (the true u fed back up to `from`,
/// over a warm-up of k_x + k_y + 50 samples, see
/// [`super::closed_loop::ClosedLoop::step_known`]) and then runs on its own
/// estimates. With `noise_seed`, the force from `from` on is replaced by
/// Gaussian noise of the same RMS — the check that the network reads the
/// force rather than predicting u from its own past.
pub fn closed_loop_score(
    model: &Model,
    x: &[f64],
    u: &[f64],
    from: usize,
    noise_seed: Option<u64>,
) -> Result<Option<ClosedLoopScore>, NarxError> {
    if from >= x.len() || x.len() != u.len() {
        return Ok(None);
    }
    let warm = model.delays.input + model.delays.feedback + 50;
    let s = from.saturating_sub(warm);
    let mut xs = x[s..].to_vec();
    if let Some(seed) = noise_seed {
        let tail = &mut xs[from - s..];
        let mut sq = SumSq::<f64>::default();
        tail.iter().for_each(|&v| sq.add(v));
        // The force's RMS, right (and finite) for a force near ±f64::MAX too.
        let rms = sq.root_mean(tail.len() as f64).saturated().0;
        let mut r = Rng::new(seed ^ 0x006e_6f69_7365);
        for v in tail.iter_mut() {
            *v = rms * r.gaussian();
        }
    }
    let mut cl = model.closed_loop()?;
    let est = cl.run_known(&xs, &u[s..], from - s);
    Ok(eval::score(&est[from - s..], &u[from..]))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn data(n: usize) -> (Vec<f64>, Vec<f64>) {
        let u = super::super::labdata::rbs(n, 4);
        let x: Vec<f64> = (0..n).map(|i| if i == 0 { 0.0 } else { (u[i] - u[i - 1]).powi(2) + 0.1 * u[i] }).collect();
        (x, u)
    }

    fn small() -> FitConfig {
        FitConfig {
            hidden: vec![4],
            feedback: 1,
            input: 2,
            options: Options { max_epochs: 5, ..Options::default() },
            ..FitConfig::default()
        }
    }

    #[test]
    fn bad_data_is_refused_naming_the_sample() {
        let (mut x, u) = data(500);
        x[123] = f64::NAN;
        let e = fit(&x, &u, &small(), &mut |_| {}).unwrap_err().to_string();
        assert!(e.contains("the force x[123] is NaN"), "{e}");
        let (x, mut u) = data(500);
        u[7] = f64::INFINITY;
        let e = fit(&x, &u, &small(), &mut |_| {}).unwrap_err().to_string();
        assert!(e.contains("the actuation y[7] is inf"), "{e}");
        let (x, u) = data(500);
        let e = fit(&x[..10], &u, &small(), &mut |_| {}).unwrap_err().to_string();
        assert!(e.contains("10 force samples but 500 actuation samples"), "{e}");
        let cfg = FitConfig { validation: 0.95, ..small() };
        assert!(fit(&x, &u, &cfg, &mut |_| {}).unwrap_err().to_string().contains("validation fraction"));
        let cfg = FitConfig { lookahead: Some(-5), ..small() };
        assert!(fit(&x, &u, &cfg, &mut |_| {}).unwrap_err().to_string().contains("leaves no input tap"));
    }

    #[test]
    fn a_fit_records_how_it_was_made() {
        let (x, u) = data(600);
        let m = fit(&x, &u, &small(), &mut |_| {}).unwrap();
        m.validate(std::path::Path::new("m.json")).unwrap();
        assert_eq!(m.training.samples, 600);
        assert_eq!(m.training.train_rows + m.training.validation_rows, m.delays.usable(600));
        assert_eq!(m.training.validation_rows, (m.delays.usable(600) as f64 * 0.15).round() as usize);
        assert_eq!(m.training.data_hash, model::data_hash(&[&x, &u]));
        assert!(m.training.closed_loop.is_some() && m.training.closed_loop_noise_force.is_some());
        // The transitions lead the force by nothing here: d from the cross-correlation is 0.
        assert_eq!(m.delays.lookahead, 0);
        // Same data, same seed: the same model, bit for bit (training time aside).
        let mut again = fit(&x, &u, &small(), &mut |_| {}).unwrap();
        again.training.seconds = m.training.seconds;
        assert_eq!(again, m);
        // Without validation there are no closed-loop scores.
        let cfg = FitConfig { validation: 0.0, ..small() };
        let m = fit(&x, &u, &cfg, &mut |_| {}).unwrap();
        assert!(m.training.closed_loop.is_none() && m.training.validation_mse.is_none());
    }
}
