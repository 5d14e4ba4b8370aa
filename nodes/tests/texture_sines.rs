//! The sine examples of dissertation §6.1–6.2 (Figs. 6.1–6.4), as tests of
//! the operators (𝒲𝒜 Eq. 6.1, 𝓡𝓢 §6.2) and of the schemes over a grid
//! whose cells are those sines (velocity standing for frequency, §6.3).

use crate::texture_util;

use evflow_nodes::texture::grid::Grid;
use evflow_nodes::texture::kernel::SincKernel;
use evflow_nodes::texture::rs::{rs, RsMethod};
use evflow_nodes::texture::scheme::{Geometry, Mix, Scheme};
use evflow_nodes::texture::wa::wa;
use texture_util::{amplitudes, peak, sine};

/// A one-load grid with cells y₁ = a₁·sin(2π·10t) at "velocity" 10 and
/// y₂ = a₂·sin(2π·20t) at 20: a texture of one cycle per cm.
fn grid(a1: f64, a2: f64) -> Grid {
    Grid::from_signals(vec![85.0], vec![10.0, 20.0], 1000.0, vec![vec![sine(10.0, a1, 8000), sine(20.0, a2, 8000)]])
}

fn table(g: &Grid, scheme: Scheme, v: f64) -> Vec<f64> {
    let k = SincKernel::default();
    let geo = Geometry::new(g, &k, 8000, 0, 0.0).unwrap();
    let mix = Mix::new(g, &geo, &k, scheme, 85.0, v);
    mix.table(g, &k)
}

/// Every bin of `a` is within 0.005 of the spectrum of amplitude·sin(2π·f·t).
fn assert_matches_single_sine(a: &[f64], f: f64, amplitude: f64) {
    let want = amplitudes(&sine(f, amplitude, 3000));
    let worst = a.iter().zip(&want).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
    assert!(worst < 0.005, "largest difference from a single {f} Hz sine: {worst}");
}

fn near(x: f64, want: f64, tol: f64) -> bool {
    (x - want).abs() <= tol
}

/// §6.1, Fig. 6.1: y₃ = 0.5·y₁ + 0.5·y₂ has two half-amplitude peaks at 10
/// and 20 Hz (a quarter of the power each) and nothing at 15 Hz.
#[test]
fn basic_average_of_10_and_20_hz_gives_two_half_peaks() {
    let y = wa(&sine(10.0, 1.0, 4000), &sine(20.0, 1.0, 4000), 10.0, 20.0, 15.0);
    let a = amplitudes(&y);
    assert!(near(a[10], 0.5, 0.01) && near(a[20], 0.5, 0.01), "10 Hz {} 20 Hz {}", a[10], a[20]);
    assert!(a[15] < 0.01, "15 Hz {}", a[15]);

    // The basic scheme over the grid does the same.
    let a = amplitudes(&table(&grid(1.0, 1.0), Scheme::Basic, 15.0));
    assert!(near(a[10], 0.5, 0.01) && near(a[20], 0.5, 0.01), "basic: 10 Hz {} 20 Hz {}", a[10], a[20]);
    assert!(a[15] < 0.01);
}

/// §6.2, Fig. 6.2: re-sampling y₁ by 10/15 and y₂ by 20/15 and averaging
/// gives a single peak at 15 Hz with the full amplitude (and power).
#[test]
fn resampled_average_of_10_and_20_hz_gives_one_full_peak_at_15() {
    for m in [RsMethod::RubatoSinc(128), RsMethod::RubatoFft, RsMethod::Kernel(16)] {
        let y1 = rs(&sine(10.0, 1.0, 6000), 10.0, 15.0, m).unwrap();
        let y2 = rs(&sine(20.0, 1.0, 6000), 20.0, 15.0, m).unwrap();
        let y3 = wa(&y1[..3000], &y2[..3000], 10.0, 20.0, 15.0);
        let a = amplitudes(&y3);
        assert_eq!(peak(&a), 15, "{m:?}");
        // Full amplitude: the two re-sampled sines are in phase (rubato's
        // whole-sample delay trimming costs at most cos(0.047) ≈ 0.999).
        assert!(near(a[15], 1.0, 0.01), "{m:?}: {}", a[15]);
        assert!(a[10] < 0.01 && a[20] < 0.01, "{m:?}: {} {}", a[10], a[20]);
    }
    // The improved scheme over the grid (Eq. 6.4 with velocity for frequency).
    let a = amplitudes(&table(&grid(1.0, 1.0), Scheme::Improved, 15.0));
    assert_eq!(peak(&a), 15);
    assert!(near(a[15], 1.0, 0.005), "{}", a[15]);
    assert!(a[10] < 0.005 && a[20] < 0.005);
}

/// §6.2, Fig. 6.3: A₁ = 1 at 10 Hz, A₂ = 0.4 at 20 Hz, f₃ = 19 Hz: weights
/// 0.1 and 0.9, so one peak at 19 Hz of amplitude 0.1·1 + 0.9·0.4 = 0.46.
#[test]
fn nineteen_hz_example() {
    let a = amplitudes(&table(&grid(1.0, 0.4), Scheme::Improved, 19.0));
    assert_eq!(peak(&a), 19);
    assert!(near(a[19], 0.46, 0.005), "{}", a[19]);
    // The whole spectrum is that of the single sine 0.46·sin(2π·19t): bin 20
    // holds only the Hann window's leakage from 19 Hz, not a 20 Hz component.
    assert_matches_single_sine(&a, 19.0, 0.46);
    // More like y₂ than y₁, as the dissertation notes.
    assert!((a[19] - 0.4).abs() < (a[19] - 1.0).abs());
}

/// §6.2, Fig. 6.4: y₁ = 0.3·sin(2π·10t), y₂ = sin(2π·20t), f₃ = 12 Hz:
/// weights 0.8 and 0.2, one peak at 12 Hz of amplitude 0.8·0.3 + 0.2 = 0.44.
#[test]
fn twelve_hz_example() {
    let a = amplitudes(&table(&grid(0.3, 1.0), Scheme::Improved, 12.0));
    assert_eq!(peak(&a), 12);
    assert!(near(a[12], 0.44, 0.005), "{}", a[12]);
    assert_matches_single_sine(&a, 12.0, 0.44);
}

/// At a grid velocity the improved scheme returns the cell itself (f₃ = f₁
/// gives y₁, §6.1), up to the kernel's error.
#[test]
fn at_a_grid_node_the_cell_comes_back() {
    let g = grid(1.0, 1.0);
    let t = table(&g, Scheme::Improved, 20.0);
    let k = SincKernel::default();
    let geo = Geometry::new(&g, &k, 8000, 0, 0.0).unwrap();
    let start = (geo.x0 * 1000.0 / 20.0) as usize;
    let frac = geo.x0 * 1000.0 / 20.0 - start as f64;
    let err = t
        .iter()
        .enumerate()
        .map(|(i, y)| (y - (std::f64::consts::TAU * 20.0 * (start as f64 + frac + i as f64) / 1000.0).sin()).abs())
        .fold(0.0, f64::max);
    assert!(err < 1e-3, "{err}");
}
