//! Identification of the forward model ([`Volterra`]) from an excitation
//! recording: actuation u and the force it produced, by linear least
//! squares.
//!
//! Every parameter of the model enters linearly, so the regressor matrix Φ
//! holds one column per parameter — u[n−i]·u[n−j] (i ≤ j), u[n−i] and 1 —
//! and the fit is the ridge-stabilized normal equations
//! (ΦᵀΦ + δ·I)θ = Φᵀy, solved by Cholesky. The recorded force went through
//! the known output filter (the 10 Hz high-pass), which is linear: each
//! column of Φ is filtered the same way, so the kernel found is the one
//! *before* the filter. Only the samples the gates keep (the constant-speed
//! stretches of a tribometer's forward passes) are rows; the filter runs
//! over the whole series so that its state at a kept sample is right. The
//! last `validation` fraction of the kept samples is held out and scored.
//!
//! **Noise model.** What the model cannot explain — friction noise, sensor
//! noise, unmodelled dynamics — is not the same at every actuation level: a
//! display's friction noise grows with the normal force the actuation adds.
//! The squared residual is regressed on the local actuation power
//! p\[n\] = mean of u² over `noise_window` samples around n: r² ≈ σ₀² + β·p.
//! The synthesis uses β to weigh matching the force against the noise a
//! stronger actuation brings ([`super::objective`]).

use super::error::SynthError;
use super::output_filter::OutputFilter;
use super::spectral::NoiseSpectrum;
use super::volterra::{upper_index, Volterra, MAX_MEMORY};
use crate::linalg::{add_lower_gram, Cholesky};
use crate::wide_sum::SumSq;
use ndarray::{Array1, Array2};

/// How to identify a model.
#[derive(Debug, Clone, PartialEq)]
pub struct FitConfig {
    /// Memory M, samples.
    pub memory: usize,
    /// The filter the recorded force went through.
    pub filter: OutputFilter,
    /// Fraction of the kept samples, at their end, held out for validation.
    pub validation: f64,
    /// Ridge δ relative to the mean diagonal of ΦᵀΦ.
    pub ridge: f64,
    /// Samples over which the local actuation power of the noise model is averaged.
    pub noise_window: usize,
    /// Sample rate, Hz (the noise spectrum's segments are one second long).
    pub rate: f64,
    /// Refit weighted by the inverse residual variance at each sample's
    /// actuation power (feasible generalized least squares): samples where
    /// the display strays from a second-order model — strong actuation
    /// that makes the contact stick and slip — count less, samples where
    /// only the noise floor limits the fit count fully.
    pub reweight: bool,
}

impl Default for FitConfig {
    fn default() -> Self {
        Self {
            memory: 20,
            filter: OutputFilter::none(),
            validation: 0.15,
            ridge: 1e-9,
            noise_window: 25,
            rate: 1000.0,
            reweight: true,
        }
    }
}

/// The noise the model leaves, as a function of actuation power.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct NoiseModel {
    /// σ₀²: residual power with no actuation, N².
    pub floor_n2: f64,
    /// β: residual power added per unit of local mean u², N².
    pub per_u2_n2: f64,
}

/// How well a model fits.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct FitScores {
    /// Samples kept by the gates.
    pub samples: usize,
    /// Of which used to fit.
    pub train_rows: usize,
    /// Of which held out.
    pub validation_rows: usize,
    /// ‖y − ŷ‖ / ‖y‖ on the fitted rows (see [`rel_rms`]).
    pub train_rel_rms: f64,
    /// ‖y − ŷ‖ / ‖y‖ on the held-out rows; `None` (`null` in a model
    /// file) without any (`validation` = 0).
    pub validation_rel_rms: Option<f64>,
}

