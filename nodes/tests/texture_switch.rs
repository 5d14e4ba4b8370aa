//! Switching textures live: `interp` loads every grid of `textures` when it
//! is built, and its live parameter `texture` picks the one played from the
//! next table on; `playback` crossfades into it, so the switch is heard at
//! once and without a click, and a replay at any block size applies it at
//! the same tick.

use crate::texture_util;

use texture_util::{amplitudes, peak, run_chain, run_chain_with, write_sine_grid};

/// Two textures of 5 and 2 cycles per cm over one grid of 85 g × 4, 6 cm/s.
fn two_textures() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    write_sine_grid(&dir.path().join("fine"), &[85.0], &[4.0, 6.0], 5.0, |_, _| 1.0);
    write_sine_grid(&dir.path().join("coarse"), &[85.0], &[4.0, 6.0], 2.0, |_, _| 1.0);
    dir
}

const TEXTURES: &str = "textures = [\"fine\", \"coarse\"]";

#[test]
fn a_texture_change_plays_the_other_grid_from_the_next_table_without_a_click() {
    let dir = two_textures();
    let n = 3000;
    let (load, vel) = (vec![85.0; n], vec![5.0; n]);
    let switch = 1500u64;
    let out =
        run_chain_with(dir.path(), TEXTURES, "mode = \"time\"", &load, &vel, n as u64, 1, &[(switch, "texture", 1.0)])
            .unwrap();
    // At 5 cm/s: 5 cycles/cm → 25 Hz before, 2 cycles/cm → 10 Hz after.
    let before = amplitudes(&out[400..1400]);
    let after = amplitudes(&out[1900..3000]);
    assert_eq!(peak(&before), 25, "the first texture before the switch");
    assert_eq!(peak(&after), 10, "the second texture after it");
    assert!(
        after[10] > 0.9 && after[25] < 0.05,
        "all of the new texture, none of the old: {} {}",
        after[10],
        after[25]
    );
    // Heard within one update period (100 ms) plus the table's latency (100 ms) and the crossfade.
    let settled = amplitudes(&out[switch as usize + 220..switch as usize + 1220]);
    assert_eq!(peak(&settled), 10);
    // No click: the steepest step around the switch is no steeper than the
    // steepest step of a 25 Hz sine of amplitude 1 at 1 kHz (2π·25/1000 = 0.157).
    let steep = out[switch as usize..switch as usize + 400].windows(2).map(|w| (w[1] - w[0]).abs()).fold(0.0, f64::max);
    assert!(steep < 0.2, "steepest step around the switch {steep}");
    // The same at any block size, as a replay applies it.
    let blocks =
        run_chain_with(dir.path(), TEXTURES, "mode = \"time\"", &load, &vel, n as u64, 64, &[(switch, "texture", 1.0)])
            .unwrap();
    assert_eq!(out, blocks);
}

#[test]
fn the_starting_texture_and_out_of_range_indices() {
    let dir = two_textures();
    let n = 1500;
    let (load, vel) = (vec![85.0; n], vec![5.0; n]);
    let start_coarse = format!("{TEXTURES}\ntexture = 1");
    let out = run_chain(dir.path(), &start_coarse, "", &load, &vel, n as u64, 32).unwrap();
    assert_eq!(peak(&amplitudes(&out[400..1400])), 10, "`texture = 1` starts on the second grid");
    let e = run_chain(dir.path(), &format!("{TEXTURES}\ntexture = 2"), "", &load, &vel, 10, 1).unwrap_err();
    assert!(e.contains("texture") && e.contains("2 is not an index into the 2 texture(s)"), "{e}");
    // A live change to an index beyond the list is refused; the texture stays.
    let e = run_chain_with(dir.path(), TEXTURES, "", &load, &vel, n as u64, 1, &[(10, "texture", 2.0)]).unwrap_err();
    assert!(e.contains("tick 10") && e.contains("texture"), "{e}");
    // `textures` with `folder` is one source too many.
    let e = run_chain(dir.path(), &format!("{TEXTURES}\nfolder = \"fine\""), "", &load, &vel, 10, 1).unwrap_err();
    assert!(e.contains("give one of `folder`"), "{e}");
}

#[test]
fn a_texture_whose_rate_differs_is_refused_naming_it() {
    let dir = two_textures();
    let odd = dir.path().join("odd");
    std::fs::create_dir_all(&odd).unwrap();
    let mut meta = evflow_nodes::recording::format::RecordingMeta::new(
        2000.0,
        vec![evflow_nodes::recording::format::Channel::new("u", "1")],
    );
    meta.condition.load_g = Some(85.0);
    meta.condition.velocity_cm_s = Some(5.0);
    let mut w = evflow_nodes::recording::format::RecordingWriter::create(&odd.join("cell"), meta).unwrap();
    for k in 0..4000 {
        w.write_frame(&[(k as f64 * 0.1).sin()]).unwrap();
    }
    w.finish().unwrap();
    let e = run_chain(dir.path(), "textures = [\"fine\", \"odd\"]", "", &[85.0; 10], &[5.0; 10], 10, 1).unwrap_err();
    assert!(e.contains("grid odd") && e.contains("2000 Hz") && e.contains("same rate"), "{e}");
}
