//! The relative spectral RMS error E_s (dissertation §5.2.3, Eq. 5.2).
//!
//! Eq. 5.2 is garbled in the dissertation's text; following its references
//! [43, 55] (Culbertson et al.) it reads
//!
//! ```text
//! E_s = RMS( |F(f_v)| − |F(f_r)| ) / RMS( |F(f_r)| )
//! ```
//!
//! with F the FFT, the RMS taken over frequency bins, f_v the virtual and
//! f_r the real force. Both RMS run over the same K bins, so the 1/K
//! cancels: E_s = √(Σ_k (V_k − R_k)²) / √(Σ_k R_k²). E_s = 0 for identical
//! spectra, 1 for a virtual spectrum twice the real one, 0.5 for half of it.
//!
//! The bins are chosen by a [`Band`]: by default every bin but 0 Hz, since a
//! force's mean (the friction level) is not texture; see the `metric` node.

use super::spectrum::ROUNDING_LEVEL;
use evflow_engine::NodeError;
use std::ops::RangeInclusive;

/// Which argument of [`Band::new`] gives no usable band; a node names its
/// own parameter for it in its error.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BandParam {
    /// The lowest frequency.
    Fmin,
    /// The highest frequency.
    Fmax,
    /// The spectrum's length (or the rate it is at).
    Nfft,
}

/// An argument that gives no usable band.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{message}")]
pub struct BandError {
    /// The argument to change.
    pub param: BandParam,
    /// What is wrong and what would be right.
    pub message: String,
}

impl BandError {
    /// The node error naming the node's own parameter for the argument:
    /// `[fmin, fmax, nfft]` are the names of its three handles.
    pub fn naming(self, [fmin, fmax, nfft]: [&str; 3]) -> NodeError {
        let param = match self.param {
            BandParam::Fmin => fmin,
            BandParam::Fmax => fmax,
            BandParam::Nfft => nfft,
        };
        NodeError::param(param, self.message)
    }
}

/// The one-sided FFT bins E_s is taken over: every bin k with
/// fmin ≤ k·rate/nfft ≤ fmax, without bin 0 unless asked for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Band {
    first: usize,
    last: usize,
    bin_hz: f64,
}

impl Band {
    /// The bins of an `nfft`-point spectrum at `rate` Hz between `fmin` and
    /// `fmax` Hz inclusive (`fmax` = 0 means the Nyquist frequency), with
    /// 0 Hz only when `include_dc` is set.
    pub fn new(rate: f64, nfft: usize, fmin: f64, fmax: f64, include_dc: bool) -> Result<Band, BandError> {
        let err = |param, message: String| Err(BandError { param, message });
        if nfft == 0 || !(rate.is_finite() && rate > 0.0) {
            return err(BandParam::Nfft, format!("no spectrum of {nfft} points at {rate} Hz"));
        }
        let nyquist = rate / 2.0;
        let fmax = if fmax == 0.0 { nyquist } else { fmax };
        if !(fmin.is_finite() && fmin >= 0.0) {
            return err(BandParam::Fmin, format!("must be a frequency ≥ 0 Hz, not {fmin}"));
        }
        if !fmax.is_finite() || fmax > nyquist * (1.0 + 1e-12) {
            return err(
                BandParam::Fmax,
                format!("{fmax} Hz is above the Nyquist frequency {nyquist} Hz (use 0 for Nyquist)"),
            );
        }
        if fmin > fmax {
            return err(BandParam::Fmin, format!("{fmin} Hz is above fmax = {fmax} Hz"));
        }
        let bin_hz = rate / nfft as f64;
        // A bin exactly on an edge belongs to the band despite rounding.
        let mut first = (fmin / bin_hz - 1e-9).ceil().max(0.0) as usize;
        let last = ((fmax / bin_hz + 1e-9).floor() as usize).min(nfft / 2);
        if !include_dc {
            first = first.max(1);
        }
        if first > last {
            let dc = if include_dc { "" } else { " (0 Hz excluded: include_dc = false)" };
            return err(
                BandParam::Fmin,
                format!(
                    "no FFT bin lies between {fmin} and {fmax} Hz{dc}: bins are {bin_hz} Hz apart \
                     (nfft = {nfft} at {rate} Hz); widen the band or raise nfft"
                ),
            );
        }
        Ok(Band { first, last, bin_hz })
    }

