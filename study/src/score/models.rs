//! "The twin made from the lab's forward models": a display that is
//! nothing but a library's forward models (`models/forward-TAG.json`,
//! second-order Volterra series identified from the display's stepped
//! multilevel excitation, [`evflow_nodes::synth::volterra`]) blended at the
//! finger's true load and speed as `synth.live` blends them — bilinearly on
//! the grid of trained (load, speed), clamped to its corners
//! ([`evflow_nodes::synth::live::envelope::ModelGrid`]) — here at every
//! sample, in the direction friction takes:
//!
//! ```text
//! F[k] = s(v[k]) · Σ_c w_c(N[k], |v[k]|) · (V_c(u)[k] − c_c)
//! ```
//!
//! V_c the model of condition c over the whole actuation, c_c its constant
//! (not identified: the 10 Hz high-pass the models were fitted through
//! removes it), s the direction of motion (+1 forwards or at rest, −1
//! backwards: the models were identified sliding forwards). What it leaves
//! out, said plainly: the display's own friction without actuation (the
//! models know only what the actuation adds — "nothing" renders no force
//! at all), its noise (not drawn), stick–slip and everything above second
//! order (docs/score.md).
//!
//! The display is differentiable exactly: ∂F/∂u is each model's gradient
//! ([`Volterra::eval_grad`]) weighted alike, so the floors are optimized
//! through the very display they are played on — the twin is the display —
//! with the stroke's floor's objective, starts and optimizer
//! ([`crate::live::floor`]): E_s² in the Welch reading of the high-passed
//! force against the goal, L-BFGS-B within |u| ≤ 1.

use crate::live::floor::{from_starts_goals, Candidate, Goal, Seeds};
use crate::live::stroke::Stroke;
use crate::starts::Objective;
use crate::StudyError;
use evflow_nodes::metric::spectral_error::Band;
use evflow_nodes::metric::spectrum::{SpectrumConfig, Window};
use evflow_nodes::synth::live::envelope::{bracket, EnvelopeModel, ModelGrid};
use evflow_nodes::synth::model_file::ForwardModel;
use evflow_nodes::synth::output_filter::OutputFilter;
use evflow_nodes::synth::spectral::SpectralTarget;
use evflow_nodes::synth::volterra::Volterra;
use std::path::{Path, PathBuf};

/// A display made of forward models over a grid of trained conditions.
#[derive(Debug, Clone)]
pub struct ForwardDisplay {
    /// The model files, in the order given.
    pub files: Vec<PathBuf>,
    /// The models of a folder left out of its grid (off the largest
    /// rectangular grid its models cover, e.g. a library's centre model).
    pub left_out: Vec<PathBuf>,
    /// Trained loads, g, ascending.
    loads: Vec<f64>,
    /// Trained speeds, cm/s, ascending.
    speeds: Vec<f64>,
    /// The models, load-major (index = i_load · speeds + i_speed).
    models: Vec<Volterra>,
    /// The models' rate, Hz.
    pub rate: f64,
}

/// +1 moving forwards or at rest, −1 backwards (as the target's floor's goal).
fn direction(v: f64) -> f64 {
    if v < 0.0 {
        -1.0
    } else {
        1.0
    }
}

