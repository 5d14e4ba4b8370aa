//! Aligning a grid's cells in position: each recording trimmed so that all
//! start at the same place on the texture.
//!
//! The schemes read cell (i, j) at the texture position of the table sample
//! (`scheme.rs`, "Spatial alignment") assuming every recording starts at the
//! same place, as tribometer passes do. Cells cut to their constant-speed
//! stretch do not: a faster pass needs a longer run-up, and a lab's
//! recordings start where the lab started them. Averaging misaligned cells
//! of a periodic texture cancels part of each harmonic (two cells half a
//! period apart cancel it wholly) and smears a random texture's peaks, so
//! the interpolated table holds less texture than any cell — the live chain
//! then renders a texture weaker and blurrier than the real one.
//!
//! Each cell is compared with a reference cell (the first: lowest load,
//! lowest velocity) in **position**: both are read at the reference's
//! spatial step (linear interpolation at x·f_s/v_j), their means removed,
//! and the normalized cross-correlation over a fixed central window is
//! maximized over shifts of up to `max_shift` cm (ties go to the smaller
//! shift). With every cell's shift δ (the cell shows at x + δ what the
//! reference shows at x), each cell is trimmed at its start by
//! (P + δ) · f_s/v_j samples, P = max(−δ), so that sample 0 of every cell
//! is the same place. Checked against cells cut from one signal at known
//! offsets and speeds (tests below).

/// What aligning did to one cell.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Shift {
    /// The shift found against the reference, cm (the cell shows at x + δ
    /// what the reference shows at x).
    pub delta_cm: f64,
    /// The normalized cross-correlation at that shift (1 = identical shape).
    pub correlation: f64,
    /// Samples trimmed from the cell's start.
    pub trimmed: usize,
}

/// `x` read at position `p` cm of a cell at `v` cm/s and `fs` Hz (linear
/// interpolation; `None` past its ends).
fn at(x: &[f64], v: f64, fs: f64, p: f64) -> Option<f64> {
    let t = p * fs / v;
    if t.is_nan() || t < 0.0 || t > (x.len() - 1) as f64 {
        return None;
    }
    let k = t.floor() as usize;
    let f = t - k as f64;
    Some(if k + 1 < x.len() { x[k] * (1.0 - f) + x[k + 1] * f } else { x[k] })
}

/// `x` (a cell at `v` cm/s) resampled at step `dx` cm from 0, its mean removed.
fn spatial(x: &[f64], v: f64, fs: f64, dx: f64) -> Vec<f64> {
    if x.len() < 2 {
        return Vec::new();
    }
    let n = ((x.len() - 1) as f64 * v / fs / dx).floor() as usize + 1;
    let mut s: Vec<f64> = (0..n).filter_map(|k| at(x, v, fs, k as f64 * dx)).collect();
    let mean = s.iter().sum::<f64>() / s.len().max(1) as f64;
    s.iter_mut().for_each(|y| *y -= mean);
    s
}

/// The shift (in steps) of `b` against `a` within ±`max` steps that
/// maximizes their normalized cross-correlation over the central window
/// both cover at every shift, and that correlation. `None` when the
/// window is empty or either signal is flat there.
fn best_lag(a: &[f64], b: &[f64], max: usize) -> Option<(isize, f64)> {
    // Window [max, a.len() − max) of a; b read at index k + lag.
    let end = a.len().min(b.len()).checked_sub(max)?;
    if end <= max + 8 {
        return None;
    }
    let win = max..end;
    let ea: f64 = a[win.clone()].iter().map(|x| x * x).sum();
    let mut best: Option<(isize, f64)> = None;
    for lag in -(max as isize)..=(max as isize) {
        let (mut ab, mut eb) = (0.0, 0.0);
        for k in win.clone() {
            let y = b[(k as isize + lag) as usize];
            ab += a[k] * y;
            eb += y * y;
        }
        let den = (ea * eb).sqrt();
        if den.is_nan() || den <= 0.0 {
            continue;
        }
        let r = ab / den;
        let better = match best {
            None => true,
            Some((l, rb)) => r > rb + 1e-12 || ((r - rb).abs() <= 1e-12 && lag.unsigned_abs() < l.unsigned_abs()),
        };
        if better {
            best = Some((lag, r));
        }
    }
    best
}

