//! Extreme cases of interpolation and playback: a resting finger, conditions
//! outside the grid (clamped, §6.4), sudden reversals, one-row and
//! one-column grids, a velocity ratio of 10, missing and duplicate cells,
//! and cells outside the session's range never being opened.

use crate::texture_util;

use evflow_nodes::texture::grid::{Grid, GridError, GridSource};
use evflow_nodes::texture::kernel::SincKernel;
use evflow_nodes::texture::scheme::{Geometry, Mix, Scheme};
use std::path::Path;
use texture_util::{amplitudes, peak, run_chain, sine, write_cell, write_sine_grid};

fn folder(dir: &Path) -> GridSource {
    GridSource { folder: Some(dir.to_path_buf()), ..GridSource::default() }
}

#[test]
fn a_resting_finger_gets_silence_without_nan() {
    let dir = tempfile::tempdir().unwrap();
    write_sine_grid(&dir.path().join("grid"), &[60.0, 110.0], &[3.0, 7.0], 5.0, |_, _| 1.0);
    let n = 2000;
    for pb in ["mode = \"time\"", "mode = \"position\""] {
        // At rest from the start: the speed 0 is clamped to v_min by interp,
        // and playback stays silent.
        let out = run_chain(dir.path(), "folder = \"grid\"", pb, &vec![85.0; n], &vec![0.0; n], n as u64, 64).unwrap();
        assert!(out.iter().all(|y| *y == 0.0), "{pb}");
        // Moving, then stopping at t = 1 s: silent within rest_fade (10 ms).
        let v: Vec<f64> = (0..n).map(|i| if i < 1000 { 5.0 } else { 0.0 }).collect();
        let out = run_chain(dir.path(), "folder = \"grid\"", pb, &vec![85.0; n], &v, n as u64, 64).unwrap();
        assert!(out[300..1000].iter().any(|y| y.abs() > 0.5), "{pb}: plays while moving");
        assert!(out[1010..].iter().all(|y| *y == 0.0), "{pb}: silent at rest");
        let jump = out[990..1012].windows(2).map(|w| (w[1] - w[0]).abs()).fold(0.0, f64::max);
        assert!(jump < 0.25, "{pb}: fade, not a click: {jump}");
    }
}

#[test]
fn conditions_outside_the_grid_take_the_extremes() {
    let dir = tempfile::tempdir().unwrap();
    write_sine_grid(dir.path(), &[60.0, 110.0], &[3.0, 5.0, 7.0], 5.0, |m, _| m / 110.0);
    let g = Grid::load(&folder(dir.path())).unwrap();
    let k = SincKernel::default();
    let geo = Geometry::new(&g, &k, 6000, 10, 0.0).unwrap();
    let table = |m: f64, v: f64| Mix::new(&g, &geo, &k, Scheme::Improved, m, v).table(&g, &k);
    assert_eq!(table(500.0, 50.0), table(110.0, 7.0));
    assert_eq!(table(-5.0, 1.0), table(60.0, 3.0));
    assert_eq!(table(0.0, -50.0), table(60.0, 7.0), "the speed's magnitude is used");
    assert_eq!(table(f64::NAN, f64::INFINITY), table(60.0, 3.0));
    let mix = Mix::new(&g, &geo, &k, Scheme::Improved, 500.0, 50.0);
    assert_eq!((mix.load, mix.velocity, mix.i, mix.j), (110.0, 7.0, [1, 1], [2, 2]));
    // At 7 cm/s the texture of 5 cycles per cm plays at 35 Hz, full amplitude.
    let a = amplitudes(&table(500.0, 50.0));
    assert_eq!(peak(&a), 35);
    assert!((a[35] - 1.0).abs() < 0.01);
}

#[test]
fn sudden_reversals_play_the_same_texture_backwards() {
    let dir = tempfile::tempdir().unwrap();
    write_sine_grid(&dir.path().join("grid"), &[85.0], &[10.0, 20.0], 1.0, |_, _| 1.0);
    let n = 1600;
    let turn = 1000;
    let v: Vec<f64> = (0..n).map(|i| if i < turn { 15.0 } else { -15.0 }).collect();
    let out =
        run_chain(dir.path(), "folder = \"grid\"\nloop = 6.0", "mode = \"position\"", &vec![85.0; n], &v, n as u64, 1)
            .unwrap();
    // The playhead retraces its path: sample turn + k is sample turn − k.
    for k in 0..500 {
        assert!((out[turn + k] - out[turn - k]).abs() < 1e-9, "k = {k}: {} vs {}", out[turn + k], out[turn - k]);
    }
    let jump = out.windows(2).skip(200).map(|w| (w[1] - w[0]).abs()).fold(0.0, f64::max);
    assert!(jump < 0.1, "no click at the reversal: {jump}");
}