impl ForwardDisplay {
    /// The forward models `files` (or, for a folder, its `forward-*.json`,
    /// or its `models/forward-*.json`: a library), checked as `synth.live`
    /// checks them: each with its condition, one per (load, speed), every
    /// combination present, one memory, one rate.
    pub fn load(files: &[PathBuf]) -> Result<Self, StudyError> {
        let (files, from_folder) = expand(files)?;
        let (files, left_out) = if from_folder { largest_grid(files)? } else { (files, Vec::new()) };
        let mut entries = Vec::with_capacity(files.len());
        let mut raw = Vec::with_capacity(files.len());
        let mut rate = None;
        for f in &files {
            let fm = ForwardModel::load(f)?;
            let (Some(mass), Some(speed)) = (fm.condition.mass_g, fm.condition.speed_cm_s) else {
                return Err(StudyError::Config(format!(
                    "{}: field `condition`: the model records no mass_g and speed_cm_s, so it has no place in the \
                     grid (identify it with forward.train's mass_g and speed_cm_s set)",
                    f.display()
                )));
            };
            match rate {
                None => rate = Some(fm.rate_hz),
                Some(r) if (fm.rate_hz - r).abs() > 1e-9 * r => {
                    return Err(StudyError::Config(format!(
                        "{}: identified at {} Hz, {} at {r} Hz: the models of one display share their rate",
                        f.display(),
                        fm.rate_hz,
                        files[0].display()
                    )))
                }
                Some(_) => {}
            }
            let v = fm.volterra()?;
            entries.push(((mass, speed.abs()), EnvelopeModel::of(&v, fm.noise.per_u2_n2)));
            raw.push(((mass, speed.abs()), v));
        }
        let names: Vec<String> = files.iter().map(|f| f.display().to_string()).collect();
        // The same grid `synth.live` would build, refused for the same reasons.
        let grid = ModelGrid::new(entries, &names)?;
        let (loads, speeds) = (grid.axes().0.to_vec(), grid.axes().1.to_vec());
        let mut models = Vec::with_capacity(loads.len() * speeds.len());
        for &l in &loads {
            for &s in &speeds {
                let v = raw.iter().find(|(c, _)| *c == (l, s)).expect("the grid holds every combination");
                models.push(v.1.clone());
            }
        }
        Ok(Self { files, left_out, loads, speeds, models, rate: rate.expect("at least one model") })
    }

    /// The trained loads (g) and speeds (cm/s).
    pub fn axes(&self) -> (&[f64], &[f64]) {
        (&self.loads, &self.speeds)
    }

    /// The weight of every model at `load` g and `speed` cm/s (bilinear,
    /// clamped; they sum to 1).
    pub fn weights(&self, load_g: f64, speed_cm_s: f64) -> Vec<f64> {
        let (l0, l1, wl) = bracket(&self.loads, load_g);
        let (s0, s1, ws) = bracket(&self.speeds, speed_cm_s.abs());
        let ns = self.speeds.len();
        let mut w = vec![0.0; self.models.len()];
        w[l0 * ns + s0] += (1.0 - wl) * (1.0 - ws);
        w[l0 * ns + s1] += (1.0 - wl) * ws;
        w[l1 * ns + s0] += wl * (1.0 - ws);
        w[l1 * ns + s1] += wl * ws;
        w
    }

    /// Every model's signed weight along `path`: w_c at the finger's load
    /// and speed, times its direction of motion, per sample.
    pub fn along(&self, path: &Stroke) -> Vec<Vec<f64>> {
        let mut out = vec![vec![0.0; path.len()]; self.models.len()];
        for (k, (load, v)) in path.load.iter().zip(&path.velocity).enumerate() {
            let w = self.weights(load * G_PER_N, v * 100.0);
            for (c, wc) in w.iter().enumerate() {
                out[c][k] = direction(*v) * wc;
            }
        }
        out
    }

    /// The display's force for `u` along the path whose signed weights are `along`, N.
    pub fn force(&self, u: &[f64], along: &[Vec<f64>]) -> Vec<f64> {
        let n = u.len();
        let mut f = vec![0.0; n];
        let mut y = vec![0.0; n];
        for (m, w) in self.models.iter().zip(along) {
            if w.iter().all(|x| *x == 0.0) {
                continue;
            }
            m.eval(u, &mut y);
            let c = m.constant();
            for k in 0..n {
                f[k] += w[k] * (y[k] - c);
            }
        }
        f
    }

