//! E_s and the amplitude spectra of forces held in memory, read as the
//! `metric` node reads them (graphs/texture-live-play.toml's `es` and
//! `welch`): 2–200 Hz without 0 Hz, one-second segments of `rate` samples
//! — rectangular and apart (the dissertation's reading), Hann and half
//! overlapping (Welch's) — magnitudes averaged over segments; the peak
//! power ratio of the rect spectra for Table 5.1's gain rule.

use crate::gains::AtGain;
use crate::StudyError;
use evflow_nodes::metric::spectral_error::{spectral_rms_error, Band};
use evflow_nodes::metric::spectrum::{averaged_spectrum, Spectrum, SpectrumConfig, Window};

/// The band E_s is read over, Hz.
pub const BAND_HZ: (f64, f64) = (2.0, 200.0);

fn config(rate: f64, window: Window) -> SpectrumConfig {
    let overlap = if window == Window::Hann { 0.5 } else { 0.0 };
    SpectrumConfig { rate, nfft: rate.round() as usize, window, overlap }
}

fn spectrum(x: &[f64], cfg: SpectrumConfig) -> Result<Spectrum, StudyError> {
    averaged_spectrum(x, cfg)
        .map_err(|e| StudyError::Config(e.to_string()))?
        .ok_or_else(|| StudyError::Config("no samples to read a spectrum from".into()))
}

fn band(rate: f64) -> Result<Band, StudyError> {
    Band::new(rate, rate.round() as usize, BAND_HZ.0, BAND_HZ.1, false).map_err(|e| StudyError::Config(e.message))
}

/// E_s of `virt` against `real` (both high-passed, N) in the rect and the
/// Welch readings, and the peak power ratio, at `gain`.
pub fn reading(virt: &[f64], real: &[f64], rate: f64, gain: f64) -> Result<AtGain, StudyError> {
    let band = band(rate)?;
    let es = |w| -> Result<(f64, Spectrum, Spectrum), StudyError> {
        let (v, r) = (spectrum(virt, config(rate, w))?, spectrum(real, config(rate, w))?);
        let e = spectral_rms_error(&v.magnitude, &r.magnitude, &band).map_err(|e| StudyError::Config(e.to_string()))?;
        Ok((e, v, r))
    };
    let (rect, v, r) = es(Window::Rect)?;
    let (welch, _, _) = es(Window::Hann)?;
    let top = |s: &Spectrum| s.magnitude[band.first()..=band.last()].iter().fold(0.0f64, |a, &m| a.max(m));
    Ok(AtGain { gain, rect, welch, peak_ratio: (top(&v) / top(&r)).powi(2) })
}

/// The amplitude spectrum of `x` (N) in Welch's reading, at 1 Hz bins
/// from the band's first to its last: (Hz, N) — a sine of amplitude A on
/// a bin reads A.
pub fn amplitude(x: &[f64], rate: f64) -> Result<Vec<(f64, f64)>, StudyError> {
    let cfg = config(rate, Window::Hann);
    let s = spectrum(x, cfg)?;
    let band = band(rate)?;
    let gain: f64 = Window::Hann.coefficients(cfg.nfft).iter().sum();
    Ok(band.bins().map(|k| (s.freq(k), 2.0 * s.magnitude[k] / gain)).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_readings_are_the_metric_s_identities_and_a_sine_reads_its_amplitude() {
        let rate = 1000.0;
        let x: Vec<f64> = (0..3000)
            .map(|n| {
                let t = n as f64 / rate;
                0.02 * (2.0 * std::f64::consts::PI * 40.0 * t).sin()
                    + 0.01 * (2.0 * std::f64::consts::PI * 90.0 * t).sin()
            })
            .collect();
        let same = reading(&x, &x, rate, 1.0).unwrap();
        assert_eq!((same.rect, same.welch, same.peak_ratio), (0.0, 0.0, 1.0));
        let twice: Vec<f64> = x.iter().map(|v| 2.0 * v).collect();
        let r = reading(&twice, &x, rate, 0.5).unwrap();
        assert!((r.rect - 1.0).abs() < 1e-12 && (r.welch - 1.0).abs() < 1e-12, "{r:?}");
        assert!((r.peak_ratio - 4.0).abs() < 1e-9 && r.gain == 0.5);
        let half: Vec<f64> = x.iter().map(|v| 0.5 * v).collect();
        assert!((reading(&half, &x, rate, 1.0).unwrap().welch - 0.5).abs() < 1e-12);
        let a = amplitude(&x, rate).unwrap();
        assert_eq!(a.first().unwrap().0, 2.0);
        assert_eq!(a.last().unwrap().0, 200.0);
        let at = |hz: f64| a.iter().find(|p| p.0 == hz).unwrap().1;
        assert!((at(40.0) - 0.02).abs() < 1e-9 && (at(90.0) - 0.01).abs() < 1e-9);
        assert!(at(60.0) < 1e-6);
        assert!(reading(&x, &vec![0.0; 3000], rate, 1.0).is_err(), "no real energy: no E_s");
    }
}
