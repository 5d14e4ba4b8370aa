use super::samples::{is_soft, sample, NAMES};
use super::surface::Surface;
use crate::lab::rng::Rng;
use crate::lab::testutil::{linear_fit, tone};
use crate::metric::spectral_error::{spectral_rms_error, Band};

const RATE: f64 = 1000.0;

/// A constant-speed scan: force at 1 kHz for `seconds`, plus white noise of rms `noise` N.
fn scan(s: &Surface, speed: f64, load: f64, seconds: f64, noise: f64, seed: u64) -> Vec<f64> {
    let mut g = vec![0.0; s.components.len()];
    s.gains(load, &mut g);
    let mut rng = Rng::new(seed);
    (0..(seconds * RATE) as usize)
        .map(|k| s.force(0.003 + speed * k as f64 / RATE, speed, load, &g) + noise * rng.gaussian())
        .collect()
}

fn ac(x: &[f64]) -> Vec<f64> {
    let m = x.iter().sum::<f64>() / x.len() as f64;
    x.iter().map(|v| v - m).collect()
}

/// The strongest component between `lo` and `hi` Hz (0.1 Hz grid).
fn main_frequency(x: &[f64], lo: f64, hi: f64) -> f64 {
    let x = ac(x);
    let mut best = (lo, 0.0);
    let mut f = lo;
    while f <= hi {
        let a = tone(&x, f, RATE);
        if a > best.1 {
            best = (f, a);
        }
        f += 0.1;
    }
    best.0
}

fn power(x: &[f64]) -> f64 {
    let x = ac(x);
    x.iter().map(|v| v * v).sum::<f64>() / x.len() as f64
}

#[test]
fn the_main_frequency_scales_linearly_with_velocity() {
    for (name, wavelength) in [("rippled-paper", 0.005), ("dotted-sheet", 0.002)] {
        let s = sample(name).unwrap();
        let speeds = [0.03, 0.04, 0.05, 0.06, 0.07];
        let f: Vec<f64> = speeds.iter().map(|&v| main_frequency(&scan(&s, v, 0.834, 4.0, 0.0, 1), 2.0, 60.0)).collect();
        let (_, slope, r2) = linear_fit(&speeds, &f);
        assert!(r2 > 0.999, "{name}: R² {r2} ({f:?})");
        assert!((slope * wavelength - 1.0).abs() < 0.02, "{name}: slope {slope} Hz per m/s, want {}", 1.0 / wavelength);
    }
}

#[test]
fn heavier_loads_raise_the_power() {
    for name in NAMES {
        let s = sample(name).unwrap();
        let light = power(&scan(&s, 0.05, 0.060 * 9.81, 4.0, 0.0, 1));
        let heavy = power(&scan(&s, 0.05, 0.110 * 9.81, 4.0, 0.0, 1));
        assert!(heavy > 1.5 * light, "{name}: {light} → {heavy}");
    }
}

/// Fraction of the AC force power above `f` Hz.
fn high_fraction(x: &[f64], f: f64) -> f64 {
    let x = ac(x);
    let (mut hi, mut all) = (0.0, 0.0);
    let mut g = 0.5;
    while g < 400.0 {
        let a = tone(&x, g, RATE).powi(2);
        all += a;
        if g >= f {
            hi += a;
        }
        g += 0.5;
    }
    hi / all
}

#[test]
fn soft_samples_lose_their_detail_under_the_contact_and_rough_ones_keep_it() {
    // Power kept through the contact patch, against the same surface under
    // a point contact; and the share of power above 25 Hz at 5 cm/s.
    let mut kept = Vec::new();
    for n in NAMES {
        let s = sample(n).unwrap();
        let point = Surface { sigma_1n: 0.0, ..s.clone() };
        let k = power(&scan(&s, 0.05, 0.834, 2.0, 0.0, 1)) / power(&scan(&point, 0.05, 0.834, 2.0, 0.0, 1));
        let hf = high_fraction(&scan(&s, 0.05, 0.834, 2.0, 0.0, 1), 25.0);
        kept.push((*n, k, hf));
    }
    for (n, k, _) in &kept {
        if is_soft(n) {
            assert!(*k < 0.6, "{n} keeps {k} ({kept:?})");
        } else {
            assert!(*k > 0.8, "{n} keeps {k} ({kept:?})");
        }
    }
    // Felt, soft and without a pattern, keeps almost nothing above 25 Hz
    // at 5 cm/s; the canvas and the dotted sheet keep most of their power there.
    let hf = |name: &str| kept.iter().find(|p| p.0 == name).map(|p| p.2).unwrap();
    for n in ["painting-canvas", "dotted-sheet"] {
        assert!(hf(n) > 5.0 * hf("felt-fabric"), "{n}: {} vs felt {}", hf(n), hf("felt-fabric"));
    }
}

#[test]
fn repeated_scans_differ_much_less_than_different_samples() {
    // Two scans of one sample with independent sensor-like noise (5 mN rms),
    // against scans of other samples: E_s (Eq. 5.2) over 2–200 Hz.
    let band = Band::new(RATE, 1000, 2.0, 200.0, false).unwrap();
    let scans: Vec<(Vec<f64>, Vec<f64>)> = NAMES
        .iter()
        .map(|n| {
            let s = sample(n).unwrap();
            (scan(&s, 0.05, 0.834, 4.0, 0.005, 1), scan(&s, 0.05, 0.834, 4.0, 0.005, 2))
        })
        .collect();
    for (i, a) in scans.iter().enumerate() {
        let repeat = spectral_rms_error(&a.1, &a.0, &band).unwrap();
        for (j, b) in scans.iter().enumerate() {
            if i != j {
                let other = spectral_rms_error(&b.0, &a.0, &band).unwrap();
                assert!(repeat < 0.5 * other, "{} repeat {repeat} vs {} {other}", NAMES[i], NAMES[j]);
            }
        }
    }
}

#[test]
fn extremes_stay_finite_and_bounded() {
    for n in NAMES {
        let s = sample(n).unwrap();
        for (speed, load) in [(0.0, 0.834), (0.5, 0.834), (-0.5, 0.834), (0.05, 0.00981), (0.05, 9.81), (0.0, 0.0)] {
            let f = scan(&s, speed, load, 0.5, 0.0, 1);
            assert!(f.iter().all(|v| v.is_finite() && v.abs() <= 1.9 * s.mu * load + 1e-12), "{n} {speed} {load}");
            if speed == 0.0 {
                assert!(f.iter().all(|v| *v == 0.0), "{n}: no force at rest");
            }
        }
    }
}
