//! `grain`: the actuation waveforms of the two haptic grains of
//! dissertation Fig. 4.3 — AREA-EVEN for the surface gradient and
//! EDGE-TICK for sharp edges — scaled by their intensities.

use evflow_engine::node::Constant;
use evflow_engine::ports::{InPort, OutPort};
use evflow_engine::spec::{BoundArgs, FoldArgs, PortBound};
use evflow_engine::typed_params::{Float, Words};
use evflow_engine::{BuildContext, Io, Node, NodeError, NodeSpec, Params, PortSpec, Role};
use std::f64::consts::TAU;

/// Partials of EDGE-TICK relative to `tick_frequency`, and their weights.
pub const TICK_RATIOS: [f64; 3] = [1.0, 2.41, 3.93];
/// Weights of the partials (normalized by their sum).
pub const TICK_WEIGHTS: [f64; 3] = [1.0, 0.6, 0.35];

/// Declaration of `grain`.
pub static SPEC: NodeSpec = NodeSpec::new(
    "grain",
    "mesh",
    Role::Filter,
    "Haptic grains of Fig. 4.3: AREA-EVEN (one smooth sinusoid) and EDGE-TICK (a multi-partial impact).",
    build,
)
.doc(
    "Turns intensities into an actuation signal (1.0 = full scale, the `limit` and `gain` nodes' unit). \
The electrostatic force grows with the square of the voltage (§3.1.2), so the waveform amplitude is \
the intensity itself and the display squares it.\n\n\
**AREA-EVEN** (Fig. 4.3a, c: a single main spectral component, smooth force): \
a(n)·sin(2π·f_a·n/f_s), f_a = `area_frequency`; a follows the `area` input through a one-pole \
smoother of time constant `smoothing` (0 = none), so steps of the intensity do not click.\n\n\
**EDGE-TICK** (Fig. 4.3b, d: several spectral components, rough, a sudden impact): when an edge \
input rises above zero (or above its previous value), a burst starts: \
I_e·e^(−t/τ)·Σ w_k cos(2π f_k t)/Σ w_k for `tick_length` seconds, with f_k = `tick_frequency`·\
(1, 2.41, 3.93) (inharmonic, so the burst is rough rather than tonal) and w = (1, 0.6, 0.35), \
τ = `tick_decay`. All cosines start at their peak, so the burst begins with a step to I_e: the \
impact. While a burst plays the area grain is ducked by (1 − e^(−t/τ)), so \
|out| ≤ max(a, I_e) ≤ 1 at every sample.\n\n\
These are this implementation's definitions: the Feelscreen SDK's grains are a black box (§3.1) \
and Fig. 4.3 gives only their character, which the unit tests check: the AREA-EVEN spectrum has one \
line holding > 99 % of the energy; the EDGE-TICK spectrum has three separate peaks; the burst's \
first sample equals I_e.\n\n\
**Ports:** `area` (0–1), one edge input per entry of `edges` (0–1; 0 = no edge), output `out`; \
all at the node's rate. Intensities are clamped to [0, 1]; NaN counts as 0. Every partial must lie \
below the Nyquist frequency (checked when the node is built).\n\n\
**Pruning** (docs/pruning.md): when the `area` input and every edge input (or none, with `edges` \
empty) are a constant 0 — e.g. fed by a `mesh.edges` the planner replaced by its constant and a \
`gain` of 0 — the output is the constant 0: the planner holds it and leaves out what fed only this \
node.",
)
.ports(PORTS)
.params(&[
    AREA_FREQUENCY.spec(),
    SMOOTHING.spec(),
    TICK_FREQUENCY.spec(),
    TICK_DECAY.spec(),
    TICK_LENGTH.spec(),
    EDGES.spec(),
])
.bound(output_bound)
.example("area_frequency = 100.0\nedges = [\"edge\"]")
.fold(fold);

