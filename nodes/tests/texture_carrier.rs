//! Cells that ride a Nyquist-rate carrier (`condition.carrier = "nyquist"`,
//! the optimized synthesis' cells): `interp` interpolates their envelopes
//! and `playback` puts the carrier back at its own output rate, so the
//! improved scheme's re-sampling — whose anti-alias filter removes
//! everything near the Nyquist rate — keeps them. Checked on a grid whose
//! envelopes are the sines of §6.2 on an offset.

use crate::texture_util;

use evflow_nodes::texture::grid::{Grid, GridSource};
use std::path::Path;
use texture_util::{amplitudes, run_chain, sine, write_cell};

const INTERP: &str = "folder = \"grid\"\nloop = 6.0";
const TIME: &str = "mode = \"time\"";

/// The envelope of the cell at `v` cm/s: 1 + 0.5·sin(2π·v·t) (a texture of
/// one cycle per cm on an offset, as the optimized envelopes sit on theirs).
fn envelope(v: f64) -> Vec<f64> {
    sine(v, 0.5, 8000).into_iter().map(|x| 1.0 + x).collect()
}

/// Velocities 10 and 20 cm/s at 85 g, u[n] = (−1)ⁿ·a[n]; `carrier` is
/// written into each sidecar's condition (None: not at all).
fn carrier_grid(dir: &Path, carrier: &[Option<&str>; 2]) {
    let grid = dir.join("grid");
    std::fs::create_dir_all(&grid).unwrap();
    for (v, c) in [10.0, 20.0].into_iter().zip(carrier) {
        let u: Vec<f64> = envelope(v).iter().enumerate().map(|(n, a)| if n % 2 == 0 { *a } else { -a }).collect();
        let name = format!("cell_85g_{v}cms");
        write_cell(&grid, &name, 85.0, v, &u);
        if let Some(c) = c {
            let path = grid.join(format!("{name}.json"));
            let mut doc: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
            doc["condition"]["carrier"] = serde_json::json!(c);
            std::fs::write(&path, serde_json::to_string_pretty(&doc).unwrap()).unwrap();
        }
    }
}

/// `y[o]·(−1)ᵒ`: the envelope of an output on the carrier.
fn demodulate(y: &[f64]) -> Vec<f64> {
    y.iter().enumerate().map(|(o, x)| if o % 2 == 0 { *x } else { -x }).collect()
}

fn share_above(y: &[f64], fraction: f64) -> f64 {
    let a = amplitudes(y);
    let k = (a.len() as f64 * fraction) as usize;
    let p = |s: &[f64]| s.iter().map(|x| x * x).sum::<f64>();
    p(&a[k..]) / p(&a)
}

#[test]
fn a_carriers_envelope_is_interpolated_and_the_carrier_put_back() {
    let dir = tempfile::tempdir().unwrap();
    carrier_grid(dir.path(), &[Some("nyquist"), Some("nyquist")]);
    let n = 3000;
    let out = run_chain(dir.path(), INTERP, TIME, &vec![85.0; n], &vec![15.0; n], n as u64, 4096).unwrap();
    let played = &out[200..];
    // The output rides the carrier: (nearly) all its power at the top of the band.
    assert!(share_above(played, 0.9) > 0.95, "{}", share_above(played, 0.9));
    // Its envelope is the improved scheme's: one full 15 Hz peak on the offset
    // (Fig. 6.2), nothing left at the cells' 10 and 20 Hz.
    let env = demodulate(&out);
    let a = amplitudes(&env[200..]);
    assert!((a[15] - 0.5).abs() < 0.02, "15 Hz {}", a[15]);
    assert!(a[10] < 0.01 && a[20] < 0.01, "{} {}", a[10], a[20]);
    let mean = env[200..].iter().sum::<f64>() / (n - 200) as f64;
    assert!((mean - 1.0).abs() < 0.01, "offset {mean}");
}