/// Identifies a model from actuation `u`, recorded force `y` (after the
/// filter) and the rows to use (`keep[n]`), all of one length.
pub fn fit(u: &[f64], y: &[f64], keep: &[bool], cfg: &FitConfig) -> Result<Fitted, SynthError> {
    check_inputs(u, y, keep, cfg)?;
    let m = cfg.memory;
    let rows: Vec<usize> = (0..u.len()).filter(|&n| keep[n]).collect();
    let p = m * (m + 1) / 2 + m + 1;
    let n_val = (rows.len() as f64 * cfg.validation).round() as usize;
    let n_tr = rows.len() - n_val;
    if n_tr < 2 * p {
        return Err(SynthError::Data(format!(
            "{} kept samples give {n_tr} rows to fit {p} parameters (memory {m}); record at least {} kept samples \
             (more passes) or shorten the memory",
            rows.len(),
            ((2 * p) as f64 / (1.0 - cfg.validation)).ceil() as usize
        )));
    }
    let kept_y: Vec<f64> = rows.iter().map(|&n| y[n]).collect();
    check_excitation(u, &rows, &kept_y)?;
    let phi = regressors(u, &rows, cfg);
    let power = local_power(u, &rows, cfg.noise_window);
    let th = coefficients(&phi, &kept_y, &power, n_tr, cfg)?;
    // The column of u[n−i]·u[n−j], i < j, carries H_ij + H_ji = 2·H_ij.
    let q = m * (m + 1) / 2;
    let mut upper = th[..q].to_vec();
    for i in 0..m {
        for j in i + 1..m {
            upper[upper_index(m, i, j)] *= 0.5;
        }
    }
    let model = Volterra::from_upper(&upper, th[q..q + m].to_vec(), th[q + m])?;

    // Residuals on every kept row.
    let mut resid = vec![0.0; rows.len()];
    for (r, out) in resid.iter_mut().enumerate() {
        let pred: f64 = (0..p).map(|k| phi[(r, k)] * th[k]).sum();
        *out = kept_y[r] - pred;
    }
    let scores = FitScores {
        samples: rows.len(),
        train_rows: n_tr,
        validation_rows: n_val,
        train_rel_rms: rel_rms(&resid[..n_tr], &kept_y[..n_tr], &kept_y),
        validation_rel_rms: (n_val > 0).then(|| rel_rms(&resid[n_tr..], &kept_y[n_tr..], &kept_y)),
    };
    let noise = noise_model(&power[..n_tr], &resid[..n_tr]);
    let kept_u: Vec<f64> = rows.iter().map(|&n| u[n]).collect();
    let spectrum = noise_spectrum(&resid, &kept_u, cfg.rate);
    Ok(Fitted { model, noise, spectrum, scores })
}

/// The settings and the series a fit can take: a memory within bounds, one
/// length, finite samples, a validation fraction below 0.9.
fn check_inputs(u: &[f64], y: &[f64], keep: &[bool], cfg: &FitConfig) -> Result<(), SynthError> {
    let m = cfg.memory;
    if m == 0 || m > MAX_MEMORY {
        return Err(SynthError::Config(format!("memory must be 1 ..= {MAX_MEMORY} samples, not {m}")));
    }
    if u.len() != y.len() || u.len() != keep.len() {
        return Err(SynthError::Data(format!(
            "the actuation ({}), force ({}) and gate ({}) have different lengths",
            u.len(),
            y.len(),
            keep.len()
        )));
    }
    if let Some(i) = u.iter().position(|v| !v.is_finite()) {
        return Err(SynthError::Data(format!("the actuation is not finite at sample {i}")));
    }
    if let Some(i) = y.iter().position(|v| !v.is_finite()) {
        return Err(SynthError::Data(format!("the force is not finite at sample {i}")));
    }
    if !(0.0..0.9).contains(&cfg.validation) {
        return Err(SynthError::Config(format!("validation must be in [0, 0.9), not {}", cfg.validation)));
    }
    Ok(())
}

/// Over the kept `rows`, the force (`kept_y`) must vary and the actuation
/// `u` must not be 0 throughout.
fn check_excitation(u: &[f64], rows: &[usize], kept_y: &[f64]) -> Result<(), SynthError> {
    let mean = kept_y.iter().sum::<f64>() / kept_y.len() as f64;
    if kept_y.iter().all(|v| (v - mean).abs() <= 1e-12 * mean.abs().max(1e-300)) {
        return Err(SynthError::Data(format!(
            "the force is constant ({mean}) over the kept samples: was the display on?"
        )));
    }
    let umax = rows.iter().map(|&n| u[n].abs()).fold(0.0, f64::max);
    if umax == 0.0 {
        return Err(SynthError::Data("the actuation is 0 over the kept samples: nothing excites the display".into()));
    }
    Ok(())
}