/// The ports: the area intensity and one edge intensity per `edges` entry
/// in, the actuation out.
const PORTS: &[PortSpec] = &[
    PortSpec::input("area", "1", "AREA-EVEN intensity (mesh.gradient's `intensity`)"),
    PortSpec::input("edge", "1", "EDGE-TICK intensity, > 0 on the tick an edge is crossed").per(EDGES.name()),
    PortSpec::output("out", "1", "actuation (1.0 = full scale)"),
];
/// `area`: the AREA-EVEN intensity.
const AREA: InPort = InPort::named(PORTS, "area");
/// `edge`: the first EDGE-TICK intensity; the k-th is `EDGE.nth(k)`.
const EDGE: InPort = InPort::named(PORTS, "edge");
/// `out`: the actuation.
const OUT: OutPort = OutPort::named(PORTS, "out");

/// `area_frequency`: f_a of AREA-EVEN.
const AREA_FREQUENCY: Float = Float::new("area_frequency", 0.0, 1e5, 100.0, "Hz", "f_a of AREA-EVEN");
/// `smoothing`: the area amplitude's time constant.
const SMOOTHING: Float = Float::new("smoothing", 0.0, 1.0, 0.002, "s", "time constant of the area amplitude");
/// `tick_frequency`: the lowest partial of EDGE-TICK.
const TICK_FREQUENCY: Float = Float::new("tick_frequency", 1.0, 1e5, 80.0, "Hz", "lowest partial of EDGE-TICK");
/// `tick_decay`: τ of EDGE-TICK.
const TICK_DECAY: Float = Float::new("tick_decay", 1e-4, 1.0, 0.008, "s", "decay time constant τ of EDGE-TICK");
/// `tick_length`: the duration of one burst.
const TICK_LENGTH: Float = Float::new("tick_length", 1e-3, 1.0, 0.04, "s", "duration of one EDGE-TICK burst");
/// `edges`: the names of the EDGE-TICK inputs.
const EDGES: Words = Words::new("edges", "names of EDGE-TICK inputs (e.g. [\"edge\"]); none: area grain only");

/// Constant 0 when every intensity is a constant 0 (NaN counts as 0): the
/// smoothed amplitude stays 0 and no burst starts.
fn fold(f: &FoldArgs<'_>) -> Option<Constant> {
    for v in f.inputs() {
        if level((*v)?) != 0.0 {
            return None;
        }
    }
    let what = if f.inputs().len() == 1 { "the area intensity is" } else { "every intensity is" };
    Some(Constant::all(1, 0.0, format!("{what} a constant 0")))
}

struct Grain {
    /// f_a / f_s, cycles per sample.
    area_step: f64,
    smooth_k: f64,
    /// Partials in cycles per sample.
    tick_steps: [f64; 3],
    /// e^(−1/(τ f_s)).
    decay: f64,
    tick_samples: u64,
    n_edges: usize,
    // state
    phase: f64,
    amp: f64,
    prev_edge: f64,
    tick_level: f64,
    /// Samples since the burst started (≥ tick_samples: none playing).
    tick_pos: u64,
    env: f64,
}

/// The output bound the stability suite checks: |out| ≤ 1, the actuation full scale (within rounding).
fn output_bound(_: &BoundArgs<'_>) -> Option<PortBound> {
    Some(("out", 1.0 + 1e-12, "actuation full scale".into()))
}

