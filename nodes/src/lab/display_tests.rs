//! Physics and robustness tests of the virtual display (model level).

use super::display_model::{DisplayModel, GUARD_N};
use super::integrator::Method;
use super::profile::{LabProfile, G};
use super::testutil::*;
use std::f64::consts::PI;

const LOAD_85G: f64 = 0.085 * G;

fn run(d: &mut DisplayModel, u: &[f64], load: f64, v: f64) -> Vec<f64> {
    u.iter().map(|&x| d.step(x, load, v)).collect()
}

fn sine(len: usize, amp: f64, f: f64, rate: f64) -> Vec<f64> {
    (0..len).map(|n| amp * (2.0 * PI * f * n as f64 / rate).sin()).collect()
}

#[test]
fn steady_sliding_matches_coulomb_friction() {
    // u = 0, no noise: the gap holds only the offset's DC part, so the force
    // is μ_k(v)·(F_n + k_e v_dc²) + c_v·v, and changes sign with direction.
    let p = LabProfile::default();
    let c = super::electrical::Circuit::of(&p);
    let fe = p.electrostatic_coefficient() * (c.dc_gain() * p.display.amplifier.offset_v).powi(2);
    let f = &p.display.friction;
    for rate in [1000.0, 10_000.0] {
        for (load, v) in [(LOAD_85G, 0.05), (0.06 * G, 0.03), (0.11 * G, -0.07), (1.0 * G, 0.5)] {
            let mut d = DisplayModel::new(&p, rate, Method::Exact, 4, 0.0, 1).unwrap();
            let out = run(&mut d, &vec![0.0; rate as usize], load, v);
            let mu = f.mu_kinetic + (f.mu_static - f.mu_kinetic) * (-(v / f.stribeck_velocity).powi(2)).exp();
            let want = v.signum() * (mu * (load + fe) + f.viscous * v.abs());
            let got = *out.last().unwrap();
            assert!((got - want).abs() < 1e-9 * (1.0 + want.abs()), "rate {rate} load {load} v {v}: {got} vs {want}");
        }
    }
}

#[test]
fn stops_and_holds_within_static_friction_then_reverses() {
    let p = LabProfile::default();
    let mut d = DisplayModel::new(&p, 1000.0, Method::Exact, 4, 0.0, 1).unwrap();
    let mut out = run(&mut d, &vec![0.0; 500], LOAD_85G, 0.05);
    let sliding = *out.last().unwrap();
    out = run(&mut d, &vec![0.0; 500], LOAD_85G, 0.0);
    // At rest the spring keeps (part of) the sliding force, within μ_s N, constant.
    let held = *out.last().unwrap();
    assert!(held > 0.0 && held <= p.display.friction.mu_static * LOAD_85G + 1e-9, "held {held}");
    assert!(out[400..].iter().all(|&x| (x - held).abs() < 1e-12), "no chatter while stuck: {:?}", &out[390..410]);
    out = run(&mut d, &vec![0.0; 500], LOAD_85G, -0.05);
    assert!((out.last().unwrap() + sliding).abs() < 1e-9, "reversal gives the mirrored force");
}

/// Mean force with and without actuation and the vibration amplitude, per
/// intensity, as the characterization of dissertation §3.1.2 measures them.
fn characterize(p: &LabProfile, noise: f64) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let rate = 10_000.0;
    let mut d = DisplayModel::new(p, rate, Method::Exact, 2, noise, 7).unwrap();
    let (mut inc, mut vib) = (Vec::new(), Vec::new());
    let intensities: Vec<f64> = (1..=10).map(|i| i as f64 / 10.0).collect();
    let seg = 2500;
    for &i in &intensities {
        // Off, on, off: the mean of the two off segments cancels the slow
        // drift of μ to first order. Skip the first 50 ms of each segment.
        let off1 = run(&mut d, &vec![0.0; seg], LOAD_85G, 0.05);
        let on = run(&mut d, &sine(seg, i, 100.0, rate), LOAD_85G, 0.05);
        let off2 = run(&mut d, &vec![0.0; seg], LOAD_85G, 0.05);
        inc.push(mean(&on[500..]) - 0.5 * (mean(&off1[500..]) + mean(&off2[500..])));
        vib.push(tone(&on[500..], 200.0, rate));
    }
    (intensities, inc, vib)
}

