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
