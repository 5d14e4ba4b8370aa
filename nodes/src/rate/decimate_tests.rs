//! Tests of `decimate` in a real plan: closed-form tones below and above
//! the new Nyquist frequency, DC, blocks, linearity, extremes, errors.

use super::*;
use crate::rate::decimator::design;
use crate::rate::testing::{noise, run_node};
use std::f64::consts::TAU;

/// Runs `decimate` with `params` on `x` at `fs_in` Hz, the base rate being
/// the input's, in blocks of `block` input samples.
fn run(params: &str, x: &[f64], fs_in: f64, block: usize) -> Result<Vec<f64>, String> {
    run_node(&SPEC, params, x, fs_in, fs_in, x.len() as u64, block)
}

/// sin(2πft + 0.7): the phase keeps a tone at the new Nyquist frequency off its zeros.
fn tone(f: f64, fs: f64, n: usize) -> Vec<f64> {
    (0..n).map(|i| (TAU * f / fs * i as f64 + 0.7).sin()).collect()
}

/// The figures the node's doc states.
#[test]
fn the_documented_designs() {
    let d = design(10, 0.8, 100.0).unwrap();
    assert_eq!((d.taps.len(), d.delay_in(), d.delay_out()), (661, 330, 33));
    assert!(d.response.pass_deviation <= 1e-5 && d.response.ripple_db() <= 8.7e-5, "{:?}", d.response);
    assert!(d.response.attenuation_db() >= 100.0, "{:?}", d.response);
    let d = design(4, 0.8, 100.0).unwrap();
    assert_eq!((d.taps.len(), d.delay_in(), d.delay_out()), (265, 132, 33));
    // docs/rates.md's table: (M, passband, attenuation) → (taps, delay in output samples).
    for (m, pass, a, taps, delay) in [
        (2, 0.8, 100.0, 133, 33),
        (10, 0.5, 100.0, 321, 16),
        (10, 0.8, 60.0, 381, 19),
        (25, 0.8, 100.0, 1651, 33),
        (100, 0.8, 100.0, 6601, 33),
    ] {
        let d = design(m, pass, a).unwrap();
        assert_eq!((d.taps.len(), d.delay_out()), (taps, delay), "M = {m}, passband {pass}, {a} dB");
        assert!(d.response.attenuation_db() >= a && d.response.pass_deviation <= 10f64.powf(-a / 20.0));
    }
}

/// 10 kHz → 1 kHz: tones below 400 Hz come out as sin(2πf(t − 33 ms)) to
/// within the passband ripple.
#[test]
fn a_tone_below_the_new_nyquist_passes_with_unit_gain_and_the_stated_delay() {
    let (fs, n) = (10_000.0, 12_000);
    for f in [7.0, 100.0, 250.0, 399.0] {
        let y = run("rate = 1000.0", &tone(f, fs, n), fs, 4096).unwrap();
        assert_eq!(y.len(), n / 10);
        let mut err = 0.0f64;
        for (l, v) in y.iter().enumerate().skip(66) {
            let want = (TAU * f * (l as f64 / 1000.0 - 0.033) + 0.7).sin();
            err = err.max((v - want).abs());
        }
        assert!(err < 1.1e-5, "{f} Hz: max deviation {err:e}");
    }
}

/// Tones at and above the new Nyquist frequency (500 Hz) are attenuated by
/// at least 100 dB, wherever they would alias to.
#[test]
fn a_tone_above_the_new_nyquist_is_attenuated_by_the_stated_figure() {
    let (fs, n) = (10_000.0, 12_000);
    for f in [500.0, 517.3, 900.0, 1_400.0, 2_999.0, 4_987.0] {
        let y = run("rate = 1000.0", &tone(f, fs, n), fs, 4096).unwrap();
        let peak = y.iter().skip(66).fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(peak <= 1e-5, "{f} Hz: output peak {peak:e} (> −100 dB)");
    }
    // A weaker design states a weaker figure, and meets it.
    for f in [500.0, 731.0] {
        let y = run("rate = 1000.0\nattenuation = 40.0\npassband = 0.5", &tone(f, fs, n), fs, 4096).unwrap();
        let peak = y.iter().skip(66).fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(peak <= 1e-2 && peak > 1e-6, "{f} Hz: output peak {peak:e}");
    }
}

#[test]
fn dc_gain_is_one() {
    let y = run("rate = 250.0", &[3.7; 4000], 1000.0, 64).unwrap();
    assert_eq!(y.len(), 1000);
    // After the 265-tap window has filled (66 output samples).
    for v in &y[67..] {
        assert!((v - 3.7).abs() <= 4.0 * f64::EPSILON * 3.7 * 16.0, "{v}");
    }
}

