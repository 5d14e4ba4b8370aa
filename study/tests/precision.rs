//! `evflow report precision`'s verdicts at the CI size: every curve
//! converges toward its reference as its setting refines, the reference is
//! at least 10× more precise than the best setting, and the shipped default
//! sits on or near the front. Orderings only: no absolute timing is
//! asserted, and "near the front" is judged on the counted work of each
//! setting, not its measured time.

use evflow_study::precision::curve::{front_gap, CostBy};
use evflow_study::precision::{self, Curve, Size};
use std::path::PathBuf;

fn graphs() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../graphs")
}

fn curves(name: &str) -> Vec<Curve> {
    let cs = precision::run(name, &graphs(), Size::Ci).unwrap_or_else(|e| panic!("{name}: {e}"));
    for c in &cs {
        assert!(!c.points.is_empty(), "{}", c.name);
        assert!(c.default_point().is_some(), "{}: the default {} was not measured", c.name, c.default);
        let best = c.best_error().expect("a finite error");
        if c.reference_error.is_nan() {
            // No reference 10× better exists: the curve must say so.
            assert!(c.reference.contains("none 10× better"), "{}: {}", c.name, c.reference);
        } else {
            assert!(
                c.reference_error * 10.0 <= best,
                "{}: the reference ({:e}) is not 10× better than the best setting ({best:e})",
                c.name,
                c.reference_error
            );
        }
        for p in &c.points {
            assert!(p.error >= 0.0 && p.cost > 0.0, "{}: {p:?}", c.name);
            if let Some(b) = c.baseline {
                assert!(p.error < b, "{}: {} is no better than the baseline {b}", c.name, p.setting);
            }
        }
        eprintln!("{}: reference {} ({:e}); baseline {:?}", c.name, c.reference, c.reference_error, c.baseline);
        for p in &c.points {
            eprintln!("  {:<32} {:>10.3e} {:>10.3e} s {:>10.3e}", p.setting, p.error, p.cost, p.work);
        }
    }
    cs
}

fn one(name: &str) -> Curve {
    curves(name).remove(0)
}

fn gap(c: &Curve) -> f64 {
    front_gap(&c.points, c.default_index().unwrap(), CostBy::Work)
}

fn falls(c: &Curve, series: &str) -> Vec<f64> {
    let e = c.errors_of(series);
    assert!(e.len() >= 3, "{}: {series}: {e:?}", c.name);
    e
}

#[cfg(feature = "lab")]
#[test]
fn lab_integrators_converge_and_the_default_is_on_the_front() {
    let cs = curves("lab");
    let by = |n: &str| cs.iter().find(|c| c.name == n).unwrap_or_else(|| panic!("no curve {n}"));
    let (display, sensor, trib) = (by("lab-display"), by("lab-forcesensor"), by("lab-tribometer"));
    // The exact integrator converges with its sub-steps on the display and the tribometer.
    for c in [display, trib] {
        let e = falls(c, "exact");
        assert!(e.last().unwrap() * 3.0 < e[0], "{}: {e:?}", c.name);
        assert!(gap(c) <= 1.0 + 1e-12, "{}: the default is off the front by {}", c.name, gap(c));
    }
    // The sensor is linear: its exact map has no discretization error at all,
    // while explicit Euler at one sub-step diverges on it.
    assert!(sensor.errors_of("exact").iter().all(|&e| e < 1e-9), "{:?}", sensor.errors_of("exact"));
    assert!(sensor.errors_of("euler")[0] > 0.1, "{:?}", sensor.errors_of("euler"));
}

#[test]
fn butterworth_converges_at_second_order_to_the_analog_response() {
    let c = one("butterworth");
    let e = falls(&c, "order 4 high-pass");
    assert!(e.windows(2).all(|w| w[1] < w[0]), "{e:?}");
    // f_s = 25 → 100 f_c: the bilinear transform's warping falls as (f/f_s)², 16×.
    let at = |s: &str| c.points.iter().find(|p| p.setting == s).unwrap().error;
    let ratio = at("f_s = 25 f_c") / at("f_s = 100 f_c");
    assert!((10.0..25.0).contains(&ratio), "{ratio}");
    assert_eq!(gap(&c), 1.0);
}

#[test]
fn decimate_converges_with_its_attenuation() {
    let c = one("decimate");
    let e = falls(&c, "÷10, passband 0.8");
    assert!(e.windows(2).all(|w| w[1] < w[0]), "{e:?}");
    assert!(c.default_point().unwrap().error < 1e-4, "{c:?}");
    assert_eq!(gap(&c), 1.0);
}