/// Aligns `cells` (cell k recorded at `velocities[k]` cm/s, all at `fs`
/// Hz) in position against cell 0, searching shifts up to `max_shift` cm,
/// and trims each cell's start so that all begin at the same place.
/// Returns each cell's shift; a cell whose shift cannot be found (too
/// short, or flat) keeps its start (δ = 0, correlation NaN).
pub fn align(cells: &mut [Vec<f64>], velocities: &[f64], fs: f64, max_shift: f64) -> Vec<Shift> {
    let none = Shift { delta_cm: 0.0, correlation: f64::NAN, trimmed: 0 };
    if cells.is_empty() || max_shift.is_nan() || max_shift <= 0.0 {
        return vec![none; cells.len()];
    }
    let dx = velocities[0] / fs;
    let max = (max_shift / dx).round() as usize;
    let reference = spatial(&cells[0], velocities[0], fs, dx);
    let mut shifts: Vec<Shift> = cells
        .iter()
        .zip(velocities)
        .enumerate()
        .map(|(k, (c, v))| {
            if k == 0 {
                return Shift { delta_cm: 0.0, correlation: 1.0, trimmed: 0 };
            }
            match best_lag(&reference, &spatial(c, *v, fs, dx), max) {
                Some((lag, r)) => Shift { delta_cm: lag as f64 * dx, correlation: r, trimmed: 0 },
                None => none,
            }
        })
        .collect();
    // Cell k's sample 0 lies at reference position −δ_k; every cell starts at P = max(−δ).
    let p = shifts.iter().map(|s| -s.delta_cm).fold(f64::NEG_INFINITY, f64::max);
    for ((cell, v), s) in cells.iter_mut().zip(velocities).zip(&mut shifts) {
        let trim = (((p + s.delta_cm) * fs / v).round().max(0.0) as usize).min(cell.len());
        cell.drain(..trim);
        s.trimmed = trim;
    }
    shifts
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    /// A texture along 20 cm: two harmonics of a 1.7 mm period and a random part.
    fn texture(x: f64, noise: &[f64]) -> f64 {
        let tau = std::f64::consts::TAU;
        let k = ((x / 20.0) * (noise.len() - 1) as f64).clamp(0.0, (noise.len() - 2) as f64);
        let (i, f) = (k.floor() as usize, k.fract());
        (tau * x / 0.17).sin() + 0.4 * (3.0 * tau * x / 0.17 + 0.5).sin() + noise[i] * (1.0 - f) + noise[i + 1] * f
    }

    /// A cell of `n` samples at `v` cm/s starting at `x0` cm.
    fn cell(x0: f64, v: f64, n: usize, noise: &[f64]) -> Vec<f64> {
        (0..n).map(|k| texture(x0 + k as f64 * v / 1000.0, noise)).collect()
    }

    #[test]
    fn cells_cut_at_known_offsets_and_speeds_come_out_starting_at_one_place() {
        let mut r = Rng::new(3);
        let noise: Vec<f64> = (0..4000).map(|_| 0.5 * r.gaussian()).collect();
        let starts = [0.30, 0.42, 0.05, 0.61];
        let speeds = [3.0, 7.0, 3.0, 7.0];
        let mut cells: Vec<Vec<f64>> =
            starts.iter().zip(&speeds).map(|(x0, v)| cell(*x0, *v, (6.0 / v * 1000.0) as usize, &noise)).collect();
        let shifts = align(&mut cells, &speeds, 1000.0, 1.0);
        // Every cell now starts at the latest start, 0.61 cm, to within a spatial step of the slowest cell.
        for (k, (s, v)) in shifts.iter().zip(&speeds).enumerate() {
            let start = starts[k] + s.trimmed as f64 * v / 1000.0;
            assert!((start - 0.61).abs() <= 0.0075, "cell {k}: starts at {start} cm ({s:?})");
            assert!(s.correlation > 0.95, "cell {k}: {s:?}");
            assert!((s.delta_cm - (starts[0] - starts[k])).abs() <= 0.004, "cell {k}: {s:?}");
        }
        // Aligned, a 50/50 average keeps the texture's amplitude; misaligned it would lose part of it.
        let n = cells[0].len().min(cells[2].len());
        let avg: Vec<f64> = (0..n).map(|k| 0.5 * (cells[0][k] + cells[2][k])).collect();
        let rms = |x: &[f64]| (x.iter().map(|y| y * y).sum::<f64>() / x.len() as f64).sqrt();
        assert!(rms(&avg) > 0.97 * rms(&cells[0][..n]), "{} vs {}", rms(&avg), rms(&cells[0][..n]));
    }

    #[test]
    fn off_short_or_flat_cells_are_left_as_they_are() {
        let mut cells = vec![vec![1.0; 500], vec![0.5; 500]];
        let before = cells.clone();
        let s = align(&mut cells, &[3.0, 3.0], 1000.0, 0.0);
        assert_eq!(cells, before);
        assert!(s.iter().all(|s| s.trimmed == 0));
        let s = align(&mut cells, &[3.0, 3.0], 1000.0, 1.0);
        assert!(s[1].correlation.is_nan() && s[1].delta_cm == 0.0, "{s:?}");
        assert_eq!(cells, before, "flat cells: nothing to align");
        let mut short = vec![vec![0.0, 1.0, 0.0], vec![1.0, 0.0, 1.0]];
        let s = align(&mut short, &[3.0, 3.0], 1000.0, 1.0);
        assert!(s[1].correlation.is_nan());
        assert!(align(&mut [], &[], 1000.0, 1.0).is_empty());
    }
}
