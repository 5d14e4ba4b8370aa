//! Tests of `resample` in a real plan: the stated latency, a 44.1 kHz tone
//! to 1 kHz against the analytic sine, a 40 Hz ramp interpolated, blocks,
//! extremes, errors.

use super::*;
use crate::rate::resampler::{Quality, Stream};
use crate::rate::testing::run_node;
use std::f64::consts::TAU;

/// Runs `resample` with `params` on `x` at `fs_in` Hz in a graph of base
/// rate `base`, for `ticks` base ticks in blocks of `block` ticks.
fn run(params: &str, x: &[f64], fs_in: f64, base: f64, ticks: u64, block: usize) -> Result<Vec<f64>, String> {
    run_node(&SPEC, params, x, fs_in, base, ticks, block)
}

fn latency(fs_in: f64, fs_out: f64, q: Quality) -> f64 {
    Stream::new(fs_out / fs_in, q).unwrap().latency()
}

/// The documented latencies (the node's doc and docs/rates.md), in seconds.
#[test]
fn the_documented_latencies() {
    use Quality::{Balanced, Best, Fast};
    let rows = [
        (40.0, 1000.0, [0.101, 1.626, 3.226]),
        (10.0, 1000.0, [0.401, 6.50, 12.9]),
        (44_100.0, 1000.0, [0.00105, 0.0650, 0.1291]),
        (10_000.0, 1000.0, [0.0012, 0.0650, 0.1290]),
        (1000.0, 10_000.0, [0.0041, 0.0651, 0.1291]),
        (300.0, 200.0, [0.0167, 0.330, 0.650]),
        (48_000.0, 44_100.0, [0.00011, 0.00155, 0.00296]),
    ];
    for (fin, fout, want) in rows {
        for (q, want) in [Fast, Balanced, Best].into_iter().zip(want) {
            let got = latency(fin, fout, q) / fout;
            // As printed: three significant figures.
            assert!((got - want).abs() <= 0.005 * want, "{fin} → {fout} {q:?}: {got} s, documented {want} s");
        }
    }
}

/// A 44.1 kHz recording to 1 kHz (base rate 100 Hz): tones come out as the
/// analytic sine at t − D, to within (measured): `fast` 2e-7, `balanced`
/// 8e-11 up to 300 Hz and 6e-6 at 400 Hz (0.8 of the new Nyquist
/// frequency, its sinc's roll-off), `best` 8e-11 up to 400 Hz.
#[test]
fn a_tone_from_44_1_khz_to_1_khz_matches_the_sine_after_the_latency() {
    let seconds = 1.2;
    let n = (44_100.0 * seconds) as usize;
    let cases = [
        (Quality::Fast, 400.0, 1e-6),
        (Quality::Balanced, 100.0, 1e-9),
        (Quality::Balanced, 300.0, 1e-9),
        (Quality::Balanced, 400.0, 1e-5),
        (Quality::Best, 100.0, 1e-9),
        (Quality::Best, 400.0, 1e-9),
    ];
    for (q, f, tol) in cases {
        let x: Vec<f64> = (0..n).map(|i| (TAU * f * i as f64 / 44_100.0).sin()).collect();
        let params = format!("rate = 1000.0\nquality = \"{}\"", q.name());
        let y = run(&params, &x, 44_100.0, 100.0, (seconds * 100.0) as u64, 16).unwrap();
        assert_eq!(y.len(), 1200);
        let d = latency(44_100.0, 1000.0, q) / 1000.0;
        // From one filter length after the start to one before the end.
        let first = (2.0 * d * 1000.0) as usize + 1;
        let last = y.len() - (d * 1000.0) as usize - 2;
        let err = (first..last).map(|l| (y[l] - (TAU * f * (l as f64 / 1000.0 - d)).sin()).abs()).fold(0.0, f64::max);
        assert!(err < tol, "{q:?} {f} Hz: max error {err:e}");
    }
}

/// Above the new Nyquist frequency the sincs remove what would alias
/// (measured: 520 Hz to 3e-9, 600 Hz to 6e-12); `fast` has no filter and
/// folds a 600 Hz tone onto 400 Hz nearly whole.
#[test]
fn a_tone_above_the_new_nyquist_is_removed_by_the_sincs_only() {
    let n = 44_100;
    for (f, bound) in [(520.0, 1e-8), (600.0, 1e-10)] {
        let x: Vec<f64> = (0..n).map(|i| (TAU * f * i as f64 / 44_100.0 + 0.3).sin()).collect();
        for q in Quality::ALL {
            let params = format!("rate = 1000.0\nquality = \"{}\"", q.name());
            let y = run(&params, &x, 44_100.0, 100.0, 100, 100).unwrap();
            let peak = y[300..].iter().fold(0.0f64, |m, v| m.max(v.abs()));
            match q {
                Quality::Fast => assert!(peak > 0.9, "{f} Hz: {peak}"),
                _ => assert!(peak < bound, "{q:?} {f} Hz: {peak:e}"),
            }
        }
    }
}

/// 40 Hz frames of a ramp to 1 kHz: `fast` gives the ramp itself at t − D
/// (a cubic reproduces a line exactly; measured 2e-14), `balanced` to
/// 1.1e-6 (its taps' sum and first moment are exact only to that); no
/// staircase.
#[test]
fn a_40_hz_ramp_is_interpolated_not_held() {
    let x: Vec<f64> = (0..200).map(|k| 0.1 * k as f64).collect();
    for (q, tol) in [(Quality::Fast, 1e-12), (Quality::Balanced, 1e-5)] {
        let params = format!("rate = 1000.0\nquality = \"{}\"", q.name());
        let y = run(&params, &x, 40.0, 1000.0, 5000, 1).unwrap();
        let d = latency(40.0, 1000.0, q);
        let start = (d + 40.0 * 25.0) as usize;
        let mut err = 0.0f64;
        for l in start..4000 {
            err = err.max((y[l] - 0.1 * (l as f64 - d) / 25.0).abs());
            // Every 1 ms step moves the value on (a hold would repeat it 24 times in 25).
            assert!(y[l + 1] - y[l] > 0.5 * 0.1 / 25.0, "{q:?}: step at {l}: {} → {}", y[l], y[l + 1]);
        }
        assert!(err < tol, "{q:?}: max deviation from the ramp {err:e}");
    }
}

