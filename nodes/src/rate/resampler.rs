//! The streaming resampler behind `resample`: rubato's asynchronous
//! resampler (`Async`, any real ratio) driven one output sample at a time,
//! with a fixed, stated latency.
//!
//! **Driving rubato.** The resampler is built with `FixedAsync::Output`
//! and a chunk of one output frame: each call asks for the input frames
//! that output needs (`input_frames_next`, 0 … ⌈1/r⌉ + 1 for a ratio r =
//! f_out/f_in) and writes one frame. The input frames wait in a FIFO sized
//! in `prepare`. The sequence of calls depends only on the input sequence,
//! never on how the engine cuts it into blocks, so every block size gives
//! the same samples bit for bit.
//!
//! **Where rubato's samples fall.** Its raw output j is the input signal at
//! input position (j + 1)/r − a, and it needs the inputs up to index
//! ⌈(j + 1)/r + b⌉ − 1 (from `rubato-5.0.1/src/asynchro*.rs`: the start
//! index −(L − 1) for a sinc of L taps and −n/2 for a polynomial of n
//! points, a window that reaches L resp. n points past it, and a sinc table
//! of `O` sub-sample phases whose centre sits 1/O past the middle):
//!
//! | kernel | lag a (input samples) | look-ahead b |
//! |---|---|---|
//! | cubic polynomial (4 points) | 2 | 2 |
//! | sinc of L taps, O phases | L/2 − 1/O | 1 |
//!
//! **Latency.** Output l of the node is raw output l − P (zeros for
//! l < P), with P = ⌈b·r + 1.5⌉: at output l the engine has delivered the
//! inputs at or before its time, ⌊l/r⌋ + 1 of them, which is at least what
//! raw output l − P needs whenever P ≥ b·r + 1 (half an output sample of
//! margin on top). So output l is the input at time l/f_out − D with the
//! fixed latency
//!
//! D = (P − 1)/f_out + a/f_in.
//!
//! **Filters.** Lowering a rate, the sinc's length and cut-off are scaled by
//! r (L/r taps, cut-off r·c of the input Nyquist frequency, c rubato's
//! automatic cut-off for L taps) so that each quality keeps the same
//! anti-aliasing relative to the new Nyquist frequency; the table's phases
//! scale by r too (O·r, at least 8), which keeps the table's size (L·O)
//! and its interpolation error the same.
//!
//! **Range.** Inputs are scaled by 2⁻¹⁰ on entry and outputs by 2¹⁰ on
//! exit (exact for normal numbers), so no weighted sum of finite inputs
//! overflows; an output beyond the f64 range is clamped to ±f64::MAX.

use rubato::audioadapter_buffers::direct::SequentialSlice;
use rubato::{
    calculate_cutoff, FixedAsync, PolynomialDegree, Resampler, SincInterpolationParameters, SincInterpolationType,
    WindowFunction,
};

/// Inputs are multiplied by this on entry (and outputs divided by it).
const SCALE: f64 = 1.0 / 1024.0;

/// Longest sinc (taps) a stream builds; lowering a rate by more than the
/// quality's length allows in one stage is refused.
pub const MAX_SINC_TAPS: usize = 1 << 18;

/// Most input samples one output sample may consume (1/r): a larger step
/// down is refused.
pub const MAX_STEP: f64 = 65_536.0;

/// Sub-sample phases of the sinc table when raising a rate.
const OVERSAMPLING: usize = 256;

/// The quality setting of `resample`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Quality {
    /// rubato's cubic polynomial (4 points): no anti-alias filter, the
    /// shortest latency.
    Fast,
    /// rubato's sinc of 128 taps (cut-off 0.895 of the lower Nyquist frequency).
    Balanced,
    /// rubato's sinc of 256 taps (cut-off 0.947 of the lower Nyquist frequency).
    Best,
}

/// The words of [`Quality`], in order.
pub const QUALITY_NAMES: &[&str] = &["fast", "balanced", "best"];

impl Quality {
    /// Every quality, in order.
    pub const ALL: [Quality; 3] = [Quality::Fast, Quality::Balanced, Quality::Best];