    /// [`ForwardDisplay::force`], and the gradient of Σ_k f̄\[k\]·F\[k\]
    /// with respect to every u\[k\] into `g` (overwritten).
    pub fn force_grad(&self, u: &[f64], along: &[Vec<f64>], fbar: &[f64], g: &mut [f64]) -> Vec<f64> {
        let n = u.len();
        let mut f = vec![0.0; n];
        let mut y = vec![0.0; n];
        let mut ybar = vec![0.0; n];
        g.iter_mut().for_each(|x| *x = 0.0);
        for (m, w) in self.models.iter().zip(along) {
            if w.iter().all(|x| *x == 0.0) {
                continue;
            }
            for k in 0..n {
                ybar[k] = w[k] * fbar[k];
            }
            m.eval_grad(u, &ybar, &mut y, g);
            let c = m.constant();
            for k in 0..n {
                f[k] += w[k] * (y[k] - c);
            }
        }
        f
    }

    /// Optimizes the stroke's actuation through this display towards
    /// `goal` as [`crate::live::floor::optimize_towards`] does through a
    /// lab profile's twin: the carrier starts at [`crate::live::floor::START_OFFSETS`] with
    /// this display's carrier gain on the stroke, and every seed (clipped
    /// to |u| ≤ 1, cut or padded with 0), `iterations` each.
    pub fn optimize(
        &self,
        path: &Stroke,
        goal: &Goal,
        seeds: &[(String, Vec<f64>)],
        iterations: usize,
    ) -> Result<Vec<Candidate>, StudyError> {
        let mut each = self.optimize_goals(path, &[(goal, seeds)], iterations)?;
        Ok(each.pop().map(|(c, _)| c).unwrap_or_default())
    }

    /// [`Self::optimize`] towards each `(goal, seeds)`, every goal's starts
    /// in one queue as [`crate::live::floor::optimize_goals`] runs them:
    /// each goal's candidates the ones it reaches alone, with its share of
    /// the evaluations.
    pub fn optimize_goals(
        &self,
        path: &Stroke,
        goals: &[(&Goal, &Seeds)],
        iterations: usize,
    ) -> Result<Vec<(Vec<Candidate>, f64)>, StudyError> {
        let rate = path.rate;
        let nfft = rate.round() as usize;
        let cfg = SpectrumConfig { rate, nfft, window: Window::Hann, overlap: 0.5 };
        let band = Band::new(rate, nfft, 2.0, 200.0, false).map_err(|e| StudyError::Config(e.message))?;
        let mut targets = Vec::with_capacity(goals.len());
        for (goal, _) in goals {
            targets.push(SpectralTarget::new(&goal.highpassed, cfg, band)?);
        }
        let mut chain = Chain {
            display: self,
            along: self.along(path),
            filter: OutputFilter::highpass(4, 10.0, rate)?,
            targets,
            y: Vec::new(),
        };
        let kappa = chain.carrier_gain(path);
        let each: Vec<(&[f64], &Seeds)> = goals.iter().map(|(g, s)| (g.magnitude.as_slice(), *s)).collect();
        from_starts_goals(&mut chain, &each, kappa, path.len(), iterations)
    }
}

/// Grams per newton (the load cell's N to the grid's g, as the chain converts).
pub const G_PER_N: f64 = 101.97162129779282;

/// The display and the high-pass of one stroke, and the target of each
/// goal optimized towards.
struct Chain<'a> {
    display: &'a ForwardDisplay,
    along: Vec<Vec<f64>>,
    filter: OutputFilter,
    targets: Vec<SpectralTarget>,
    y: Vec<f64>,
}

impl Objective for Chain<'_> {
    fn value(&mut self, u: &[f64]) -> f64 {
        self.value_of(0, u)
    }
    fn value_grad(&mut self, u: &[f64], g: &mut [f64]) -> f64 {
        self.value_grad_of(0, u, g)
    }
    fn value_of(&mut self, goal: usize, u: &[f64]) -> f64 {
        let mut y = self.display.force(u, &self.along);
        self.filter.apply_in_place(&mut y);
        self.targets[goal].es(&y).powi(2)
    }
    /// One point after the other (the forward models run no lanes).
    fn value_grad_each_of(&mut self, goals: &[usize], u: &[&[f64]], g: &mut [&mut [f64]], fx: &mut [f64]) {
        for (((goal, u), g), fx) in goals.iter().zip(u).zip(g.iter_mut()).zip(fx.iter_mut()) {
            *fx = self.value_grad_of(*goal, u, g);
        }
    }
}

