//! `interp` → `playback` end to end: the played signal's spectrum, block ≡
//! tick, time and position modes, and switching tables without a click.

use crate::texture_util;

use texture_util::{amplitudes, peak, run_chain, write_cell, write_sine_grid};

/// A loop of 6 cm: six periods of the one-cycle-per-cm texture, so the
/// loop itself has no seam and the spectra are those of pure sines.
const INTERP: &str = "folder = \"grid\"\nloop = 6.0";
const TIME: &str = "mode = \"time\"";

fn sine_grid(dir: &std::path::Path) {
    // One load, velocities 10 and 20 cm/s, a texture of one cycle per cm.
    write_sine_grid(&dir.join("grid"), &[85.0], &[10.0, 20.0], 1.0, |_, _| 1.0);
}

#[test]
fn the_played_signal_has_the_interpolated_frequency() {
    let dir = tempfile::tempdir().unwrap();
    sine_grid(dir.path());
    let n = 3000;
    let out = run_chain(dir.path(), INTERP, TIME, &vec![85.0; n], &vec![15.0; n], n as u64, 4096).unwrap();
    // The first table is complete after one update period (100 ms), then fades in over 20 ms.
    assert!(out[..100].iter().all(|y| *y == 0.0));
    let a = amplitudes(&out[200..]);
    assert_eq!(peak(&a), 15);
    assert!((a[15] - 1.0).abs() < 0.02, "{}", a[15]);
    assert!(a[10] < 0.01 && a[20] < 0.01, "{} {}", a[10], a[20]);

    // The basic scheme plays both grid frequencies at half amplitude.
    let basic = format!("{INTERP}\nscheme = \"basic\"");
    let out = run_chain(dir.path(), &basic, TIME, &vec![85.0; n], &vec![15.0; n], n as u64, 4096).unwrap();
    let a = amplitudes(&out[200..]);
    assert!((a[10] - 0.5).abs() < 0.02 && (a[20] - 0.5).abs() < 0.02, "{} {}", a[10], a[20]);
    assert!(a[15] < 0.01);
}

#[test]
fn block_and_tick_processing_are_identical() {
    let dir = tempfile::tempdir().unwrap();
    sine_grid(dir.path());
    let n = 1500;
    let v: Vec<f64> = (0..n).map(|i| 25.0 * (i as f64 / 300.0).sin()).collect();
    let m: Vec<f64> = (0..n).map(|i| 60.0 + i as f64 / 10.0).collect();
    for pb in [TIME, "mode = \"position\"\ncrossfade = 35.0"] {
        let tick = run_chain(dir.path(), INTERP, pb, &m, &v, n as u64, 1).unwrap();
        for block in [7, 100, 4096] {
            let blk = run_chain(dir.path(), INTERP, pb, &m, &v, n as u64, block).unwrap();
            assert!(tick.iter().zip(&blk).all(|(a, b)| a.to_bits() == b.to_bits()), "{pb}, block {block}");
        }
        assert!(tick.iter().all(|y| y.is_finite() && y.abs() <= 1.5));
    }
}

#[test]
fn position_mode_at_the_tables_velocity_plays_like_time_mode() {
    let dir = tempfile::tempdir().unwrap();
    sine_grid(dir.path());
    let n = 2000;
    let t = run_chain(dir.path(), INTERP, TIME, &vec![85.0; n], &vec![13.0; n], n as u64, 512).unwrap();
    let p =
        run_chain(dir.path(), INTERP, "mode = \"position\"", &vec![85.0; n], &vec![13.0; n], n as u64, 512).unwrap();
    let worst = t.iter().zip(&p).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    assert!(worst < 1e-6, "{worst}");
}

#[test]
fn a_lookahead_plays_the_texture_that_many_samples_early() {
    // At a constant velocity the playhead moves by equal steps: reading L
    // samples ahead is the same signal L samples earlier, in both modes
    // (after the first table's fade-in and away from table switches).
    let dir = tempfile::tempdir().unwrap();
    sine_grid(dir.path());
    let n = 3000;
    let l = 15;
    for mode in ["time", "position"] {
        let now = format!("mode = \"{mode}\"\ncrossfade = 0.0");
        let ahead = format!("{now}\nlookahead = {l}");
        let a = run_chain(dir.path(), INTERP, &now, &vec![85.0; n], &vec![13.0; n], n as u64, 64).unwrap();
        let b = run_chain(dir.path(), INTERP, &ahead, &vec![85.0; n], &vec![13.0; n], n as u64, 64).unwrap();
        let worst = (300..n - l).map(|k| (b[k] - a[k + l]).abs()).fold(0.0, f64::max);
        assert!(worst < 1e-9, "{mode}: {worst}");
        assert!(b.iter().any(|x| x.abs() > 0.1), "{mode}: something plays");
    }
}