    /// The quality of that name.
    pub fn from_name(name: &str) -> Option<Quality> {
        Self::ALL.into_iter().find(|q| q.name() == name)
    }
    /// The name in graph files.
    pub fn name(self) -> &'static str {
        match self {
            Quality::Fast => "fast",
            Quality::Balanced => "balanced",
            Quality::Best => "best",
        }
    }
    /// Sinc length (taps at a ratio ≥ 1), or `None` for the polynomial.
    pub fn sinc_len(self) -> Option<usize> {
        match self {
            Quality::Fast => None,
            Quality::Balanced => Some(128),
            Quality::Best => Some(256),
        }
    }
}

/// Why a stream could not be built or run.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ResampleError {
    /// The ratio is not a positive finite number.
    #[error("the resampling ratio f_out/f_in = {0} must be a positive finite number")]
    Ratio(f64),
    /// Lowering a rate by more than one stage can do.
    #[error(
        "lowering a rate {step}-fold in one stage is more than `resample` does at quality `{quality}` \
         (it would need {taps} sinc taps or {step} input samples per output); put a `decimate` node first"
    )]
    StepTooLarge {
        /// Input samples per output sample, 1/r.
        step: f64,
        /// The quality asked for.
        quality: &'static str,
        /// Sinc taps the stage would need.
        taps: usize,
    },
    /// rubato refused.
    #[error("rubato: {0}")]
    Rubato(String),
    /// More input waiting than the FIFO sized in `prepare` holds.
    #[error("the resampler's input buffer ({0} samples) is full: a block larger than `prepare` allowed for")]
    Overflow(usize),
    /// An output was due before its inputs had arrived (a latency too short: a bug).
    #[error("the resampler ran out of input before output {0} (its latency is too short)")]
    Underrun(u64),
}

/// One resampled stream.
pub struct Stream {
    inner: Box<dyn Resampler<f64>>,
    ratio: f64,
    lag: f64,
    lookahead: f64,
    pad: u64,
    fifo: Vec<f64>,
    start: usize,
    end: usize,
    emitted: u64,
}

impl std::fmt::Debug for Stream {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Stream").field("ratio", &self.ratio).field("lag", &self.lag).field("pad", &self.pad).finish()
    }
}

impl Stream {
    /// A stream from f_in to f_out = `ratio`·f_in at `quality`, at t = 0.
    /// Call [`Stream::prepare`] before pushing input.
    pub fn new(ratio: f64, quality: Quality) -> Result<Stream, ResampleError> {
        if !(ratio.is_finite() && ratio > 0.0) {
            return Err(ResampleError::Ratio(ratio));
        }
        let step = 1.0 / ratio;
        let rub = |e: &dyn std::fmt::Display| ResampleError::Rubato(e.to_string());
        let (inner, lag, lookahead) = match quality.sinc_len() {
            None => {
                if step > MAX_STEP {
                    return Err(ResampleError::StepTooLarge { step, quality: quality.name(), taps: 4 });
                }
                let inner = evflow_dsp::resamplers::async_poly(ratio, PolynomialDegree::Cubic, 1, FixedAsync::Output)
                    .map_err(|e| rub(&e))?;
                (inner, 2.0, 2.0)
            }
            Some(len) => {
                let (taps, phases) = if ratio < 1.0 {
                    ((len as f64 * step / 8.0).ceil() * 8.0, ((OVERSAMPLING as f64 * ratio).ceil() as usize).max(8))
                } else {
                    (len as f64, OVERSAMPLING)
                };
                if taps > MAX_SINC_TAPS as f64 || step > MAX_STEP {
                    return Err(ResampleError::StepTooLarge { step, quality: quality.name(), taps: taps as usize });
                }
                let taps = taps as usize;
                let cutoff: f32 = calculate_cutoff(len, WindowFunction::BlackmanHarris2);
                let params = SincInterpolationParameters::new(taps, WindowFunction::BlackmanHarris2)
                    .oversampling_factor(phases)
                    .interpolation(SincInterpolationType::Cubic)
                    .f_cutoff(cutoff);
                let inner =
                    evflow_dsp::resamplers::async_sinc(ratio, &params, 1, FixedAsync::Output).map_err(|e| rub(&e))?;
                (inner, taps as f64 / 2.0 - 1.0 / phases as f64, 1.0)
            }
        };
        let pad = (lookahead * ratio + 1.5).ceil() as u64;
        Ok(Stream { inner, ratio, lag, lookahead, pad, fifo: Vec::new(), start: 0, end: 0, emitted: 0 })
    }

