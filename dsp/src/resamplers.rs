//! rubato's resamplers of `f64` samples, each returned as a
//! `Box<dyn Resampler<f64>>`: the caller drives it through rubato's
//! [`Resampler`] trait (`process_into_buffer`, `process_all`,
//! `input_frames_next`, `reset`).

use rubato::{
    Async, Fft, FixedAsync, FixedSync, PolynomialDegree, Resampler, ResamplerConstructionError,
    SincInterpolationParameters,
};

/// What rubato's constructors return.
pub type Made = Result<Box<dyn Resampler<f64>>, ResamplerConstructionError>;

/// rubato's asynchronous resampler with sinc interpolation
/// (`Async::new_sinc`): output rate / input rate `ratio` (fixed: no
/// relative change allowed), `chunk` frames per call on the `fixed` side,
/// one channel.
pub fn async_sinc(ratio: f64, params: &SincInterpolationParameters, chunk: usize, fixed: FixedAsync) -> Made {
    Ok(Box::new(Async::<f64>::new_sinc(ratio, 1.0, params, chunk, 1, fixed)?))
}

/// rubato's asynchronous resampler with polynomial interpolation
/// (`Async::new_poly`) of `degree`: as [`async_sinc`] without the
/// anti-alias filter.
pub fn async_poly(ratio: f64, degree: PolynomialDegree, chunk: usize, fixed: FixedAsync) -> Made {
    Ok(Box::new(Async::<f64>::new_poly(ratio, 1.0, degree, chunk, 1, fixed)?))
}

/// rubato's synchronous FFT resampler (`Fft::new`) from `rate_in` to
/// `rate_out` (integers), `chunk` frames per call on the `fixed` side, one
/// channel.
pub fn fft(rate_in: usize, rate_out: usize, chunk: usize, fixed: FixedSync) -> Made {
    Ok(Box::new(Fft::<f64>::new(rate_in, rate_out, chunk, 1, fixed)?))
}

#[cfg(test)]
mod tests {
    use super::*;
    use rubato::audioadapter_buffers::direct::SequentialSlice;
    use rubato::{SincInterpolationType, WindowFunction};

    /// A slow sine (period 200 samples) through `r` at ratio 2: the output,
    /// away from the ends where the filters ring in, is a sine of period
    /// 400 samples and amplitude 1 (its phase is the resampler's delay).
    fn doubles_a_slow_sine(mut r: Box<dyn Resampler<f64>>) {
        let x: Vec<f64> = (0..4096).map(|k| (2.0 * std::f64::consts::PI * k as f64 / 200.0).sin()).collect();
        let input = SequentialSlice::new(&x, 1, x.len()).unwrap();
        let y = r.process_all(&input, x.len(), None).unwrap().take_data();
        assert_eq!(y.len(), 2 * x.len());
        for j in 1000..7000 {
            assert!((y[j + 400] - y[j]).abs() < 2e-3, "samples {j} and {}: {} {}", j + 400, y[j], y[j + 400]);
        }
        let peak = y[1000..1400].iter().fold(0.0f64, |m, v| m.max(v.abs()));
        assert!((peak - 1.0).abs() < 2e-3, "amplitude {peak}");
    }

    #[test]
    fn each_resampler_doubles_a_slow_sine() {
        let params = SincInterpolationParameters::new(128, WindowFunction::BlackmanHarris2)
            .oversampling_factor(256)
            .interpolation(SincInterpolationType::Cubic);
        doubles_a_slow_sine(async_sinc(2.0, &params, 1024, FixedAsync::Input).unwrap());
        doubles_a_slow_sine(async_poly(2.0, PolynomialDegree::Cubic, 1024, FixedAsync::Input).unwrap());
        doubles_a_slow_sine(fft(1, 2, 1024, FixedSync::Input).unwrap());
    }

    #[test]
    fn a_ratio_rubato_refuses_is_its_error() {
        assert!(async_poly(0.0, PolynomialDegree::Cubic, 1024, FixedAsync::Input).is_err());
    }
}
