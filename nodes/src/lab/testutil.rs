//! Helpers shared by the lab's tests.

/// Coefficient of determination of the least-squares fit y ≈ a + b·x, with (a, b).
pub fn linear_fit(x: &[f64], y: &[f64]) -> (f64, f64, f64) {
    let n = x.len() as f64;
    let mx = x.iter().sum::<f64>() / n;
    let my = y.iter().sum::<f64>() / n;
    let sxy: f64 = x.iter().zip(y).map(|(a, b)| (a - mx) * (b - my)).sum();
    let sxx: f64 = x.iter().map(|a| (a - mx) * (a - mx)).sum();
    let b = sxy / sxx;
    let a = my - b * mx;
    let ss_res: f64 = x.iter().zip(y).map(|(xi, yi)| (yi - a - b * xi).powi(2)).sum();
    let ss_tot: f64 = y.iter().map(|yi| (yi - my).powi(2)).sum();
    (a, b, 1.0 - ss_res / ss_tot)
}

/// Mean of a slice.
pub fn mean(x: &[f64]) -> f64 {
    x.iter().sum::<f64>() / x.len() as f64
}

/// Amplitude of the component at `f` Hz of `x` sampled at `rate` (a single DFT bin).
pub fn tone(x: &[f64], f: f64, rate: f64) -> f64 {
    let (mut re, mut im) = (0.0, 0.0);
    for (n, v) in x.iter().enumerate() {
        let ph = 2.0 * std::f64::consts::PI * f * n as f64 / rate;
        re += v * ph.cos();
        im += v * ph.sin();
    }
    2.0 * re.hypot(im) / x.len() as f64
}

/// A shipped lab profile, `graphs/lab/NAME.toml`.
pub fn shipped(name: &str) -> crate::lab::LabProfile {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../graphs/lab").join(format!("{name}.toml"));
    crate::lab::LabProfile::load(&path).unwrap_or_else(|e| panic!("{e}"))
}

/// The shipped profiles with their names.
pub fn all_shipped() -> Vec<(&'static str, crate::lab::LabProfile)> {
    ["nominal", "stiff", "display-b", "relaxing", "resonant"].into_iter().map(|n| (n, shipped(n))).collect()
}

/// ±`level` PRBS from a 9-bit maximal LFSR (x⁹ + x⁵ + 1), one value per sample.
pub fn prbs(len: usize, level: f64) -> Vec<f64> {
    let mut s: u32 = 0x1ff;
    (0..len)
        .map(|_| {
            let bit = ((s >> 8) ^ (s >> 4)) & 1;
            s = ((s << 1) | bit) & 0x1ff;
            if bit == 1 {
                level
            } else {
                -level
            }
        })
        .collect()
}