/// Φ: the regressor columns — u[n−i]·u[n−j] (i ≤ j), u[n−i], 1 — over the
/// whole series, filtered, then at the kept `rows`.
fn regressors(u: &[f64], rows: &[usize], cfg: &FitConfig) -> Array2<f64> {
    let m = cfg.memory;
    let p = m * (m + 1) / 2 + m + 1;
    let at = |k: isize| if k >= 0 { u[k as usize] } else { 0.0 };
    let mut col = vec![0.0; u.len()];
    let mut phi = Array2::<f64>::zeros((rows.len(), p));
    let mut fill = |c: usize, f: &dyn Fn(usize) -> f64, phi: &mut Array2<f64>| {
        for (n, v) in col.iter_mut().enumerate() {
            *v = f(n);
        }
        cfg.filter.apply_in_place(&mut col);
        for (r, &n) in rows.iter().enumerate() {
            phi[(r, c)] = col[n];
        }
    };
    for i in 0..m {
        for j in i..m {
            let c = upper_index(m, i, j);
            fill(c, &|n| at(n as isize - i as isize) * at(n as isize - j as isize), &mut phi);
        }
    }
    let q = m * (m + 1) / 2;
    for i in 0..m {
        fill(q + i, &|n| at(n as isize - i as isize), &mut phi);
    }
    fill(q + m, &|_| 1.0, &mut phi);
    phi
}

/// The local actuation power of each kept row (the noise model's
/// regressor): the mean of u² over `window` samples around it.
fn local_power(u: &[f64], rows: &[usize], window: usize) -> Vec<f64> {
    let w = window.max(1);
    let mut cum = vec![0.0; u.len() + 1];
    for (n, v) in u.iter().enumerate() {
        cum[n + 1] = cum[n] + v * v;
    }
    let local = |n: usize| {
        let a = n.saturating_sub(w / 2);
        let b = (n + w - w / 2).min(u.len());
        (cum[b] - cum[a]) / (b - a) as f64
    };
    rows.iter().map(|&n| local(n)).collect()
}

/// θ by ordinary least squares on the first `n_tr` rows, then (with
/// `reweight`) weighted by the inverse residual variance at each row's
/// actuation `power`.
fn coefficients(
    phi: &Array2<f64>,
    kept_y: &[f64],
    power: &[f64],
    n_tr: usize,
    cfg: &FitConfig,
) -> Result<Vec<f64>, SynthError> {
    let p = phi.ncols();
    let mut weights = vec![1.0; n_tr];
    let mut th = solve(phi, kept_y, &weights, n_tr, cfg.ridge)?;
    if cfg.reweight {
        let resid: Vec<f64> = (0..n_tr).map(|r| kept_y[r] - (0..p).map(|k| phi[(r, k)] * th[k]).sum::<f64>()).collect();
        weights = inverse_variance(&power[..n_tr], &resid);
        th = solve(phi, kept_y, &weights, n_tr, cfg.ridge)?;
    }
    Ok(th)
}

/// The noise model: the squared residuals `resid` of the fitted rows
/// regressed on their local actuation `power`, r² ≈ σ₀² + β·p (both ≥ 0).
fn noise_model(power: &[f64], resid: &[f64]) -> NoiseModel {
    let (mut sx, mut sy, mut sxx, mut sxy) = (0.0, 0.0, 0.0, 0.0);
    for r in 0..resid.len() {
        let (x, e2) = (power[r], resid[r] * resid[r]);
        sx += x;
        sy += e2;
        sxx += x * x;
        sxy += x * e2;
    }
    let nn = resid.len() as f64;
    let var = sxx - sx * sx / nn;
    let beta = if var > 1e-12 * sxx.max(f64::MIN_POSITIVE) { (sxy - sx * sy / nn) / var } else { 0.0 };
    let beta = beta.max(0.0);
    let floor = ((sy - beta * sx) / nn).max(0.0);
    NoiseModel { floor_n2: floor, per_u2_n2: beta }
}

/// ‖resid‖ / ‖y‖: the relative RMS error of rows whose force is `y` and
/// residual `resid`. The sums of squares are scaled where plain ones
/// would over- or underflow ([`SumSq`]), so a subnormal force has its true
/// relative error, not 0/0. Where `y` is exactly 0 on every row it is
/// relative to the RMS force over `all` the kept rows instead: rms(resid)
/// / rms(all) (the fit refuses a constant force, so that is not 0).
pub fn rel_rms(resid: &[f64], y: &[f64], all: &[f64]) -> f64 {
    let sum_sq = |v: &[f64]| {
        let mut q = SumSq::<f64>::default();
        v.iter().for_each(|&x| q.add(x));
        q
    };
    let (e, s) = (sum_sq(resid), sum_sq(y));
    if s.is_zero() {
        e.root_mean(resid.len() as f64).ratio(sum_sq(all).root_mean(all.len() as f64))
    } else {
        e.sqrt_ratio(&s)
    }
}

