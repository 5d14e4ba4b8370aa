//! The samples' surfaces scanned at constant speed and load (the texture
//! model alone; `chain_tests.rs` runs the whole recording chain).

use super::samples::{is_soft, sample, NAMES};
use super::surface::Surface;
use crate::lab::testutil::{linear_fit, mean, tone};
use crate::metric::spectral_error::{spectral_rms_error, Band};
use crate::metric::spectrum::{averaged_spectrum, SpectrumConfig, Window};
use crate::rng::Rng;

const RATE: f64 = 1000.0;
const G: f64 = 9.806_65;
/// The grid's loads (§5.1.1), N.
const M60: f64 = 0.060 * G;
const M85: f64 = 0.085 * G;
const M110: f64 = 0.110 * G;

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
    let m = mean(x);
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

/// Averaged magnitude spectrum with a 1000-point FFT (1 Hz bins, §5.2.3).
fn spectrum(x: &[f64]) -> Vec<f64> {
    let cfg = SpectrumConfig { rate: RATE, nfft: 1000, window: Window::Rect, overlap: 0.0 };
    averaged_spectrum(x, cfg).unwrap().unwrap().magnitude
}

#[test]
fn the_main_frequency_scales_linearly_with_velocity() {
    // §6.3, Appendix A: the frequency of the main component against the
    // scanning velocity is a line through 0 whose slope is 1/λ of one of
    // the sample's main components, on every sample.
    let speeds = [0.03, 0.04, 0.05, 0.06, 0.07];
    for name in NAMES {
        let s = sample(name).unwrap();
        let f: Vec<f64> = speeds.iter().map(|&v| main_frequency(&scan(&s, v, M85, 4.0, 0.0, 1), 2.0, 120.0)).collect();
        let (icpt, slope, r2) = linear_fit(&speeds, &f);
        assert!(r2 > 0.999, "{name}: R² {r2} ({f:?})");
        let (lo, hi) = main_wavelengths(&s, M85, 0.02);
        assert!(
            (lo..=hi).contains(&(1.0 / slope)),
            "{name}: slope {slope} Hz per m/s is not 1/λ for λ in {lo}..{hi} m"
        );
        assert!(icpt.abs() < 0.5, "{name}: intercept {icpt} Hz");
    }
}

/// The wavelength range, m, of a surface's main components under `load`:
/// those at least 70 % the size of the largest (after the contact patch),
/// widened by the fraction `slack` for the spectral resolution. A periodic sample has one;
/// on the random ones (felt, scrunched paper) the main peak is a cluster of
/// comparable components around the preferred scale.
pub(super) fn main_wavelengths(s: &Surface, load: f64, slack: f64) -> (f64, f64) {
    let mut g = vec![0.0; s.components.len()];
    s.gains(load, &mut g);
    let sizes: Vec<f64> = s.components.iter().zip(&g).map(|(c, g)| c.amplitude.abs() * g).collect();
    let top = sizes.iter().fold(0.0f64, |a, b| a.max(*b));
    let (lo, hi) = s
        .components
        .iter()
        .zip(&sizes)
        .filter(|(_, a)| **a >= 0.7 * top)
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), (c, _)| (lo.min(c.wavelength), hi.max(c.wavelength)));
    (lo / (1.0 + slack), hi * (1.0 + slack))
}

#[test]
fn heavier_loads_raise_the_power() {
    // §5.3.1: "with heavier mass, only the level of power density increased".
    for name in NAMES {
        let s = sample(name).unwrap();
        let light = power(&scan(&s, 0.05, M60, 4.0, 0.0, 1));
        let heavy = power(&scan(&s, 0.05, M110, 4.0, 0.0, 1));
        assert!(heavy > 1.5 * light, "{name}: {light} → {heavy}");
    }
}

/// E_s (Eq. 5.2) between two spectra scaled to unit RMS: the difference of shape alone.
fn shape_difference(a: &[f64], b: &[f64], band: &Band) -> f64 {
    let unit = |x: &[f64]| {
        let r = (x[band.bins()].iter().map(|v| v * v).sum::<f64>()).sqrt();
        x.iter().map(|v| v / r).collect::<Vec<f64>>()
    };
    spectral_rms_error(&unit(a), &unit(b), band).unwrap()
}

