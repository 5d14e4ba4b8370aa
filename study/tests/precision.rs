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
        assert!(
            c.reference_error * 10.0 <= best,
            "{}: the reference ({:e}) is not 10× better than the best setting ({best:e})",
            c.name,
            c.reference_error
        );
        for p in &c.points {
            assert!(p.error >= 0.0 && p.cost > 0.0, "{}: {p:?}", c.name);
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

#[test]
fn an_unknown_computation_is_named_in_the_error() {
    let e = precision::run("nonsense", &graphs(), Size::Ci).unwrap_err().to_string();
    assert!(e.contains("nonsense") && e.contains("butterworth"), "{e}");
}