#[test]
fn friction_increase_and_vibration_are_quadratic_in_amplitude() {
    // Dissertation §3.1.2: both the static friction increase and the
    // vibratory force grow with the square of the input intensity.
    for noise in [0.0, 1.0] {
        let (i, inc, vib) = characterize(&LabProfile::default(), noise);
        let i2: Vec<f64> = i.iter().map(|x| x * x).collect();
        let (a, b, r2) = linear_fit(&i2, &inc);
        assert!(r2 > 0.99, "noise {noise}: static increase R² {r2}");
        assert!(b > 0.03 && a.abs() < 0.1 * b, "noise {noise}: increase {a} + {b}·I²");
        let (a, b, r2) = linear_fit(&i2, &vib);
        assert!(r2 > 0.99, "noise {noise}: vibration R² {r2}");
        assert!(b > 0.03 && a.abs() < 0.1 * b, "noise {noise}: vibration {a} + {b}·I²");
        // Magnitudes of the dissertation's range: p-p vibration at 1.0 in 0.1–0.3 N.
        let pp = 2.0 * vib[9];
        assert!((0.1..0.3).contains(&pp), "p-p vibration at intensity 1.0: {pp} N");
    }
}

#[test]
fn sine_gives_force_at_twice_its_frequency_and_offset_adds_the_fundamental() {
    let rate = 10_000.0;
    let mut p = LabProfile::default();
    let mut d = DisplayModel::new(&p, rate, Method::Exact, 2, 0.0, 1).unwrap();
    let f = run(&mut d, &sine(20_000, 1.0, 80.0, rate), LOAD_85G, 0.05);
    let tail = &f[10_000..];
    let (f1, f2) = (tone(tail, 80.0, rate), tone(tail, 160.0, rate));
    assert!(f2 > 0.05, "2f component {f2}");
    assert!(f1 > 0.01 * f2 && f1 < 0.2 * f2, "offset term {f1} vs {f2}");
    p.display.amplifier.offset_v = 0.0;
    let mut d = DisplayModel::new(&p, rate, Method::Exact, 2, 0.0, 1).unwrap();
    let f = run(&mut d, &sine(20_000, 1.0, 80.0, rate), LOAD_85G, 0.05);
    let tail = &f[10_000..];
    assert!(tone(tail, 80.0, rate) < 1e-9, "pure square law: no fundamental");
}

#[test]
fn without_offset_the_sign_of_u_is_invisible_with_it_visible() {
    let mut p = LabProfile::default();
    let u = prbs(3000, 1.0);
    let neg: Vec<f64> = u.iter().map(|x| -x).collect();
    let diff = |p: &LabProfile| {
        let mut a = DisplayModel::new(p, 1000.0, Method::Exact, 4, 0.0, 1).unwrap();
        let mut b = DisplayModel::new(p, 1000.0, Method::Exact, 4, 0.0, 1).unwrap();
        let fa = run(&mut a, &u, LOAD_85G, 0.04);
        let fb = run(&mut b, &neg, LOAD_85G, 0.04);
        fa.iter().zip(&fb).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max)
    };
    assert!(diff(&p) > 1e-3, "nominal offset makes u and −u differ");
    p.display.amplifier.offset_v = 0.0;
    assert_eq!(diff(&p), 0.0, "square law alone: u and −u give the same force");
}