#[test]
fn heavier_loads_bring_out_the_plastic_sheets_minor_components_only() {
    // §5.3.1: "for dotted sheet the spectrum shapes were almost the same in
    // all the conditions … for plastic sheet, additional main components
    // appeared with heavier mass".
    let band = Band::new(RATE, 1000, 1.0, 500.0, false).unwrap();
    let v = 0.05;
    let plastic = sample("plastic-sheet").unwrap();
    let fundamental = v / plastic.dominant(M85).unwrap().wavelength;
    let harmonics = |load: f64| {
        let x = ac(&scan(&plastic, v, load, 4.0, 0.0, 1));
        (tone(&x, 3.0 * fundamental, RATE).powi(2) + tone(&x, 5.0 * fundamental, RATE).powi(2))
            / tone(&x, fundamental, RATE).powi(2)
    };
    let (h60, h110) = (harmonics(M60), harmonics(M110));
    assert!(h110 > 3.0 * h60, "plastic sheet: harmonic share {h60} at 60 g, {h110} at 110 g");
    let shape = |name: &str| {
        let s = sample(name).unwrap();
        shape_difference(&spectrum(&scan(&s, v, M60, 4.0, 0.0, 1)), &spectrum(&scan(&s, v, M110, 4.0, 0.0, 1)), &band)
    };
    let (dotted, plastic) = (shape("dotted-sheet"), shape("plastic-sheet"));
    assert!(dotted < 0.05, "dotted sheet changes shape with the load: {dotted}");
    assert!(plastic > 4.0 * dotted, "plastic {plastic} vs dotted {dotted}");
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
    // §6.5.1: "Chair and felt fabrics feel soft while others generally feel
    // rough". Power kept through the contact patch, against the same
    // surface under a point contact; and the share of power above 50 Hz at
    // 5 cm/s (wavelengths under 1 mm).
    let mut kept = Vec::new();
    for n in NAMES {
        let s = sample(n).unwrap();
        let point = Surface { sigma_1n: 0.0, ..s.clone() };
        let k = power(&scan(&s, 0.05, M85, 2.0, 0.0, 1)) / power(&scan(&point, 0.05, M85, 2.0, 0.0, 1));
        let hf = high_fraction(&scan(&s, 0.05, M85, 2.0, 0.0, 1), 50.0);
        kept.push((*n, k, hf));
    }
    for (n, k, _) in &kept {
        if is_soft(n) {
            assert!(*k < 0.6, "{n} keeps {k} ({kept:?})");
        } else {
            assert!(*k > 0.8, "{n} keeps {k} ({kept:?})");
        }
    }
    let soft_hf = kept.iter().filter(|p| is_soft(p.0)).map(|p| p.2).fold(0.0, f64::max);
    for (n, _, hf) in &kept {
        if !is_soft(n) && *n != "rippled-paper" {
            assert!(*hf > 5.0 * soft_hf, "{n}: {hf} vs soft {soft_hf} ({kept:?})");
        }
    }
}

#[test]
fn repeated_scans_differ_much_less_than_different_samples() {
    // Two scans of one sample with independent sensor-like white noise
    // (3 mN rms, the lab sensor's), against scans of other samples: E_s
    // (Eq. 5.2) between their spectra over 1–500 Hz.
    let band = Band::new(RATE, 1000, 1.0, 500.0, false).unwrap();
    let spectra: Vec<(Vec<f64>, Vec<f64>)> = NAMES
        .iter()
        .map(|n| {
            let s = sample(n).unwrap();
            (spectrum(&scan(&s, 0.05, M85, 4.0, 0.003, 1)), spectrum(&scan(&s, 0.05, M85, 4.0, 0.003, 2)))
        })
        .collect();
    for (i, a) in spectra.iter().enumerate() {
        let repeat = spectral_rms_error(&a.1, &a.0, &band).unwrap();
        assert!(repeat > 0.0);
        for (j, b) in spectra.iter().enumerate() {
            if i != j {
                let other = spectral_rms_error(&b.0, &a.0, &band).unwrap();
                assert!(repeat < 0.5 * other, "{} repeat {repeat} vs {} {other}", NAMES[i], NAMES[j]);
            }
        }
    }
}

#[test]
fn mean_friction_lies_in_the_force_range_of_the_dissertation() {
    // §3.2.1: forces of 0.075–0.25 N; the stylus of §5.1.1 weighs 60–110 g.
    for n in NAMES {
        let s = sample(n).unwrap();
        for load in [M60, M110] {
            let f = mean(&scan(&s, 0.05, load, 4.0, 0.0, 1));
            assert!((0.075..=0.25).contains(&f), "{n} at {load} N: mean {f} N");
        }
    }
}

#[test]
fn extremes_stay_finite_and_bounded() {
    for n in NAMES {
        let s = sample(n).unwrap();
        for (speed, load) in [(0.0, M85), (0.5, M85), (-0.5, M85), (0.05, 0.001 * G), (0.05, G), (0.0, 0.0)] {
            let f = scan(&s, speed, load, 0.5, 0.0, 1);
            assert!(f.iter().all(|v| v.is_finite() && v.abs() <= 1.9 * s.mu * load + 1e-12), "{n} {speed} {load}");
            if speed == 0.0 {
                assert!(f.iter().all(|v| *v == 0.0), "{n}: no force at rest");
            }
        }
    }
}
