//! `metric`: E_s, RMS and peak-to-peak of a virtual force against a real one.

use super::spectral_error::{spectral_rms_error, Band, BandError, SpectralError};
use super::spectrum::{Spectrum, SpectrumAccumulator, SpectrumConfig, Window};
use crate::filters::segment::{Gates, GATES};
use evflow_engine::ports::InPort;
use evflow_engine::typed_params::{Choice, Flag, Float, Int};
use evflow_engine::{BuildContext, Io, Node, NodeError, NodeSpec, Params, PortSpec, Role, Summary};

/// Largest FFT length (2²⁰ samples: 17 min at 1 kHz, 105 s at 10 kHz).
const MAX_NFFT: i64 = 1 << 20;

/// Declaration of `metric`.
pub static SPEC: NodeSpec = NodeSpec::new(
    "metric",
    "metric",
    Role::Sink,
    "Relative spectral RMS error E_s (Eq. 5.2), RMS, peak-to-peak and spectral peak of a virtual force against a real one.",
    build,
)
.doc(
    "Compares the force a virtual texture produces on the display (`virtual`, f_v) with the force \
recorded on the real material (`real`, f_r), as dissertation §5.2.3 does to score synthesized \
actuation signals (Figs. 5.7–5.9). Both inputs run at the node's rate f_s. Nothing is emitted while \
the run goes; when it ends the node reports:

* `E_s` — the relative spectral RMS error of Eq. 5.2. The equation is garbled in the dissertation's \
text; following its references [43, 55] (Culbertson et al.) it is \
E_s = RMS(|F(f_v)| − |F(f_r)|) / RMS(|F(f_r)|), with F the FFT and both RMS taken over the same \
frequency bins, so E_s = √(Σ_k (V_k − R_k)²) / √(Σ_k R_k²). 0 for identical spectra, 1 when the \
virtual spectrum is twice the real one, 0.5 when it is half; the dissertation's baseline between \
two recordings of one material is 0.07–0.33 (§5.3.1).
* `rms_virtual`, `rms_real` — √(mean x²) of the samples (the mean included).
* `pp_virtual`, `pp_real` — peak-to-peak, max − min.
* `peak_psd_freq_virtual`, `peak_psd_freq_real` — frequency in Hz of the largest peak of the averaged \
magnitude spectrum inside the band, never 0 Hz; a peak is a bin above its lower neighbour and not \
below its upper one and above the FFT's rounding level (1e-10 of the largest bin), so leakage \
sloping down from the mean is not taken for one. 0 when there is no peak (the summary says so).
* `peak_magnitude_virtual`, `peak_magnitude_real` — the largest averaged magnitude in the band (raw \
DFT scale) of each force; `peak_psd_ratio` — their ratio squared, the largest power density of the \
virtual force over the real one: the level the gain sweep of §5.3.2 matches (Table 5.1 picks the gain that gives \"almost the same \
maximum magnitude of power density\").
* `samples` (per input) and `segments` (FFT segments averaged).

**Spectrum.** The dissertation sets \"the length of FFT equal to the sampling frequency, 1000 Hz, to \
generate a smooth and less spiky spectrum\": `nfft = 0` (the default) takes the node's rate, giving \
1 Hz bins. Each force is cut into segments of `nfft` samples, `nfft − round(overlap·nfft)` apart; each \
segment is windowed (`window`) and transformed, and the magnitudes |X_k|, k = 0 … nfft/2, are \
averaged over segments (Welch's method applied to magnitudes). A force shorter than `nfft` is \
windowed over its own length and zero-padded to one segment; samples after the last complete \
segment are left out (the summary says how many). MATLAB's `fft(x, 1000)` would instead keep only \
the first second of a recording; with a recording of exactly `nfft` samples both agree. Magnitudes \
are raw DFT sums (a sine of amplitude A on a bin reads A·nfft/2 with `rect`); the scale cancels in \
E_s.

**Band.** E_s is taken over the bins k with `fmin` ≤ k·f_s/nfft ≤ `fmax` (`fmax = 0`: Nyquist). By \
default the 0 Hz bin is left out (`include_dc = false`): a force's mean is the friction level set \
by the normal load and the finger, not texture, and being the largest bin by far it would dominate \
E_s and hide the texture's spectrum. Set `include_dc = true` to count it as a literal reading of \
Eq. 5.2 would.

**Errors, never NaN.** If the real force has no spectral energy in the band (all zero, or a \
constant with 0 Hz excluded), E_s is undefined and `finish` fails with a message saying so; also \
when no sample arrived, when an input holds NaN or Inf (the index is named), or when a value would \
overflow f64.

Memory is bounded: spectra are accumulated segment by segment (a few buffers of `nfft` per input), \
so a run can last any time; `process` does not allocate, and the result does not depend on how the \
samples were split into blocks.

**Gate.** Each entry of `gate` adds an input of that name (e.g. `gate = [\"steady\"]`, fed by \
`segment`); then only the samples where every gate is above 0.5 count, and the kept stretches are \
concatenated before the spectra — the constant-speed segments of §5.1.1. Both forces are kept or \
left out together, sample for sample.

Checked against analytic spectra: a sine on a bin (A·nfft/2 in that bin only; A·nfft/4 and \
A·nfft/8 with `hann`), the Rayleigh mean √(π/4·nfft·σ²) of white noise, Parseval, the Dirichlet \
kernel of a zero-padded boxcar, a naive DFT, and the identities E_s(x, x) = 0, E_s(2x, x) = 1, \
E_s(x, 2x) = 0.5, E_s = √2 for equal sines on different bins.",
)
.ports(PORTS)
.params(&[
    NFFT.spec(),
    WINDOW.spec(),
    OVERLAP.spec(),
    FMIN.spec(),
    FMAX.spec(),
    INCLUDE_DC.spec(),
    GATES.spec(),
])
.example("nfft = 0\nwindow = \"rect\"\noverlap = 0.0\nfmin = 0.0\nfmax = 0.0\ninclude_dc = false");

/// The ports: the two forces and the gates.
const PORTS: &[PortSpec] = &[
    PortSpec::input("virtual", "N", "virtual force f_v, from the display (N or normalized)"),
    PortSpec::input("real", "N", "real force f_r, recorded on the material (same unit)"),
    PortSpec::input("gate", "1", "one per `gate` entry: the sample counts only where every gate is above 0.5")
        .per(GATES.name()),
];
/// The virtual force f_v.
const VIRTUAL: InPort = InPort::named(PORTS, "virtual");
/// The real force f_r.
const REAL: InPort = InPort::named(PORTS, "real");
/// The first gate.
const GATE: InPort = InPort::named(PORTS, "gate");

/// `nfft`: the FFT (segment) length.
const NFFT: Int =
    Int::new("nfft", 0, MAX_NFFT, 0, "samples", "FFT (segment) length; 0 = the sampling rate (1 Hz bins)");
/// `overlap`: the fraction of a segment shared with the next.
const OVERLAP: Float = Float::new("overlap", 0.0, 0.9, 0.0, "1", "fraction of a segment shared with the next");
/// `fmin`: the lowest frequency counted in E_s.
const FMIN: Float = Float::new("fmin", 0.0, 1e7, 0.0, "Hz", "lowest frequency counted in E_s");
/// `fmax`: the highest frequency counted in E_s.
const FMAX: Float = Float::new("fmax", 0.0, 1e7, 0.0, "Hz", "highest frequency counted in E_s; 0 = Nyquist");
/// `include_dc`: whether the 0 Hz bin counts.
const INCLUDE_DC: Flag = Flag::new("include_dc", false, "count the 0 Hz bin (the mean force) in E_s");

/// Running RMS (scaled sum of squares, as LAPACK's `dnrm2`, so no
/// overflow or underflow), extremes, and the first non-finite sample.
#[derive(Debug, Clone)]
struct Stats {
    n: u64,
    scale: f64,
    ssq: f64,
    min: f64,
    max: f64,
    bad: Option<u64>,
}

impl Stats {
    fn new() -> Self {
        Self { n: 0, scale: 0.0, ssq: 1.0, min: f64::INFINITY, max: f64::NEG_INFINITY, bad: None }
    }

    fn push(&mut self, x: &[f64]) {
        for &x in x {
            if !x.is_finite() {
                self.bad.get_or_insert(self.n);
            } else {
                let a = x.abs();
                if a > self.scale {
                    self.ssq = 1.0 + self.ssq * (self.scale / a).powi(2);
                    self.scale = a;
                } else if a > 0.0 {
                    self.ssq += (a / self.scale).powi(2);
                }
                self.min = self.min.min(x);
                self.max = self.max.max(x);
            }
            self.n += 1;
        }
    }

    fn rms(&self) -> f64 {
        if self.n == 0 {
            0.0
        } else {
            self.scale * (self.ssq / self.n as f64).sqrt()
        }
    }
}

/// One input: its statistics and its spectrum.
struct Channel {
    name: &'static str,
    port: InPort,
    stats: Stats,
    spectrum: SpectrumAccumulator,
}

impl Channel {
    fn push(&mut self, x: &[f64]) {
        self.stats.push(x);
        self.spectrum.push(x);
    }
}

struct Metric {
    rate: f64,
    band: Band,
    fmin: f64,
    include_dc: bool,
    channels: [Channel; 2],
    gates: Gates,
    /// Samples left out by the gates.
    gated_out: u64,
}

/// `window`: applied to each segment, arriving as a [`Window`].
const WINDOW: Choice<Window> =
    Choice::new("window", &["rect", "hann"], &[Window::Rect, Window::Hann], "rect", "window applied to each segment");

/// A band error, naming this node's parameter.
fn band_error(e: BandError) -> NodeError {
    e.naming([FMIN.name(), FMAX.name(), NFFT.name()])
}

fn build(p: &Params, ctx: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
    let rate = ctx.rate;
    let gates = Gates::from_params(p, GATE)?;
    let nfft = match NFFT.count(p) {
        0 => {
            let n = rate.round();
            if !(2.0..=MAX_NFFT as f64).contains(&n) {
                return Err(NodeError::param(
                    NFFT.name(),
                    format!("0 means the sampling rate, {rate} Hz, which is not an FFT length in 2 ..= {MAX_NFFT}; set nfft"),
                ));
            }
            n as usize
        }
        1 => return Err(NodeError::param(NFFT.name(), "must be 0 (= the sampling rate) or at least 2 samples")),
        n => n,
    };
    let window = WINDOW.get(p);
    let include_dc = INCLUDE_DC.get(p);
    let band = Band::new(rate, nfft, FMIN.get(p), FMAX.get(p), include_dc).map_err(band_error)?;
    let cfg = SpectrumConfig { rate, nfft, window, overlap: OVERLAP.get(p) };
    let channel = |name, port| -> Result<Channel, NodeError> {
        let spectrum = SpectrumAccumulator::new(cfg).map_err(|e| NodeError::param(NFFT.name(), e.to_string()))?;
        Ok(Channel { name, port, stats: Stats::new(), spectrum })
    };
    Ok(Box::new(Metric {
        rate,
        band,
        fmin: FMIN.get(p),
        include_dc,
        channels: [channel("virtual", VIRTUAL)?, channel("real", REAL)?],
        gates,
        gated_out: 0,
    }))
}

impl Node for Metric {
    fn process(&mut self, io: &mut Io<'_>) -> Result<(), NodeError> {
        let channels = &mut self.channels;
        let kept = self.gates.open_runs(io, |a, b| {
            for c in channels.iter_mut() {
                c.push(&io.input(c.port)[a..b]);
            }
        });
        let n = io.len();
        self.gated_out += (n - kept) as u64;
        Ok(())
    }

    fn reset(&mut self) {
        for c in &mut self.channels {
            c.stats = Stats::new();
            c.spectrum.reset();
        }
        self.gated_out = 0;
    }

    fn finish(&mut self) -> Result<Summary, NodeError> {
        self.check_finite()?;
        let spectra = self.spectra()?;
        let (sv, sr) = (&spectra[0], &spectra[1]);
        let es = self.spectral_error(sv, sr)?;
        let summary = self.values(es, sv, sr)?;
        Ok(self.lines(summary, es, sv, sr))
    }
}

impl Metric {
    /// Every input sample was finite.
    fn check_finite(&self) -> Result<(), NodeError> {
        for c in &self.channels {
            if let Some(i) = c.stats.bad {
                return Err(NodeError::Data(format!(
                    "input `{}`: sample {i} (t = {} s) is NaN or Inf; the metric needs finite forces",
                    c.name,
                    i as f64 / self.rate
                )));
            }
        }
        Ok(())
    }

    /// The spectrum of each input (virtual, real); an input without a
    /// sample has none, which the error explains.
    fn spectra(&self) -> Result<Vec<Spectrum>, NodeError> {
        self.channels
            .iter()
            .map(|c| {
                c.spectrum.spectrum().ok_or_else(|| {
                    NodeError::Data(format!(
                        "input `{}` received no samples{}: E_s, RMS and peak-to-peak need at least one \
                         sample of each force",
                        c.name,
                        if self.gates.any() {
                            format!(
                                " (the gate never opened over {} samples; check the `segment` speed)",
                                self.gated_out
                            )
                        } else {
                            " (the run was empty)".into()
                        }
                    ))
                })
            })
            .collect()
    }

    /// E_s of the virtual spectrum `sv` against the real `sr` over the band.
    fn spectral_error(&self, sv: &Spectrum, sr: &Spectrum) -> Result<f64, NodeError> {
        spectral_rms_error(&sv.magnitude, &sr.magnitude, &self.band).map_err(|e| {
            NodeError::Data(match e {
                SpectralError::NoRealEnergy { .. } if !self.include_dc => format!(
                    "{e}; check that `real` is connected to a recorded force that varies, or set \
                     include_dc = true to count its mean"
                ),
                SpectralError::NoRealEnergy { .. } => {
                    format!("{e}; check that `real` is connected to a recorded force")
                }
                // The inputs were finite (checked above), so the FFT sums overflowed.
                SpectralError::NonFinite(name) => {
                    format!("the FFT of `{name}` overflows f64: the force is too large (scale it down)")
                }
                _ => e.to_string(),
            })
        })
    }

    /// The values reported (E_s `es`, RMS, peak-to-peak, peaks of the
    /// spectra `sv`, `sr`, counts); one that overflows f64 is an error.
    fn values(&self, es: f64, sv: &Spectrum, sr: &Spectrum) -> Result<Summary, NodeError> {
        let band = &self.band;
        let peak = |s: &Spectrum| s.largest_peak(band.first(), band.last()).map_or(0.0, |k| s.freq(k));
        let [v, r] = [&self.channels[0].stats, &self.channels[1].stats];
        let top = |s: &Spectrum| s.magnitude[band.first()..=band.last()].iter().fold(0.0f64, |a, &m| a.max(m));
        let (pv, pr) = (top(sv), top(sr));
        let values = [
            ("E_s", es, "1"),
            ("rms_virtual", v.rms(), "N"),
            ("rms_real", r.rms(), "N"),
            ("pp_virtual", v.max - v.min, "N"),
            ("pp_real", r.max - r.min, "N"),
            ("peak_psd_freq_virtual", peak(sv), "Hz"),
            ("peak_psd_freq_real", peak(sr), "Hz"),
            ("peak_magnitude_virtual", pv, "1"),
            ("peak_magnitude_real", pr, "1"),
            ("peak_psd_ratio", (pv / pr).powi(2), "1"),
            ("samples", v.n as f64, "1"),
            ("segments", sv.segments as f64, "1"),
        ];
        let mut summary = Summary::default();
        for (name, x, unit) in values {
            if !x.is_finite() {
                return Err(NodeError::Data(format!(
                    "{name} overflows f64: the forces are too large (|x| up to {:e})",
                    v.max.abs().max(v.min.abs()).max(r.max.abs()).max(r.min.abs())
                )));
            }
            summary = summary.value(name, x, unit);
        }
        Ok(summary)
    }

    /// The summary's lines: how E_s was read, what the gate kept, what
    /// the segments left out, a spectrum without a peak.
    fn lines(&self, mut summary: Summary, es: f64, sv: &Spectrum, sr: &Spectrum) -> Summary {
        let band = &self.band;
        let cfg = self.channels[0].spectrum.config();
        let dc = if !self.include_dc && self.fmin == 0.0 { ", 0 Hz excluded" } else { "" };
        summary = summary.line(format!(
            "E_s = {es:.4} over {} bins ({}–{} Hz{dc}); {} segment(s) of {} samples, {} window, overlap {}",
            band.len(),
            band.lo_hz(),
            band.hi_hz(),
            sv.segments,
            cfg.nfft,
            cfg.window.name(),
            cfg.overlap
        ));
        if self.gates.any() {
            summary = summary.line(format!("gate: {} samples kept, {} left out", sv.samples, self.gated_out));
        }
        if sv.samples < cfg.nfft as u64 {
            summary = summary.line(format!("{} samples, zero-padded to one segment of {}", sv.samples, cfg.nfft));
        } else if sv.trailing > 0 {
            summary = summary.line(format!("last {} samples not in a complete segment, left out", sv.trailing));
        }
        for (s, c) in [(sv, &self.channels[0]), (sr, &self.channels[1])] {
            if s.largest_peak(band.first(), band.last()).is_none() {
                summary = summary.line(format!("no spectral peak in `{}` within the band (reported as 0 Hz)", c.name));
            }
        }
        summary
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::metric::spectrum::tests::{gaussian, sine};
    use evflow_engine::harness::Single;

    /// Runs the node through a real plan in blocks of `block` base ticks and
    /// returns its summary (or the error of building, running or finishing).
    fn run_at(rate: f64, params: &str, v: &[f64], r: &[f64], block: usize) -> Result<Summary, String> {
        assert_eq!(v.len(), r.len());
        let single = Single::new(&SPEC, params)
            .input("virtual", v.to_vec(), rate)
            .input("real", r.to_vec(), rate)
            .base_rate(rate)
            .ticks(v.len() as u64)
            .block(block);
        let (mut plan, _) = single.plan()?;
        let mut done = 0;
        while done < v.len() {
            let n = plan.max_block().min(v.len() - done);
            plan.step(n).map_err(|e| e.to_string())?;
            done += n;
        }
        let summaries = plan.finish().map_err(|e| e.to_string())?;
        summaries.into_iter().find(|(n, _)| n == "dut").map(|(_, s)| s).ok_or_else(|| "no summary".into())
    }

    fn run(params: &str, v: &[f64], r: &[f64]) -> Result<Summary, String> {
        run_at(1000.0, params, v, r, 256)
    }

    fn value(s: &Summary, name: &str) -> f64 {
        s.values.iter().find(|(n, _, _)| n == name).unwrap_or_else(|| panic!("no value `{name}`")).1
    }

    #[test]
    fn a_gate_keeps_and_concatenates_only_the_open_stretches() {
        // Two open stretches of 1000 samples carry the same 37 Hz tone in
        // both forces; between and around them the forces differ wildly.
        // E_s over the gated samples is that of the tones alone: 0.
        let tone = sine(1.0, 37.0, 1000, 1000);
        let (mut v, mut r, mut g) = (Vec::new(), Vec::new(), Vec::new());
        for (k, junk) in [(300, 5.0), (0, 0.0), (200, -3.0), (0, 0.0), (300, 7.0)] {
            if k == 0 {
                v.extend(&tone);
                r.extend(&tone);
                g.extend(std::iter::repeat_n(1.0, 1000));
            } else {
                v.extend(gaussian(k as u64, k).iter().map(|x| junk * x));
                r.extend(std::iter::repeat_n(junk, k));
                g.extend(std::iter::repeat_n(0.0, k));
            }
        }
        for block in [1, 77, 4096] {
            let single = Single::new(&SPEC, "gate = [\"steady\"]")
                .input("virtual", v.clone(), 1000.0)
                .input("real", r.clone(), 1000.0)
                .input("steady", g.clone(), 1000.0)
                .ticks(v.len() as u64)
                .block(block);
            let (mut plan, _) = single.plan().expect("builds");
            let mut done = 0;
            while done < v.len() {
                let n = plan.max_block().min(v.len() - done);
                plan.step(n).expect("steps");
                done += n;
            }
            let sums = plan.finish().expect("finishes");
            let s = &sums.iter().find(|(n, _)| n == "dut").expect("summary").1;
            assert_eq!(value(s, "samples"), 2000.0);
            assert_eq!(value(s, "segments"), 2.0);
            assert!(value(s, "E_s") < 1e-12, "block {block}: {}", value(s, "E_s"));
            assert!(s.lines.iter().any(|l| l.contains("2000 samples kept, 800 left out")), "{:?}", s.lines);
        }
        // A gate may not take a force input's name (the validator says so).
        let e = run("gate = [\"real\"]", &v, &r).expect_err("refused");
        assert!(e.contains("two ports named `real`"), "{e}");
        // A gate that never opens is an error naming it.
        let e = run_gated_never(&v, &r);
        assert!(e.contains("gate never opened"), "{e}");
    }

    fn run_gated_never(v: &[f64], r: &[f64]) -> String {
        let single = Single::new(&SPEC, "gate = [\"steady\"]")
            .input("virtual", v.to_vec(), 1000.0)
            .input("real", r.to_vec(), 1000.0)
            .input("steady", vec![0.0; v.len()], 1000.0)
            .ticks(v.len() as u64)
            .block(512);
        single.run().expect_err("no samples kept")
    }

    /// A texture-like force: a mean, a tone at 37 Hz, noise.
    fn force(seed: u64, len: usize) -> Vec<f64> {
        let tone = sine(0.3, 37.0, 1000, len);
        gaussian(seed, len).iter().zip(tone).map(|(g, t)| 0.5 + t + 0.05 * g).collect()
    }

    #[test]
    fn e_s_identities_through_the_node() {
        let x = force(1, 3066);
        let x2: Vec<f64> = x.iter().map(|x| 2.0 * x).collect();
        assert_eq!(value(&run("", &x, &x).unwrap(), "E_s"), 0.0);
        let s = run("", &x2, &x).unwrap();
        assert!((value(&s, "E_s") - 1.0).abs() < 1e-12);
        assert_eq!(value(&s, "samples"), 3066.0);
        assert_eq!(value(&s, "segments"), 3.0); // nfft = rate = 1000: 66 samples left out
        assert!(s.lines.iter().any(|l| l.contains("last 66 samples")), "{:?}", s.lines);
        // Twice the force is four times the power density at every bin.
        assert!((value(&s, "peak_psd_ratio") - 4.0).abs() < 1e-12);
        assert!((value(&s, "peak_magnitude_virtual") / value(&s, "peak_magnitude_real") - 2.0).abs() < 1e-12);
        assert!((value(&run("window = \"hann\"\noverlap = 0.5", &x, &x2).unwrap(), "E_s") - 0.5).abs() < 1e-12);
    }

    #[test]
    fn two_sines_give_root_two_and_their_peaks() {
        // As in spectral_error: |V| = A·N/2 at 40 Hz, |R| = A·N/2 at 130 Hz, so
        // E_s = √(2·(A·N/2)²) / √((A·N/2)²) = √2. The real force also carries a
        // large mean, which is excluded and is not a peak.
        let v = sine(0.8, 40.0, 1000, 2000);
        let r: Vec<f64> = sine(0.8, 130.0, 1000, 2000).iter().map(|x| 5.0 + x).collect();
        let s = run("", &v, &r).unwrap();
        assert!((value(&s, "E_s") - 2f64.sqrt()).abs() < 1e-9);
        assert_eq!(value(&s, "peak_psd_freq_virtual"), 40.0);
        assert_eq!(value(&s, "peak_psd_freq_real"), 130.0);
        // Counting 0 Hz, the mean dominates: R_0 = 5·N against A·N/2 elsewhere.
        // Σ(V−R)² = (5N)² + 2(0.4N)², ΣR² = (5N)² + (0.4N)²: E_s = √(25.32/25.16).
        let s = run("include_dc = true", &v, &r).unwrap();
        assert!((value(&s, "E_s") - (25.32f64 / 25.16).sqrt()).abs() < 1e-9);
    }

    #[test]
    fn rms_and_peak_to_peak_of_known_signals() {
        // x[n] = c + A·sin(πn/2) takes c, c+A, c, c−A: over whole periods
        // RMS = √(c² + A²/2) and p-p = 2A exactly.
        let (c, a) = (0.25, 1.5);
        let x: Vec<f64> = (0..2000).map(|n| c + a * [0.0, 1.0, 0.0, -1.0][n % 4]).collect();
        let r = force(2, 2000);
        let s = run("", &x, &r).unwrap();
        assert!((value(&s, "rms_virtual") - (c * c + a * a / 2.0).sqrt()).abs() < 1e-12);
        assert!((value(&s, "pp_virtual") - 2.0 * a).abs() < 1e-12);
        assert_eq!(value(&s, "peak_psd_freq_virtual"), 250.0);
        let rms_r = (r.iter().map(|x| x * x).sum::<f64>() / r.len() as f64).sqrt();
        let pp_r =
            r.iter().cloned().fold(f64::NEG_INFINITY, f64::max) - r.iter().cloned().fold(f64::INFINITY, f64::min);
        assert!((value(&s, "rms_real") / rms_r - 1.0).abs() < 1e-13);
        assert_eq!(value(&s, "pp_real"), pp_r);
    }

    #[test]
    fn blocks_and_single_samples_give_identical_results() {
        let (v, r) = (force(3, 1537), force(4, 1537));
        let params = "nfft = 200\nwindow = \"hann\"\noverlap = 0.3\nfmin = 10.0\nfmax = 400.0";
        let reference = run_at(1000.0, params, &v, &r, 1).unwrap();
        for block in [7, 200, 1000, 4096] {
            assert_eq!(run_at(1000.0, params, &v, &r, block).unwrap(), reference, "block {block}");
        }
        // Also for a force shorter than one segment.
        let short = run_at(1000.0, "", &v[..300], &r[..300], 1).unwrap();
        assert_eq!(run_at(1000.0, "", &v[..300], &r[..300], 64).unwrap(), short);
    }

    #[test]
    fn reset_returns_to_the_start() {
        let (v, r) = (force(5, 1200), force(6, 1200));
        let single = Single::new(&SPEC, "nfft = 256")
            .input("virtual", v.clone(), 1000.0)
            .input("real", r.clone(), 1000.0)
            .ticks(1200)
            .block(100);
        let (mut plan, _) = single.plan().unwrap();
        let mut once = || {
            for _ in 0..12 {
                plan.step(100).unwrap();
            }
            let s = plan.finish().unwrap();
            plan.reset();
            s
        };
        let first = once();
        assert_eq!(once(), first);
        assert_eq!(first[0].1, run("nfft = 256", &v, &r).unwrap());
    }

    #[test]
    fn a_force_shorter_than_nfft_is_zero_padded() {
        // 300 samples of a 50 Hz sine padded to 1000: both forces padded the
        // same way, so E_s(2x, x) is still exactly 1 and the peak stays at 50 Hz.
        let x = sine(1.0, 50.0, 1000, 300);
        let x2: Vec<f64> = x.iter().map(|x| 2.0 * x).collect();
        let s = run("", &x2, &x).unwrap();
        assert!((value(&s, "E_s") - 1.0).abs() < 1e-12);
        assert_eq!(value(&s, "segments"), 1.0);
        assert_eq!(value(&s, "peak_psd_freq_real"), 50.0);
        assert!(s.lines.iter().any(|l| l.contains("zero-padded")), "{:?}", s.lines);
    }

    #[test]
    fn nfft_zero_is_the_sampling_rate() {
        // At 500 Hz, nfft = 500: 1 Hz bins, so a 37 Hz tone is found at 37 Hz.
        let v = sine(1.0, 37.0, 500, 1500);
        let r = sine(1.0, 61.0, 500, 1500);
        let s = run_at(500.0, "", &v, &r, 128).unwrap();
        assert_eq!(value(&s, "segments"), 3.0);
        assert_eq!(value(&s, "peak_psd_freq_virtual"), 37.0);
        assert_eq!(value(&s, "peak_psd_freq_real"), 61.0);
        assert!(s.lines[0].contains("250 bins (1–250 Hz, 0 Hz excluded)"), "{}", s.lines[0]);
    }

    #[test]
    fn a_real_force_without_spectral_energy_is_an_error() {
        let v = force(7, 1000);
        for real in [vec![0.0; 1000], vec![2.5; 1000]] {
            let e = run("", &v, &real).unwrap_err();
            assert!(e.contains("no spectral energy") && e.contains("include_dc"), "{e}");
        }
        // A constant real force with 0 Hz counted is defined (and finite).
        let s = run("include_dc = true", &v, &[2.5; 1000]).unwrap();
        assert!(value(&s, "E_s").is_finite());
        // A constant has no spectral peak: 0 Hz, said in a line.
        assert_eq!(value(&s, "peak_psd_freq_real"), 0.0);
        assert!(s.lines.iter().any(|l| l.contains("no spectral peak in `real`")));
        // A zero virtual force is fine: E_s = 1 (all of the real spectrum missing).
        assert!((value(&run("", &[0.0; 1000], &v).unwrap(), "E_s") - 1.0).abs() < 1e-12);
    }

    #[test]
    fn an_empty_run_is_an_error() {
        let e = run("", &[], &[]).unwrap_err();
        assert!(e.contains("received no samples"), "{e}");
    }

    #[test]
    fn non_finite_input_is_named() {
        let mut v = force(8, 500);
        v[123] = f64::INFINITY;
        let e = run("", &v, &force(9, 500)).unwrap_err();
        assert!(e.contains("`virtual`") && e.contains("sample 123") && e.contains("0.123 s"), "{e}");
    }

    #[test]
    fn extreme_amplitudes_stay_finite_or_fail_clearly() {
        for scale in [1e-300, 1e300] {
            let x: Vec<f64> = force(10, 1000).iter().map(|x| x * scale).collect();
            let x2: Vec<f64> = x.iter().map(|x| 2.0 * x).collect();
            let s = run("", &x2, &x).unwrap();
            assert!(s.values.iter().all(|(_, v, _)| v.is_finite()));
            assert!((value(&s, "E_s") - 1.0).abs() < 1e-12, "scale {scale}");
            let rms = (x.iter().map(|x| (x / scale).powi(2)).sum::<f64>() / 1000.0).sqrt() * scale;
            assert!((value(&s, "rms_real") / rms - 1.0).abs() < 1e-12);
        }
        // Beyond f64: the FFT sums overflow; a clear error, not Inf.
        let big: Vec<f64> = vec![1.5e308; 1000];
        let e = run("", &big, &force(11, 1000)).unwrap_err();
        assert!(e.contains("FFT of `virtual` overflows f64"), "{e}");
        assert!(!e.contains("NaN"), "{e}");
    }

    #[test]
    fn parameter_combinations_are_checked() {
        let x = force(12, 100);
        let e = run("nfft = 1", &x, &x).unwrap_err();
        assert!(e.contains("nfft") && e.contains("at least 2"), "{e}");
        let e = run("fmax = 600.0", &x, &x).unwrap_err();
        assert!(e.contains("fmax") && e.contains("Nyquist"), "{e}");
        let e = run("nfft = 100\nfmin = 3.0\nfmax = 8.0", &x, &x).unwrap_err();
        assert!(e.contains("no FFT bin"), "{e}");
        let e = run("fmin = 300.0\nfmax = 200.0", &x, &x).unwrap_err();
        assert!(e.contains("fmin"), "{e}");
        // Limits of the declaration are enforced before construction.
        assert!(run("overlap = 0.95", &x, &x).is_err());
        assert!(run("window = \"hamming\"", &x, &x).is_err());
        // Extreme but legal settings run.
        let s = run("nfft = 2\noverlap = 0.9", &x, &x).unwrap();
        assert_eq!(value(&s, "segments"), 99.0);
        assert_eq!(value(&s, "E_s"), 0.0);
    }

    #[test]
    fn the_example_runs() {
        let x = force(13, 1000);
        assert_eq!(value(&run(SPEC.example, &x, &x).unwrap(), "E_s"), 0.0);
    }
}