    /// Sizes the input FIFO for calls that push at most `max_input` samples
    /// between pulls (may allocate).
    pub fn prepare(&mut self, max_input: usize) {
        let backlog = 2.0 * ((self.pad + 2) as f64 / self.ratio + self.lookahead).ceil() + 16.0;
        self.fifo = vec![0.0; max_input + backlog as usize];
        self.start = 0;
        self.end = 0;
    }

    /// f_out / f_in.
    pub fn ratio(&self) -> f64 {
        self.ratio
    }

    /// The latency D in output samples: output l is the input at output
    /// time l − D (see the module notes).
    pub fn latency(&self) -> f64 {
        (self.pad - 1) as f64 + self.lag * self.ratio
    }

    /// Appends input samples (finite; the caller checks).
    pub fn push(&mut self, x: &[f64]) -> Result<(), ResampleError> {
        if self.end + x.len() > self.fifo.len() {
            self.fifo.copy_within(self.start..self.end, 0);
            self.end -= self.start;
            self.start = 0;
            if self.end + x.len() > self.fifo.len() {
                return Err(ResampleError::Overflow(self.fifo.len()));
            }
        }
        for (slot, v) in self.fifo[self.end..self.end + x.len()].iter_mut().zip(x) {
            *slot = v * SCALE;
        }
        self.end += x.len();
        Ok(())
    }

    /// The next output sample.
    pub fn pull(&mut self) -> Result<f64, ResampleError> {
        let l = self.emitted;
        if l < self.pad {
            self.emitted += 1;
            return Ok(0.0);
        }
        let need = self.inner.input_frames_next();
        if self.end - self.start < need {
            return Err(ResampleError::Underrun(l));
        }
        let rub = |e: &dyn std::fmt::Display| ResampleError::Rubato(e.to_string());
        let input = SequentialSlice::new(&self.fifo[self.start..self.start + need], 1, need).map_err(|e| rub(&e))?;
        let mut frame = [0.0f64];
        let mut output = SequentialSlice::new_mut(&mut frame[..], 1, 1).map_err(|e| rub(&e))?;
        let (used, _) = self.inner.process_into_buffer(&input, &mut output, None).map_err(|e| rub(&e))?;
        self.start += used;
        self.emitted += 1;
        let y = frame[0] / SCALE;
        Ok(if y.is_finite() { y } else { y.clamp(-f64::MAX, f64::MAX) })
    }

    /// Back to t = 0 (the FIFO keeps its size).
    pub fn reset(&mut self) {
        self.inner.reset();
        self.start = 0;
        self.end = 0;
        self.emitted = 0;
    }