/// A step at input sample 1000 rises at the stated time: the centre of
/// its rise, Σ l·(y[l] − y[l−1]) − ½ (the centre of the impulse response
/// the differences sample), against 999.5·r + D (a sampled step's
/// half-way point lies between its last 0 and its first 1).
#[test]
fn a_step_appears_at_the_stated_latency() {
    for (fin, fout, base) in [(1000.0, 250.0, 1000.0), (40.0, 1000.0, 1000.0), (300.0, 200.0, 100.0)] {
        for q in Quality::ALL {
            let x: Vec<f64> = (0..3000).map(|k| if k >= 1000 { 1.0 } else { 0.0 }).collect();
            let ticks = (3000.0 / fin * base) as u64;
            let params = format!("rate = {fout:?}\nquality = \"{}\"", q.name());
            let y = run(&params, &x, fin, base, ticks, 64).unwrap();
            let rise: f64 = y.windows(2).map(|w| w[1] - w[0]).sum();
            let centre =
                y.windows(2).enumerate().map(|(l, w)| (l + 1) as f64 * (w[1] - w[0])).sum::<f64>() / rise - 0.5;
            let want = 999.5 * fout / fin + latency(fin, fout, q);
            // The cubic without a filter, lowering a rate 4-fold, jumps within
            // one output sample: its centre is known to that sample only.
            let tol = if q == Quality::Fast && fout < fin { 0.5 } else { 1e-6 };
            assert!((rise - 1.0).abs() < 1e-9, "{fin} → {fout} {q:?}: rise {rise}");
            assert!((centre - want).abs() < tol, "{fin} → {fout} {q:?}: rises at {centre}, stated {want}");
        }
    }
}

#[test]
fn any_block_size_gives_the_same_samples() {
    let x: Vec<f64> = (0..3000).map(|k| ((k as f64) * 0.37).sin() + 0.3 * ((k as f64) * 0.011).cos()).collect();
    // (input Hz, output Hz, base Hz): 2/3 at a 100 Hz base (blocks of 3 inputs),
    // 25× up and 4× down at the input's own rate (blocks of single samples).
    for (fin, fout, base) in [(300.0, 200.0, 100.0), (40.0, 1000.0, 40.0), (1000.0, 250.0, 1000.0)] {
        for q in Quality::ALL {
            let params = format!("rate = {fout:?}\nquality = \"{}\"", q.name());
            let ticks = (x.len() as f64 / fin * base) as u64;
            let whole = run(&params, &x, fin, base, ticks, ticks as usize).unwrap();
            assert_eq!(whole.len() as f64, (ticks as f64 / base * fout).round());
            for block in [1, 7, 64] {
                let y = run(&params, &x, fin, base, ticks, block).unwrap();
                assert!(
                    y.iter().zip(&whole).all(|(a, b)| a.to_bits() == b.to_bits()),
                    "{fin} → {fout} {q:?}: block {block} differs"
                );
            }
        }
    }
}

#[test]
fn it_is_linear() {
    let x: Vec<f64> = (0..2000).map(|k| ((k as f64) * 0.21).sin()).collect();
    let z: Vec<f64> = (0..2000).map(|k| ((k as f64) * 0.05).cos()).collect();
    let mix: Vec<f64> = x.iter().zip(&z).map(|(p, q)| 2.0 * p - 0.5 * q).collect();
    for q in Quality::ALL {
        let params = format!("rate = 200.0\nquality = \"{}\"", q.name());
        let go = |v: &[f64]| run(&params, v, 300.0, 100.0, 600, 8).unwrap();
        let (yx, yz, ym) = (go(&x), go(&z), go(&mix));
        for l in 0..ym.len() {
            assert!((ym[l] - (2.0 * yx[l] - 0.5 * yz[l])).abs() < 1e-12, "{q:?} {l}");
        }
    }
}

#[test]
fn extreme_and_non_finite_inputs() {
    let x: Vec<f64> = (0..1000).map(|n| if (n / 2) % 2 == 0 { 1e300 } else { -1e300 }).collect();
    for q in Quality::ALL {
        let params = format!("rate = 500.0\nquality = \"{}\"", q.name());
        let y = run(&params, &x, 1000.0, 1000.0, 1000, 64).unwrap();
        assert!(y.iter().all(|v| v.is_finite() && v.abs() < 3e300), "{q:?}");
    }
    let e = run("rate = 500.0", &[0.0, 1.0, 2.0, f64::NEG_INFINITY], 1000.0, 1000.0, 4, 2).unwrap_err();
    assert!(e.contains("input sample 3 is -inf"), "{e}");
}

#[test]
fn bad_parameters_are_clear_errors() {
    let x = vec![0.0; 10];
    let e = run("rate = 1.0\nquality = \"best\"", &x, 10_000.0, 10_000.0, 10, 1).unwrap_err();
    assert!(e.contains("decimate") && e.contains("rate"), "{e}");
    let e = run("rate = 500.0\nquality = \"good\"", &x, 1000.0, 1000.0, 10, 1).unwrap_err();
    assert!(e.contains("quality") && e.contains("balanced"), "{e}");
}
