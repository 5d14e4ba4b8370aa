//! rustfft and rubato as evflow-dsp hands them out, against references.

use evflow_dsp::fft::forward;
use rustfft::num_complex::Complex64;

#[test]
fn transforms_a_cosine_into_two_lines() {
    // x[k] = cos(2π·3k/16): X[3] = X[13] = 8, every other bin 0.
    let n = 16;
    let mut x: Vec<Complex64> =
        (0..n).map(|k| Complex64::new((2.0 * std::f64::consts::PI * 3.0 * k as f64 / n as f64).cos(), 0.0)).collect();
    forward(n).process(&mut x);
    for (k, v) in x.iter().enumerate() {
        let want = if k == 3 || k == 13 { 8.0 } else { 0.0 };
        assert!((v.re - want).abs() < 1e-12 && v.im.abs() < 1e-12, "bin {k}: {v}");
    }
}

#[test]
fn a_prime_length_equals_the_direct_sum() {
    // 31 takes rustfft's prime butterfly; the DFT sum is the reference.
    let n = 31;
    let x: Vec<Complex64> = (0..n).map(|k| Complex64::new((k as f64 * 0.7).sin(), (k as f64 * 0.3).cos())).collect();
    let mut y = x.clone();
    forward(n).process(&mut y);
    for (j, v) in y.iter().enumerate() {
        let want: Complex64 = x
            .iter()
            .enumerate()
            .map(|(k, xk)| xk * Complex64::from_polar(1.0, -2.0 * std::f64::consts::PI * (j * k) as f64 / n as f64))
            .sum();
        assert!((v - want).norm() < 1e-10, "bin {j}: {v} against {want}");
    }
}