impl Chain<'_> {
    /// J towards goal `goal` at `u`, ∂J/∂u into `g`.
    fn value_grad_of(&mut self, goal: usize, u: &[f64], g: &mut [f64]) -> f64 {
        // The forward pass first, for the objective's gradient with respect to the force.
        let mut y = self.display.force(u, &self.along);
        self.filter.apply_in_place(&mut y);
        self.y.resize(y.len(), 0.0);
        let j = self.targets[goal].value_grad(&y, &mut self.y);
        self.filter.adjoint_in_place(&mut self.y);
        let fbar = std::mem::take(&mut self.y);
        self.display.force_grad(u, &self.along, &fbar, g);
        self.y = fbar;
        j
    }

    /// The steady friction a unit Nyquist-rate carrier adds on this stroke
    /// in the direction of motion, N (as the stroke's floor measures it).
    fn carrier_gain(&mut self, path: &Stroke) -> f64 {
        let n = path.len();
        let unit: Vec<f64> = (0..n).map(|k| if k % 2 == 0 { 1.0 } else { -1.0 }).collect();
        let on = self.display.force(&unit, &self.along);
        let off = self.display.force(&vec![0.0; n], &self.along);
        let v = &path.velocity;
        let moving: Vec<usize> = (0..n).filter(|&k| v[k] != 0.0).collect();
        let s: f64 = moving.iter().map(|&k| (on[k] - off[k]) * v[k].signum()).sum();
        s / moving.len().max(1) as f64
    }
}

/// The condition of a model file (g, |cm/s|), or an error naming it.
fn condition_of(f: &Path) -> Result<(f64, f64), StudyError> {
    let fm = ForwardModel::load(f)?;
    match (fm.condition.mass_g, fm.condition.speed_cm_s) {
        (Some(m), Some(s)) => Ok((m, s.abs())),
        _ => Err(StudyError::Config(format!(
            "{}: field `condition`: the model records no mass_g and speed_cm_s, so it has no place in the grid",
            f.display()
        ))),
    }
}

/// The files of the largest rectangular grid (every load × every speed
/// present) the models of a folder cover, and the others: a library holds
/// the corners of its grid and its centre (60/110 g × 3/7 cm/s and 85 g,
/// 5 cm/s), and `synth.live` blends the corners.
fn largest_grid(files: Vec<PathBuf>) -> Result<(Vec<PathBuf>, Vec<PathBuf>), StudyError> {
    let conds = files.iter().map(|f| condition_of(f)).collect::<Result<Vec<_>, _>>()?;
    let mut loads: Vec<f64> = Vec::new();
    for c in &conds {
        if !loads.contains(&c.0) {
            loads.push(c.0);
        }
    }
    loads.sort_by(f64::total_cmp);
    if loads.len() > 16 {
        return Ok((files, Vec::new()));
    }
    let mut best: (usize, u32, Vec<f64>) = (0, 0, Vec::new());
    for mask in 1u32..(1 << loads.len()) {
        let chosen: Vec<f64> = (0..loads.len()).filter(|i| mask & (1 << i) != 0).map(|i| loads[i]).collect();
        let mut speeds: Vec<f64> = conds.iter().filter(|c| c.0 == chosen[0]).map(|c| c.1).collect();
        speeds.retain(|s| chosen.iter().all(|l| conds.contains(&(*l, *s))));
        speeds.sort_by(f64::total_cmp);
        speeds.dedup();
        let size = chosen.len() * speeds.len();
        if size > best.0 {
            best = (size, mask, speeds);
        }
    }
    let (_, mask, speeds) = best;
    let keep = |c: &(f64, f64)| {
        loads.iter().enumerate().any(|(i, l)| mask & (1 << i) != 0 && *l == c.0) && speeds.contains(&c.1)
    };
    let (mut inside, mut outside) = (Vec::new(), Vec::new());
    for (f, c) in files.into_iter().zip(&conds) {
        // A second model at a condition already kept goes to the grid too: the grid refuses it by name.
        if keep(c) {
            inside.push(f);
        } else {
            outside.push(f);
        }
    }
    Ok((inside, outside))
}