#[test]
fn one_load_one_velocity_and_a_single_cell_work() {
    let dir = tempfile::tempdir().unwrap();
    // One velocity, two loads: only the mass step remains.
    write_sine_grid(&dir.path().join("col"), &[60.0, 110.0], &[4.0], 5.0, |m, _| m / 110.0);
    // One load, two velocities: only the velocity step remains.
    write_sine_grid(&dir.path().join("row"), &[85.0], &[3.0, 6.0], 5.0, |_, _| 1.0);
    // A single cell.
    write_sine_grid(&dir.path().join("one"), &[85.0], &[4.0], 5.0, |_, _| 0.5);
    let k = SincKernel::default();
    for (name, m, v, f, amp) in [
        ("col", 85.0, 9.0, 20.0, 0.5 * (60.0 / 110.0) + 0.5),
        ("row", 10.0, 5.0, 25.0, 1.0),
        ("one", 300.0, 0.0, 20.0, 0.5),
    ] {
        let g = Grid::load(&folder(&dir.path().join(name))).unwrap();
        let geo = Geometry::new(&g, &k, 6000, 0, 0.0).unwrap();
        let a = amplitudes(&Mix::new(&g, &geo, &k, Scheme::Improved, m, v).table(&g, &k));
        assert_eq!(peak(&a), f as usize, "{name}");
        assert!((a[f as usize] - amp).abs() < 0.01, "{name}: {} vs {amp}", a[f as usize]);
        // And the nodes run on it.
        let out = run_chain(
            dir.path(),
            &format!("folder = \"{name}\""),
            "mode = \"time\"",
            &vec![m; 1000],
            &vec![v.max(1.0); 1000],
            1000,
            128,
        )
        .unwrap();
        assert!(out.iter().all(|y| y.is_finite()) && out[300..].iter().any(|y| y.abs() > 0.1), "{name}");
    }
}

#[test]
fn a_velocity_ratio_of_ten() {
    // 2 and 20 cm/s; a texture of 2.5 cycles per cm: 5 Hz and 50 Hz.
    let dir = tempfile::tempdir().unwrap();
    write_sine_grid(dir.path(), &[85.0], &[2.0, 20.0], 2.5, |_, _| 1.0);
    let g = Grid::load(&folder(dir.path())).unwrap();
    let k = SincKernel::default();
    let geo = Geometry::new(&g, &k, 8000, 0, 0.0).unwrap();
    for (v, f) in [(8.0, 20usize), (16.0, 40), (3.2, 8)] {
        let a = amplitudes(&Mix::new(&g, &geo, &k, Scheme::Improved, 85.0, v).table(&g, &k));
        assert_eq!(peak(&a), f, "{v} cm/s");
        assert!((a[f] - 1.0).abs() < 0.01, "{v} cm/s: {}", a[f]);
        assert!(a[5] < 0.01 && a[50] < 0.01, "{v} cm/s: grid components left: {} {}", a[5], a[50]);
    }
}

#[test]
fn a_missing_cell_is_a_clear_error_at_load() {
    let dir = tempfile::tempdir().unwrap();
    write_cell(dir.path(), "a", 60.0, 3.0, &sine(15.0, 1.0, 4000));
    write_cell(dir.path(), "b", 60.0, 5.0, &sine(25.0, 1.0, 4000));
    write_cell(dir.path(), "c", 110.0, 3.0, &sine(15.0, 1.0, 4000));
    let err = Grid::load(&folder(dir.path())).unwrap_err();
    assert!(matches!(err, GridError::MissingCell { load: 110.0, velocity: 5.0, .. }), "{err}");
    let msg = err.to_string();
    assert!(msg.contains("load 110 g, velocity 5 cm/s is missing") && msg.contains("3 of 4"), "{msg}");
    // A session that cannot reach the missing cell loads fine.
    let src = GridSource { velocity_range: Some((3.0, 3.0)), ..folder(dir.path()) };
    let g = Grid::load(&src).unwrap();
    assert_eq!((g.loads.clone(), g.velocities.clone()), (vec![60.0, 110.0], vec![3.0]));
    // Through the node: the build fails with the same message.
    let out = run_chain(dir.path(), "folder = \".\"", "mode = \"time\"", &[85.0], &[4.0], 1, 1).unwrap_err();
    assert!(out.contains("interp") && out.contains("is missing"), "{out}");
}

#[test]
fn duplicates_and_conditionless_recordings_are_errors() {
    let dir = tempfile::tempdir().unwrap();
    write_cell(dir.path(), "a", 60.0, 3.0, &sine(15.0, 1.0, 4000));
    write_cell(dir.path(), "a_again", 60.0, 3.0, &sine(15.0, 1.0, 4000));
    let err = Grid::load(&folder(dir.path())).unwrap_err().to_string();
    assert!(err.contains("both hold the cell load 60 g, velocity 3 cm/s"), "{err}");
    // An explicit path without a condition.
    use evflow_nodes::recording::format::{Channel, RecordingMeta, RecordingWriter};
    let mut w =
        RecordingWriter::create(&dir.path().join("plain"), RecordingMeta::new(1000.0, vec![Channel::new("u", "")]))
            .unwrap();
    w.write_frame(&[0.0]).unwrap();
    w.finish().unwrap();
    let src = GridSource { paths: vec![dir.path().join("plain.wav")], ..GridSource::default() };
    let err = Grid::load(&src).unwrap_err().to_string();
    assert!(err.contains("plain.json") && err.contains("lacks load_g or velocity_cm_s"), "{err}");
}

#[test]
fn cells_out_of_the_sessions_reach_are_never_opened() {
    let dir = tempfile::tempdir().unwrap();
    write_sine_grid(dir.path(), &[60.0, 85.0, 110.0], &[3.0, 5.0], 5.0, |_, _| 1.0);
    // Break the 110 g recordings' samples (the sidecars stay valid).
    for v in [3.0, 5.0] {
        std::fs::write(dir.path().join(format!("cell_110g_{v}cms.wav")), b"not a wav").unwrap();
    }
    let src = GridSource { load_range: Some((60.0, 85.0)), ..folder(dir.path()) };
    let g = Grid::load(&src).unwrap();
    assert_eq!(g.loads, vec![60.0, 85.0]);
    let err = Grid::load(&folder(dir.path())).unwrap_err().to_string();
    assert!(err.contains("cell_110g_3cms.wav"), "{err}");
}