#[test]
fn prbs_excites_dynamics_not_a_constant_force() {
    // Under a memoryless square law a ±1 PRBS would give a constant force.
    // The circuit's charge and leakage dynamics make the force spike at each
    // transition and decay within a run: the force carries the history of u.
    let u = prbs(4000, 1.0);
    let mut d = DisplayModel::new(&LabProfile::default(), 1000.0, Method::Exact, 4, 0.0, 1).unwrap();
    let f = run(&mut d, &u, LOAD_85G, 0.05);
    let (mut after, mut later) = (Vec::new(), Vec::new());
    let mut run_len = 0;
    for n in 1000..4000 {
        run_len = if u[n] == u[n - 1] { run_len + 1 } else { 0 };
        match run_len {
            0 => after.push(f[n]),
            r if r >= 3 => later.push(f[n]),
            _ => {}
        }
    }
    let (ma, ml) = (mean(&after), mean(&later));
    assert!(ma - ml > 0.05, "transition {ma} vs within-run {ml}");
    let sd = (f[1000..].iter().map(|x| (x - mean(&f[1000..])).powi(2)).sum::<f64>() / 3000.0).sqrt();
    assert!(sd > 0.03, "force standard deviation {sd}");
}

#[test]
fn every_profile_stays_finite_and_bounded_in_extreme_conditions() {
    for (name, p) in all_shipped() {
        let fs_max = p.display.friction.mu_static;
        let ke = p.electrostatic_coefficient();
        for rate in [1000.0, 10_000.0] {
            for v in [0.0, 0.001, 0.01, 0.05, 0.5, -0.5] {
                for grams in [1.0, 85.0, 1000.0] {
                    for (kind, u) in [("zero", vec![0.0; 600]), ("2.0", vec![2.0; 600]), ("prbs 2.0", prbs(600, 2.0))] {
                        for noise in [0.0, 1.0, 100.0] {
                            let load = grams * 1e-3 * G;
                            let mut d = DisplayModel::new(&p, rate, Method::Exact, 1, noise, 3).unwrap();
                            let out = run(&mut d, &u, load, v);
                            let what = format!("{name} {rate} Hz v {v} {grams} g u {kind} noise {noise}");
                            assert_eq!(d.diverged, 0, "{what}");
                            assert!(out.iter().all(|x| x.is_finite()), "{what}");
                            if noise <= 1.0 {
                                // |F| ≤ 2 μ_s (1 + 5σ) (F_n + k_e V²max) + c_v |v|.
                                let sig = p.display.friction.noise + p.display.friction.drift;
                                let bound =
                                    2.0 * fs_max * (1.0 + 5.0 * sig) * (load + ke * p.display.amplifier.max_v.powi(2))
                                        + p.display.friction.viscous * v.abs();
                                let peak = out.iter().fold(0.0f64, |m, x| m.max(x.abs()));
                                assert!(peak <= bound, "{what}: peak {peak} > {bound}");
                            } else {
                                assert!(out.iter().all(|x| x.abs() < GUARD_N), "{what}");
                            }
                        }
                    }
                }
            }
        }
    }
}

#[test]
fn bad_inputs_read_as_zero() {
    let mut d = DisplayModel::new(&LabProfile::default(), 1000.0, Method::Exact, 4, 1.0, 1).unwrap();
    for x in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        assert!(d.step(x, x, x).is_finite());
    }
    assert_eq!(d.bad_inputs, 9);
}

#[test]
fn contact_never_creates_energy() {
    // Holder at rest, tip released from a deflection beyond static friction,
    // load and electrostatic force changing under a PRBS: the contact's
    // energy ½kδ² + ½mv² never rises, on every profile and at both rates.
    for (name, p) in all_shipped() {
        for rate in [1000.0, 10_000.0] {
            for substeps in [1, 4] {
                let mut d = DisplayModel::new(&p, rate, Method::Exact, substeps, 1.0, 5).unwrap();
                let k = p.display.contact.stiffness_n_per_m;
                d.set_contact(3.0 / k, 0.0);
                let mut e = d.mechanical_energy();
                for &u in &prbs(2000, 1.0) {
                    d.step(u, LOAD_85G, 0.0);
                    let e1 = d.mechanical_energy();
                    assert!(e1 <= e * (1.0 + 1e-9) + 1e-15, "{name} {rate} Hz ×{substeps}: {e} → {e1}");
                    e = e1;
                }
            }
        }
    }
}