#[test]
fn any_block_size_gives_the_same_samples() {
    let x = noise(5000, 3);
    let whole = run("rate = 1000.0", &x, 10_000.0, x.len()).unwrap();
    assert_eq!(whole.len(), 500);
    for block in [1, 7, 64] {
        let y = run("rate = 1000.0", &x, 10_000.0, block).unwrap();
        assert!(y.iter().zip(&whole).all(|(a, b)| a.to_bits() == b.to_bits()), "block {block}");
    }
    // Input below the base rate: 40 Hz → 20 Hz at a 1 kHz base, in ticks.
    let slow = run_at("rate = 20.0", &x[..200], 40.0, 1000.0, 5000, 1).unwrap();
    let slow_blk = run_at("rate = 20.0", &x[..200], 40.0, 1000.0, 5000, 777).unwrap();
    assert_eq!(slow.len(), 100);
    assert!(slow.iter().zip(&slow_blk).all(|(a, b)| a.to_bits() == b.to_bits()));
}

fn run_at(params: &str, x: &[f64], fs_in: f64, base: f64, ticks: u64, block: usize) -> Result<Vec<f64>, String> {
    run_node(&SPEC, params, x, fs_in, base, ticks, block)
}

#[test]
fn it_is_linear_and_factor_one_is_the_identity() {
    let (x, z) = (noise(3000, 5), noise(3000, 9));
    let (a, b) = (2.5, -0.75);
    let mix: Vec<f64> = x.iter().zip(&z).map(|(p, q)| a * p + b * q).collect();
    let (yx, yz, ym) = (
        run("rate = 500.0", &x, 1000.0, 64).unwrap(),
        run("rate = 500.0", &z, 1000.0, 64).unwrap(),
        run("rate = 500.0", &mix, 1000.0, 64).unwrap(),
    );
    for l in 0..ym.len() {
        assert!((ym[l] - (a * yx[l] + b * yz[l])).abs() < 1e-14, "{l}");
    }
    assert_eq!(run("rate = 1000.0", &x, 1000.0, 7).unwrap(), x);
}

#[test]
fn extreme_inputs_give_bounded_finite_output() {
    let x: Vec<f64> = (0..2000).map(|n| if (n / 2) % 2 == 0 { 1e300 } else { -1e300 }).collect();
    let y = run("rate = 250.0", &x, 1000.0, 64).unwrap();
    let bound = design(4, 0.8, 100.0).unwrap().taps.iter().map(|t| t.abs()).sum::<f64>() * 1e300;
    assert!(y.iter().all(|v| v.is_finite() && v.abs() <= bound));
    let e = run("rate = 250.0", &[0.0, 1.0, f64::INFINITY, 2.0], 1000.0, 4).unwrap_err();
    assert!(e.contains("input sample 2 is inf"), "{e}");
}

#[test]
fn a_nan_input_is_an_error_naming_the_sample() {
    let ctx = BuildContext {
        node: "d".into(),
        base_rate: 1000.0,
        rate: 250.0,
        input_rates: vec![1000.0],
        output_rates: vec![250.0],
        base_dir: ".".into(),
        out_dir: ".".into(),
        seed: 0,
        check_only: false,
    };
    let params = evflow_engine::Params::from_map(
        [("passband", 0.8), ("attenuation", 100.0), ("rate", 250.0)]
            .into_iter()
            .map(|(k, v)| (k.to_string(), evflow_engine::Value::Float(v)))
            .collect(),
    );
    let mut node = build(&params, &ctx).unwrap();
    let pool = vec![vec![1.0, 2.0, 3.0, 4.0], vec![5.0, f64::NAN, 6.0, 7.0]];
    let mut outs = vec![vec![0.0; 1]];
    node.process(&mut Io::new(&pool, &[0], &[4], &mut outs, &[1], 0)).unwrap();
    let e = node.process(&mut Io::new(&pool, &[1], &[4], &mut outs, &[1], 1)).unwrap_err();
    assert!(matches!(&e, NodeError::Data(m) if m.contains("input sample 5 is NaN")), "{e}");
}

#[test]
fn rates_that_do_not_divide_are_clear_errors() {
    let x = vec![0.0; 100];
    // 10 kHz to 4 kHz at a 1 kHz base: both rates valid, their ratio 2.5.
    let e = run_at("rate = 4000.0", &x, 10_000.0, 1000.0, 10, 1).unwrap_err();
    assert!(e.contains("not an integer multiple") && e.contains("5000") && e.contains("resample"), "{e}");
    let e = run_at("rate = 2000.0", &x, 1000.0, 1000.0, 100, 10).unwrap_err();
    assert!(e.contains("only lowers a rate") && e.contains("hold"), "{e}");
    let e = run("rate = 500.0\npassband = 0.99", &x, 1000.0, 10).unwrap_err();
    assert!(e.contains("passband") && e.contains("0.95"), "{e}");
    let e = run("rate = 1.0\nattenuation = 200.0\npassband = 0.95", &x, 10_000.0, 10).unwrap_err();
    assert!(e.contains("two stages"), "{e}");
}