#[cfg(feature = "texture")]
#[test]
fn resamplers_and_interp_s_kernel_converge_and_the_defaults_are_near_the_front() {
    let c = one("resample");
    let d = c.default_point().unwrap();
    assert!(d.error < 1e-9, "the resample node's balanced sinc: {d:?}");
    let poly = falls(&c, "rubato polynomial");
    assert!(poly.windows(2).all(|w| w[1] < w[0]), "{poly:?}");
    assert!(gap(&c) <= 1.0 + 1e-12, "{}", gap(&c));

    let k = one("interp-kernel");
    let e = k.errors_of("Kaiser-windowed sinc, β 8.6, γ 0.9");
    // Widening the kernel from 2 to 8 zero crossings gains orders of
    // magnitude; beyond, the table's resolution sets a floor near 1e-5.
    assert!(e[2] * 100.0 < e[0], "{e:?}");
    assert!(k.best_error().unwrap() < 1e-4, "{e:?}");
    assert!(gap(&k) < 2.0, "{}", gap(&k));
}

#[test]
fn foaw_beats_finite_differences_and_its_default_is_near_the_front() {
    let c = one("foaw");
    let fd = c.errors_of("finite difference")[0];
    let d = c.default_point().unwrap();
    assert!(d.error * 2.0 < fd, "{d:?} against {fd}");
    assert!(gap(&c) < 1.5, "{}", gap(&c));
}

#[cfg(feature = "mesh")]
#[test]
fn mesh_gradient_converges_with_resolution() {
    let c = one("mesh-gradient");
    for slope in ["secant", "normal"] {
        let e = falls(&c, slope);
        assert!(e.last().unwrap() * 3.0 < e[0], "{slope}: {e:?}");
    }
    assert!(gap(&c) < 2.0, "{}", gap(&c));
}

#[cfg(feature = "synth")]
#[test]
fn the_volterra_model_improves_with_memory() {
    let c = one("volterra-memory");
    let e = c.errors_of("second-order Volterra");
    assert!(e.last().unwrap() * 1.5 < e[0], "{e:?}");
    assert!(gap(&c) < 1.5, "{}", gap(&c));
}

#[cfg(feature = "synth")]
#[test]
fn the_optimizer_converges_with_its_iterations_on_the_nominal_lab() {
    let cs = curves("optimize");
    assert_eq!(cs.len(), 1, "CI: the nominal lab only");
    let c = &cs[0];
    let e = falls(c, "start = best (carrier and inverse NARX)");
    assert!(e.windows(2).all(|w| w[1] < w[0]), "{e:?}");
    // Counted in objective evaluations, more iterations cost more.
    let work: Vec<f64> = c.points.iter().map(|p| p.work).collect();
    assert!(work.windows(2).all(|w| w[1] > w[0]), "{work:?}");
    assert!(gap(c) <= 1.0 + 1e-12, "{}", gap(c));
}

#[cfg(feature = "synth")]
#[test]
fn narx_settings_are_scored_against_training_time() {
    let c = one("narx");
    assert_eq!(c.points.len(), 2);
    // E_s of a model that renders anything is below 1 (1: no match at all), and no reference is 10× better.
    assert!(c.points.iter().all(|p| p.error > 0.0 && p.error < 1.0), "{:?}", c.points);
    assert!(c.reference_error.is_nan());
    // The default network has more weights than the one-layer network: it costs more work.
    let (d, other) = (c.default_point().unwrap(), c.points.iter().find(|p| p.setting != c.default).unwrap());
    assert!(d.work > other.work, "{d:?} {other:?}");
}

#[cfg(feature = "synth")]
#[test]
fn the_live_texture_chain_beats_no_actuation_and_its_default_is_near_the_front() {
    let c = one("live-texture");
    assert!(c.baseline.is_some());
    // More iterations per tick cost more counted work; the default is not far off the front.
    assert!(gap(&c) < 1.5, "{}", gap(&c));
}

#[cfg(feature = "mesh")]
#[test]
fn the_live_mesh_chain_converges_with_resolution() {
    let c = one("live-mesh");
    let e = falls(&c, "secant slope");
    assert!(e.windows(2).all(|w| w[1] < w[0]), "{e:?}");
    assert!(gap(&c) <= 1.0 + 1e-12, "{}", gap(&c));
}

#[test]
fn an_unknown_computation_is_named_in_the_error() {
    let e = precision::run("nonsense", &graphs(), Size::Ci).unwrap_err().to_string();
    assert!(e.contains("nonsense") && e.contains("butterworth"), "{e}");
}