#[test]
fn without_the_carrier_the_improved_scheme_filters_such_cells_away() {
    // The same cells, not marked: re-sampling (even by 1, at a trained
    // velocity) low-passes below the Nyquist rate, and nearly nothing is left.
    let dir = tempfile::tempdir().unwrap();
    carrier_grid(dir.path(), &[None, None]);
    let n = 3000;
    let rms = |y: &[f64]| (y.iter().map(|x| x * x).sum::<f64>() / y.len() as f64).sqrt();
    let plain = run_chain(dir.path(), INTERP, TIME, &vec![85.0; n], &vec![10.0; n], n as u64, 4096).unwrap();
    let marked = format!("{INTERP}\ncarrier = \"nyquist\"");
    let kept = run_chain(dir.path(), &marked, TIME, &vec![85.0; n], &vec![10.0; n], n as u64, 4096).unwrap();
    // The cell's RMS is √(1 + 0.5²/2) ≈ 1.06.
    assert!(rms(&kept[200..]) > 1.0, "{}", rms(&kept[200..]));
    assert!(rms(&plain[200..]) < 0.2 * rms(&kept[200..]), "{} vs {}", rms(&plain[200..]), rms(&kept[200..]));
    // `carrier = "nyquist"` on the node does what the sidecars would.
    carrier_grid(dir.path(), &[Some("nyquist"), Some("nyquist")]);
    let auto = run_chain(dir.path(), INTERP, TIME, &vec![85.0; n], &vec![10.0; n], n as u64, 4096).unwrap();
    assert!(auto.iter().zip(&kept).all(|(a, b)| a.to_bits() == b.to_bits()));
}

#[test]
fn carrier_tables_play_alike_in_blocks_and_ticks_and_in_both_modes() {
    let dir = tempfile::tempdir().unwrap();
    carrier_grid(dir.path(), &[Some("nyquist"), Some("nyquist")]);
    let n = 1500;
    let v: Vec<f64> = (0..n).map(|i| 12.0 + 6.0 * (i as f64 / 200.0).sin()).collect();
    for pb in [TIME, "mode = \"position\""] {
        let tick = run_chain(dir.path(), INTERP, pb, &vec![85.0; n], &v, n as u64, 1).unwrap();
        let block = run_chain(dir.path(), INTERP, pb, &vec![85.0; n], &v, n as u64, 333).unwrap();
        assert!(tick.iter().zip(&block).all(|(a, b)| a.to_bits() == b.to_bits()), "{pb}");
        // Bounded by the envelope's peak, 1.5, through every switch.
        assert!(tick.iter().all(|y| y.is_finite() && y.abs() <= 1.5 + 1e-9), "{pb}");
    }
    // At the table's own velocity the position-locked playhead plays what time does.
    let t = run_chain(dir.path(), INTERP, TIME, &vec![85.0; n], &vec![13.0; n], n as u64, 512).unwrap();
    let p =
        run_chain(dir.path(), INTERP, "mode = \"position\"", &vec![85.0; n], &vec![13.0; n], n as u64, 512).unwrap();
    let worst = t.iter().zip(&p).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    assert!(worst < 1e-6, "{worst}");
}

#[test]
fn a_grid_says_whether_its_cells_ride_a_carrier_and_they_must_agree() {
    let dir = tempfile::tempdir().unwrap();
    let src = |d: &Path| GridSource { folder: Some(d.join("grid")), ..GridSource::default() };
    carrier_grid(dir.path(), &[Some("nyquist"), Some("nyquist")]);
    assert!(Grid::load(&src(dir.path())).unwrap().carrier);
    carrier_grid(dir.path(), &[Some("none"), None]);
    assert!(!Grid::load(&src(dir.path())).unwrap().carrier);
    carrier_grid(dir.path(), &[Some("nyquist"), None]);
    let e = Grid::load(&src(dir.path())).unwrap_err().to_string();
    assert!(e.contains("cell_85g_20cms.json") && e.contains("has no carrier") && e.contains("must agree"), "{e}");
    carrier_grid(dir.path(), &[Some("am"), Some("am")]);
    let e = Grid::load(&src(dir.path())).unwrap_err().to_string();
    assert!(e.contains("cell_85g_10cms.json") && e.contains("condition.carrier is \"am\""), "{e}");
}
