//! The re-sampling operator 𝓡𝓢(y, p, q) of dissertation §6.2 for whole
//! signals: y re-sampled at p/q times its sample rate (decimation factor
//! d.f. = p/q), so that, played at the original rate, every frequency is
//! multiplied by q/p. 𝓡𝓢(y₁, f₁, f₃) moves a component at f₁ to f₃;
//! with velocities for frequencies (Eq. 6.3) 𝓡𝓢(U, v_j, v_u).
//!
//! Several resamplers are offered, to trade error against run time
//! (`docs/texture.md` has the table): rubato's asynchronous sinc resampler
//! at a chosen sinc length, rubato's polynomial resampler, rubato's
//! synchronous FFT resampler (p/q must then be a ratio of small integers),
//! the table-driven windowed sinc of [`SincKernel`] that `interp` runs
//! live, and the streaming resampler of the `resample` node at each of its
//! qualities ([`crate::rate::resampler`]).

use super::kernel::SincKernel;
use crate::rate::resampler::{Quality, ResampleError, Stream};
use rubato::audioadapter_buffers::direct::SequentialSlice;
use rubato::{
    FixedAsync, FixedSync, PolynomialDegree, Resampler, SincInterpolationParameters, SincInterpolationType,
    WindowFunction,
};

/// Which resampler carries out 𝓡𝓢.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum RsMethod {
    /// rubato `Async` with sinc interpolation of this length (taps), cubic
    /// interpolation between 256 oversampled sincs, Blackman–Harris² window.
    RubatoSinc(usize),
    /// rubato `Async` with polynomial interpolation (no anti-aliasing).
    RubatoPoly(PolynomialDegree),
    /// rubato `Fft` (synchronous; p/q reduced to integers below 100 000).
    RubatoFft,
    /// The Kaiser-windowed sinc table of [`SincKernel`] with this half-width.
    Kernel(usize),
    /// The `resample` node's streaming resampler at this quality, its
    /// stated latency removed to the nearest output sample.
    Node(Quality),
}

impl RsMethod {
    /// A short name for tables.
    pub fn label(&self) -> String {
        match self {
            RsMethod::RubatoSinc(n) => format!("rubato sinc {n}"),
            RsMethod::RubatoPoly(d) => format!("rubato poly {d:?}").to_lowercase(),
            RsMethod::RubatoFft => "rubato fft".into(),
            RsMethod::Kernel(w) => format!("kaiser sinc W={w}"),
            RsMethod::Node(q) => format!("resample node {}", q.name()),
        }
    }
}

/// Why 𝓡𝓢 could not run.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RsError {
    /// p or q is not a positive finite number.
    #[error("re-sampling needs positive finite p and q, not p = {p}, q = {q}")]
    Ratio {
        /// p.
        p: f64,
        /// q.
        q: f64,
    },
    /// The FFT resampler needs p/q as a ratio of integers it can handle.
    #[error("p/q = {p}/{q} is not a ratio of integers below 100000; use a sinc or polynomial resampler")]
    NotRational {
        /// p.
        p: f64,
        /// q.
        q: f64,
    },
    /// rubato refused.
    #[error("rubato: {0}")]
    Rubato(String),
    /// The `resample` node's stream refused.
    #[error("resample: {0}")]
    Stream(#[from] ResampleError),
}

/// p/q as a reduced fraction of integers below 100 000, if one matches to
/// 1e-12 relative (continued fractions).
pub fn rational(p: f64, q: f64) -> Option<(usize, usize)> {
    let x = p / q;
    let (mut h0, mut h1, mut k0, mut k1) = (0u64, 1u64, 1u64, 0u64);
    let mut r = x;
    for _ in 0..40 {
        let a = r.floor();
        if a > 1e6 {
            return None;
        }
        let a = a as u64;
        let (h2, k2) = (a * h1 + h0, a * k1 + k0);
        if h2 >= 100_000 || k2 >= 100_000 {
            return None;
        }
        (h0, h1, k0, k1) = (h1, h2, k1, k2);
        if ((h1 as f64 / k1 as f64) - x).abs() <= 1e-12 * x {
            return Some((h1 as usize, k1 as usize));
        }
        let f = r - a as f64;
        if f < 1e-15 {
            break;
        }
        r = 1.0 / f;
    }
    None
}