    /// The bins, first ..= last.
    pub fn bins(&self) -> RangeInclusive<usize> {
        self.first..=self.last
    }

    /// The first bin.
    pub fn first(&self) -> usize {
        self.first
    }

    /// The last bin.
    pub fn last(&self) -> usize {
        self.last
    }

    /// Number of bins (at least 1).
    pub fn len(&self) -> usize {
        self.last - self.first + 1
    }

    /// Always false: a band holds at least one bin.
    pub fn is_empty(&self) -> bool {
        false
    }

    /// Frequency of the first bin in Hz.
    pub fn lo_hz(&self) -> f64 {
        self.first as f64 * self.bin_hz
    }

    /// Frequency of the last bin in Hz.
    pub fn hi_hz(&self) -> f64 {
        self.last as f64 * self.bin_hz
    }
}

/// Why E_s could not be computed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SpectralError {
    /// The two spectra have different numbers of bins.
    #[error("the virtual spectrum has {virtual_bins} bins and the real one {real_bins}: they must come from the same FFT length")]
    Length {
        /// Bins of the virtual spectrum.
        virtual_bins: usize,
        /// Bins of the real spectrum.
        real_bins: usize,
    },
    /// The band reaches past the spectra.
    #[error("the band ends at bin {last} but the spectra have {bins} bins")]
    Outside {
        /// Last bin of the band.
        last: usize,
        /// Bins of the spectra.
        bins: usize,
    },
    /// A spectrum holds NaN or Inf.
    #[error("the {0} spectrum holds a non-finite value (NaN or Inf)")]
    NonFinite(&'static str),
    /// The real spectrum is zero over the band, so E_s (a ratio to it) is undefined.
    #[error(
        "the real force has no spectral energy between {lo_hz} and {hi_hz} Hz ({bins} bins, all zero or at \
         rounding level): E_s = RMS(|F(f_v)| − |F(f_r)|) / RMS(|F(f_r)|) is undefined"
    )]
    NoRealEnergy {
        /// Lower edge of the band in Hz.
        lo_hz: f64,
        /// Upper edge of the band in Hz.
        hi_hz: f64,
        /// Bins in the band.
        bins: usize,
    },
    /// The ratio exceeds the range of f64.
    #[error("E_s overflows: the real spectrum is more than 1e150 times smaller than the difference")]
    Overflow,
}

