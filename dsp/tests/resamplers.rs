//! rubato's resamplers as evflow-dsp makes them.

use evflow_dsp::resamplers::{async_poly, async_sinc, fft};
use rubato::audioadapter_buffers::direct::SequentialSlice;
use rubato::{FixedAsync, FixedSync, PolynomialDegree, Resampler, SincInterpolationParameters};
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
