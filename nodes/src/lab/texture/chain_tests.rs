//! `sim.texture` in the recording chain of `graphs/record-textures.toml`:
//! tribometer → texture → force sensor (seeded per repetition) → 10 Hz
//! high-pass, through a real plan, as §5.1.1 records a sample.

use super::samples::{sample, NAMES};
use super::tests::main_wavelengths;
use crate::lab::testutil::linear_fit;
use crate::metric::spectral_error::{spectral_rms_error, Band};
use crate::metric::spectrum::{averaged_spectrum, Spectrum, SpectrumConfig, Window};
use evflow_engine::graph::parse_graph;
use evflow_engine::harness::TAP;
use evflow_engine::{check, Plan, PlanOptions, Registry};
use std::path::Path;

/// The high-passed force over the constant-speed parts of two passes (the
/// segments §5.1.1 extracts and concatenates).
fn record(sample: &str, mass: f64, speed: f64, rep: u64) -> Vec<f64> {
    let text = format!(
        r#"[graph]
format = 1
name = "texture-chain"
rate = 1000
connections = [
  "trib.position -> texture.position",
  "trib.velocity -> texture.velocity",
  "trib.load -> texture.load",
  "texture.force -> sensor.surface_force",
  "trib.velocity -> sensor.velocity",
  "sensor.force -> hp.in",
  "hp.out -> out.in",
  "trib.velocity -> vel.in",
]
[nodes.trib]
type = "sim.tribometer"
speed = {speed:?}
mass = {mass:?}
passes = 2
[nodes.texture]
type = "sim.texture"
sample = "{sample}"
[nodes.sensor]
type = "sim.forcesensor"
seed = {rep}
[nodes.hp]
type = "butterworth"
kind = "highpass"
order = 4
cutoff = 10.0
[nodes.out]
type = "harness.tap"
[nodes.vel]
type = "harness.tap"
"#
    );
    let mut reg = Registry::new();
    for s in crate::lab::SPECS {
        reg.add(s);
    }
    reg.add(&crate::filters::butterworth::SPEC).add(&TAP);
    let g = parse_graph(Path::new("texture-chain.toml"), &text).unwrap();
    let checked = check(&g, &reg, &[]).unwrap_or_else(|e| panic!("{e}"));
    let opts = PlanOptions {
        max_block: 256,
        seed: Some(1),
        base_dir: None,
        timing: false,
        out_dir: None,
        mode: evflow_engine::RunMode::Offline,
        check_only: false,
    };
    let mut plan = Plan::build(&checked, &opts).unwrap();
    let mut out = Vec::new();
    let cruise = speed * 1e-2;
    while plan.remaining_ticks().is_none_or(|r| r > 0) {
        let n = plan.remaining_ticks().map_or(256, |r| r.min(256) as usize);
        plan.step(n).unwrap();
        let f = plan.output("hp", 0).unwrap();
        let v = plan.output("trib", 1).unwrap();
        out.extend(
            f.iter().zip(v).filter(|(_, v)| (v.abs() - cruise).abs() < 1e-9 * cruise.max(1e-3)).map(|(f, _)| *f),
        );
    }
    plan.finish().unwrap();
    out
}

/// Averaged magnitude spectrum, 1000-point FFT (1 Hz bins, §5.2.3).
fn spectrum(x: &[f64]) -> Spectrum {
    let cfg = SpectrumConfig { rate: 1000.0, nfft: 1000, window: Window::Rect, overlap: 0.0 };
    averaged_spectrum(x, cfg).unwrap().unwrap()
}

#[test]
fn recorded_main_frequency_is_linear_in_velocity_on_every_sample() {
    // §6.3 and Appendix A, on the recordings themselves (after the 10 Hz
    // high-pass of §5.1.1): the main spectral peak against the velocity
    // is a line of slope 1/λ at both ends of the load range.
    let speeds = [3.0, 4.0, 5.0, 6.0, 7.0];
    for name in NAMES {
        let s = sample(name).unwrap();
        for mass in [60.0, 110.0] {
            let load = mass * 1e-3 * 9.806_65;
            // 1 Hz bins: ±0.5 Hz on a 15 Hz peak is ±3 %.
            let (lo, hi) = main_wavelengths(&s, load, 0.05);
            let f: Vec<f64> = speeds
                .iter()
                .map(|&v| {
                    let sp = spectrum(&record(name, mass, v, 1));
                    sp.freq(sp.largest_peak(1, 500).unwrap())
                })
                .collect();
            let v: Vec<f64> = speeds.iter().map(|v| v * 1e-2).collect();
            let (_, slope, r2) = linear_fit(&v, &f);
            println!(
                "{name:16} {mass} g: main peak {f:?} Hz, slope {slope:.1} Hz per m/s (λ {:.3} mm), R² {r2:.5}",
                1e3 / slope
            );
            assert!(r2 > 0.99, "{name} {mass} g: R² {r2} ({f:?} Hz)");
            assert!((lo..=hi).contains(&(1.0 / slope)), "{name} {mass} g: slope {slope} Hz per m/s, λ {lo}..{hi} m");
            assert!(f[0] >= 12.0, "{name} {mass} g: the main peak at 3 cm/s ({} Hz) is above the high-pass", f[0]);
        }
    }
}