/// 𝓡𝓢(y, p, q): `y` re-sampled at p/q times its rate, ⌊len·p/q⌋ samples,
/// aligned so that output sample k is y at input position k·q/p (within
/// one output sample for the rubato resamplers, whose delay is trimmed in
/// whole output samples, and within half of one for [`RsMethod::Node`];
/// exactly for [`RsMethod::Kernel`]).
pub fn rs(y: &[f64], p: f64, q: f64, method: RsMethod) -> Result<Vec<f64>, RsError> {
    if !(p.is_finite() && q.is_finite() && p > 0.0 && q > 0.0) {
        return Err(RsError::Ratio { p, q });
    }
    let ratio = p / q;
    let len_out = (y.len() as f64 * ratio).floor() as usize;
    if y.is_empty() || len_out == 0 {
        return Ok(Vec::new());
    }
    let rub = |e: &dyn std::fmt::Display| RsError::Rubato(e.to_string());
    let mut resampler: Box<dyn Resampler<f64>> = match method {
        RsMethod::Kernel(w) => {
            let k = SincKernel::for_interp(w);
            return Ok(k.resample(y, 0.0, 1.0 / ratio, len_out));
        }
        RsMethod::Node(quality) => {
            let mut stream = Stream::new(ratio, quality)?;
            let shift = stream.latency().round() as usize;
            let mut v = stream.run(y, len_out + shift)?;
            v.drain(..shift);
            return Ok(v);
        }
        RsMethod::RubatoSinc(len) => {
            let params = SincInterpolationParameters::new(len.max(8), WindowFunction::BlackmanHarris2)
                .oversampling_factor(256)
                .interpolation(SincInterpolationType::Cubic);
            evflow_dsp::resamplers::async_sinc(ratio, &params, 1024, FixedAsync::Input).map_err(|e| rub(&e))?
        }
        RsMethod::RubatoPoly(d) => {
            evflow_dsp::resamplers::async_poly(ratio, d, 1024, FixedAsync::Input).map_err(|e| rub(&e))?
        }
        RsMethod::RubatoFft => {
            let (a, b) = rational(p, q).ok_or(RsError::NotRational { p, q })?;
            evflow_dsp::resamplers::fft(b, a, 1024, FixedSync::Input).map_err(|e| rub(&e))?
        }
    };
    let input = SequentialSlice::new(y, 1, y.len()).map_err(|e| rub(&e))?;
    let out = resampler.process_all(&input, y.len(), None).map_err(|e| rub(&e))?;
    let mut v = out.take_data();
    v.resize(len_out, 0.0);
    Ok(v)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::TAU;

    fn sine(f: f64, a: f64, n: usize) -> Vec<f64> {
        (0..n).map(|i| a * (TAU * f * i as f64 / 1000.0).sin()).collect()
    }

    #[test]
    fn rational_reduces_ratios() {
        assert_eq!(rational(10.0, 15.0), Some((2, 3)));
        assert_eq!(rational(3.5, 4.0), Some((7, 8)));
        assert_eq!(rational(20.0, 15.0), Some((4, 3)));
        assert_eq!(rational(std::f64::consts::PI, 1.0), None);
    }

    #[test]
    fn every_method_moves_10_hz_to_15_hz_in_phase() {
        let y = sine(10.0, 1.0, 4000);
        for m in [
            RsMethod::RubatoSinc(128),
            RsMethod::RubatoPoly(PolynomialDegree::Cubic),
            RsMethod::RubatoFft,
            RsMethod::Kernel(16),
            RsMethod::Node(Quality::Fast),
            RsMethod::Node(Quality::Balanced),
            RsMethod::Node(Quality::Best),
        ] {
            let r = rs(&y, 10.0, 15.0, m).unwrap();
            assert_eq!(r.len(), 2666, "{m:?}");
            let want = sine(15.0, 1.0, r.len());
            let err = r[300..2300].iter().zip(&want[300..2300]).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
            // rubato's delay is trimmed in whole output samples: the
            // alignment is within one output sample (2π·15/1000 = 0.094 rad).
            assert!(err < 0.094, "{m:?}: {err}");
        }
    }

    #[test]
    fn bad_ratios_are_errors() {
        assert!(matches!(rs(&[1.0], 0.0, 1.0, RsMethod::RubatoSinc(64)), Err(RsError::Ratio { .. })));
        assert!(matches!(
            rs(&[1.0; 100], std::f64::consts::PI, 1.0, RsMethod::RubatoFft),
            Err(RsError::NotRational { .. })
        ));
        assert_eq!(rs(&[], 1.0, 2.0, RsMethod::RubatoSinc(64)).unwrap(), Vec::<f64>::new());
    }
}