fn build(p: &Params, ctx: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
    let fs = ctx.rate;
    let fa = AREA_FREQUENCY.get(p);
    if fa > fs / 2.0 {
        return Err(NodeError::param(
            AREA_FREQUENCY.name(),
            format!("{fa} Hz is above the Nyquist frequency {} Hz", fs / 2.0),
        ));
    }
    let f0 = TICK_FREQUENCY.get(p);
    let top = f0 * TICK_RATIOS[2];
    if top >= fs / 2.0 {
        return Err(NodeError::param(
            TICK_FREQUENCY.name(),
            format!("the highest partial {top} Hz must lie below the Nyquist frequency {} Hz", fs / 2.0),
        ));
    }
    let tau_s = SMOOTHING.get(p);
    let smooth_k = if tau_s > 0.0 { 1.0 - (-1.0 / (tau_s * fs)).exp() } else { 1.0 };
    let mut g = Grain {
        area_step: fa / fs,
        smooth_k,
        tick_steps: TICK_RATIOS.map(|r| r * f0 / fs),
        decay: (-1.0 / (TICK_DECAY.get(p) * fs)).exp(),
        tick_samples: (TICK_LENGTH.get(p) * fs).round().max(1.0) as u64,
        n_edges: EDGES.get(p).len(),
        phase: 0.0,
        amp: 0.0,
        prev_edge: 0.0,
        tick_level: 0.0,
        tick_pos: 0,
        env: 0.0,
    };
    g.reset();
    Ok(Box::new(g))
}

fn level(x: f64) -> f64 {
    if x.is_nan() {
        0.0
    } else {
        x.clamp(0.0, 1.0)
    }
}

impl Grain {
    #[inline]
    fn sample(&mut self, area: f64, edge: f64) -> f64 {
        self.amp += self.smooth_k * (level(area) - self.amp);
        let e = level(edge);
        if e > 0.0 && (self.prev_edge <= 0.0 || e > self.prev_edge) {
            self.tick_level = e;
            self.tick_pos = 0;
            self.env = 1.0;
        }
        self.prev_edge = e;
        let area_wave = self.amp * (TAU * self.phase).sin();
        self.phase += self.area_step;
        if self.phase >= 1.0 {
            self.phase -= 1.0;
        }
        if self.tick_pos >= self.tick_samples {
            return area_wave;
        }
        let t = self.tick_pos as f64;
        let mut w = 0.0;
        for (s, wt) in self.tick_steps.iter().zip(TICK_WEIGHTS) {
            w += wt * (TAU * (s * t).fract()).cos();
        }
        w /= TICK_WEIGHTS.iter().sum::<f64>();
        let env = self.env;
        self.env *= self.decay;
        self.tick_pos += 1;
        (1.0 - env) * area_wave + env * self.tick_level * w
    }
}

impl Node for Grain {
    fn process(&mut self, io: &mut Io<'_>) -> Result<(), NodeError> {
        for i in 0..io.len() {
            let area = io.input(AREA)[i];
            let mut edge: f64 = 0.0;
            for k in 0..self.n_edges {
                edge = edge.max(level(io.input(EDGE.nth(k))[i]));
            }
            io.output(OUT)[i] = self.sample(area, edge);
        }
        Ok(())
    }