/// Solves the (weighted, ridge-stabilized) normal equations on the first
/// `n_tr` rows.
fn solve(phi: &Array2<f64>, y: &[f64], weights: &[f64], n_tr: usize, ridge: f64) -> Result<Vec<f64>, SynthError> {
    let p = phi.ncols();
    let wphi = Array2::<f64>::from_shape_fn((n_tr, p), |(r, k)| phi[(r, k)] * weights[r].sqrt());
    let wy = Array1::<f64>::from_shape_fn(n_tr, |r| y[r] * weights[r].sqrt());
    // AᵀA's lower triangle (what the factorization reads) and Aᵀy.
    let mut ata = Array2::<f64>::zeros((p, p));
    add_lower_gram(&mut ata, wphi.view(), false);
    let aty = wphi.t().dot(&wy);
    let mean_diag = (0..p).map(|k| ata[(k, k)]).sum::<f64>() / p as f64;
    let delta = ridge.max(0.0) * mean_diag.max(f64::MIN_POSITIVE);
    for k in 0..p {
        ata[(k, k)] += delta;
    }
    let llt = Cholesky::factor(&ata)
        .map_err(|_| SynthError::Data("the regressors are degenerate (raise `ridge` or vary the excitation)".into()))?;
    let th = llt.solve(aty.as_slice().expect("a new vector is contiguous"));
    if th.iter().any(|v| !v.is_finite()) {
        return Err(SynthError::Data("the fit is not finite (raise `ridge`)".into()));
    }
    Ok(th)
}

/// Power bins of the reweighting.
const BINS: usize = 8;

/// 1/σ² per row, σ² the mean squared residual of the rows whose actuation
/// power falls in the same of [`BINS`] equally populated bins, normalized
/// to a mean weight of 1.
fn inverse_variance(power: &[f64], resid: &[f64]) -> Vec<f64> {
    let n = power.len();
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| power[a].total_cmp(&power[b]));
    let mut w = vec![1.0; n];
    let per = n.div_ceil(BINS).max(1);
    for chunk in order.chunks(per) {
        let var = chunk.iter().map(|&i| resid[i] * resid[i]).sum::<f64>() / chunk.len() as f64;
        for &i in chunk {
            w[i] = if var > 0.0 { 1.0 / var } else { 1.0 };
        }
    }
    let mean = w.iter().sum::<f64>() / n.max(1) as f64;
    w.iter_mut().for_each(|v| *v /= mean);
    w
}

/// What [`fit`] finds.
#[derive(Debug, Clone, PartialEq)]
pub struct Fitted {
    /// The model.
    pub model: Volterra,
    /// Residual power against local actuation power.
    pub noise: NoiseModel,
    /// Residual spectrum against actuation power (None: too few samples for
    /// three one-second segments).
    pub spectrum: Option<NoiseSpectrum>,
    /// How well it fits.
    pub scores: FitScores,
}

/// Bins on each side averaged when the noise spectrum is smoothed.
const SMOOTH: usize = 4;