#[test]
fn explicit_euler_diverges_on_the_stiff_lab_at_1khz_exact_does_not() {
    let p = shipped("stiff");
    let u = prbs(1000, 1.0);
    let mut exact = DisplayModel::new(&p, 1000.0, Method::Exact, 1, 0.0, 1).unwrap();
    let fe = run(&mut exact, &u, LOAD_85G, 0.05);
    assert_eq!(exact.diverged, 0);
    assert!(fe.iter().all(|x| x.abs() < 2.0), "exact stays bounded");
    let mut euler = DisplayModel::new(&p, 1000.0, Method::Euler, 1, 0.0, 1).unwrap();
    let fu = run(&mut euler, &u, LOAD_85G, 0.05);
    assert!(euler.diverged > 0, "explicit Euler must diverge here");
    assert!(
        fu.iter().all(|x| x.is_finite() && x.abs() <= GUARD_N),
        "even diverging, the output stays finite and clamped"
    );
    // RK4 fails too at one substep (its stability region ends near |hλ| ≈ 2.8).
    let mut rk4 = DisplayModel::new(&p, 1000.0, Method::Rk4, 1, 0.0, 1).unwrap();
    run(&mut rk4, &u, LOAD_85G, 0.05);
    assert!(rk4.diverged > 0);
}

#[test]
fn explicit_methods_converge_to_the_exact_one_with_enough_substeps() {
    // Nominal lab, 1 kHz: with fine substeps RK4 and the exact method agree
    // (both discretize the same equations and the same set-valued friction;
    // convergence_tests.rs checks both against an independent reference).
    let p = LabProfile::default();
    let u = prbs(300, 1.0);
    let mut exact = DisplayModel::new(&p, 1000.0, Method::Exact, 400, 0.0, 1).unwrap();
    let fe = run(&mut exact, &u, LOAD_85G, 0.05);
    let mut rk4 = DisplayModel::new(&p, 1000.0, Method::Rk4, 400, 0.0, 1).unwrap();
    let fr = run(&mut rk4, &u, LOAD_85G, 0.05);
    assert_eq!(rk4.diverged, 0);
    let err = fe.iter().zip(&fr).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    assert!(err < 1e-4, "max difference {err} N");
}

#[test]
fn seeded_noise_reproduces_and_reset_replays() {
    let p = LabProfile::default();
    let u = prbs(2000, 1.0);
    let mut a = DisplayModel::new(&p, 1000.0, Method::Exact, 4, 1.0, 11).unwrap();
    let mut b = DisplayModel::new(&p, 1000.0, Method::Exact, 4, 1.0, 11).unwrap();
    let mut c = DisplayModel::new(&p, 1000.0, Method::Exact, 4, 1.0, 12).unwrap();
    let fa = run(&mut a, &u, LOAD_85G, 0.05);
    assert_eq!(fa, run(&mut b, &u, LOAD_85G, 0.05));
    assert_ne!(fa, run(&mut c, &u, LOAD_85G, 0.05));
    a.reset();
    assert_eq!(fa, run(&mut a, &u, LOAD_85G, 0.05));
}

#[test]
fn the_latency_delays_the_actuation_by_whole_samples() {
    let mut p = LabProfile::default();
    let u: Vec<f64> = (0..400).map(|k| if k % 2 == 0 { 0.7 } else { -0.7 } * (1.0 + (k as f64 * 0.05).sin())).collect();
    let mut now = DisplayModel::new(&p, 1000.0, Method::Exact, 4, 0.0, 1).unwrap();
    p.display.amplifier.delay_ms = 2.6; // rounds to 3 samples at 1 kHz
    let mut late = DisplayModel::new(&p, 1000.0, Method::Exact, 4, 0.0, 1).unwrap();
    let shifted: Vec<f64> = [0.0; 3].iter().chain(&u[..u.len() - 3]).copied().collect();
    let a = run(&mut now, &shifted, 0.85, 0.05);
    let b = run(&mut late, &u, 0.85, 0.05);
    assert_eq!(a, b);
    // Reset empties the line.
    late.reset();
    assert_eq!(run(&mut late, &u, 0.85, 0.05), b);
    assert_eq!(super::display_model::delay_samples(2.6, 10_000.0), 26);
    assert_eq!(super::display_model::delay_samples(0.4, 1000.0), 0);
}