    fn reset(&mut self) {
        self.phase = 0.0;
        self.amp = 0.0;
        self.prev_edge = 0.0;
        self.tick_level = 0.0;
        self.tick_pos = self.tick_samples;
        self.env = 0.0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use evflow_engine::harness::Single;
    use rustfft::num_complex::Complex;

    fn run(params: &str, area: Vec<f64>, edge: Option<Vec<f64>>) -> Vec<f64> {
        let n = area.len() as u64;
        let mut inputs = vec![("area", area, 1000.0)];
        if let Some(e) = edge {
            inputs.push(("edge", e, 1000.0));
        }
        Single::new(&SPEC, params).inputs(inputs).output("out").ticks(n).run().unwrap().remove(0)
    }

    fn magnitudes(x: &[f64], n: usize) -> Vec<f64> {
        let mut buf: Vec<Complex<f64>> = (0..n).map(|i| Complex::new(x.get(i).copied().unwrap_or(0.0), 0.0)).collect();
        evflow_dsp::fft::forward(n).process(&mut buf);
        buf[..n / 2].iter().map(|c| c.norm()).collect()
    }

    #[test]
    fn area_even_has_a_single_spectral_line() {
        let out = run("area_frequency = 100.0\nsmoothing = 0.0", vec![0.8; 4000], None);
        assert!(out.iter().all(|x| x.abs() <= 0.8 + 1e-12));
        let m = magnitudes(&out, 4000);
        let total: f64 = m.iter().map(|v| v * v).sum();
        assert!(m[400] * m[400] / total > 0.99);
        // Amplitude equals the intensity: the line's height is A·N/2.
        assert!((2.0 * m[400] / 4000.0 - 0.8).abs() < 1e-9);
    }

    #[test]
    fn edge_tick_is_a_sudden_multi_partial_impact() {
        let mut edge = vec![0.0; 1000];
        edge[100] = 0.6;
        let out = run("edges = [\"edge\"]", vec![0.0; 1000], Some(edge));
        assert!(out[..100].iter().all(|&x| x == 0.0));
        assert!((out[100] - 0.6).abs() < 1e-15); // the impact: a step to I_e
        assert!(out[140..].iter().all(|&x| x == 0.0)); // 40 ms long
        let m = magnitudes(&out[100..140], 1000);
        let max = m.iter().cloned().fold(0.0, f64::max);
        let peaks: Vec<usize> =
            (1..m.len() - 1).filter(|&i| m[i] > m[i - 1] && m[i] >= m[i + 1] && m[i] > 0.1 * max).collect();
        assert_eq!(peaks.len(), 3, "{peaks:?}");
        for (p, f) in peaks.iter().zip(TICK_RATIOS.map(|r| 80.0 * r)) {
            assert!((*p as f64 - f).abs() < 12.0, "{peaks:?}");
        }
    }

    #[test]
    fn ticks_duck_the_area_grain_and_stay_bounded() {
        let mut edge = vec![0.0; 600];
        for k in (50..600).step_by(37) {
            edge[k] = 1.0 - (k as f64 / 1000.0);
        }
        let area: Vec<f64> = (0..600).map(|i| if i % 90 < 45 { 1.0 } else { 0.2 }).collect();
        let out = run("edges = [\"edge\"]\nsmoothing = 0.001", area, Some(edge));
        assert!(out.iter().all(|x| x.is_finite() && x.abs() <= 1.0 + 1e-12));
    }

    #[test]
    fn folds_to_zero_only_when_every_intensity_is_a_constant_zero() {
        let mut m = std::collections::BTreeMap::new();
        m.insert("edges".to_string(), evflow_engine::Value::TextList(vec!["edge".into()]));
        let p = Params::from_map(m);
        let fold = |inputs: &[Option<f64>]| (SPEC.fold.unwrap())(&FoldArgs::new(&SPEC, &p, inputs, 1, true));
        assert_eq!(fold(&[Some(0.0), Some(0.0)]).unwrap().outputs, [Some(0.0)]);
        assert_eq!(fold(&[Some(-2.0), Some(f64::NAN)]).unwrap().outputs, [Some(0.0)]); // clamped, NaN as 0
        assert!(fold(&[Some(0.5), Some(0.0)]).is_none()); // AREA-EVEN plays
        assert!(fold(&[Some(0.0), Some(0.3)]).is_none()); // one burst
        assert!(fold(&[None, Some(0.0)]).is_none());
        assert!(fold(&[Some(0.0)]).unwrap().reason.contains("area intensity"));
        // What the fold claims is what the node does.
        let out = run("edges = [\"edge\"]", vec![0.0; 300], Some(vec![0.0; 300]));
        assert!(out.iter().all(|&v| v == 0.0));
    }

    #[test]
    fn partials_above_nyquist_are_refused() {
        let e = Single::new(&SPEC, "tick_frequency = 200.0")
            .input("area", vec![0.0], 1000.0)
            .output("out")
            .ticks(1)
            .block(1)
            .run()
            .unwrap_err();
        assert!(e.contains("tick_frequency") && e.contains("Nyquist"), "{e}");
    }
}
