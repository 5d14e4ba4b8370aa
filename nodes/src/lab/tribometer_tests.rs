//! Tests of the tribometer model and node.

use super::integrator::Method;
use super::profile::{LabProfile, G};
use super::testutil::*;
use super::tribometer_model::{Motion, TribometerModel};

fn model(
    p: &LabProfile,
    rate: f64,
    speed: f64,
    grams: f64,
    passes: u64,
    method: Method,
    substeps: usize,
) -> TribometerModel {
    TribometerModel::new(p, rate, speed, grams * 1e-3, passes, method, substeps).unwrap()
}

#[test]
fn motion_is_the_analytic_trapezoid() {
    // 8 cm at 5 cm/s, 1 m/s²: 50 ms ramps of 1.25 mm, 1.55 s cruise, 1.65 s move.
    let m = Motion::new(0.08, 0.05, 1.0, 0.5);
    assert!((m.move_time() - 1.65).abs() < 1e-12);
    assert!((m.total_time(2) - (2.0 * 2.15 + 0.5)).abs() < 1e-12);
    let (x, v) = m.at(0.5 + 0.05, 2);
    assert!((x - 0.00125).abs() < 1e-12 && (v - 0.05).abs() < 1e-12);
    let (x, v) = m.at(0.5 + 1.0, 2);
    assert!((x - (0.00125 + 0.05 * 0.95)).abs() < 1e-12 && v == 0.05);
    assert_eq!(m.at(2.15, 2), (0.08, 0.0), "end of the right pass");
    let (x, v) = m.at(2.15 + 0.5 + 1.0, 2);
    assert!((x - (0.08 - 0.00125 - 0.05 * 0.95)).abs() < 1e-12 && v == -0.05, "left pass");
    assert_eq!(m.at(100.0, 2), (0.0, 0.0), "rests at the left end after two passes");
    // Too fast to reach the speed within the travel: triangular, peak √(a·D).
    let t = Motion::new(0.08, 0.5, 1.0, 0.5);
    assert!((t.peak_speed() - 0.08f64.sqrt()).abs() < 1e-12);
    assert!((t.at(0.5 + t.move_time(), 1).0 - 0.08).abs() < 1e-12);
    // Speed 0: standing still.
    assert_eq!(Motion::new(0.08, 0.0, 1.0, 0.5).at(3.0, 0), (0.0, 0.0));
}

#[test]
fn sampled_velocity_integrates_to_the_position() {
    let p = LabProfile::default();
    for rate in [1000.0, 10_000.0] {
        let mut t = model(&p, rate, 0.04, 85.0, 4, Method::Exact, 4);
        let total = t.total_samples().unwrap();
        assert_eq!(total, ((4.0 * (0.5 + 0.08 / 0.04 + 0.04) + 0.5) * rate).ceil() as u64);
        let (mut x_int, mut last, mut vmax) = (0.0, 0.0, 0.0f64);
        for _ in 0..total {
            let (x, v, _) = t.step();
            x_int += v / rate;
            last = x;
            vmax = vmax.max(v.abs());
        }
        assert!((x_int - last).abs() < 1e-12, "rate {rate}: ∫v = {x_int}, x = {last}");
        assert!(last.abs() < 1e-12, "four passes end at the left end");
        assert!(vmax <= 0.04 + 1e-12);
    }
}

#[test]
fn load_is_mg_at_rest_and_differs_by_bearing_friction_between_directions() {
    let p = LabProfile::default();
    let fb = p.tribometer.bearing_friction_n;
    let grams = 85.0;
    let mg = grams * 1e-3 * G;
    let mut t = model(&p, 1000.0, 0.05, grams, 2, Method::Exact, 4);
    let mut rows = Vec::new();
    for _ in 0..t.total_samples().unwrap() {
        rows.push(t.step());
    }
    assert!((rows[0].2 - mg).abs() < 1e-9, "at rest the bearing carries nothing: {}", rows[0].2);
    let cruise = |sign: f64| -> Vec<f64> { rows.iter().filter(|r| r.1 * sign > 0.049).map(|r| r.2).collect() };
    let (right, left) = (mean(&cruise(1.0)), mean(&cruise(-1.0)));
    // Rightward the sample rises under the pen (tilt), pushing the stylus up
    // against the bearing: m·g + F_b; leftward it sinks: m·g − F_b.
    assert!((right - mg - fb).abs() < 0.3 * fb, "right {right} vs {}", mg + fb);
    assert!((left - mg + fb).abs() < 0.3 * fb, "left {left} vs {}", mg - fb);
}