/// The residual's spectrum against the actuation power: Hann-windowed,
/// half-overlapping one-second segments of the kept residual `r` (with the
/// kept actuation `u` beside it); per bin, |DFT|²/Σw² regressed on the
/// segment's window-weighted mean u² (P_k = p0_k + p·p1_k, both ≥ 0),
/// then smoothed over ±4 bins.
pub fn noise_spectrum(r: &[f64], u: &[f64], rate: f64) -> Option<NoiseSpectrum> {
    use rustfft::num_complex::Complex;
    let nfft = rate.round() as usize;
    if nfft < 8 || r.len() < 2 * nfft {
        return None;
    }
    let hop = nfft / 2;
    let w = crate::metric::spectrum::Window::Hann.coefficients(nfft);
    let energy: f64 = w.iter().map(|v| v * v).sum();
    let fft = evflow_dsp::fft::forward(nfft);
    let bins = nfft / 2 + 1;
    let (mut powers, mut ps) = (Vec::new(), Vec::new());
    let mut buf = vec![Complex::default(); nfft];
    let mut start = 0;
    while start + nfft <= r.len() {
        for n in 0..nfft {
            buf[n] = Complex::new(w[n] * r[start + n], 0.0);
        }
        fft.process(&mut buf);
        powers.push(buf[..bins].iter().map(|c| c.norm_sqr() / energy).collect::<Vec<f64>>());
        ps.push((0..nfft).map(|n| w[n] * w[n] * u[start + n] * u[start + n]).sum::<f64>() / energy);
        start += hop;
    }
    if powers.len() < 3 {
        return None;
    }
    let m = ps.len() as f64;
    let pm = ps.iter().sum::<f64>() / m;
    let var: f64 = ps.iter().map(|p| (p - pm) * (p - pm)).sum();
    let (mut p0, mut p1) = (vec![0.0; bins], vec![0.0; bins]);
    for k in 0..bins {
        let ym = powers.iter().map(|pw| pw[k]).sum::<f64>() / m;
        let slope = if var > 1e-12 * pm.max(1e-300) * pm.max(1e-300) * m {
            powers.iter().zip(&ps).map(|(pw, p)| (p - pm) * (pw[k] - ym)).sum::<f64>() / var
        } else {
            0.0
        };
        let slope = slope.max(0.0);
        p1[k] = slope;
        p0[k] = (ym - slope * pm).max(0.0);
    }
    let smooth = |v: &[f64]| -> Vec<f64> {
        (0..v.len())
            .map(|k| {
                let (a, b) = (k.saturating_sub(SMOOTH), (k + SMOOTH + 1).min(v.len()));
                v[a..b].iter().sum::<f64>() / (b - a) as f64
            })
            .collect()
    };
    Some(NoiseSpectrum { nfft, p0: smooth(&p0), p1: smooth(&p1) })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    /// A square-law "display": v = g * u (FIR), y = v² + 0.1·v + 0.02, then
    /// the output filter. Its exact Volterra kernel is H = g gᵀ, l = 0.1 g.
    fn plant(u: &[f64], g: &[f64], filter: &OutputFilter) -> Vec<f64> {
        let mut y: Vec<f64> = (0..u.len())
            .map(|n| {
                let v: f64 = g.iter().enumerate().filter(|(i, _)| *i <= n).map(|(i, gi)| gi * u[n - i]).sum();
                v * v + 0.1 * v + 0.02
            })
            .collect();
        filter.apply_in_place(&mut y);
        y
    }

    #[test]
    fn recovers_the_kernel_of_a_square_law_behind_a_filter_exactly() {
        let g = [0.9, -0.4, 0.2, 0.05];
        let mut r = Rng::new(9);
        let levels = [-1.0, -0.5, 0.0, 0.5, 1.0];
        let u: Vec<f64> = (0..3000).map(|_| levels[(r.uniform() * 5.0) as usize % 5]).collect();
        for filter in [OutputFilter::none(), OutputFilter::highpass(4, 10.0, 1000.0).unwrap()] {
            let y = plant(&u, &g, &filter);
            let keep: Vec<bool> = (0..u.len()).map(|n| n >= 200).collect();
            let cfg = FitConfig { memory: 6, filter: filter.clone(), ..FitConfig::default() };
            let Fitted { model: v, noise, scores: s, .. } = fit(&u, &y, &keep, &cfg).unwrap();
            for i in 0..6 {
                for j in 0..6 {
                    let want = if i < 4 && j < 4 { g[i] * g[j] } else { 0.0 };
                    assert!((v.quadratic(i, j) - want).abs() < 1e-6, "H[{i}][{j}] {} vs {want}", v.quadratic(i, j));
                }
                let want = if i < 4 { 0.1 * g[i] } else { 0.0 };
                assert!((v.linear()[i] - want).abs() < 1e-6, "l[{i}]");
            }
            assert!(s.validation_rel_rms.unwrap() < 1e-6 && s.train_rel_rms < 1e-6, "{s:?}");
            assert!(noise.per_u2_n2 < 1e-12 && noise.floor_n2 < 1e-12, "{noise:?}");
        }
    }

    #[test]
    fn the_noise_model_finds_noise_that_grows_with_the_actuation_power() {
        // Residual noise of variance 1e-4 + 4e-4·u² (in blocks of steady power).
        let g = [1.0, 0.5];
        let mut r = Rng::new(11);
        let n = 20000;
        let amp: Vec<f64> = (0..n).map(|k| [0.2, 0.5, 0.8][(k / 400) % 3]).collect();
        let u: Vec<f64> = (0..n).map(|k| amp[k] * (2.0 * r.uniform() - 1.0)).collect();
        let filter = OutputFilter::none();
        let mut y = plant(&u, &g, &filter);
        // Noise driven by the block's mean power (the uniform law: E u² = a²/3).
        for k in 0..n {
            let p = amp[k] * amp[k] / 3.0;
            y[k] += (1e-4 + 4e-4 * p).sqrt() * r.gaussian();
        }
        let keep = vec![true; n];
        let cfg = FitConfig { memory: 3, noise_window: 101, ..FitConfig::default() };
        let noise = fit(&u, &y, &keep, &cfg).unwrap().noise;
        assert!((noise.per_u2_n2 / 4e-4 - 1.0).abs() < 0.2, "{noise:?}");
        assert!((noise.floor_n2 / 1e-4 - 1.0).abs() < 0.2, "{noise:?}");
    }

    #[test]
    fn relative_errors_are_defined_for_a_subnormal_force_and_without_held_out_rows() {
        let g = [0.9, -0.4];
        let levels = [-1.0, -0.5, 0.0, 0.5, 1.0];
        let mut r = Rng::new(3);
        let u: Vec<f64> = (0..1000).map(|_| levels[(r.uniform() * 5.0) as usize % 5]).collect();
        let y = plant(&u, &g, &OutputFilter::none());
        let keep = vec![true; u.len()];
        // validation = 0 holds nothing out: no validation error (was NaN).
        let cfg = FitConfig { memory: 3, validation: 0.0, ..FitConfig::default() };
        let s = fit(&u, &y, &keep, &cfg).unwrap().scores;
        assert_eq!((s.validation_rows, s.validation_rel_rms), (0, None));
        assert!(s.train_rel_rms < 1e-6, "{s:?}");
        // A subnormal force: its squares underflow to 0 (0/0 was NaN).
        let tiny = [5e-324, -5e-324, f64::MIN_POSITIVE / 3.0, -f64::MIN_POSITIVE / 7.0, f64::MIN_POSITIVE];
        let y: Vec<f64> = (0..1000).map(|n| tiny[n % 5]).collect();
        let cfg = FitConfig { memory: 3, ..FitConfig::default() };
        let s = fit(&u, &y, &keep, &cfg).unwrap().scores;
        let (t, v) = (s.train_rel_rms, s.validation_rel_rms.unwrap());
        assert!(t.is_finite() && v.is_finite() && t >= 0.0 && v >= 0.0, "{s:?}");
        // The definition, on rows of known values: plain, subnormal, zero force.
        assert_eq!(rel_rms(&[3.0, 4.0], &[6.0, 8.0], &[6.0, 8.0]), 0.5);
        let small = [3e-320, 4e-320];
        assert_eq!(rel_rms(&small, &small.map(|v| 2.0 * v), &[1.0]), 0.5);
        // rms [3, 4] / rms [0, 0, 10, 10] = √12.5 / √50.
        assert_eq!(rel_rms(&[3.0, 4.0], &[0.0, 0.0], &[0.0, 0.0, 10.0, 10.0]), 0.5);
    }

    #[test]
    fn unusable_data_is_refused_with_a_reason() {
        let cfg = FitConfig::default();
        let u = vec![0.5; 100];
        let y = vec![0.1; 100];
        let keep = vec![true; 100];
        let e = fit(&u, &y, &keep, &cfg).unwrap_err().to_string();
        assert!(e.contains("kept samples give"), "{e}");
        let u: Vec<f64> = (0..5000).map(|k| (k as f64).sin()).collect();
        let e = fit(&u, &vec![0.3; 5000], &vec![true; 5000], &cfg).unwrap_err().to_string();
        assert!(e.contains("constant"), "{e}");
        let mut y: Vec<f64> = u.clone();
        y[7] = f64::NAN;
        let e = fit(&u, &y, &vec![true; 5000], &cfg).unwrap_err().to_string();
        assert!(e.contains("sample 7"), "{e}");
        assert!(fit(&u, &u, &[true; 10], &cfg).is_err(), "lengths");
        let zero = FitConfig { memory: 0, ..FitConfig::default() };
        assert!(fit(&u, &u, &vec![true; 5000], &zero).is_err());
    }
}