/// E_s of Eq. 5.2 between two magnitude spectra (`virt` and `real`, values
/// ≥ 0, e.g. [`crate::metric::spectrum::Spectrum::magnitude`]) over the
/// band's bins. Computed with both sums scaled by their largest term, so
/// magnitudes from 1e-300 to 1e300 give the right ratio. An error, never
/// NaN or Inf, when the real spectrum has no energy in the band (every bin
/// zero or below [`ROUNDING_LEVEL`] of its largest bin, 0 Hz included).
pub fn spectral_rms_error(virt: &[f64], real: &[f64], band: &Band) -> Result<f64, SpectralError> {
    if virt.len() != real.len() {
        return Err(SpectralError::Length { virtual_bins: virt.len(), real_bins: real.len() });
    }
    if band.last >= real.len() {
        return Err(SpectralError::Outside { last: band.last, bins: real.len() });
    }
    if let Some(name) =
        [("virtual", virt), ("real", real)].iter().find(|(_, s)| s.iter().any(|x| !x.is_finite())).map(|(n, _)| *n)
    {
        return Err(SpectralError::NonFinite(name));
    }
    let (v, r) = (&virt[band.bins()], &real[band.bins()]);
    let real_peak = real.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let band_peak = r.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    if band_peak == 0.0 || band_peak <= ROUNDING_LEVEL * real_peak {
        return Err(SpectralError::NoRealEnergy { lo_hz: band.lo_hz(), hi_hz: band.hi_hz(), bins: band.len() });
    }
    let scale = v.iter().zip(r).fold(band_peak, |m, (a, b)| m.max((a - b).abs()));
    let (mut num, mut den) = (0.0, 0.0);
    for (a, b) in v.iter().zip(r) {
        num += ((a - b) / scale).powi(2);
        den += (b / scale).powi(2);
    }
    let e = (num / den).sqrt();
    if e.is_finite() {
        Ok(e)
    } else {
        Err(SpectralError::Overflow)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_band_error_names_the_nodes_own_parameter() {
        let names = ["lo_hz", "hi_hz", "len"];
        let e = Band::new(1000.0, 1000, 300.0, 100.0, false).unwrap_err();
        let (param, message) = (e.param, e.message.clone());
        let NodeError::Param { param: named, message: m } = e.naming(names) else { panic!("a parameter error") };
        let want = match param {
            BandParam::Fmin => "lo_hz",
            BandParam::Fmax => "hi_hz",
            BandParam::Nfft => "len",
        };
        assert_eq!((named.as_str(), m), (want, message));
    }
    use crate::metric::spectrum::tests::{gaussian, sine};
    use crate::metric::spectrum::{averaged_spectrum, SpectrumConfig, Window};

    fn mag(x: &[f64], nfft: usize) -> Vec<f64> {
        let cfg = SpectrumConfig { rate: 1000.0, nfft, window: Window::Rect, overlap: 0.0 };
        averaged_spectrum(x, cfg).unwrap().unwrap().magnitude
    }

    fn all_but_dc(nfft: usize) -> Band {
        Band::new(1000.0, nfft, 0.0, 0.0, false).unwrap()
    }

    #[test]
    fn default_band_is_every_bin_but_dc() {
        let b = all_but_dc(1000);
        assert_eq!((b.first(), b.last(), b.len()), (1, 500, 500));
        assert_eq!((b.lo_hz(), b.hi_hz()), (1.0, 500.0));
        let b = Band::new(1000.0, 1000, 0.0, 0.0, true).unwrap();
        assert_eq!(b.bins(), 0..=500);
        // Odd length: Nyquist is not a bin.
        assert_eq!(Band::new(1000.0, 999, 0.0, 0.0, false).unwrap().bins(), 1..=499);
        // Edges on bins are inside; between bins, rounded inwards.
        assert_eq!(Band::new(1000.0, 1000, 20.0, 300.0, false).unwrap().bins(), 20..=300);
        assert_eq!(Band::new(1000.0, 500, 20.5, 301.0, false).unwrap().bins(), 11..=150);
        // fmin > 0 drops 0 Hz even with include_dc.
        assert_eq!(Band::new(1000.0, 1000, 5.0, 0.0, true).unwrap().first(), 5);
    }

    #[test]
    fn bands_without_bins_or_past_nyquist_are_refused() {
        let e = Band::new(1000.0, 1000, 0.3, 0.6, false).unwrap_err();
        assert_eq!(e.param, BandParam::Fmin);
        assert!(e.message.contains("no FFT bin"), "{e}");
        assert_eq!(Band::new(1000.0, 1000, 0.0, 501.0, false).unwrap_err().param, BandParam::Fmax);
        assert_eq!(Band::new(1000.0, 1000, 300.0, 200.0, false).unwrap_err().param, BandParam::Fmin);
        // nfft = 1: only the 0 Hz bin, excluded by default.
        assert!(Band::new(1000.0, 1, 0.0, 0.0, false).is_err());
        assert_eq!(Band::new(1000.0, 1, 0.0, 0.0, true).unwrap().bins(), 0..=0);
    }

    #[test]
    fn identities_of_the_ratio() {
        let nfft = 256;
        let x: Vec<f64> = gaussian(9, 2000).iter().zip(sine(1.0, 17.0, nfft, 2000)).map(|(g, s)| g + s).collect();
        let x2: Vec<f64> = x.iter().map(|x| 2.0 * x).collect();
        let (m, m2, band) = (mag(&x, nfft), mag(&x2, nfft), all_but_dc(nfft));
        // E_s(x, x) = 0.
        assert_eq!(spectral_rms_error(&m, &m, &band).unwrap(), 0.0);
        // |F(2x)| = 2|F(x)|: E_s(2x, x) = RMS(|X|)/RMS(|X|) = 1.
        assert!((spectral_rms_error(&m2, &m, &band).unwrap() - 1.0).abs() < 1e-12);
        // E_s(x, 2x) = RMS(−|X|)/RMS(2|X|) = 0.5.
        assert!((spectral_rms_error(&m, &m2, &band).unwrap() - 0.5).abs() < 1e-12);
    }

    #[test]
    fn two_sines_on_different_bins_give_root_two() {
        // Rectangular window, one segment: |V| = A·N/2 at bin a only and
        // |R| = A·N/2 at bin b only. Over a band holding both,
        // Σ(V−R)² = 2·(A·N/2)² and ΣR² = (A·N/2)², so E_s = √2 / 1 = √2.
        // Over a band holding b but not a, Σ(V−R)² = (A·N/2)²: E_s = 1.
        let (nfft, a) = (1000, 0.8);
        let v = mag(&sine(a, 40.0, nfft, nfft), nfft);
        let r = mag(&sine(a, 130.0, nfft, nfft), nfft);
        let e = spectral_rms_error(&v, &r, &all_but_dc(nfft)).unwrap();
        assert!((e - 2f64.sqrt()).abs() < 1e-9, "{e}");
        let only_b = Band::new(1000.0, nfft, 100.0, 200.0, false).unwrap();
        assert!((spectral_rms_error(&v, &r, &only_b).unwrap() - 1.0).abs() < 1e-9);
    }

    #[test]
    fn differences_outside_the_band_do_not_count() {
        let nfft = 500;
        let r: Vec<f64> = (0..1000).map(|i| (i as f64 * 0.3).sin() + 0.2 * (i as f64 * 1.7).cos()).collect();
        let hum: Vec<f64> = sine(3.0, 200.0, nfft, 1000); // 400 Hz
        let v: Vec<f64> = r.iter().zip(&hum).map(|(a, b)| a + b + 7.0).collect(); // plus a mean of 7
        let (mv, mr) = (mag(&v, nfft), mag(&r, nfft));
        let band = Band::new(1000.0, nfft, 0.0, 300.0, false).unwrap();
        assert!(spectral_rms_error(&mv, &mr, &band).unwrap() < 1e-12);
        assert!(spectral_rms_error(&mv, &mr, &all_but_dc(nfft)).unwrap() > 0.1);
    }

    #[test]
    fn no_real_energy_is_an_error_not_nan() {
        let nfft = 100;
        let v = mag(&gaussian(1, 300), nfft);
        let zero = mag(&[0.0; 300], nfft);
        let e = spectral_rms_error(&v, &zero, &all_but_dc(nfft)).unwrap_err();
        assert!(matches!(e, SpectralError::NoRealEnergy { bins: 50, .. }), "{e}");
        assert!(e.to_string().contains("no spectral energy"));
        // A constant force: only 0 Hz, the rest at rounding level.
        let constant = mag(&[5.0; 300], nfft);
        assert!(matches!(
            spectral_rms_error(&v, &constant, &all_but_dc(nfft)),
            Err(SpectralError::NoRealEnergy { .. })
        ));
        // …but with 0 Hz counted it is defined.
        let with_dc = Band::new(1000.0, nfft, 0.0, 0.0, true).unwrap();
        assert!(spectral_rms_error(&v, &constant, &with_dc).unwrap().is_finite());
    }

    #[test]
    fn extreme_magnitudes_stay_exact_and_finite() {
        let band = all_but_dc(8);
        let r = [0.0, 1.0, 2.0, 3.0, 4.0];
        for s in [1e-300, 1e-160, 1.0, 1e160, 1e300] {
            let rs: Vec<f64> = r.iter().map(|x| x * s).collect();
            let vs: Vec<f64> = rs.iter().map(|x| 2.0 * x).collect();
            let e = spectral_rms_error(&vs, &rs, &band).unwrap();
            assert!((e - 1.0).abs() < 1e-12, "scale {s}: {e}");
        }
        // Real far below the difference: a clear error, never Inf.
        let tiny = [1.0, 1e-300, 1e-300, 1e-300, 1e-300];
        let huge = [0.0, 1e300, 1e300, 1e300, 1e300];
        assert!(matches!(spectral_rms_error(&huge, &tiny, &band), Err(SpectralError::NoRealEnergy { .. })));
        let tiny = [1e-300; 5];
        assert_eq!(spectral_rms_error(&huge, &tiny, &band), Err(SpectralError::Overflow));
        assert_eq!(spectral_rms_error(&[f64::NAN; 5], &r, &band), Err(SpectralError::NonFinite("virtual")));
        assert!(matches!(spectral_rms_error(&r[..4], &r, &band), Err(SpectralError::Length { .. })));
        assert!(matches!(spectral_rms_error(&r[..3], &r[..3], &band), Err(SpectralError::Outside { .. })));
    }
}
