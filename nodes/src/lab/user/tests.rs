use super::*;
use evflow_engine::harness::Single;

fn run(params: &str, seconds: f64, outputs: Vec<&'static str>) -> Vec<Vec<f64>> {
    Single::new(&SPEC, params).outputs(outputs).ticks((seconds * 1000.0) as u64).block(37).run().unwrap()
}

#[test]
fn the_ir_frame_reports_at_40_hz_quantized_and_the_load_cell_is_noisy() {
    let out = run("seed = 3", 10.0, vec!["x", "ir_x", "load", "load_cell"]);
    let (x, ir, load, cell) = (&out[0], &out[1], &out[2], &out[3]);
    assert_eq!(x.len(), 10_000);
    assert_eq!(ir.len(), 400);
    for (k, v) in ir.iter().enumerate() {
        // On the 0.5 mm grid, and the finger's position at the frame's time (frame k at tick 25k).
        let steps = v / 0.0005;
        assert!((steps - steps.round()).abs() < 1e-6, "{v}");
        assert!((v - x[25 * k]).abs() <= 0.00025 + 1e-12, "frame {k}: {v} vs {}", x[25 * k]);
    }
    let err: Vec<f64> = cell.iter().enumerate().map(|(k, c)| c - load[25 * k]).collect();
    let rms = (err.iter().map(|e| e * e).sum::<f64>() / err.len() as f64).sqrt();
    assert!((rms - 0.005).abs() < 0.001, "load cell noise rms {rms}");
    assert!(err.iter().sum::<f64>().abs() / (err.len() as f64) < 0.001, "unbiased");
}

#[test]
fn speed_and_load_vary_like_a_person_within_the_ranges() {
    let out = run("seed = 4", 30.0, vec!["velocity", "load"]);
    let speeds: Vec<f64> = out[0].iter().map(|v| v.abs()).collect();
    assert!(speeds.iter().all(|s| *s <= 0.07 + 1e-9));
    let cruising: Vec<f64> = speeds.iter().copied().filter(|s| *s > 0.02).collect();
    let (lo, hi) = cruising.iter().fold((f64::MAX, 0.0f64), |(a, b), s| (a.min(*s), b.max(*s)));
    assert!(lo < 0.035 && hi > 0.065, "speeds {lo}..{hi} should span most of 3–7 cm/s");
    let g = finger::G;
    assert!(out[1].iter().all(|l| *l >= 0.06 * g - 1e-9 && *l <= 0.11 * g + 1e-9));
    let (lmin, lmax) = out[1].iter().fold((f64::MAX, 0.0f64), |(a, b), l| (a.min(*l), b.max(*l)));
    assert!(lmax - lmin > 0.02 * g, "the pressure varies: {lmin}..{lmax} N");
}

#[test]
fn the_touch_point_follows_the_direction_and_origin() {
    let out = run("seed = 1\ndirection = 90.0\norigin_x = 0.01\norigin_y = -0.02", 3.0, vec!["position", "x", "y"]);
    for ((p, x), y) in out[0].iter().zip(&out[1]).zip(&out[2]) {
        assert!((x - 0.01).abs() < 1e-12);
        assert!((y - (-0.02 + p)).abs() < 1e-12);
    }
}

#[test]
fn seeds_decide_the_finger() {
    let a = run("seed = 9", 2.0, vec!["velocity", "load_cell"]);
    let b = run("seed = 9", 2.0, vec!["velocity", "load_cell"]);
    let c = run("seed = 10", 2.0, vec!["velocity", "load_cell"]);
    assert_eq!(a, b);
    assert_ne!(a, c);
}

#[test]
fn extreme_settings_stay_finite_and_bounded() {
    for params in [
        "speed_min = 0.0\nspeed_max = 0.0\nmass_min = 1.0\nmass_max = 1.0",
        "speed_min = 50.0\nspeed_max = 50.0\nmass_min = 1000.0\nmass_max = 1000.0\nreversal = 0.002",
        "load_noise = 10.0\nir_resolution = 0.1\nwander = 0.01",
    ] {
        let out = run(params, 5.0, vec!["position", "velocity", "load", "ir_x", "load_cell"]);
        for o in &out {
            assert!(o.iter().all(|v| v.is_finite()), "{params}");
        }
        assert!(out[0].iter().all(|p| (0.0..=0.08).contains(p)), "{params}");
        assert!(out[1].iter().all(|v| v.abs() <= 0.5 + 1e-9), "{params}");
    }
}

#[test]
fn inverted_ranges_are_refused() {
    let r = Single::new(&SPEC, "speed_min = 7.0\nspeed_max = 3.0").output("x").ticks(10).block(10).run();
    assert!(r.is_err_and(|e| e.to_string().contains("speed_min")));
}