#[test]
fn repeated_recordings_differ_only_by_the_sensor_and_much_less_than_samples() {
    // §5.3.1's baseline: two recordings of one sample under one condition
    // (sensor seeds 1 and 2) against recordings of the other samples, E_s
    // (Eq. 5.2) over every bin but 0 Hz. The same seed gives the same bytes.
    let band = Band::new(1000.0, 1000, 1.0, 500.0, false).unwrap();
    assert_eq!(record(NAMES[0], 85.0, 5.0, 1), record(NAMES[0], 85.0, 5.0, 1));
    for (mass, speed) in [(60.0, 3.0), (60.0, 7.0), (85.0, 5.0), (110.0, 3.0), (110.0, 7.0)] {
        let spectra: Vec<Vec<f64>> = NAMES.iter().map(|n| spectrum(&record(n, mass, speed, 1)).magnitude).collect();
        for (i, n) in NAMES.iter().enumerate() {
            let again = spectrum(&record(n, mass, speed, 2)).magnitude;
            let repeat = spectral_rms_error(&again, &spectra[i], &band).unwrap();
            let closest = (0..NAMES.len())
                .filter(|&j| j != i)
                .map(|j| spectral_rms_error(&spectra[j], &spectra[i], &band).unwrap())
                .fold(f64::INFINITY, f64::min);
            println!("{n:16} {mass} g {speed} cm/s: repeat E_s {repeat:.3}, closest other sample {closest:.3}");
            assert!(repeat > 0.0 && repeat < 0.4, "{n} {mass} g {speed} cm/s: repeat E_s {repeat}");
            assert!(repeat < 0.5 * closest, "{n} {mass} g {speed} cm/s: repeat {repeat} vs another sample {closest}");
        }
    }
}

#[test]
fn under_the_virtual_users_finger_the_texture_stays_on_the_surface() {
    // sim.user strokes rippled paper for 20 s with speed and pressure
    // varying like a person's: μ = F / (N·tanh(v/v_s)) read back at the
    // same place on different strokes agrees, whatever the speed — the
    // texture is a surface, not a time signal.
    let text = r#"[graph]
format = 1
name = "user-on-texture"
rate = 1000
connections = [
  "user.position -> texture.position",
  "user.velocity -> texture.velocity",
  "user.load -> texture.load",
  "texture.force -> f.in",
  "user.position -> x.in",
  "user.velocity -> v.in",
  "user.load -> n.in",
]
[nodes.user]
type = "sim.user"
seed = 5
[nodes.texture]
type = "sim.texture"
sample = "rippled-paper"
[nodes.f]
type = "harness.tap"
[nodes.x]
type = "harness.tap"
[nodes.v]
type = "harness.tap"
[nodes.n]
type = "harness.tap"
"#;
    let mut reg = Registry::new();
    for s in crate::lab::SPECS {
        reg.add(s);
    }
    reg.add(&TAP);
    let g = parse_graph(Path::new("user-on-texture.toml"), text).unwrap();
    let checked = check(&g, &reg, &[]).unwrap_or_else(|e| panic!("{e}"));
    let opts = PlanOptions {
        max_block: 100,
        seed: Some(1),
        base_dir: None,
        timing: false,
        out_dir: None,
        mode: evflow_engine::RunMode::Offline,
        check_only: false,
    };
    let mut plan = Plan::build(&checked, &opts).unwrap();
    // μ per 25 µm of position: (min, max, count) over the strokes.
    let mut bins = vec![(f64::INFINITY, f64::NEG_INFINITY, 0usize); 3200];
    let (mut speeds, mut loads) = (Vec::new(), Vec::new());
    for _ in 0..200 {
        plan.step(100).unwrap();
        let (f, x) = (plan.output("texture", 0).unwrap(), plan.output("user", 0).unwrap());
        let (v, n) = (plan.output("user", 1).unwrap(), plan.output("user", 2).unwrap());
        for k in 0..f.len() {
            assert!(f[k].is_finite() && f[k].abs() <= 1.9 * 0.17 * n[k] + 1e-12);
            if v[k].abs() > 0.01 {
                let mu = f[k] / (n[k] * (v[k] / super::surface::V_SIGN).tanh());
                let b = &mut bins[((x[k] * 4e4) as usize).min(3199)];
                *b = (b.0.min(mu), b.1.max(mu), b.2 + 1);
                speeds.push(v[k].abs());
                loads.push(n[k]);
            }
        }
    }
    let span =
        |x: &[f64]| x.iter().fold(f64::NEG_INFINITY, |a, b| a.max(*b)) - x.iter().fold(f64::INFINITY, |a, b| a.min(*b));
    assert!(span(&speeds) > 0.03 && span(&loads) > 0.2, "the user varied speed and load");
    let visited: Vec<_> = bins.iter().filter(|b| b.2 >= 3).collect();
    assert!(visited.len() > 1600, "{} bins visited on several strokes", visited.len());
    // Within a 25 µm bin μ moves by at most its slope times 25 µm (about
    // μ₀·(2π·0.5/2.5 + 2π·0.06/1.25 + roughness) mm⁻¹ · 0.025 mm ≈ 0.008)
    // plus the patch's small load dependence; across the surface it spans
    // about ±50 % of μ₀ = 0.17.
    let within = visited.iter().map(|b| b.1 - b.0).fold(0.0, f64::max);
    println!("{} bins visited 3 times or more; μ spread within a bin ≤ {within:.4}", visited.len());
    let across = visited.iter().map(|b| b.1).fold(0.0, f64::max) - visited.iter().map(|b| b.0).fold(1.0, f64::min);
    assert!(within < 0.012, "μ at one place differs by {within} between strokes");
    assert!(across > 0.15, "μ spans {across} over the surface");
}