#[test]
fn every_profile_stays_finite_and_bounded_in_extreme_conditions() {
    for (name, p) in all_shipped() {
        let tr = &p.tribometer;
        for rate in [1000.0, 10_000.0] {
            for speed in [0.0, 0.001, 0.01, 0.05, 0.5] {
                for grams in [1.0, 60.0, 110.0, 1000.0] {
                    let mut t = model(&p, rate, speed, grams, 2, Method::Exact, 1);
                    let mg = grams * 1e-3 * G;
                    let vmax = speed.max(t.motion().peak_speed());
                    let surf_rate = vmax
                        * (tr.tilt_mm.abs() / tr.travel_cm * 0.1
                            + tr.waviness_um * 1e-6 * 2.0 * std::f64::consts::PI / (tr.waviness_mm * 1e-3));
                    // The load stays within m·g + F_b plus the inertia of following the sample.
                    let bound = 1.1 * (mg + tr.bearing_friction_n) + tr.normal_damping_ns_per_m * surf_rate;
                    let what = format!("{name} {rate} Hz {speed} m/s {grams} g");
                    let n = t.total_samples().unwrap_or(3000).min(60_000);
                    for _ in 0..n {
                        let (x, v, load) = t.step();
                        assert!(x.is_finite() && v.is_finite() && load.is_finite(), "{what}");
                        assert!((0.0..=bound).contains(&load), "{what}: load {load} outside 0 ..= {bound}");
                    }
                    assert_eq!(t.diverged, 0, "{what}");
                }
            }
        }
    }
}

#[test]
fn stylus_never_creates_energy() {
    // Carriage at rest; the stylus released from 1.5× its static compression
    // (stays in contact): ½mż² + m·g·z + ½k_n·pen² never rises.
    for (name, p) in all_shipped() {
        for rate in [1000.0, 10_000.0] {
            for grams in [60.0, 110.0, 1000.0] {
                let mut t = model(&p, rate, 0.0, grams, 0, Method::Exact, 1);
                let (q0, _) = t.stylus();
                t.set_stylus(1.5 * q0, 0.0);
                let mut e = t.energy(0.0);
                let mut stuck_load = 0.0;
                for _ in 0..3000 {
                    stuck_load = t.step().2;
                    let e1 = t.energy(0.0);
                    assert!(e1 <= e + 1e-12 * e.abs().max(1e-9), "{name} {rate} Hz {grams} g: {e} → {e1}");
                    e = e1;
                }
                // At rest the load is within the bearing's friction of m·g.
                let mg = grams * 1e-3 * G;
                assert!(
                    (stuck_load - mg).abs() <= p.tribometer.bearing_friction_n + 1e-9,
                    "{name}: {stuck_load} vs {mg}"
                );
            }
        }
    }
}

#[test]
fn explicit_euler_diverges_on_the_stiff_lab_at_1khz_exact_does_not() {
    let p = shipped("stiff");
    let mut exact = model(&p, 1000.0, 0.05, 85.0, 1, Method::Exact, 1);
    let mut euler = model(&p, 1000.0, 0.05, 85.0, 1, Method::Euler, 1);
    for _ in 0..1000 {
        let (_, _, a) = exact.step();
        let (_, _, b) = euler.step();
        assert!(a.is_finite() && b.is_finite());
        assert!(a < 1.0);
    }
    assert_eq!(exact.diverged, 0);
    assert!(euler.diverged > 0);
}

mod node {
    use crate::lab::testutil::shipped;
    use crate::lab::tribometer::SPEC;
    use evflow_engine::harness::Single;
    use std::path::Path;

    fn single(params: &str, block: usize, ticks: u64) -> Vec<Vec<f64>> {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../graphs/lab");
        Single::new(&SPEC, params)
            .outputs(["position", "velocity", "load"])
            .ticks(ticks)
            .block(block)
            .base_dir(&dir)
            .run()
            .unwrap()
    }

    #[test]
    fn block_and_per_sample_agree_and_the_example_runs() {
        let _ = shipped("stiff");
        for params in [SPEC.example, "profile = \"stiff.toml\"\nspeed = 50.0\nmass = 1.0\nsubsteps = 1"] {
            let a = single(params, 1, 3000);
            let b = single(params, 128, 3000);
            assert_eq!(a, b, "{params}");
        }
    }

    #[test]
    fn reset_restores_the_start() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../graphs/lab");
        let s = Single::new(&SPEC, "speed = 7.0\nmass = 60.0").output("load").block(100).base_dir(&dir);
        let (mut plan, idx) = s.plan().unwrap();
        let grab = |plan: &mut evflow_engine::Plan| {
            let mut v = Vec::new();
            for _ in 0..20 {
                plan.step(100).unwrap();
                v.extend_from_slice(plan.output("dut", idx[0]).unwrap());
            }
            v
        };
        let a = grab(&mut plan);
        plan.reset();
        assert_eq!(a, grab(&mut plan));
    }
}