/// The model files named by `items`: files as they are; a folder gives its
/// `forward-*.json`, or its `models/forward-*.json` (a library's layout).
/// Also whether a folder was named.
fn expand(items: &[PathBuf]) -> Result<(Vec<PathBuf>, bool), StudyError> {
    let mut out = Vec::new();
    let mut folder = false;
    for item in items {
        folder |= item.is_dir();
        if !item.is_dir() {
            if !item.is_file() {
                return Err(StudyError::Missing(item.clone()));
            }
            out.push(item.clone());
            continue;
        }
        let mut found = forward_files(item)?;
        if found.is_empty() && item.join("models").is_dir() {
            found = forward_files(&item.join("models"))?;
        }
        if found.is_empty() {
            return Err(StudyError::Config(format!(
                "{}: no forward-*.json here nor in its models/ folder (a library's layout: `evflow library build`, \
                 or graphs/forward-build-recordings.toml from a rig's excitation recordings)",
                item.display()
            )));
        }
        out.extend(found);
    }
    if out.is_empty() {
        return Err(StudyError::Config("name at least one forward model or library folder".into()));
    }
    Ok((out, folder))
}

fn forward_files(dir: &Path) -> Result<Vec<PathBuf>, StudyError> {
    let read = std::fs::read_dir(dir).map_err(|e| StudyError::Io { path: dir.into(), message: e.to_string() })?;
    let mut v: Vec<PathBuf> = read
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            let name = p.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
            name.starts_with("forward-") && name.ends_with(".json") && p.is_file()
        })
        .collect();
    v.sort();
    Ok(v)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::live::scope::User;

    fn shipped() -> ForwardDisplay {
        let lib = Path::new(env!("CARGO_MANIFEST_DIR")).join("../graphs/data");
        ForwardDisplay::load(&[lib]).unwrap()
    }

    #[test]
    fn the_library_folder_gives_its_grid_blended_as_synth_live_blends_it() {
        let d = shipped();
        assert_eq!(d.files.len(), 4);
        assert_eq!(d.left_out.len(), 1, "the centre model is off the grid");
        assert!(d.left_out[0].ends_with("forward-85g-5cms.json"));
        assert_eq!(d.axes(), (&[60.0, 110.0][..], &[3.0, 7.0][..]));
        // The weights blend the models' carrier gains as synth.live's grid does.
        let names: Vec<String> = d.files.iter().map(|f| f.display().to_string()).collect();
        let entries = d.files.iter().map(|f| {
            let fm = ForwardModel::load(f).unwrap();
            let c = (fm.condition.mass_g.unwrap(), fm.condition.speed_cm_s.unwrap());
            (c, EnvelopeModel::of(&fm.volterra().unwrap(), 0.0))
        });
        let grid = ModelGrid::new(entries.collect(), &names).unwrap();
        let mut at = EnvelopeModel::zeros(d.models[0].memory());
        for (load, speed) in [(60.0, 3.0), (85.0, 4.0), (200.0, -9.0), (10.0, 5.5), (f64::NAN, 2.0)] {
            grid.at(load, speed, &mut at);
            let w = d.weights(load, speed);
            assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-12);
            let kappa: f64 = w.iter().zip(&d.models).map(|(w, m)| w * m.carrier_gain()).sum();
            assert!((kappa - at.kappa).abs() < 1e-12 * at.kappa.abs().max(1e-9), "{load} g {speed} cm/s");
        }
    }

    #[test]
    fn the_gradient_is_the_force_s_derivative_and_the_floor_never_rises() {
        let d = shipped();
        let user = User { name: "t".into(), seed: 5, speed: [3.0, 7.0], mass: [60.0, 110.0], travel_cm: 8.0 };
        let path = Stroke::of(&user, "plastic-sheet", 2.0, 1000.0).unwrap();
        let along = d.along(&path);
        let n = path.len();
        let u: Vec<f64> = (0..n).map(|k| 0.5 * (k as f64 * 0.37).sin()).collect();
        let fbar: Vec<f64> = (0..n).map(|k| (k as f64 * 0.011).cos()).collect();
        let mut g = vec![0.0; n];
        let f = d.force_grad(&u, &along, &fbar, &mut g);
        assert_eq!(f, d.force(&u, &along));
        let j = |u: &[f64]| d.force(u, &along).iter().zip(&fbar).map(|(a, b)| a * b).sum::<f64>();
        for k in [0, 17, 500, 1999] {
            let h = 1e-6;
            let (mut up, mut dn) = (u.clone(), u.clone());
            up[k] += h;
            dn[k] -= h;
            let fd = (j(&up) - j(&dn)) / (2.0 * h);
            assert!((fd - g[k]).abs() < 1e-6 * (1.0 + fd.abs()), "sample {k}: {fd} vs {}", g[k]);
        }
        // Backwards the force turns over: friction opposes the motion.
        let back = (0..n).find(|&k| path.velocity[k] < -0.01).unwrap();
        let unit: Vec<f64> = (0..n).map(|k| if k % 2 == 0 { 0.8 } else { -0.8 }).collect();
        let fu = d.force(&unit, &along);
        let fwd = (0..n).find(|&k| path.velocity[k] > 0.01 && k > 100).unwrap();
        assert!(fu[fwd] > 0.0 && fu[back] < 0.0, "{} {}", fu[fwd], fu[back]);
        // The floor through the models: never above its starts, within |u| ≤ 1.
        let real = Goal::real(&path).unwrap();
        let seeds = [("seed".to_string(), unit)];
        let c = d.optimize(&path, &real, &seeds, 4).unwrap();
        assert_eq!(c.len(), 3);
        for cand in &c {
            assert!(cand.objective <= cand.start_objective, "{}", cand.start);
            assert!(cand.u.iter().all(|x| x.abs() <= 1.0));
        }
        // Two goals in one queue: each goal's candidates as alone.
        let wanted: Vec<f64> = (0..n).map(|k| 0.05 + 0.02 * (k as f64 * 0.09).sin()).collect();
        let target = Goal::chain_target(&path, &wanted).unwrap();
        let alone = d.optimize(&path, &target, &seeds, 4).unwrap();
        let both = d.optimize_goals(&path, &[(&target, &seeds), (&real, &seeds)], 4).unwrap();
        assert_eq!(both[0].0, alone);
        assert_eq!(both[1].0, c);
        assert_ne!(alone[2].u, c[2].u, "the goals differ");
    }

    #[test]
    fn a_folder_without_models_and_an_incomplete_grid_are_refused_by_name() {
        let dir = tempfile::tempdir().unwrap();
        let e = ForwardDisplay::load(&[dir.path().to_path_buf()]).unwrap_err().to_string();
        assert!(e.contains("no forward-*.json") && e.contains(&dir.path().display().to_string()), "{e}");
        let lib = Path::new(env!("CARGO_MANIFEST_DIR")).join("../graphs/data/models");
        let e = ForwardDisplay::load(&[lib.join("forward-60g-3cms.json"), lib.join("forward-110g-7cms.json")])
            .unwrap_err()
            .to_string();
        assert!(e.contains("no model at"), "{e}");
        let e = ForwardDisplay::load(&[lib.join("forward-1g-1cms.json")]).unwrap_err().to_string();
        assert!(e.contains("forward-1g-1cms.json"), "{e}");
    }
}