#[test]
fn switching_tables_does_not_click() {
    let dir = tempfile::tempdir().unwrap();
    sine_grid(dir.path());
    let n = 3000;
    // The finger jumps from 11 to 19 cm/s and back: the tables change from
    // 11 Hz to 19 Hz sines. The largest step between samples of a unit sine
    // at 19 Hz is 2π·19/1000 ≈ 0.12; a click would be a step of up to 2.
    let v: Vec<f64> = (0..n).map(|i| if (i / 700) % 2 == 0 { 11.0 } else { 19.0 }).collect();
    for pb in [TIME, "mode = \"position\""] {
        let out = run_chain(dir.path(), INTERP, pb, &vec![85.0; n], &v, n as u64, 64).unwrap();
        let jump = out.windows(2).map(|w| (w[1] - w[0]).abs()).fold(0.0, f64::max);
        assert!(jump < 0.13, "{pb}: largest step {jump}");
        // Without the crossfade the same switches do click.
        let hard = format!("{pb}\ncrossfade = 0.0");
        let out = run_chain(dir.path(), INTERP, &hard, &vec![85.0; n], &v, n as u64, 64).unwrap();
        let jump_hard = out.windows(2).map(|w| (w[1] - w[0]).abs()).fold(0.0, f64::max);
        assert!(jump_hard > 2.0 * jump, "{pb}: {jump_hard} vs {jump}");
    }
}

#[test]
fn playback_ignores_what_is_not_a_table() {
    use evflow_engine::harness::Single;
    let noise: Vec<f64> = (0..4000).map(|i| ((i * 7919) % 101) as f64 / 50.0 - 1.0).collect();
    let single = Single::new(&evflow_nodes::texture::playback::SPEC, "mode = \"time\"")
        .input("table", noise.clone(), 1000.0)
        .input("velocity", vec![5.0; 4000], 1000.0)
        .output("out")
        .ticks(4000)
        .block(256);
    assert!(single.run().unwrap()[0].iter().all(|y| *y == 0.0));
    let s = single.summary().unwrap();
    assert_eq!(s.get("tables"), Some(0.0));
    assert_eq!(s.get("rejected_frames"), Some(40.0));
}

#[test]
fn a_loop_of_whole_texture_periods_keeps_the_main_component_in_phase() {
    let dir = tempfile::tempdir().unwrap();
    sine_grid(dir.path());
    let n = 3000;
    // The longest loop is 1980 samples at 10 cm/s: 19.8 cm, 19.8 periods of
    // the texture, so the seam (100 ms + 1980 samples in: the first table
    // arrives after one update) jumps 0.8 of a period; `period = 1.0` makes
    // it 19 whole periods. One second around the first seam:
    let level = |interp: &str| {
        let out = run_chain(dir.path(), interp, TIME, &vec![85.0; n], &vec![10.0; n], n as u64, 1024).unwrap();
        amplitudes(&out[1580..2580])[10]
    };
    let whole = level("folder = \"grid\"\nperiod = 1.0");
    let cut = level("folder = \"grid\"");
    assert!((whole - 1.0).abs() < 0.02, "{whole}");
    // Halves of a Hann window 0.8 of a cycle apart: |cos(0.8·π)| ≈ 0.81.
    assert!(cut < 0.85, "a seam 0.8 of a period out of phase left the 10 Hz component at {cut}");
    let e = run_chain(dir.path(), "folder = \"grid\"\nperiod = 25.0", TIME, &[85.0], &[10.0], 1, 1).unwrap_err();
    assert!(e.contains("period") && e.contains("longer than the loop"), "{e}");
}

#[test]
fn cells_recorded_from_different_places_cancel_unless_aligned_in_position() {
    // Two loads at one velocity, the same 1 cycle/cm texture recorded half a
    // period apart: averaged at the middle load they cancel; aligned first,
    // they add up to the texture's full amplitude.
    let dir = tempfile::tempdir().unwrap();
    let grid = dir.path().join("grid");
    std::fs::create_dir_all(&grid).unwrap();
    let (v, n) = (10.0, 8000);
    let wave = |x0: f64| -> Vec<f64> {
        (0..n).map(|i| (std::f64::consts::TAU * (x0 + i as f64 * v / 1000.0)).sin()).collect()
    };
    write_cell(&grid, "light", 60.0, v, &wave(0.0));
    write_cell(&grid, "heavy", 110.0, v, &wave(0.5));
    let ticks = 3000;
    let (m, vel) = (vec![85.0; ticks], vec![v; ticks]);
    let played = |align: f64| {
        let interp = format!(
            "{INTERP}
align = {align}"
        );
        let out = run_chain(dir.path(), &interp, TIME, &m, &vel, ticks as u64, 512).unwrap();
        amplitudes(&out[200..])[10]
    };
    let (misaligned, aligned) = (played(0.0), played(1.0));
    assert!(misaligned < 0.02, "{misaligned}");
    assert!((aligned - 1.0).abs() < 0.03, "{aligned}");
}