    /// A whole signal through the stream as the engine would feed it (each
    /// output after the inputs at or before its time; inputs past the end
    /// of `y` read as 0): the first `count` output samples.
    pub fn run(&mut self, y: &[f64], count: usize) -> Result<Vec<f64>, ResampleError> {
        let per_output = (1.0 / self.ratio).ceil() as usize + 2;
        self.prepare(per_output.max(4096));
        self.reset();
        let zeros = [0.0; 64];
        let mut fed = 0usize;
        let mut out = Vec::with_capacity(count);
        for l in 0..count {
            let due = (l as f64 / self.ratio).floor() as usize + 1;
            while fed < due {
                let n = (due - fed).min(4096);
                if fed < y.len() {
                    let n = n.min(y.len() - fed);
                    self.push(&y[fed..fed + n])?;
                    fed += n;
                } else {
                    let n = n.min(zeros.len());
                    self.push(&zeros[..n])?;
                    fed += n;
                }
            }
            out.push(self.pull()?);
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::TAU;

    /// Centre of mass, in output samples, of the response to a smooth bump
    /// centred on input sample `n0`; against n0·r + D.
    fn centroid_delay(ratio: f64, q: Quality) -> (f64, f64) {
        let mut s = Stream::new(ratio, q).unwrap();
        let n0 = 3000.0 / ratio.min(1.0);
        let width = 6.0 / ratio.min(1.0);
        let len = (2.0 * n0) as usize;
        let x: Vec<f64> = (0..len).map(|i| (-0.5 * ((i as f64 - n0) / width).powi(2)).exp()).collect();
        let y = s.run(&x, (len as f64 * ratio) as usize).unwrap();
        let mass: f64 = y.iter().sum();
        let c = y.iter().enumerate().map(|(j, v)| j as f64 * v).sum::<f64>() / mass;
        (c, n0 * ratio + s.latency())
    }

    #[test]
    fn the_stated_latency_is_where_a_bump_comes_out() {
        for ratio in [25.0, 1.5, 1.0, 0.7, 1000.0 / 44_100.0, 0.1] {
            for q in Quality::ALL {
                let (got, want) = centroid_delay(ratio, q);
                assert!((got - want).abs() < 1e-6, "r = {ratio}, {q:?}: centre at {got}, stated {want}");
            }
        }
    }

    #[test]
    fn a_slow_tone_is_reproduced_after_the_latency() {
        // 0.01 cycles per input sample (well inside every passband).
        for (ratio, tol) in [(25.0f64, 2e-5), (1.5, 1e-5), (0.3, 1e-5)] {
            for q in Quality::ALL {
                let f = 0.01 * ratio.min(1.0);
                let x: Vec<f64> = (0..20_000).map(|n| (TAU * f * n as f64).sin()).collect();
                let mut s = Stream::new(ratio, q).unwrap();
                let count = (x.len() as f64 * ratio) as usize;
                let y = s.run(&x, count).unwrap();
                let d = s.latency();
                let skip = (d.ceil() as usize) + (200.0 * ratio) as usize;
                let err = (skip..count - (d as usize) - 10)
                    .map(|l| (y[l] - (TAU * f * (l as f64 - d) / ratio).sin()).abs())
                    .fold(0.0, f64::max);
                let tol = if q == Quality::Fast { tol * 100.0 } else { tol };
                assert!(err < tol, "r = {ratio}, {q:?}: max error {err:e}");
            }
        }
    }

    #[test]
    fn bad_ratios_are_errors() {
        assert_eq!(Stream::new(0.0, Quality::Best).unwrap_err(), ResampleError::Ratio(0.0));
        assert!(matches!(Stream::new(f64::NAN, Quality::Fast), Err(ResampleError::Ratio(_))));
        let e = Stream::new(1e-4, Quality::Best).unwrap_err();
        assert!(matches!(e, ResampleError::StepTooLarge { .. }) && e.to_string().contains("decimate"), "{e}");
        assert!(Stream::new(1e-6, Quality::Fast).is_err());
        assert_eq!(Quality::from_name("balanced"), Some(Quality::Balanced));
        assert_eq!(Quality::from_name("good"), None);
        assert_eq!(QUALITY_NAMES, Quality::ALL.map(Quality::name));
    }

    #[test]
    fn extreme_inputs_stay_finite() {
        for q in Quality::ALL {
            let mut s = Stream::new(0.5, q).unwrap();
            let x: Vec<f64> = (0..4000).map(|n| if (n / 3) % 2 == 0 { f64::MAX } else { -f64::MAX }).collect();
            let y = s.run(&x, 1500).unwrap();
            assert!(y.iter().all(|v| v.is_finite()), "{q:?}");
            let mut s = Stream::new(2.0, q).unwrap();
            let y = s.run(&vec![1e300; 500], 900).unwrap();
            assert!(y.iter().all(|v| v.is_finite() && v.abs() < 2e300), "{q:?}");
        }
    }
}
